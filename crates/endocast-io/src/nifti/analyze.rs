//! Analyze 7.5 pairs (`.hdr` + `.img`) read as nibabel reads them: `nibabel.load` takes a
//! 348-byte `.hdr` without NIfTI's magic for an SPM2 Analyze image (`Spm2AnalyzeImage`), so
//! the values and the world geometry are that class's.
//!
//! - Values: `funused1` scales them when finite and non-zero, `funused2` being the intercept;
//!   otherwise, when both ranges are non-zero, `glmin..glmax` maps onto `cal_min..cal_max`
//!   (SPM2's `spm_vol_ana`); otherwise they are as stored.
//! - Geometry: the `.mat` beside the header (SPM's voxel-to-world matrix) when there is one:
//!   its `mat`, or its `M` with x negated, moved from MATLAB's 1-based voxel indices.
//!   Otherwise the voxel sizes (`pixdim`; 0 taken as 1, a negative size as positive) along
//!   RAS with x negated, radiological storage: the first index axis runs from the patient's
//!   right to left (`LAS`); voxel `originator − 1` (SPM99's origin) at 0 when it is set and
//!   within reach of the volume (−dim < origin < 2·dim), else the centre of the volume.
//!   Analyze declares no orientation, so a warning says that this convention was assumed.

use super::affine::geometry_from_ras;
use super::header::{Header, SpmFields};
use super::mat4::{self, Matrix};
use super::{pair_file, Stream};
use crate::detached;
use crate::error::Result;
use crate::samples::Rescale;
use endocast_core::Geometry;
use glam::{DAffine3, DMat3, DMat4, DVec3};
use std::io::Read;
use std::path::Path;

/// The largest `.mat` read: SPM's holds two 4×4 matrices (about 300 bytes).
const MAX_MAT_BYTES: u64 = 1 << 16;

/// The values' scaling: `funused1`/`funused2` as NIfTI's slope and intercept when the slope is
/// usable, else SPM2's calibration from the `gl` and `cal` ranges.
pub(super) fn rescale(
    path: &Path,
    header: &Header,
    spm: &SpmFields,
    warnings: &mut Vec<String>,
) -> Rescale {
    if header.scl_slope.is_finite() && header.scl_slope != 0.0 {
        return super::rescale(path, header, warnings);
    }
    let [glmin, glmax] = spm.gl;
    let [cal_min, cal_max] = spm.cal;
    let stored = i64::from(glmax) - i64::from(glmin);
    let scaled = cal_max - cal_min;
    if stored == 0 || scaled == 0.0 {
        return Rescale::IDENTITY;
    }
    let slope = f64::from(scaled) / stored as f64;
    let intercept = f64::from(cal_min) - slope * f64::from(glmin);
    if !slope.is_finite() || !intercept.is_finite() {
        warnings.push(format!(
            "{}: cal_min {cal_min} and cal_max {cal_max} give no usable scaling; the values \
             are as stored",
            path.display()
        ));
        return Rescale::IDENTITY;
    }
    warnings.push(format!(
        "{}: no scale factor (funused1); the stored range {glmin}..{glmax} (glmin, glmax) was \
         mapped onto {cal_min}..{cal_max} (cal_min, cal_max), as SPM2 and nibabel do",
        path.display()
    ));
    Rescale { slope, intercept }
}

/// The volume's LPS geometry: from the `.mat` beside the header when there is a usable one,
/// else from the voxel sizes and SPM's origin by nibabel's convention (with a warning).
pub(super) fn geometry(
    path: &Path,
    header: &Header,
    spm: &SpmFields,
    dims: [usize; 3],
    warnings: &mut Vec<String>,
) -> Result<Geometry> {
    let mat = pair_file(path, "mat")?;
    if let Some((ras, flip_assumed)) = mat_affine(path, &mat, warnings) {
        if flip_assumed {
            warnings.push(format!(
                "{}: its M matrix leaves out the x flip; nibabel's radiological convention was \
                 assumed (x negated)",
                mat.display()
            ));
        }
        return geometry_from_ras(path, dims, ras, "SPM .mat");
    }
    let (ras, origin) = origin_affine(path, header, spm, warnings);
    warnings.push(format!(
        "{}: an Analyze 7.5 header declares no orientation; nibabel's convention was assumed: \
         radiological storage, the index axes pointing to the patient's left, anterior and \
         superior (LAS), {origin}",
        path.display()
    ));
    geometry_from_ras(path, dims, ras, "Analyze pixdim")
}

