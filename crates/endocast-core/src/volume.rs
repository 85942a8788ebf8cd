//! The scalar volume every reader produces and every renderer consumes.
//!
//! Voxels are stored as `u16` (`i` fastest, then `j`, then `k`) with one linear map back to
//! physical values (`physical = stored * scale + offset`, Hounsfield units for CT). Sixteen bits
//! hold every clinical CT and MR scan exactly, halve the memory of `f32` and keep the renderer's
//! sample loop on integers. Thresholds the user types are physical; [`ValueMap`] is the one place
//! that converts them into the stored domain.

use crate::geometry::Geometry;
use glam::DVec3;
use thiserror::Error;

/// A volume whose parts do not fit together.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum VolumeError {
    /// The voxel buffer length does not match the geometry.
    #[error("voxel buffer holds {found} values but the geometry needs {expected}")]
    LengthMismatch {
        /// Voxels the geometry calls for.
        expected: usize,
        /// Voxels supplied.
        found: usize,
    },
    /// The value map's scale is zero, NaN or infinite, or its offset is not finite.
    #[error("value map scale {scale} / offset {offset} must be finite with a non-zero scale")]
    BadValueMap {
        /// The rejected scale.
        scale: f64,
        /// The rejected offset.
        offset: f64,
    },
}

/// The linear map from stored `u16` values to physical values: `physical = stored * scale + offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ValueMap {
    scale: f64,
    offset: f64,
}

impl ValueMap {
    /// Stored values are the physical values.
    pub const IDENTITY: Self = Self {
        scale: 1.0,
        offset: 0.0,
    };

    /// A validated map: `scale` finite and non-zero, `offset` finite.
    pub fn new(scale: f64, offset: f64) -> Result<Self, VolumeError> {
        if !scale.is_finite() || scale == 0.0 || !offset.is_finite() {
            return Err(VolumeError::BadValueMap { scale, offset });
        }
        Ok(Self { scale, offset })
    }

    /// Physical units per stored unit.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Physical value of stored 0.
    pub fn offset(&self) -> f64 {
        self.offset
    }

    /// Physical value of a stored value.
    #[inline]
    pub fn physical(&self, stored: u16) -> f64 {
        f64::from(stored) * self.scale + self.offset
    }

    /// The (continuous, unclamped) stored value that maps to `physical`. Use this to turn a
    /// user's threshold into the stored domain; compare trilinear samples against it directly.
    #[inline]
    pub fn stored_from_physical(&self, physical: f64) -> f64 {
        (physical - self.offset) / self.scale
    }

    /// The map for physical values in `[min, max]`: exact (scale 1) when every value is an
    /// integer (`integral`) and the range fits 16 bits, otherwise the range spread over all
    /// 65 536 levels.
    pub fn fitting(min: f64, max: f64, integral: bool) -> Result<Self, VolumeError> {
        if !min.is_finite() || !max.is_finite() || max < min {
            return Err(VolumeError::BadValueMap {
                scale: max - min,
                offset: min,
            });
        }
        if max == min || (integral && max - min <= f64::from(u16::MAX)) {
            Self::new(1.0, min)
        } else {
            Self::new((max - min) / f64::from(u16::MAX), min)
        }
    }

    /// The stored value nearest to `physical`, clamped to the `u16` range.
    #[inline]
    pub fn quantize(&self, physical: f64) -> u16 {
        let s = self.stored_from_physical(physical).round();
        // NaN maps to 0 through the saturating cast; callers validate inputs beforehand.
        s.clamp(0.0, f64::from(u16::MAX)) as u16
    }
}

/// The imaging modality of a scan, when the source says.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
#[non_exhaustive]
pub enum Modality {
    /// Computed tomography: values are Hounsfield units.
    Ct,
    /// Magnetic resonance: values are arbitrary intensity units.
    Mr,
    /// Another modality, by its DICOM code (e.g. `"PT"`).
    Other(String),
    /// The source does not say.
    #[default]
    Unknown,
}

impl Modality {
    /// Parses a DICOM modality code; empty means unknown.
    pub fn from_code(code: &str) -> Self {
        match code.trim().to_ascii_uppercase().as_str() {
            "" => Self::Unknown,
            "CT" => Self::Ct,
            "MR" => Self::Mr,
            other => Self::Other(other.to_string()),
        }
    }

    /// Short display name: `CT`, `MR`, the DICOM code, or `unknown`.
    pub fn name(&self) -> &str {
        match self {
            Self::Ct => "CT",
            Self::Mr => "MR",
            Self::Other(code) => code,
            Self::Unknown => "unknown",
        }
    }
}

