//! Placeholder, being written.

use crate::error::{ReadError, Result};
use crate::open::{Loaded, OpenOptions};
use endocast_core::Volume;
use std::path::Path;

/// Reads a nrrd file.
pub fn read(path: &Path, _options: &OpenOptions) -> Result<Loaded> {
    Err(ReadError::unsupported(path, "nrrd (not yet)"))
}

/// Writes a nrrd file.
pub fn write(path: &Path, _volume: &Volume) -> Result<()> {
    Err(ReadError::unsupported(path, "nrrd (not yet)"))
}
