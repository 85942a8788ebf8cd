//! The NIfTI-1 writer.

use super::affine::ras_fields;
use super::header::{self, Header, Version, NIFTI1_VOX_OFFSET, UNITS_MM};
use crate::atomic::write_file;
use crate::encode::SampleEncoding;
use crate::error::{ReadError, Result};
use crate::samples::Endian;
use endocast_core::Volume;
use flate2::write::GzEncoder;
use flate2::Compression;
use std::io::Write;
use std::path::Path;

/// `qform_code` / `sform_code` 1: "scanner-based anatomical coordinates".
const XFORM_SCANNER: i32 = 1;

/// Writes `volume` as a little-endian NIfTI-1 file, gzip-compressed when `path` ends in `.gz`.
///
/// Values: a volume whose value map has unit scale and an integral offset, with a physical
/// range inside `int16` (CT in HU), is written as `int16` physical values with
/// `scl_slope` 1 / `scl_inter` 0, as other tools expect. Any other volume is written as its
/// `uint16` stored values with `scl_slope` = scale and `scl_inter` = offset: exact whenever
/// scale and offset are representable as `float32` (the fields' type), within float32
/// rounding otherwise.
///
/// Geometry: the LPS→RAS affine as the sform (code 1, scanner) and, when the axes are
/// orthogonal, the same transform as the qform (code 1); a sheared grid has `qform_code` 0.
/// Units are mm, `vox_offset` 352 with a zero extension flag. Dimensions above 32 767 do not
/// fit NIfTI-1 and are refused.
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    let header = header_for(volume);
    let header_bytes = header
        .encode_nifti1()
        .map_err(|why| ReadError::unsupported(path, format!("NIfTI-1 output: {why}")))?;
    let encoding = SampleEncoding::int16_or_stored(volume);
    let gzip = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gz"));
    write_file(path, |w| {
        if gzip {
            let mut gz = GzEncoder::new(w, Compression::default());
            gz.write_all(&header_bytes)?;
            encoding.write_voxels(volume, &mut gz)?;
            gz.finish().map(drop)
        } else {
            w.write_all(&header_bytes)?;
            encoding.write_voxels(volume, w)
        }
    })
}

fn header_for(volume: &Volume) -> Header {
    let encoding = SampleEncoding::int16_or_stored(volume);
    let (scl_slope, scl_inter) = match encoding {
        SampleEncoding::U16Stored => (volume.value_map().scale(), volume.value_map().offset()),
        _ => (1.0, 0.0),
    };
    let geometry = volume.geometry();
    let [ni, nj, nk] = geometry
        .dims()
        .map(|d| i64::try_from(d).unwrap_or(i64::MAX));
    let spacing = geometry.spacing_mm();
    let ras = ras_fields(geometry);
    let (qform_code, quatern, qfac) = match ras.quaternion {
        Some((quatern, qfac)) => (XFORM_SCANNER, quatern, qfac),
        None => (0, [0.0; 3], 1.0),
    };
    let element = encoding.element_type();
    Header {
        version: Version::One,
        endian: Endian::Little,
        paired: false,
        dim: [3, ni, nj, nk, 1, 1, 1, 1],
        datatype: header::datatype_code(element),
        bitpix: 8 * element.size() as i16,
        pixdim: [qfac, spacing.x, spacing.y, spacing.z, 0.0, 0.0, 0.0, 0.0],
        vox_offset: NIFTI1_VOX_OFFSET as f64,
        scl_slope,
        scl_inter,
        xyzt_units: UNITS_MM,
        qform_code,
        sform_code: XFORM_SCANNER,
        quatern,
        qoffset: [ras.srow[0][3], ras.srow[1][3], ras.srow[2][3]],
        srow: ras.srow,
    }
}
