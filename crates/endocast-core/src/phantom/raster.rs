//! Turns a phantom's value function into a [`Volume`]: slices in parallel, `u16` written
//! directly, noise added per voxel from its index.

use super::{noise, PhantomOptions};
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;
use rayon::prelude::*;

/// Physical value of stored 0: CT's customary −1024 HU, so stored values are HU + 1024.
const OFFSET_HU: f64 = -1024.0;

/// A phantom's noiseless value, a function of the continuous voxel index.
pub(crate) trait Field: Sync {
    /// The value at `p`, HU.
    fn hu_at(&self, p: DVec3) -> f64;

    /// When voxels `i..end` of row (`j`, `k`) all have one known value, `Some((end, hu))`, so the
    /// row is filled without asking each voxel (most of the colon's volume is plain tissue).
    fn uniform_run(&self, _i: usize, _j: usize, _k: usize) -> Option<(usize, f64)> {
        None
    }
}

impl<F: Fn(DVec3) -> f64 + Sync> Field for F {
    fn hu_at(&self, p: DVec3) -> f64 {
        self(p)
    }
}

/// Samples `field` at every voxel centre of a `dims` grid, adds the options' noise and quantises
/// to the CT value map (scale 1, offset −1024 HU). The grid has 1 mm isotropic spacing, identity
/// direction and its centre at world (0, 0, 0). Every voxel depends only on its index, so the
/// result does not depend on the number of threads.
pub(crate) fn rasterize(dims: [usize; 3], options: &PhantomOptions, field: &impl Field) -> Volume {
    let [nx, ny, nz] = dims;
    let sigma = options.noise_sigma_hu();
    let seed = options.seed;
    let mut voxels = vec![0u16; nx * ny * nz];
    voxels
        .par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(k, slice)| {
            let mut noise_row = vec![0.0; if sigma > 0.0 { nx } else { 0 }];
            for (j, row) in slice.chunks_exact_mut(nx).enumerate() {
                if sigma > 0.0 {
                    noise::fill(seed, ((k * ny + j) * nx) as u64, &mut noise_row);
                }
                let noisy = |hu: f64, i: usize| match noise_row.get(i) {
                    Some(g) => quantize(hu + sigma * g),
                    None => quantize(hu),
                };
                let mut i = 0;
                while i < nx {
                    if let Some((end, hu)) = field.uniform_run(i, j, k) {
                        let end = end.clamp(i + 1, nx);
                        for (n, voxel) in row[i..end].iter_mut().enumerate() {
                            *voxel = noisy(hu, i + n);
                        }
                        i = end;
                    } else {
                        row[i] = noisy(field.hu_at(DVec3::new(i as f64, j as f64, k as f64)), i);
                        i += 1;
                    }
                }
            }
        });
    // Dimensions are at least PhantomOptions::MIN_SIZE and the spacing is 1 mm, so neither the
    // geometry nor the length check can fail.
    let geometry = Geometry::axis_aligned(dims, DVec3::ONE, -grid_centre(dims))
        .unwrap_or_else(|e| unreachable!("phantom geometry: {e}"));
    let map = ValueMap::new(1.0, OFFSET_HU).unwrap_or_else(|e| unreachable!("constant map: {e}"));
    Volume::new(geometry, voxels, map, Modality::Ct)
        .unwrap_or_else(|e| unreachable!("phantom voxel count: {e}"))
}

/// The stored value nearest to `hu` under the map (scale 1, offset [`OFFSET_HU`]), clamped to
/// the `u16` range. Same result as `ValueMap::quantize` (ties differ only below the range), but
/// with no division and no call to `round`, which is a library call on baseline x86-64 and was
/// a fifth of the generation time.
#[inline]
fn quantize(hu: f64) -> u16 {
    // The saturating cast truncates, which is rounding for the non-negative value plus 0.5;
    // NaN becomes 0.
    (hu - OFFSET_HU + 0.5).clamp(0.0, f64::from(u16::MAX)) as u16
}

/// The continuous voxel index of the grid's centre.
pub(crate) fn grid_centre(dims: [usize; 3]) -> DVec3 {
    DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) / 2.0 - 0.5
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantize_agrees_with_the_value_map() {
        let map = ValueMap::new(1.0, OFFSET_HU).unwrap();
        for hu in [
            -5000.0, -1024.6, -1024.4, -1000.0, -480.5, 39.49, 2500.0, 64511.4, 1e9,
        ] {
            assert_eq!(quantize(hu), map.quantize(hu), "{hu}");
        }
        assert_eq!(quantize(f64::NAN), 0);
    }
}
