//! Reading small text files (JSON documents) with a size limit checked before the whole file
//! is read, so a wrong file given by mistake (a scan, a video) fails at once.

use crate::error::{ReadError, Result};
use std::io::Read;
use std::path::Path;

/// The content of `path` as UTF-8 text, or an error if it is larger than `max_bytes`;
/// `what` names the kind of file in that error ("a transfer function file").
pub(crate) fn read_text(path: &Path, max_bytes: u64, what: &str) -> Result<String> {
    let Some(bytes) = read_capped(path, max_bytes).map_err(|e| ReadError::io(path, e))? else {
        return Err(ReadError::format(
            path,
            format!("{what} is at most {max_bytes} bytes, this one is larger"),
        ));
    };
    String::from_utf8(bytes).map_err(|e| ReadError::format(path, format!("{what}: {e}")))
}

/// The bytes of `path`, or `None` when it holds more than `max_bytes` (read no further).
pub(crate) fn read_capped(path: &Path, max_bytes: u64) -> std::io::Result<Option<Vec<u8>>> {
    let mut bytes = Vec::new();
    std::fs::File::open(path)?
        .take(max_bytes + 1)
        .read_to_end(&mut bytes)?;
    Ok((bytes.len() as u64 <= max_bytes).then_some(bytes))
}
