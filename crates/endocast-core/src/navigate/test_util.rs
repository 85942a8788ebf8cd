//! Helpers shared by the navigation tests.

use crate::test_rng::Rng;
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;

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
