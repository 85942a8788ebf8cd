//! A scan's fingerprint: what a case file records so its annotations are drawn on that scan
//! and no other.

use crate::Volume;
use thiserror::Error;

/// A scan's dimensions, spacing, origin, axes and a hash of its values.
#[derive(Debug, Clone, PartialEq)]
pub struct ScanIdentity {
    /// Voxels per axis.
    pub dims: [usize; 3],
    /// Voxel spacing, mm.
    pub spacing_mm: [f64; 3],
    /// World position of voxel (0, 0, 0), mm.
    pub origin_mm: [f64; 3],
    /// The world directions of the index axes (the direction matrix, column by column); `None`
    /// in fingerprints recorded before it was kept, which then match any axes.
    pub axes: Option<[f64; 9]>,
    /// A hash of the stored values and their scale and offset, 16 hex digits.
    pub voxel_hash: String,
}

/// Why a scan is not the one a case was made on.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("the scan's {what} is {found}, the case was made on {expected}")]
pub struct IdentityMismatch {
    /// What differs: `dimensions`, `spacing`, `origin`, `axes` or `voxel values`.
    pub what: &'static str,
    /// The scan's.
    pub found: String,
    /// The case's.
    pub expected: String,
}

/// How far spacings and origins may differ and still match, mm (rounding in file headers).
const GEOMETRY_TOLERANCE_MM: f64 = 1e-3;
/// How far the direction cosines may differ and still match (rounding in file headers).
const AXES_TOLERANCE: f64 = 1e-4;

impl ScanIdentity {
    /// The identity of `volume` (one pass over its voxels).
    pub fn of(volume: &Volume) -> Self {
        let g = volume.geometry();
        let map = volume.value_map();
        let mut hash = Hash64::default();
        hash.add(map.scale().to_bits());
        hash.add(map.offset().to_bits());
        for chunk in volume.voxels().chunks(4) {
            let word = chunk
                .iter()
                .enumerate()
                .fold(0u64, |w, (i, &v)| w | u64::from(v) << (16 * i));
            hash.add(word);
        }
        hash.add(volume.voxels().len() as u64);
        Self {
            dims: volume.dims(),
            spacing_mm: g.spacing_mm().to_array(),
            origin_mm: g.origin_mm().to_array(),
            axes: Some(g.direction().to_cols_array()),
            voxel_hash: format!("{:016x}", hash.finish()),
        }
    }

    /// Whether `scan` (the identity of the scan opened now) is this one; the error says what
    /// differs.
    pub fn check(&self, scan: &ScanIdentity) -> Result<(), IdentityMismatch> {
        let near = |a: [f64; 3], b: [f64; 3]| {
            a.iter()
                .zip(b)
                .all(|(x, y)| (x - y).abs() <= GEOMETRY_TOLERANCE_MM)
        };
        let mismatch = |what, found: String, expected: String| {
            Err(IdentityMismatch {
                what,
                found,
                expected,
            })
        };
        let [a, b] = [scan.dims, self.dims];
        if a != b {
            return mismatch("dimensions", format!("{a:?}"), format!("{b:?}"));
        }
        if !near(scan.spacing_mm, self.spacing_mm) {
            let [a, b] = [scan.spacing_mm, self.spacing_mm];
            return mismatch("spacing", format!("{a:?} mm"), format!("{b:?} mm"));
        }
        if !near(scan.origin_mm, self.origin_mm) {
            let [a, b] = [scan.origin_mm, self.origin_mm];
            return mismatch("origin", format!("{a:?} mm"), format!("{b:?} mm"));
        }
        if let (Some(a), Some(b)) = (scan.axes, self.axes) {
            if a.iter().zip(b).any(|(x, y)| (x - y).abs() > AXES_TOLERANCE) {
                let show = |m: [f64; 9]| format!("{:?}", m.map(|v| (v * 1e4).round() / 1e4));
                return mismatch("axes", show(a), show(b));
            }
        }
        if scan.voxel_hash != self.voxel_hash {
            let [a, b] = [&scan.voxel_hash, &self.voxel_hash];
            return mismatch("voxel values", format!("hash {a}"), format!("hash {b}"));
        }
        Ok(())
    }
}

/// A 64-bit hash of words (a multiply–rotate mix per word, the murmur3 finaliser at the end):
/// not cryptographic, but any changed voxel changes it, on every machine alike.
#[derive(Debug)]
struct Hash64(u64);

impl Default for Hash64 {
    fn default() -> Self {
        Self(0x9e37_79b9_7f4a_7c15)
    }
}

impl Hash64 {
    fn add(&mut self, word: u64) {
        let mixed = word.wrapping_mul(0x87c3_7b91_1142_53d5).rotate_left(31);
        self.0 = (self.0 ^ mixed)
            .rotate_left(27)
            .wrapping_mul(5)
            .wrapping_add(0x52dc_e729);
    }

    fn finish(&self) -> u64 {
        let mut h = self.0;
        h ^= h >> 33;
        h = h.wrapping_mul(0xff51_afd7_ed55_8ccd);
        h ^= h >> 33;
        h = h.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
        h ^ (h >> 33)
    }
}