/// A scalar volume: voxels, their geometry in the patient, and the map to physical values.
#[derive(Debug, Clone)]
pub struct Volume {
    geometry: Geometry,
    voxels: Vec<u16>,
    value_map: ValueMap,
    modality: Modality,
    stored_range: (u16, u16),
}

impl Volume {
    /// A volume from stored voxels (`i` fastest). Fails when the buffer length does not match.
    pub fn new(
        geometry: Geometry,
        voxels: Vec<u16>,
        value_map: ValueMap,
        modality: Modality,
    ) -> Result<Self, VolumeError> {
        let expected = geometry.voxel_count();
        if voxels.len() != expected {
            return Err(VolumeError::LengthMismatch {
                expected,
                found: voxels.len(),
            });
        }
        let stored_range = stored_range(&voxels);
        Ok(Self {
            geometry,
            voxels,
            value_map,
            modality,
            stored_range,
        })
    }

    /// Where the voxels sit in the patient.
    pub fn geometry(&self) -> &Geometry {
        &self.geometry
    }

    /// Number of voxels along `i`, `j`, `k`.
    pub fn dims(&self) -> [usize; 3] {
        self.geometry.dims()
    }

    /// Stored voxels, `i` fastest, then `j`, then `k`.
    pub fn voxels(&self) -> &[u16] {
        &self.voxels
    }

    /// Gives the voxel buffer back (e.g. to a writer or a resampler).
    pub fn into_voxels(self) -> Vec<u16> {
        self.voxels
    }

    /// The map from stored to physical values.
    pub fn value_map(&self) -> ValueMap {
        self.value_map
    }

    /// The imaging modality, when known.
    pub fn modality(&self) -> &Modality {
        &self.modality
    }

    /// Bytes held by the voxel buffer.
    pub fn voxel_bytes(&self) -> usize {
        self.voxels.len() * size_of::<u16>()
    }

    /// Linear index of voxel `(i, j, k)`. Panics (a caller bug) when out of range in debug builds.
    #[inline]
    pub fn index(&self, i: usize, j: usize, k: usize) -> usize {
        let [nx, ny, _] = self.geometry.dims();
        debug_assert!(i < nx && j < ny && k < self.geometry.dims()[2]);
        i + nx * (j + ny * k)
    }

    /// Stored value of voxel `(i, j, k)`, or `None` outside the grid.
    #[inline]
    pub fn stored(&self, i: usize, j: usize, k: usize) -> Option<u16> {
        let [nx, ny, nz] = self.geometry.dims();
        (i < nx && j < ny && k < nz).then(|| self.voxels[i + nx * (j + ny * k)])
    }

    /// Physical value (e.g. HU) of voxel `(i, j, k)`, or `None` outside the grid.
    #[inline]
    pub fn physical(&self, i: usize, j: usize, k: usize) -> Option<f64> {
        self.stored(i, j, k).map(|s| self.value_map.physical(s))
    }

    /// Smallest and largest stored values.
    pub fn stored_range(&self) -> (u16, u16) {
        self.stored_range
    }

    /// Smallest and largest physical values (ordered even when the scale is negative).
    pub fn physical_range(&self) -> (f64, f64) {
        let a = self.value_map.physical(self.stored_range.0);
        let b = self.value_map.physical(self.stored_range.1);
        (a.min(b), a.max(b))
    }

    /// The same scan stored with its axis `order[n]` as index axis `n` (`order` a permutation
    /// of 0, 1, 2): the same voxels, each at the same world position (e.g. a scan in sagittal
    /// slices stored again as axial slices). `None` when `order` is no permutation.
    pub fn with_axes(&self, order: [usize; 3]) -> Option<Volume> {
        if !(0..3).all(|a| order.contains(&a)) {
            return None;
        }
        let g = &self.geometry;
        let dims = g.dims();
        let (spacing, d) = (g.spacing_mm(), g.direction());
        let geometry = Geometry::new(
            order.map(|a| dims[a]),
            DVec3::from_array(order.map(|a| spacing[a])),
            g.origin_mm(),
            glam::DMat3::from_cols(d.col(order[0]), d.col(order[1]), d.col(order[2])),
        )
        .ok()?;
        let stride = [1, dims[0], dims[0] * dims[1]];
        let [sx, sy, sz] = order.map(|a| stride[a]);
        let [nx, ny, nz] = geometry.dims();
        let mut voxels = Vec::with_capacity(self.voxels.len());
        for k in 0..nz {
            for j in 0..ny {
                voxels.extend((0..nx).map(|i| self.voxels[i * sx + j * sy + k * sz]));
            }
        }
        Volume::new(geometry, voxels, self.value_map, self.modality.clone()).ok()
    }

