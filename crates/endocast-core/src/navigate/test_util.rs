//! Helpers shared by the navigation tests.

use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;

/// A small deterministic generator (SplitMix64), so tests need no extra crate.
pub(crate) struct Rng(u64);

impl Rng {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in [0, 1).
    pub(crate) fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [-1, 1)³.
    pub(crate) fn vec(&mut self) -> DVec3 {
        DVec3::new(self.unit(), self.unit(), self.unit()) * 2.0 - 1.0
    }
}

/// A volume of `dims` voxels with `spacing_mm` whose voxels are −100 (lumen below 0) with
/// probability `lumen_fraction`, else +100.
pub(crate) fn random_volume(
    dims: [usize; 3],
    spacing_mm: DVec3,
    seed: u64,
    lumen_fraction: f64,
) -> Volume {
    let mut rng = Rng::new(seed);
    let n = dims[0] * dims[1] * dims[2];
    let voxels = (0..n)
        .map(|_| {
            if rng.unit() < lumen_fraction {
                924
            } else {
                1124
            }
        })
        .collect();
    let geometry = Geometry::axis_aligned(dims, spacing_mm, DVec3::new(-3.0, 5.0, 1.0)).unwrap();
    Volume::new(
        geometry,
        voxels,
        ValueMap::new(1.0, -1024.0).unwrap(),
        Modality::Ct,
    )
    .unwrap()
}
