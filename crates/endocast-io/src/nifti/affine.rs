//! From the header's spatial fields to the volume's LPS geometry, and back for the writer.
//!
//! NIfTI maps voxel indices to RAS+ millimetres (+x towards the patient's Right, +y Anterior,
//! +z Superior), while endocast's world is DICOM LPS (+x Left, +y Posterior, +z Superior). The
//! two differ by negating x and y, applied to the whole affine (its x and y rows, translation
//! included).

use super::header::Header;
use crate::error::{ReadError, Result};
use endocast_core::Geometry;
use glam::{DAffine3, DMat3, DQuat, DVec3};
use std::path::Path;

/// Negates x and y: LPS from RAS and RAS from LPS alike (the map is its own inverse).
const FLIP_XY: DVec3 = DVec3::new(-1.0, -1.0, 1.0);

/// The affine switching between RAS and LPS world coordinates.
fn flip_xy() -> DAffine3 {
    DAffine3::from_scale(FLIP_XY)
}

/// The volume's LPS geometry from the header: the sform when `sform_code > 0`, else the qform
/// when `qform_code > 0`, else the voxel sizes alone (as ITK and nibabel do: RAS axes through
/// the origin, with a warning). Spatial units in metres or microns are converted to mm.
pub(super) fn geometry(
    path: &Path,
    header: &Header,
    dims: [usize; 3],
    warnings: &mut Vec<String>,
) -> Result<Geometry> {
    if let Some(n) = (0..4).find(|&n| !header.pixdim[n].is_finite()) {
        return Err(ReadError::format(
            path,
            format!("pixdim[{n}] = {} must be finite", header.pixdim[n]),
        ));
    }
    let (ras, source) = if header.sform_code > 0 {
        (sform(header), "sform")
    } else if header.qform_code > 0 {
        (qform(path, header)?, "qform")
    } else {
        warnings.push(format!(
            "{}: neither sform nor qform is set; the voxel sizes are used with RAS axes \
             through the origin, so the position in the patient is unknown",
            path.display()
        ));
        let spacing = DVec3::from_slice(&header.pixdim[1..4]).abs();
        (DAffine3::from_scale(spacing), "pixdim")
    };
    let ras_mm = DAffine3::from_scale(DVec3::splat(mm_per_unit(header.xyzt_units))) * ras;
    geometry_from_ras(path, dims, ras_mm, source)
}

/// The LPS geometry of `ras` (RAS mm from voxel index); `source` names where it came from in
/// errors (`sform`, `SPM origin`).
pub(super) fn geometry_from_ras(
    path: &Path,
    dims: [usize; 3],
    ras: DAffine3,
    source: &str,
) -> Result<Geometry> {
    decompose(path, dims, flip_xy() * ras, source)
}

/// Millimetres per spatial unit of `xyzt_units`: metres (1) and microns (3) are scaled, mm (2)
/// and unknown (0, the common case of careless writers) are taken as mm.
fn mm_per_unit(xyzt_units: i32) -> f64 {
    match xyzt_units & 0x07 {
        1 => 1000.0,
        3 => 0.001,
        _ => 1.0,
    }
}

fn sform(header: &Header) -> DAffine3 {
    let [x, y, z] = &header.srow;
    DAffine3::from_cols(
        DVec3::new(x[0], y[0], z[0]),
        DVec3::new(x[1], y[1], z[1]),
        DVec3::new(x[2], y[2], z[2]),
        DVec3::new(x[3], y[3], z[3]),
    )
}

/// The qform: a rotation from the quaternion (b, c, d; a ≥ 0 implied by unit length), the
/// third axis flipped when `qfac = pixdim[0]` is negative, scaled by the voxel sizes.
fn qform(path: &Path, header: &Header) -> Result<DAffine3> {
    let [b, c, d] = header.quatern;
    let bcd = b * b + c * c + d * d;
    if !bcd.is_finite() || !header.qoffset.iter().all(|v| v.is_finite()) {
        return Err(ReadError::format(
            path,
            format!(
                "the qform holds a NaN or infinite number (quatern {:?}, qoffset {:?})",
                header.quatern, header.qoffset
            ),
        ));
    }
    // Rounding can push b²+c²+d² past 1; nifti1_io then takes a = 0 and renormalises (b, c, d).
    let a = (1.0 - bcd).max(0.0).sqrt();
    let quat = DQuat::from_xyzw(b, c, d, a);
    if quat.length() == 0.0 {
        return Err(ReadError::format(path, "the qform quaternion is zero"));
    }
    let rotation = DMat3::from_quat(quat.normalize());
    let qfac = if header.pixdim[0] < 0.0 { -1.0 } else { 1.0 };
    // nifti1_io takes the voxel sizes' magnitudes; their sign is not part of the qform.
    let spacing = DVec3::from_slice(&header.pixdim[1..4]).abs() * DVec3::new(1.0, 1.0, qfac);
    Ok(DAffine3::from_mat3_translation(
        rotation * DMat3::from_diagonal(spacing),
        DVec3::from(header.qoffset),
    ))
}

