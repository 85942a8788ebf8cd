//! Headerless sample files, described by the caller (dimensions, spacing, type, byte order).

use crate::error::{ReadError, Result};
pub use crate::loaded::RawSpec;
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::{read_voxels, Endian, Rescale};
use endocast_core::{Geometry, Modality, Volume};
use glam::DVec3;
use std::io::{BufReader, Seek, SeekFrom};
use std::path::Path;

/// Reads the raw file at `path` as `options.raw` describes it.
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let spec = options.raw.ok_or_else(|| {
        ReadError::format(path, "a raw file needs its dimensions, spacing and type")
    })?;
    let dims = spec.dims.map(|d| d as u64);
    let count = options.limits.check_dims(path, &dims)?;
    let geometry = Geometry::axis_aligned(spec.dims, DVec3::from(spec.spacing_mm), DVec3::ZERO)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    let needed = spec.header_bytes + count as u64 * spec.element.size() as u64;
    let file = std::fs::File::open(path).map_err(|e| ReadError::io(path, e))?;
    let len = file.metadata().map_err(|e| ReadError::io(path, e))?.len();
    if len < needed {
        return Err(ReadError::format(
            path,
            format!("expected at least {needed} bytes for the given raw layout, found {len}"),
        ));
    }
    let mut warnings = Vec::new();
    if len > needed {
        warnings.push(format!(
            "{}: {} bytes after the voxel data were ignored",
            path.display(),
            len - needed
        ));
    }
    let mut reader = BufReader::new(file);
    reader
        .seek(SeekFrom::Start(spec.header_bytes))
        .map_err(|e| ReadError::io(path, e))?;
    let (voxels, map) = read_voxels(
        path,
        &mut reader,
        spec.element,
        spec.endian,
        count,
        Rescale::IDENTITY,
        &mut warnings,
    )?;
    let volume = Volume::new(geometry, voxels, map, Modality::Unknown)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    let endian = match spec.endian {
        Endian::Little => "little-endian",
        Endian::Big => "big-endian",
    };
    let mut source = SourceInfo::new(Format::Raw, format!("{} {endian}", spec.element.name()));
    source.orientation_declared = false;
    Ok(Loaded {
        volume,
        source,
        warnings,
    })
}