/// nibabel's `Spm99AnalyzeHeader.get_origin_affine` (RAS mm from voxel index), and where its
/// origin came from, in words.
fn origin_affine(
    path: &Path,
    header: &Header,
    spm: &SpmFields,
    warnings: &mut Vec<String>,
) -> (DAffine3, &'static str) {
    let zooms = zooms(path, header, warnings);
    let dims = [1, 2, 3].map(|n| header.dim[n]);
    let origin = spm.origin.map(i64::from);
    let within = (0..3).all(|n| -dims[n] < origin[n] && origin[n] < 2 * dims[n]);
    let (translation, source) = if origin != [0; 3] && within {
        // nibabel multiplies the 0-based origin by the float32 zooms in float32.
        let mm = |n: usize| -f64::from((origin[n] - 1) as f32 * zooms[n] as f32);
        (
            DVec3::new(mm(0), mm(1), mm(2)),
            "voxel originator − 1 (SPM's origin) at 0 mm",
        )
    } else {
        let mm = |n: usize| -((dims[n] - 1) as f64 / 2.0) * zooms[n];
        (
            DVec3::new(mm(0), mm(1), mm(2)),
            "the centre of the volume at 0 mm (no SPM origin in reach)",
        )
    };
    let ras = DAffine3::from_mat3_translation(DMat3::from_diagonal(zooms), translation);
    (ras, source)
}

/// The voxel sizes `pixdim[1..=3]` as nibabel fixes them on reading (0 becomes 1, a negative
/// size its magnitude, with a warning), x negated for radiological storage.
fn zooms(path: &Path, header: &Header, warnings: &mut Vec<String>) -> DVec3 {
    let given = DVec3::from_slice(&header.pixdim[1..4]);
    let fixed = given.abs() + DVec3::select(given.cmpeq(DVec3::ZERO), DVec3::ONE, DVec3::ZERO);
    if fixed != given && fixed.is_finite() {
        warnings.push(format!(
            "{}: pixdim[1..3] = {given} must be positive; {fixed} was used, as nibabel does",
            path.display()
        ));
    }
    fixed * DVec3::new(-1.0, 1.0, 1.0)
}

/// The affine of the `.mat` file `mat` beside the header `path` (RAS mm from voxel index), and
/// whether x was negated by convention (its `M`); `None` when there is none (or it is empty,
/// which nibabel skips too), or none usable (with a warning).
fn mat_affine(path: &Path, mat: &Path, warnings: &mut Vec<String>) -> Option<(DAffine3, bool)> {
    if !mat.exists() {
        return None;
    }
    match read_mat(path, mat).and_then(|matrices| spm_affine(&matrices)) {
        Ok(found) => found,
        Err(why) => {
            warnings.push(format!(
                "{}: not used ({why}); the geometry comes from the Analyze header, where SPM and \
                 nibabel would take it from this file",
                mat.display()
            ));
            None
        }
    }
}

/// nibabel's reading of SPM's matrices: `mat`, else `M` with x negated (and `true`), each moved
/// from MATLAB's first voxel (1, 1, 1) to 0; `None` for a file without matrices.
fn spm_affine(matrices: &[Matrix]) -> std::result::Result<Option<(DAffine3, bool)>, String> {
    if matrices.is_empty() {
        return Ok(None);
    }
    let find = |name: &str| matrices.iter().find(|m| m.name == name);
    let (matrix, flip_assumed) = match (find("mat"), find("M")) {
        (Some(mat), _) => (mat, false),
        (None, Some(m)) => (m, true),
        (None, None) => return Err("it holds neither a mat nor an M matrix".into()),
    };
    if (matrix.rows, matrix.cols) != (4, 4) {
        return Err(format!(
            "its {} is {}×{}, not 4×4",
            matrix.name, matrix.rows, matrix.cols
        ));
    }
    let values: [f64; 16] = matrix.values.clone().try_into().unwrap_or_default();
    let flip = if flip_assumed { -1.0 } else { 1.0 };
    let affine = DAffine3::from_scale(DVec3::new(flip, 1.0, 1.0))
        * DAffine3::from_mat4(DMat4::from_cols_array(&values))
        * DAffine3::from_translation(DVec3::ONE);
    Ok(Some((affine, flip_assumed)))
}