/// Spacing (column lengths), direction (unit columns) and origin (translation) of an affine.
fn decompose(path: &Path, dims: [usize; 3], lps: DAffine3, source: &str) -> Result<Geometry> {
    let m = lps.matrix3;
    let cols = [m.x_axis, m.y_axis, m.z_axis];
    let spacing = DVec3::new(cols[0].length(), cols[1].length(), cols[2].length());
    let bad = |why: String| {
        ReadError::format(
            path,
            format!("the {source} does not describe a voxel grid: {why}"),
        )
    };
    if !spacing.is_finite() || !lps.translation.is_finite() {
        return Err(bad("it holds a NaN or infinite number".into()));
    }
    if spacing.min_element() <= 0.0 {
        return Err(bad(format!(
            "an axis has zero length (voxel sizes {spacing})"
        )));
    }
    Geometry::from_world_from_voxel(dims, lps).map_err(|e| bad(e.to_string()))
}

/// The NIfTI spatial fields of a geometry, in RAS.
pub(super) struct RasFields {
    /// The sform rows: RAS mm from voxel index.
    pub srow: [[f64; 4]; 3],
    /// The qform, when the axes are orthogonal: (quatern b/c/d, qfac).
    pub quaternion: Option<([f64; 3], f64)>,
}

/// The sform (always) and the qform (when the direction is orthogonal) of an LPS geometry.
pub(super) fn ras_fields(geometry: &Geometry) -> RasFields {
    let ras = flip_xy() * geometry.world_from_voxel();
    let (m, t) = (ras.matrix3, ras.translation);
    let srow = [0, 1, 2].map(|r| {
        let row = m.row(r);
        [row.x, row.y, row.z, t[r]]
    });
    let quaternion = geometry
        .is_orthogonal()
        .then(|| quaternion_of(DMat3::from_diagonal(FLIP_XY) * geometry.direction()));
    RasFields { srow, quaternion }
}

/// The NIfTI quaternion (b, c, d with a ≥ 0) and qfac of an orthonormal direction matrix. A
/// left-handed matrix has its third column negated first and qfac = −1.
fn quaternion_of(direction: DMat3) -> ([f64; 3], f64) {
    let (rotation, qfac) = if direction.determinant() < 0.0 {
        let d = direction;
        (DMat3::from_cols(d.x_axis, d.y_axis, -d.z_axis), -1.0)
    } else {
        (direction, 1.0)
    };
    let q = DQuat::from_mat3(&rotation).normalize();
    let q = if q.w < 0.0 { -q } else { q };
    ([q.x, q.y, q.z], qfac)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nifti::header::Version;
    use crate::samples::Endian;

    fn header() -> Header {
        Header {
            version: Version::One,
            endian: Endian::Little,
            paired: false,
            dim: [3, 2, 2, 2, 1, 1, 1, 1],
            datatype: 2,
            bitpix: 8,
            pixdim: [1.0, 0.5, 0.75, 2.0, 0.0, 0.0, 0.0, 0.0],
            vox_offset: 352.0,
            scl_slope: 0.0,
            scl_inter: 0.0,
            xyzt_units: 2,
            qform_code: 0,
            sform_code: 0,
            quatern: [0.0; 3],
            qoffset: [0.0; 3],
            srow: [[0.0; 4]; 3],
        }
    }

    #[test]
    fn identity_qform_is_ras_so_lps_negates_x_and_y() {
        let mut h = header();
        h.qform_code = 1;
        h.qoffset = [10.0, 20.0, 30.0];
        let g = geometry(Path::new("t"), &h, [2, 2, 2], &mut Vec::new()).unwrap();
        assert_eq!(g.orientation_code(), "RAS");
        assert_eq!(g.origin_mm(), DVec3::new(-10.0, -20.0, 30.0));
        assert_eq!(g.spacing_mm(), DVec3::new(0.5, 0.75, 2.0));
    }

    #[test]
    fn quaternion_round_trips_through_qform_with_negative_qfac() {
        let rotation = DMat3::from_quat(DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.2, 1.1));
        let lefty = DMat3::from_cols(rotation.x_axis, rotation.y_axis, -rotation.z_axis);
        let (quatern, qfac) = quaternion_of(lefty);
        let mut h = header();
        h.qform_code = 1;
        h.quatern = quatern;
        h.pixdim[0] = qfac;
        let ras = qform(Path::new("t"), &h).unwrap();
        let expected = lefty * DMat3::from_diagonal(DVec3::new(0.5, 0.75, 2.0));
        assert!(ras.matrix3.abs_diff_eq(expected, 1e-12));
    }

    #[test]
    fn missing_transforms_fall_back_with_a_warning() {
        let mut w = Vec::new();
        let g = geometry(Path::new("t"), &header(), [2, 2, 2], &mut w).unwrap();
        assert_eq!(w.len(), 1);
        assert_eq!(g.spacing_mm(), DVec3::new(0.5, 0.75, 2.0));
    }

    #[test]
    fn degenerate_sform_is_an_error() {
        let mut h = header();
        h.sform_code = 1;
        h.srow = [
            [1.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 0.0],
            [0.0, 0.0, 1.0, 0.0],
        ];
        assert!(geometry(Path::new("t"), &h, [2, 2, 2], &mut Vec::new()).is_err());
    }
}
