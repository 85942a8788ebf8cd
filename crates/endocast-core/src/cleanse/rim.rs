//! Rewriting a pool and its partial volumes as air, and the tissue mixed into them as tissue in
//! air (see the module documentation of [`super`]).

use super::pools::{Found, HuScan, VoxelSet};
use super::{Gravity, AIR_HU, LEVEL_RAMP_VOX, RIM_MM, SOFT_TISSUE_HU};

/// Where the fluid's share makes air-and-fluid read like tissue, the voxel's value says nothing
/// of its tissue: within this share of the tag-to-air span of the tissue value it is
/// ambiguous, and takes the mean of its neighbours along gravity. Less than half the step of the
/// level's ramp per voxel (1 / [`LEVEL_RAMP_VOX`]), so no two ambiguous voxels are neighbours.
const AMBIGUOUS_SHARE: f64 = 0.15;

/// Rewrites every pool of `found` and the voxels within [`RIM_MM`] of it in `voxels` (a copy of
/// the scan's); returns how many stored values changed. Tagged voxels of other structures in a
/// pool's rim (bone, a vessel) are left alone.
pub(crate) fn rewrite(scan: &HuScan, found: &[Found], voxels: &mut [u16]) -> usize {
    let mut fluid = VoxelSet::new(voxels.len());
    for pool in found {
        pool.voxels.iter().for_each(|&v| {
            fluid.insert(v);
        });
    }
    let mut claimed = VoxelSet::new(voxels.len());
    let mut changed = 0;
    for pool in found {
        let rim = rim_of(scan, pool, &fluid, &mut claimed);
        changed += rewrite_rim(scan, pool, &rim, voxels);
    }
    changed
}

/// The pool's voxels and the voxels within [`RIM_MM`] of its boundary not claimed by an
/// earlier pool, less other structures' tagged voxels.
fn rim_of(scan: &HuScan, pool: &Found, fluid: &VoxelSet, claimed: &mut VoxelSet) -> Vec<usize> {
    let spacing = scan.volume.geometry().spacing_mm();
    let reach: [usize; 3] = std::array::from_fn(|a| ((RIM_MM / spacing[a]).ceil() as usize).max(1));
    let mut rim = Vec::new();
    for &index in &pool.voxels {
        if claimed.insert(index) {
            rim.push(index);
        }
        let ijk = scan.ijk(index);
        if scan.neighbours(ijk).all(|n| fluid.contains(scan.index(n))) {
            continue;
        }
        let range =
            |a: usize| ijk[a].saturating_sub(reach[a])..=(ijk[a] + reach[a]).min(scan.dims[a] - 1);
        for k in range(2) {
            for j in range(1) {
                for i in range(0) {
                    let n = scan.index([i, j, k]);
                    let other_tag = scan.is_tag(n) && !fluid.contains(n);
                    if !other_tag && claimed.insert(n) {
                        rim.push(n);
                    }
                }
            }
        }
    }
    rim
}

/// Writes the cleansed value of every voxel of `rim` into `voxels`; the ambiguous ones last, from
/// their neighbours along gravity. Returns how many stored values changed.
fn rewrite_rim(scan: &HuScan, pool: &Found, rim: &[usize], voxels: &mut [u16]) -> usize {
    let map = scan.volume.value_map();
    let store = |hu: f64| map.quantize(hu + scan.offset);
    let gravity = pool.pool.gravity;
    let mut ambiguous = Vec::new();
    let mut changed = 0;
    for &index in rim {
        let depth = gravity.depth(scan.ijk(index));
        match cleansed_hu(scan.hu(index), depth, pool) {
            Some(hu) => {
                let stored = store(hu);
                changed += usize::from(stored != voxels[index]);
                voxels[index] = stored;
            }
            None => ambiguous.push(index),
        }
    }
    for index in ambiguous {
        let hu = along_gravity_mean(scan, gravity, index, voxels);
        let stored = store(hu);
        changed += usize::from(stored != voxels[index]);
        voxels[index] = stored;
    }
    changed
}

