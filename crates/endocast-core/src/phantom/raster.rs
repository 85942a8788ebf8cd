//! Turns a phantom's value function into a [`Volume`]: slices in parallel, `u16` written
//! directly, noise added per voxel from its index.

use super::{noise, PhantomOptions};
use crate::{Geometry, Modality, ValueMap, Volume};
use glam::DVec3;
use rayon::prelude::*;

/// Physical value of stored 0: CT's customary −1024 HU, so stored values are HU + 1024.
const OFFSET_HU: f64 = -1024.0;

/// Samples `hu_at` (a function of the continuous voxel index, in HU) at every voxel centre of a
/// `dims` grid, adds the options' noise and quantises to the CT value map (scale 1, offset
/// −1024 HU). The grid has 1 mm isotropic spacing, identity direction and its centre at world
/// (0, 0, 0). Every voxel depends only on its index, so the result does not depend on threads.
pub(crate) fn rasterize(
    dims: [usize; 3],
    options: &PhantomOptions,
    hu_at: impl Fn(DVec3) -> f64 + Sync,
) -> Volume {
    let [nx, ny, nz] = dims;
    let map = ValueMap::new(1.0, OFFSET_HU).unwrap_or_else(|e| unreachable!("constant map: {e}"));
    let sigma = options.noise_sigma_hu();
    let seed = options.seed;
    let mut voxels = vec![0u16; nx * ny * nz];
    voxels
        .par_chunks_mut(nx * ny)
        .enumerate()
        .for_each(|(k, slice)| {
            for (j, row) in slice.chunks_exact_mut(nx).enumerate() {
                let row_start = (k * ny + j) * nx;
                for (i, voxel) in row.iter_mut().enumerate() {
                    let mut hu = hu_at(DVec3::new(i as f64, j as f64, k as f64));
                    if sigma > 0.0 {
                        hu += sigma * noise::gaussian(seed, (row_start + i) as u64);
                    }
                    *voxel = map.quantize(hu);
                }
            }
        });
    // Dimensions are at least PhantomOptions::MIN_SIZE and the spacing is 1 mm, so neither the
    // geometry nor the length check can fail.
    let geometry = Geometry::axis_aligned(dims, DVec3::ONE, -grid_centre(dims))
        .unwrap_or_else(|e| unreachable!("phantom geometry: {e}"));
    Volume::new(geometry, voxels, map, Modality::Ct)
        .unwrap_or_else(|e| unreachable!("phantom voxel count: {e}"))
}

/// The continuous voxel index of the grid's centre.
pub(crate) fn grid_centre(dims: [usize; 3]) -> DVec3 {
    DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) / 2.0 - 0.5
}