/// The matrices of the `.mat` file (plain or gzip) beside the header `path`, or why they could
/// not be read.
fn read_mat(path: &Path, mat: &Path) -> std::result::Result<Vec<Matrix>, String> {
    // A regular file in the header's folder, not a device or a link elsewhere.
    detached::data_file_len(path, mat).map_err(|e| e.to_string())?;
    let stream = Stream::open(mat).map_err(|e| e.to_string())?;
    let mut bytes = Vec::new();
    stream
        .reader
        .take(MAX_MAT_BYTES + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| e.to_string())?;
    if bytes.len() as u64 > MAX_MAT_BYTES {
        return Err(format!("larger than {MAX_MAT_BYTES} bytes"));
    }
    mat4::parse(&bytes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nifti::header::read_header;

    fn spm(origin: [i16; 3]) -> SpmFields {
        SpmFields {
            origin,
            cal: [0.0; 2],
            gl: [0; 2],
        }
    }

    /// A little-endian Analyze header of a 4×5×6 volume with voxel sizes `pixdim`.
    fn header(pixdim: [f32; 3]) -> Header {
        let mut b = vec![0u8; 348];
        let mut put = |at: usize, bytes: &[u8]| b[at..at + bytes.len()].copy_from_slice(bytes);
        put(0, &348i32.to_le_bytes());
        for (n, d) in [3i16, 4, 5, 6].iter().enumerate() {
            put(40 + 2 * n, &d.to_le_bytes());
        }
        for (n, p) in pixdim.iter().enumerate() {
            put(80 + 4 * n, &p.to_le_bytes());
        }
        read_header(Path::new("t.hdr"), &mut &b[..]).unwrap()
    }

    #[test]
    fn origin_is_spm_origin_in_reach_else_the_centre() {
        let p = Path::new("t.hdr");
        let h = header([0.5, 2.0, 3.0]);
        let mut w = Vec::new();
        let (ras, _) = origin_affine(p, &h, &spm([3, 4, 5]), &mut w);
        assert_eq!(
            ras.matrix3,
            DMat3::from_diagonal(DVec3::new(-0.5, 2.0, 3.0))
        );
        assert_eq!(ras.translation, DVec3::new(1.0, -6.0, -12.0));
        // The centre (1.5, 2, 2.5) when the origin is unset or out of reach (z: 12 = 2 · 6).
        for origin in [[0, 0, 0], [3, 4, 12], [-4, 1, 1]] {
            let (ras, _) = origin_affine(p, &h, &spm(origin), &mut w);
            assert_eq!(ras.translation, DVec3::new(0.75, -4.0, -7.5));
        }
        assert!(w.is_empty(), "{w:?}");
    }

    #[test]
    fn zero_and_negative_voxel_sizes_are_fixed_with_a_warning() {
        let mut w = Vec::new();
        let z = zooms(Path::new("t.hdr"), &header([0.0, -2.0, 3.0]), &mut w);
        assert_eq!(z, DVec3::new(-1.0, 2.0, 3.0));
        assert_eq!(w.len(), 1);
    }

    #[test]
    fn scaling_is_funused1_else_the_calibrated_range() {
        let p = Path::new("t.hdr");
        let mut w = Vec::new();
        let mut h = header([1.0; 3]);
        let mut s = spm([0; 3]);
        assert_eq!(rescale(p, &h, &s, &mut w), Rescale::IDENTITY);
        s.gl = [10, 110];
        s.cal = [0.25, 0.75];
        let r = rescale(p, &h, &s, &mut w);
        assert!((r.slope - 0.005).abs() < 1e-12 && (r.intercept - 0.2).abs() < 1e-12);
        assert_eq!(w.len(), 1);
        h.scl_slope = 2.0;
        h.scl_inter = f64::NAN;
        let r = rescale(p, &h, &s, &mut w);
        assert_eq!((r.slope, r.intercept), (2.0, 0.0));
    }

    #[test]
    fn spm_matrices_are_mat_else_m_flipped_from_one_based_voxels() {
        let matrix = |name: &str, rows: usize, cols: usize| Matrix {
            name: name.into(),
            rows,
            cols,
            values: DMat4::from_diagonal(glam::DVec4::new(2.0, 3.0, 4.0, 1.0)).to_cols_array()
                [..rows * cols]
                .to_vec(),
        };
        let (mat, flipped) = spm_affine(&[matrix("M", 4, 4), matrix("mat", 4, 4)])
            .unwrap()
            .unwrap();
        assert!(!flipped);
        assert_eq!(mat.translation, DVec3::new(2.0, 3.0, 4.0));
        let (m, flipped) = spm_affine(&[matrix("M", 4, 4)]).unwrap().unwrap();
        assert!(flipped);
        assert_eq!(m.translation, DVec3::new(-2.0, 3.0, 4.0));
        assert_eq!(spm_affine(&[]), Ok(None));
        assert!(spm_affine(&[matrix("x", 4, 4)]).is_err());
        assert!(spm_affine(&[matrix("mat", 3, 4)]).is_err());
    }
}
