//! The coarser levels of an OME-Zarr pyramid: each a box-filtered halving of the one before.

use endocast_core::{Geometry, Volume};
use glam::DVec3;

/// The next coarser level of `volume`: every axis longer than one voxel halved (rounding up),
/// each voxel the rounded mean of the up to 2 × 2 × 2 stored values it covers, its centre at
/// theirs. The value map and modality are kept. `None` where the coarser grid is not a valid
/// one (a spacing that overflows when doubled).
pub(super) fn halved(volume: &Volume) -> Option<Volume> {
    let geometry = volume.geometry();
    let dims = geometry.dims();
    let factor = dims.map(|d| if d > 1 { 2 } else { 1 });
    let new_dims = [0, 1, 2].map(|a| dims[a].div_ceil(factor[a]));
    let step = DVec3::from(factor.map(|f| f as f64));
    let spacing = geometry.spacing_mm() * step;
    // The first coarse voxel is centred between the first fine voxels it covers.
    let shift = (step - DVec3::ONE) * 0.5 * geometry.spacing_mm();
    let origin = geometry.origin_mm() + geometry.direction() * shift;
    let mut voxels = Vec::with_capacity(new_dims.iter().product());
    for k in 0..new_dims[2] {
        for j in 0..new_dims[1] {
            for i in 0..new_dims[0] {
                voxels.push(mean(volume, [i, j, k], factor));
            }
        }
    }
    let geometry = Geometry::new(new_dims, spacing, origin, geometry.direction()).ok()?;
    Volume::new(
        geometry,
        voxels,
        volume.value_map(),
        volume.modality().clone(),
    )
    .ok()
}

/// The rounded mean of the stored values the coarse voxel `at` covers.
fn mean(volume: &Volume, at: [usize; 3], factor: [usize; 3]) -> u16 {
    let (mut sum, mut count) = (0u32, 0u32);
    for dk in 0..factor[2] {
        for dj in 0..factor[1] {
            for di in 0..factor[0] {
                let fine = [
                    at[0] * factor[0] + di,
                    at[1] * factor[1] + dj,
                    at[2] * factor[2] + dk,
                ];
                if let Some(v) = volume.stored(fine[0], fine[1], fine[2]) {
                    sum += u32::from(v);
                    count += 1;
                }
            }
        }
    }
    // count ≥ 1: the first fine voxel always exists; the mean of u16 values fits a u16.
    ((sum + count / 2) / count.max(1)) as u16
}

#[cfg(test)]
mod tests {
    use super::*;
    use endocast_core::{Modality, ValueMap};

    #[test]
    fn halving_averages_and_keeps_the_centre() {
        let geometry =
            Geometry::axis_aligned([3, 2, 1], DVec3::new(1.0, 2.0, 3.0), DVec3::ZERO).unwrap();
        let voxels = vec![0, 2, 10, 4, 6, 20];
        let volume = Volume::new(geometry, voxels, ValueMap::IDENTITY, Modality::Ct).unwrap();
        let half = halved(&volume).unwrap();
        assert_eq!(half.dims(), [2, 1, 1]);
        assert_eq!(half.voxels(), &[3, 15]);
        assert_eq!(half.geometry().spacing_mm(), DVec3::new(2.0, 4.0, 3.0));
        // The first coarse voxel is centred on the first 2 × 2 fine ones.
        assert_eq!(half.geometry().origin_mm(), DVec3::new(0.5, 1.0, 0.0));
    }
}
