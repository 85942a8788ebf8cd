//! Data files that a header names (NRRD `data file`, MetaImage `ElementDataFile`). A header is
//! input like any other: one naming `/dev/zero` would make a reader wait forever for the end of
//! its data, and one naming `/etc/passwd` or `../../secret` would read a file the user never
//! chose. So the named file must be a regular file inside the header's folder (or below it),
//! unless the user allows files elsewhere ([`crate::OpenOptions::allow_outside_data`]).

use crate::error::{ReadError, Result};
use std::path::Path;

/// The length of the data file `data` named by the header at `header`, once it is known to be
/// a regular file inside the header's folder (links resolved); an error naming both otherwise.
pub(crate) fn data_file_len(header: &Path, data: &Path) -> Result<u64> {
    data_file_len_where(header, data, false)
}

/// [`data_file_len`], but when `anywhere` the data file may lie outside the header's folder
/// (it must still be a regular file).
pub(crate) fn data_file_len_where(header: &Path, data: &Path, anywhere: bool) -> Result<u64> {
    let meta = std::fs::metadata(data).map_err(|e| ReadError::io(data, e))?;
    if !meta.is_file() {
        return Err(ReadError::format(
            header,
            format!(
                "the data file {} is not a regular file (a device, pipe or folder); name the \
                 file that holds the samples",
                data.display()
            ),
        ));
    }
    if anywhere {
        return Ok(meta.len());
    }
    let folder = match header.parent() {
        Some(parent) if !parent.as_os_str().is_empty() => parent,
        _ => Path::new("."),
    };
    let canonical = |path: &Path| path.canonicalize().map_err(|e| ReadError::io(path, e));
    if !canonical(data)?.starts_with(canonical(folder)?) {
        return Err(ReadError::format(
            header,
            format!(
                "the data file {} lies outside the header's folder; headers may only name \
                 files beside them or in their sub-folders (move the data file there, or allow \
                 data elsewhere: --allow-outside-data)",
                data.display()
            ),
        ));
    }
    Ok(meta.len())
}
