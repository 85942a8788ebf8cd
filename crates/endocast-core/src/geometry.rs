//! Where a voxel grid sits in the patient: dimensions, spacing, origin and direction cosines.
//!
//! World space is the DICOM patient frame (LPS: +x to the patient's left, +y posterior,
//! +z superior), in millimetres. Index space has voxel centres at integer coordinates, `i`
//! running fastest in memory. The direction matrix holds, as columns, the unit world vectors
//! of the `i`, `j` and `k` index axes. The columns need not be orthogonal: a CT series with
//! gantry tilt is a sheared grid, and we keep that shear in the affine instead of resampling
//! in-plane (which would blur the slices); see the DICOM reader.

use glam::{DAffine3, DMat3, DVec3};
use thiserror::Error;

/// A geometry that cannot describe a voxel grid.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum GeometryError {
    /// A dimension is zero.
    #[error("dimensions {0:?} contain a zero")]
    ZeroDimension([usize; 3]),
    /// A spacing is zero, negative, NaN or infinite.
    #[error("spacing {0:?} mm must be finite and positive")]
    BadSpacing([f64; 3]),
    /// The origin has a NaN or infinite coordinate.
    #[error("origin {0:?} mm must be finite")]
    BadOrigin([f64; 3]),
    /// The direction cosines are not finite, not unit length, or (nearly) linearly dependent.
    #[error("direction cosines {0:?} are not three finite, independent unit vectors")]
    BadDirection([[f64; 3]; 3]),
}

/// Tolerance on the length of a direction column (headers store cosines to a few digits).
const UNIT_TOLERANCE: f64 = 1e-3;
/// Smallest |det| of the direction matrix accepted; below it the axes are (nearly) coplanar.
const MIN_DETERMINANT: f64 = 1e-3;

/// The placement of a voxel grid in the patient frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Geometry {
    dims: [usize; 3],
    spacing_mm: DVec3,
    origin_mm: DVec3,
    direction: DMat3,
}

impl Geometry {
    /// A validated geometry. `origin_mm` is the world position of the centre of voxel (0,0,0);
    /// `direction` holds the unit world vectors of the index axes as columns. Columns are
    /// renormalised (headers round cosines); they must be finite, within 1e-3 of unit length
    /// and independent.
    pub fn new(
        dims: [usize; 3],
        spacing_mm: DVec3,
        origin_mm: DVec3,
        direction: DMat3,
    ) -> Result<Self, GeometryError> {
        if dims.contains(&0) {
            return Err(GeometryError::ZeroDimension(dims));
        }
        if !spacing_mm.is_finite() || spacing_mm.min_element() <= 0.0 {
            return Err(GeometryError::BadSpacing(spacing_mm.to_array()));
        }
        if !origin_mm.is_finite() {
            return Err(GeometryError::BadOrigin(origin_mm.to_array()));
        }
        let bad_direction = || GeometryError::BadDirection(direction.to_cols_array_2d());
        let cols = [direction.x_axis, direction.y_axis, direction.z_axis];
        if cols
            .iter()
            .any(|c| !c.is_finite() || (c.length() - 1.0).abs() > UNIT_TOLERANCE)
        {
            return Err(bad_direction());
        }
        let direction = DMat3::from_cols(
            cols[0].normalize(),
            cols[1].normalize(),
            cols[2].normalize(),
        );
        if direction.determinant().abs() < MIN_DETERMINANT {
            return Err(bad_direction());
        }
        Ok(Self {
            dims,
            spacing_mm,
            origin_mm,
            direction,
        })
    }

    /// The geometry whose [`Self::world_from_voxel`] is `world_from_voxel` (LPS mm from voxel
    /// index): spacing from the lengths of its columns, direction from the unit columns, origin
    /// from its translation. Fails as [`Self::new`] does (a zero or non-finite column, dependent
    /// axes).
    pub fn from_world_from_voxel(
        dims: [usize; 3],
        world_from_voxel: DAffine3,
    ) -> Result<Self, GeometryError> {
        let m = world_from_voxel.matrix3;
        let spacing = DVec3::new(m.x_axis.length(), m.y_axis.length(), m.z_axis.length());
        if !spacing.is_finite() || spacing.min_element() <= 0.0 {
            return Err(GeometryError::BadSpacing(spacing.to_array()));
        }
        let direction = DMat3::from_cols(
            m.x_axis / spacing.x,
            m.y_axis / spacing.y,
            m.z_axis / spacing.z,
        );
        Self::new(dims, spacing, world_from_voxel.translation, direction)
    }

