//! NIfTI-1 and NIfTI-2 images: single files (`.nii`, `.nii.gz`) and header/image pairs
//! (`.hdr` + `.img`, read only), and the Analyze 7.5 pairs NIfTI-1 grew from (read only, as
//! nibabel reads them: [`analyze`]): reader and NIfTI-1 writer.
//!
//! Reading streams the file (through a gzip decoder when it starts with the gzip magic, whatever
//! its name) and keeps no more than the header and the first 3-D volume's voxels; a gzip stream
//! is then read to its end (the other volumes of a 4-D image are inflated and dropped) so that
//! //! its CRC and length are checked, and inflated bytes beyond the header's volumes are refused.
//! The version and byte order come from `sizeof_hdr` (348 or 540 in the file's byte order); a
//! 348-byte header without NIfTI-1's magic is Analyze 7.5. Geometry comes from the sform when `sform_code > 0`, else the qform
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
mod analyze;
mod header;
mod mat4;
mod write;

pub use write::write;

use crate::compressed;
use crate::detached;
use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::samples::{read_voxels, Endian, Rescale};
use endocast_core::{Modality, Volume};
use flate2::read::MultiGzDecoder;
use header::{Header, Version};
use std::fs::File;
use std::io::{self, BufRead, BufReader, Read};
use std::path::{Path, PathBuf};

/// Reads a NIfTI-1 or NIfTI-2 file, plain or gzip-compressed: a single file (`.nii`), or a
/// header (`.hdr`) whose voxels are in the `.img` beside it (each plain or gzip); an Analyze
/// 7.5 `.hdr` likewise.
///
/// Only the first volume of a 4-D series is read (with a warning). Errors: a header that is
/// neither NIfTI version nor Analyze (`sizeof_hdr` not 348 or 540), RGB or complex voxels (unsupported), bad dims, pixdim or
/// `vox_offset`, a missing `.img`, a transform that is not a voxel grid, more voxels than
/// `options.limits` allow, and data that ends early.
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let mut stream = Stream::open(path)?;
    let header = header::read_header(path, &mut stream.reader)?;
    stream.position = header.version.header_size() as u64;
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
    let mut data = if header.paired {
        let image = pair_file(path, "img")?;
        detached::data_file_len(path, &image)?;
        Stream::open(&image)?
    } else {
        stream
    };
    let data_bytes = count as u64 * element.size() as u64;
    data.check_holds(vox_offset, data_bytes)?;
    data.skip_to(vox_offset)?;
    let (voxels, map) = read_voxels(
        &data.path,
        &mut data.reader,
        element,
        header.endian,
        count,
        values_rescale(path, &header, &mut warnings),
        &mut warnings,
    )
    .map_err(|e| {
        if data.gzip {
            compressed::io_as_corrupt(e, "gzip")
        } else {
            e
        }
    })?;
    if data.gzip {
        let rest = (volumes - 1).saturating_mul(data_bytes);
        compressed::finish(&data.path, &mut data.reader, "gzip", rest)?;
    }

    // check_dims proved the product fits usize, so each factor does.
    let dims = dims.map(|d| d as usize);
    let (geometry, format) = match &header.version {
        Version::Analyze(spm) => (
            analyze::geometry(path, &header, spm, dims, &mut warnings)?,
            Format::Analyze,
        ),
        _ => (
            affine::geometry(path, &header, dims, &mut warnings)?,
            Format::Nifti,
        ),
    };
    let volume = Volume::new(geometry, voxels, map, Modality::Unknown)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    Ok(Loaded {
        volume,
        source: SourceInfo::new(format, stored_type(&header, element.name(), data.gzip)),
        warnings,
    })
}

/// The values' scaling by the header's version: NIfTI's `scl_slope`, or SPM's for Analyze.
fn values_rescale(path: &Path, header: &Header, warnings: &mut Vec<String>) -> Rescale {
    match &header.version {
        Version::Analyze(spm) => analyze::rescale(path, header, spm, warnings),
        _ => rescale(path, header, warnings),
    }
}

/// The file beside the pair's header `path` with the extension `ext` (`img`, `mat`): `x.hdr` →
/// `x.img`, `x.hdr.gz` → `x.img.gz`, in the header's case.
fn pair_file(path: &Path, ext: &str) -> Result<PathBuf> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .unwrap_or_default();
    let lower = name.to_ascii_lowercase();
    let Some(at) = lower
        .rfind(".hdr")
        .filter(|&at| matches!(&lower[at + 4..], "" | ".gz"))
    else {
        return Err(ReadError::format(
            path,
            "the header of a .hdr/.img pair (NIfTI magic ni1 or ni2, or an Analyze 7.5 header, \
             which has no magic) must be named .hdr or .hdr.gz",
        ));
    };
    let ext = if &name[at + 1..at + 4] == "HDR" {
        ext.to_ascii_uppercase()
    } else {
        ext.to_owned()
    };
    Ok(path.with_file_name(format!("{}.{ext}{}", &name[..at], &name[at + 4..])))
}

/// A NIfTI file being read: its bytes, inflated when it starts with the gzip magic.
struct Stream {
    path: PathBuf,
    reader: Box<dyn Read>,
    gzip: bool,
    /// The file's length on disk.
    len: u64,
    /// Bytes of the (inflated) data read so far.
    position: u64,
}

impl Stream {
    fn open(path: &Path) -> Result<Self> {
        let file = File::open(path).map_err(|e| ReadError::io(path, e))?;
        let len = file.metadata().map_err(|e| ReadError::io(path, e))?.len();
        let mut buffered = BufReader::new(file);
        let gzip = buffered
            .fill_buf()
            .map_err(|e| ReadError::io(path, e))?
            .starts_with(&[0x1f, 0x8b]);
        let reader: Box<dyn Read> = if gzip {
            Box::new(MultiGzDecoder::new(buffered))
        } else {
            Box::new(buffered)
        };
        Ok(Self {
            path: path.to_path_buf(),
            reader,
            gzip,
            len,
            position: 0,
        })
    }

    /// Refuses a file that cannot hold `data_bytes` of voxels from `vox_offset` (stored, or
    /// inflated from what is stored), before they are allocated.
    fn check_holds(&self, vox_offset: u64, data_bytes: u64) -> Result<()> {
        if self.gzip {
            let needed = vox_offset.saturating_add(data_bytes);
            return compressed::check_inflates_to(&self.path, "gzip", self.len, needed);
        }
        check_file_holds(&self.path, self.len, vox_offset, data_bytes)
    }

    /// Skips the extensions (or whatever lies) before `vox_offset`, storing nothing.
    fn skip_to(&mut self, vox_offset: u64) -> Result<()> {
        let wanted = vox_offset - self.position;
        let skipped = io::copy(&mut (&mut self.reader).take(wanted), &mut io::sink())
            .map_err(|e| ReadError::io(&self.path, e))?;
        if skipped < wanted {
            return Err(ReadError::format(
                &self.path,
                format!(
                    "vox_offset {vox_offset} lies beyond the end of the decompressed data ({} \
                     bytes)",
                    self.position + skipped
                ),
            ));
        }
        self.position = vox_offset;
        Ok(())
    }
}

/// E.g. `uint8 (NIfTI-1, gzip)`, `int16 (NIfTI-2, big-endian)` or `int16 (Analyze 7.5)`.
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
