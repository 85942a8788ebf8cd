//! Reading a store's JSON metadata files: bounded in size, regular files only (a FIFO named
//! `zarr.json` would block a read forever), parsed errors naming the file.

use crate::error::{ReadError, Result};
use serde_json::{Map, Value};
use std::io::Read;
use std::path::Path;

/// Largest metadata file read: OME-Zarr metadata is a few kilobytes.
pub(super) const MAX_JSON_BYTES: u64 = 16 << 20;

/// The JSON object in the file at `path`, or `None` where there is no such file.
pub(super) fn read_object(path: &Path) -> Result<Option<Map<String, Value>>> {
    let Ok(meta) = std::fs::metadata(path) else {
        return Ok(None);
    };
    if !meta.is_file() {
        return Err(ReadError::format(path, "is not a regular file"));
    }
    if meta.len() > MAX_JSON_BYTES {
        return Err(ReadError::Limit {
            path: path.to_path_buf(),
            what: "the metadata file (bytes)".into(),
            requested: meta.len(),
            limit: MAX_JSON_BYTES,
        });
    }
    let mut text = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_JSON_BYTES).read_to_end(&mut text))
        .map_err(|e| ReadError::io(path, e))?;
    match serde_json::from_slice(&text) {
        Ok(Value::Object(object)) => Ok(Some(object)),
        Ok(_) => Err(ReadError::format(path, "the JSON is not an object")),
        Err(e) => Err(ReadError::format(path, format!("bad JSON: {e}"))),
    }
}