    /// An axis-aligned LPS geometry (identity direction) with the given spacing and origin.
    pub fn axis_aligned(
        dims: [usize; 3],
        spacing_mm: DVec3,
        origin_mm: DVec3,
    ) -> Result<Self, GeometryError> {
        Self::new(dims, spacing_mm, origin_mm, DMat3::IDENTITY)
    }

    /// Number of voxels along `i`, `j`, `k`.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Total number of voxels.
    pub fn voxel_count(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// Distance in mm between neighbouring voxel centres along each index axis.
    pub fn spacing_mm(&self) -> DVec3 {
        self.spacing_mm
    }

    /// World position (mm, LPS) of the centre of voxel (0,0,0).
    pub fn origin_mm(&self) -> DVec3 {
        self.origin_mm
    }

    /// Unit world vectors of the index axes, as columns (index → world, LPS).
    pub fn direction(&self) -> DMat3 {
        self.direction
    }

    /// The affine taking continuous voxel indices to world millimetres (LPS).
    pub fn world_from_voxel(&self) -> DAffine3 {
        let linear = self.direction * DMat3::from_diagonal(self.spacing_mm);
        DAffine3::from_mat3_translation(linear, self.origin_mm)
    }

    /// The affine taking world millimetres (LPS) to continuous voxel indices.
    pub fn voxel_from_world(&self) -> DAffine3 {
        self.world_from_voxel().inverse()
    }

    /// World position (mm) of a (continuous) voxel index.
    pub fn world_of(&self, voxel: DVec3) -> DVec3 {
        self.world_from_voxel().transform_point3(voxel)
    }

    /// True when the index axes are mutually perpendicular (no gantry-tilt shear).
    pub fn is_orthogonal(&self) -> bool {
        let d = self.direction;
        let tol = 1e-4;
        d.x_axis.dot(d.y_axis).abs() < tol
            && d.x_axis.dot(d.z_axis).abs() < tol
            && d.y_axis.dot(d.z_axis).abs() < tol
    }

    /// The patient direction each index axis points to most, e.g. `"LPS"` for an identity
    /// direction, `"RAS"` for a NIfTI-style grid, `"LAI"` for a flipped stack. Letters follow the
    /// ITK/DICOM convention: the direction of increasing index.
    pub fn orientation_code(&self) -> String {
        [
            self.direction.x_axis,
            self.direction.y_axis,
            self.direction.z_axis,
        ]
        .iter()
        .map(|axis| dominant_label(*axis))
        .collect()
    }

    /// The same grid with other direction cosines (spacing and origin kept).
    pub fn with_direction(&self, direction: DMat3) -> Result<Self, GeometryError> {
        Self::new(self.dims, self.spacing_mm, self.origin_mm, direction)
    }

    /// The axis-aligned direction matrix an orientation code names, the inverse of
    /// [`Geometry::orientation_code`]: `"LPS"` is the identity, `"LPI"` a stack running from the
    /// head down, `"RAS"` the NIfTI convention. Each of the three letters (L/R, P/A, S/I) must name
    /// a different patient axis; anything else is `None`.
    pub fn direction_from_code(code: &str) -> Option<DMat3> {
        let letters: Vec<char> = code.trim().to_ascii_uppercase().chars().collect();
        let [a, b, c] = letters.as_slice() else {
            return None;
        };
        let axis = |letter: char| match letter {
            'L' => Some(DVec3::X),
            'R' => Some(-DVec3::X),
            'P' => Some(DVec3::Y),
            'A' => Some(-DVec3::Y),
            'S' => Some(DVec3::Z),
            'I' => Some(-DVec3::Z),
            _ => None,
        };
        let m = DMat3::from_cols(axis(*a)?, axis(*b)?, axis(*c)?);
        (m.determinant().abs() > 0.5).then_some(m)
    }

    /// World-space axis-aligned bounds (min, max) of the voxel centres.
    pub fn world_bounds(&self) -> (DVec3, DVec3) {
        let last = DVec3::new(
            (self.dims[0] - 1) as f64,
            (self.dims[1] - 1) as f64,
            (self.dims[2] - 1) as f64,
        );
        let m = self.world_from_voxel();
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for corner in 0..8 {
            let c = DVec3::new(
                if corner & 1 == 0 { 0.0 } else { last.x },
                if corner & 2 == 0 { 0.0 } else { last.y },
                if corner & 4 == 0 { 0.0 } else { last.z },
            );
            let w = m.transform_point3(c);
            lo = lo.min(w);
            hi = hi.max(w);
        }
        (lo, hi)
    }
}

/// The LPS letter of the patient axis closest to `axis` (its sign picks L/R, P/A, S/I).
fn dominant_label(axis: DVec3) -> char {
    let a = axis.abs();
    let (component, positive, negative) = if a.x >= a.y && a.x >= a.z {
        (axis.x, 'L', 'R')
    } else if a.y >= a.z {
        (axis.y, 'P', 'A')
    } else {
        (axis.z, 'S', 'I')
    };
    if component >= 0.0 {
        positive
    } else {
        negative
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_affine_gives_back_its_geometry() {
        let spacing = DVec3::new(0.5, 1.0, 2.5);
        let origin = DVec3::new(-10.0, 3.0, 7.0);
        let tilted = DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(-0.2);
        let g = Geometry::new([4, 5, 6], spacing, origin, tilted).unwrap();
        let back = Geometry::from_world_from_voxel([4, 5, 6], g.world_from_voxel()).unwrap();
        assert!(back.spacing_mm().abs_diff_eq(spacing, 1e-12));
        assert!(back.origin_mm().abs_diff_eq(origin, 1e-12));
        assert!(back.direction().abs_diff_eq(tilted, 1e-12));
        let flat = DAffine3::from_scale(DVec3::new(1.0, 0.0, 1.0));
        let error = Geometry::from_world_from_voxel([2, 2, 2], flat).unwrap_err();
        assert!(matches!(error, GeometryError::BadSpacing(_)));
    }

    #[test]
    fn affine_round_trip_with_shear() {
        let tilt = 18.5_f64.to_radians();
        let dir = DMat3::from_cols(DVec3::X, DVec3::new(0.0, tilt.cos(), -tilt.sin()), DVec3::Z);
        let g = Geometry::new(
            [4, 5, 6],
            DVec3::new(0.5, 0.5, 2.0),
            DVec3::new(-10.0, 3.0, 7.0),
            dir,
        )
        .unwrap();
        assert!(!g.is_orthogonal());
        let p = DVec3::new(1.25, 3.5, 4.75);
        let back = g.voxel_from_world().transform_point3(g.world_of(p));
        assert!((back - p).length() < 1e-12);
        assert_eq!(g.world_of(DVec3::ZERO), DVec3::new(-10.0, 3.0, 7.0));
        let k1 = g.world_of(DVec3::Z) - g.world_of(DVec3::ZERO);
        assert!((k1 - DVec3::new(0.0, 0.0, 2.0)).length() < 1e-12);
    }

    #[test]
    fn orientation_codes() {
        let lps = Geometry::axis_aligned([2, 2, 2], DVec3::ONE, DVec3::ZERO).unwrap();
        assert_eq!(lps.orientation_code(), "LPS");
        let ras = Geometry::new(
            [2, 2, 2],
            DVec3::ONE,
            DVec3::ZERO,
            DMat3::from_diagonal(DVec3::new(-1.0, -1.0, 1.0)),
        )
        .unwrap();
        assert_eq!(ras.orientation_code(), "RAS");
    }

    #[test]
    fn orientation_codes_round_trip() {
        for code in ["LPS", "RAS", "LPI", "ASL", "IRP"] {
            let d = Geometry::direction_from_code(code).unwrap();
            let g = Geometry::new([2, 2, 2], DVec3::ONE, DVec3::ZERO, d).unwrap();
            assert_eq!(g.orientation_code(), code);
        }
        for bad in ["", "LP", "LLS", "LRS", "XYZ", "LPSI"] {
            assert!(Geometry::direction_from_code(bad).is_none(), "{bad}");
        }
    }

    #[test]
    fn rejects_bad_geometry() {
        let ok = DVec3::ONE;
        assert!(Geometry::axis_aligned([0, 1, 1], ok, DVec3::ZERO).is_err());
        assert!(
            Geometry::axis_aligned([1, 1, 1], DVec3::new(1.0, f64::NAN, 1.0), DVec3::ZERO).is_err()
        );
        assert!(
            Geometry::axis_aligned([1, 1, 1], DVec3::new(1.0, -1.0, 1.0), DVec3::ZERO).is_err()
        );
        assert!(
            Geometry::axis_aligned([1, 1, 1], ok, DVec3::new(f64::INFINITY, 0.0, 0.0)).is_err()
        );
        let coplanar = DMat3::from_cols(DVec3::X, DVec3::Y, DVec3::X);
        assert!(Geometry::new([1, 1, 1], ok, DVec3::ZERO, coplanar).is_err());
        let zero = DMat3::from_cols(DVec3::X, DVec3::Y, DVec3::ZERO);
        assert!(Geometry::new([1, 1, 1], ok, DVec3::ZERO, zero).is_err());
    }
}
