//! NIfTI-1 and NIfTI-2 single-file images (`.nii`, `.nii.gz`): reader and NIfTI-1 writer.
//!
//! Reading streams the file (through a gzip decoder when it starts with the gzip magic, whatever
//! its name) and keeps no more than the header and the first 3-D volume's voxels; a gzip stream
//! is then read to its end (the other volumes of a 4-D image are inflated and dropped) so that
//! its CRC and length are checked, and inflated bytes beyond the header's volumes are refused. The version and byte order come from `sizeof_hdr` (348 or 540 in the
//! file's byte order). Geometry comes from the sform when `sform_code > 0`, else the qform
//! when `qform_code > 0`, else the voxel sizes alone (with a warning); NIfTI's RAS world
//! becomes endocast's LPS by negating x and y, and the 3×4 affine splits into spacing (column
//! lengths), direction (unit columns) and origin. Spatial units in metres or microns are
//! converted to mm. A non-zero,
//! finite `scl_slope` is applied with `scl_inter`. NIfTI says nothing reliable about the
//! modality, so it is [`Modality::Unknown`].
//!
//! Writing produces a little-endian NIfTI-1 file, gzip-compressed when the name ends in `.gz`;
//! see [`write()`] for the sample type chosen.

mod affine;
mod header;
mod write;

pub use write::write;

use crate::compressed;
use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::{read_voxels, Endian, Rescale};
use endocast_core::{Modality, Volume};
use flate2::read::MultiGzDecoder;
use header::Header;
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::Path;

/// Reads a NIfTI-1 or NIfTI-2 file, plain or gzip-compressed.
///
/// Only the first volume of a 4-D series is read (with a warning). Errors: a header that is
/// neither NIfTI version, a `.hdr`/`.img` pair, RGB or complex voxels (unsupported), bad dims,
/// pixdim or `vox_offset`, a transform that is not a voxel grid, more voxels than
/// `options.limits` allow, and data that ends early.
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let file = File::open(path).map_err(|e| ReadError::io(path, e))?;
    let file_len = file.metadata().map_err(|e| ReadError::io(path, e))?.len();
    let mut buffered = BufReader::new(file);
    let gzip = buffered
        .fill_buf()
        .map_err(|e| ReadError::io(path, e))?
        .starts_with(&[0x1f, 0x8b]);
    let mut reader: Box<dyn Read> = if gzip {
        Box::new(MultiGzDecoder::new(buffered))
    } else {
        Box::new(buffered)
    };

    let header = header::read_header(path, &mut reader)?;
    let mut warnings = Vec::new();
    let element = header.element_type(path)?;
    if i64::from(header.bitpix) != 8 * element.size() as i64 {
        warnings.push(format!(
            "{}: bitpix {} does not match datatype {} ({}); the datatype was used",
            path.display(),
            header.bitpix,
            header.datatype,
            element.name()
        ));
    }
    let (dims, volumes) = header.volume_dims(path, &mut warnings)?;
    let count = options.limits.check_dims(path, &dims)?;
    let vox_offset = header.data_offset(path)?;
    let data_bytes = count as u64 * element.size() as u64;
    if gzip {
        compressed::check_inflates_to(
            path,
            "gzip",
            file_len,
            vox_offset.saturating_add(data_bytes),
        )?;
    } else {
        check_file_holds(path, file_len, vox_offset, data_bytes)?;
    }
    skip_to_voxels(
        path,
        &mut reader,
        header.version.header_size() as u64,
        vox_offset,
    )?;
    let (voxels, map) = read_voxels(
        path,
        &mut reader,
        element,
        header.endian,
        count,
        rescale(path, &header, &mut warnings),
        &mut warnings,
    )
    .map_err(|e| {
        if gzip {
            compressed::io_as_corrupt(e, "gzip")
        } else {
            e
        }
    })?;
    if gzip {
        let volume_bytes = count as u64 * element.size() as u64;
        let rest = (volumes - 1).saturating_mul(volume_bytes);
        compressed::finish(path, &mut reader, "gzip", rest)?;
    }

    // check_dims proved the product fits usize, so each factor does.
    let dims = dims.map(|d| d as usize);
    let geometry = affine::geometry(path, &header, dims, &mut warnings)?;
    let volume = Volume::new(geometry, voxels, map, Modality::Unknown)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    Ok(Loaded {
        volume,
        source: SourceInfo::new(Format::Nifti, stored_type(&header, element.name(), gzip)),
        warnings,
    })
}

/// E.g. `uint8 (NIfTI-1, gzip)` or `int16 (NIfTI-2, big-endian)`.
fn stored_type(header: &Header, element: &str, gzip: bool) -> String {
    let mut parts = vec![header.version.name()];
    if header.endian == Endian::Big {
        parts.push("big-endian");
    }
    if gzip {
        parts.push("gzip");
    }
    format!("{element} ({})", parts.join(", "))
}

/// An uncompressed file must hold the header's claim before anything that size is read.
fn check_file_holds(path: &Path, file_len: u64, vox_offset: u64, data_bytes: u64) -> Result<()> {
    if vox_offset > file_len {
        return Err(ReadError::format(
            path,
            format!("vox_offset {vox_offset} lies beyond the end of the file ({file_len} bytes)"),
        ));
    }
    let needed = vox_offset.saturating_add(data_bytes);
    if needed > file_len {
        return Err(ReadError::format(
            path,
            format!(
                "the voxel data ends early: the header needs {needed} bytes \
                 ({data_bytes} from offset {vox_offset}), the file has {file_len}"
            ),
        ));
    }
    Ok(())
}

/// Skips the extensions between the header (already read) and `vox_offset`, storing nothing.
fn skip_to_voxels(
    path: &Path,
    reader: &mut dyn Read,
    header_size: u64,
    vox_offset: u64,
) -> Result<()> {
    let wanted = vox_offset - header_size;
    let skipped =
        io::copy(&mut reader.take(wanted), &mut io::sink()).map_err(|e| ReadError::io(path, e))?;
    if skipped < wanted {
        return Err(ReadError::format(
            path,
            format!(
                "vox_offset {vox_offset} lies beyond the end of the decompressed data ({} bytes)",
                header_size + skipped
            ),
        ));
    }
    Ok(())
}

/// `scl_slope` 0 or non-finite means "no scaling" (NIfTI-1 §scl_slope); a non-finite
/// intercept with a valid slope is taken as 0 with a warning.
fn rescale(path: &Path, header: &Header, warnings: &mut Vec<String>) -> Rescale {
    let slope = header.scl_slope;
    if slope == 0.0 || !slope.is_finite() {
        return Rescale::IDENTITY;
    }
    let intercept = if header.scl_inter.is_finite() {
        header.scl_inter
    } else {
        warnings.push(format!(
            "{}: scl_inter {} is not finite; 0 was used",
            path.display(),
            header.scl_inter
        ));
        0.0
    };
    Rescale { slope, intercept }
}