    /// Trilinearly interpolated physical value at a continuous voxel index, or `None` when the
    /// point lies outside the voxel centres' hull (or is not finite).
    pub fn sample_physical(&self, voxel: DVec3) -> Option<f64> {
        let [nx, ny, nz] = self.geometry.dims();
        let max = DVec3::new((nx - 1) as f64, (ny - 1) as f64, (nz - 1) as f64);
        if !voxel.is_finite() || voxel.cmplt(DVec3::ZERO).any() || voxel.cmpgt(max).any() {
            return None;
        }
        let base = voxel.floor().min((max - 1.0).max(DVec3::ZERO));
        let f = voxel - base;
        let (i, j, k) = (base.x as usize, base.y as usize, base.z as usize);
        let at = |di: usize, dj: usize, dk: usize| {
            let s = self.stored(
                (i + di).min(nx - 1),
                (j + dj).min(ny - 1),
                (k + dk).min(nz - 1),
            );
            f64::from(s.unwrap_or(0))
        };
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let c00 = lerp(at(0, 0, 0), at(1, 0, 0), f.x);
        let c10 = lerp(at(0, 1, 0), at(1, 1, 0), f.x);
        let c01 = lerp(at(0, 0, 1), at(1, 0, 1), f.x);
        let c11 = lerp(at(0, 1, 1), at(1, 1, 1), f.x);
        let stored = lerp(lerp(c00, c10, f.y), lerp(c01, c11, f.y), f.z);
        Some(stored * self.value_map.scale() + self.value_map.offset())
    }
}

fn stored_range(voxels: &[u16]) -> (u16, u16) {
    use rayon::prelude::*;
    voxels
        .par_chunks(1 << 16)
        .map(|chunk| {
            chunk
                .iter()
                .fold((u16::MAX, u16::MIN), |(lo, hi), &v| (lo.min(v), hi.max(v)))
        })
        .reduce(
            || (u16::MAX, u16::MIN),
            |(a, b), (c, d)| (a.min(c), b.max(d)),
        )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tiny() -> Volume {
        let g = Geometry::axis_aligned([3, 2, 2], DVec3::ONE, DVec3::ZERO).unwrap();
        let voxels: Vec<u16> = (0..12).map(|v| v * 10).collect();
        Volume::new(
            g,
            voxels,
            ValueMap::new(1.0, -1024.0).unwrap(),
            Modality::Ct,
        )
        .unwrap()
    }

    #[test]
    fn physical_values_and_range() {
        let v = tiny();
        assert_eq!(v.physical(0, 0, 0), Some(-1024.0));
        assert_eq!(v.physical(2, 1, 1), Some(110.0 - 1024.0));
        assert_eq!(v.physical(3, 0, 0), None);
        assert_eq!(v.physical_range(), (-1024.0, 110.0 - 1024.0));
        assert_eq!(v.voxel_bytes(), 24);
    }

    #[test]
    fn trilinear_sampling_of_a_linear_field_is_exact() {
        // stored = 10 * (i + 3 j + 6 k) is linear in the index, so interpolation is exact.
        let v = tiny();
        let p = DVec3::new(1.3, 0.6, 0.25);
        let expected = 10.0 * (p.x + 3.0 * p.y + 6.0 * p.z) - 1024.0;
        assert!((v.sample_physical(p).unwrap() - expected).abs() < 1e-9);
        assert!(v.sample_physical(DVec3::new(2.0, 1.0, 1.0)).is_some());
        assert!(v.sample_physical(DVec3::new(2.01, 1.0, 1.0)).is_none());
        assert!(v.sample_physical(DVec3::new(f64::NAN, 0.0, 0.0)).is_none());
    }

    #[test]
    fn value_map_conversions() {
        let m = ValueMap::new(0.5, -100.0).unwrap();
        assert_eq!(m.stored_from_physical(-50.0), 100.0);
        assert_eq!(m.quantize(-50.2), 100);
        assert_eq!(m.quantize(-1e9), 0);
        assert!(ValueMap::new(0.0, 1.0).is_err());
        assert!(ValueMap::new(f64::NAN, 1.0).is_err());
        let exact = ValueMap::fitting(-1024.0, 3071.0, true).unwrap();
        assert_eq!((exact.scale(), exact.offset()), (1.0, -1024.0));
        let spread = ValueMap::fitting(0.0, 1.0, false).unwrap();
        assert_eq!(spread.quantize(1.0), u16::MAX);
    }

    #[test]
    fn length_mismatch_is_an_error() {
        let g = Geometry::axis_aligned([2, 2, 2], DVec3::ONE, DVec3::ZERO).unwrap();
        let err = Volume::new(g, vec![0; 7], ValueMap::IDENTITY, Modality::Unknown);
        assert!(matches!(
            err,
            Err(VolumeError::LengthMismatch {
                expected: 8,
                found: 7
            })
        ));
    }
}
