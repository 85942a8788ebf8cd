//! Reading small text files (JSON documents) with a size limit checked before the whole file
//! is read, so a wrong file given by mistake (a scan, a video) fails at once.

use crate::error::{ReadError, Result};
use std::io::Read;
use std::path::Path;

/// The content of `path` as UTF-8 text, or an error if it is larger than `max_bytes`;
/// `what` names the kind of file in that error ("a transfer function file").
pub(crate) fn read_text(path: &Path, max_bytes: u64, what: &str) -> Result<String> {
    let file = std::fs::File::open(path).map_err(|e| ReadError::io(path, e))?;
    let mut text = String::new();
    file.take(max_bytes + 1)
        .read_to_string(&mut text)
        .map_err(|e| ReadError::io(path, e))?;
    if text.len() as u64 > max_bytes {
        return Err(ReadError::format(
            path,
            format!("{what} is at most {max_bytes} bytes, this one is larger"),
        ));
    }
    Ok(text)
}