/// The value of a voxel of value `hu` at `depth` in the pool's rim once its fluid is air: the
/// fluid's share from the depth against the level, the tissue's from the value, the rest air.
/// `None` where the value cannot tell tissue from air and fluid (see [`AMBIGUOUS_SHARE`]).
fn cleansed_hu(hu: f64, depth: f64, pool: &Found) -> Option<f64> {
    let (level, tag) = (pool.pool.level_depth, pool.pool.tag_hu);
    let fluid = ((depth - level) / LEVEL_RAMP_VOX + 0.5).clamp(0.0, 1.0);
    if fluid == 0.0 {
        return Some(hu);
    }
    let lumen = AIR_HU + fluid * (tag - AIR_HU);
    let span = SOFT_TISSUE_HU - lumen;
    if span.abs() < AMBIGUOUS_SHARE * (tag - AIR_HU) {
        return None;
    }
    let tissue = ((hu - lumen) / span).clamp(0.0, 1.0);
    Some(AIR_HU + tissue * (SOFT_TISSUE_HU - AIR_HU))
}

/// The mean of the (already written) values of the voxels just above and below `index`, HU.
fn along_gravity_mean(scan: &HuScan, gravity: Gravity, index: usize, voxels: &[u16]) -> f64 {
    let map = scan.volume.value_map();
    let ijk = scan.ijk(index);
    let values: Vec<f64> = [gravity.up(ijk, scan.dims), gravity.down(ijk, scan.dims)]
        .into_iter()
        .flatten()
        .map(|n| map.physical(voxels[scan.index(n)]) - scan.offset)
        .collect();
    if values.is_empty() {
        return scan.hu(index);
    }
    values.iter().sum::<f64>() / values.len() as f64
}

#[cfg(test)]
mod tests {
    use super::super::pools::TaggedPool;
    use super::*;

    fn pool(level_depth: f64, tag_hu: f64) -> Found {
        Found {
            pool: TaggedPool {
                gravity: Gravity { axis: 1, sign: 1 },
                level_depth,
                tag_hu,
                voxels: 0,
            },
            voxels: Vec::new(),
        }
    }

    #[test]
    fn the_tag_to_tissue_ramp_becomes_an_air_to_tissue_ramp_with_the_same_midpoint() {
        let deep = pool(0.0, 600.0);
        let mid = cleansed_hu(320.0, 10.0, &deep).unwrap();
        assert!(
            (mid - 0.5 * (AIR_HU + SOFT_TISSUE_HU)).abs() < 1e-9,
            "{mid}"
        );
        assert_eq!(cleansed_hu(600.0, 10.0, &deep), Some(AIR_HU));
        assert_eq!(
            cleansed_hu(SOFT_TISSUE_HU, 10.0, &deep),
            Some(SOFT_TISSUE_HU)
        );
        assert_eq!(cleansed_hu(900.0, 10.0, &deep), Some(AIR_HU));
    }

    #[test]
    fn the_level_becomes_air_and_the_wall_above_it_is_kept() {
        let level = pool(5.0, 600.0);
        // A voxel below the level: nine tenths fluid, a tenth air.
        assert_eq!(cleansed_hu(440.0, 5.8, &level), Some(AIR_HU));
        // Well above the level the value is kept, whatever it is.
        assert_eq!(cleansed_hu(-480.0, 2.0, &level), Some(-480.0));
        // A voxel whose fluid share makes air and fluid read as tissue is ambiguous.
        let tissue_like = 5.0 + LEVEL_RAMP_VOX * ((SOFT_TISSUE_HU - AIR_HU) / 1600.0 - 0.5);
        assert_eq!(cleansed_hu(SOFT_TISSUE_HU, tissue_like, &level), None);
    }
}
