//! Where the object (the voxels above the background/object threshold) lies in the volume.

use super::ScanValues;
use crate::Volume;
use glam::DVec3;

/// The inclusive voxel box holding the object of `volume` (voxels above `scan`'s
/// background/object threshold) between its `q` and `1 − q` quantiles along each axis, so that
/// a fraction `q` of stray voxels on either side is left out; `None` for a volume without
/// object.
pub fn object_extent(
    volume: &Volume,
    scan: &ScanValues,
    q: f64,
) -> Option<([usize; 3], [usize; 3])> {
    let marginals = object_marginals(volume, scan);
    let mut lo = [0; 3];
    let mut hi = [0; 3];
    for a in 0..3 {
        lo[a] = quantile(&marginals[a], q)?;
        hi[a] = quantile(&marginals[a], 1.0 - q)?;
    }
    Some((lo, hi))
}

/// Per axis, how many object voxels each index plane holds.
fn object_marginals(volume: &Volume, scan: &ScanValues) -> [Vec<u64>; 3] {
    let dims = volume.dims();
    let map = volume.value_map();
    let object: Vec<bool> = (0..=u16::MAX)
        .map(|s| map.physical(s) > scan.object_threshold)
        .collect();
    let mut marginals = dims.map(|n| vec![0u64; n]);
    for (n, &s) in volume.voxels().iter().enumerate() {
        if object[usize::from(s)] {
            let v = [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])];
            for a in 0..3 {
                marginals[a][v[a]] += 1;
            }
        }
    }
    marginals
}

/// The index below which a fraction `q` of the counts lie.
fn quantile(counts: &[u64], q: f64) -> Option<usize> {
    let total: u64 = counts.iter().sum();
    if total == 0 {
        return None;
    }
    let mut seen = 0;
    counts.iter().position(|&c| {
        seen += c;
        seen as f64 >= q * total as f64
    })
}

/// Voxels along each axis of the largest grid [`object_points`] reads: larger volumes are read
/// every few voxels.
const POINTS_GRID: usize = 128;

/// Calls `f` with the world position (LPS mm) of the object voxels of `volume` (above `scan`'s
/// background/object threshold); a large volume's every few voxels along each axis (at most
/// [`POINTS_GRID`] along an axis), which changes what is measured by less than that step.
pub fn object_points(volume: &Volume, scan: &ScanValues, mut f: impl FnMut(DVec3)) {
    let geometry = volume.geometry();
    let map = volume.value_map();
    let object: Vec<bool> = (0..=u16::MAX)
        .map(|s| map.physical(s) > scan.object_threshold)
        .collect();
    let dims = volume.dims();
    let step = dims.map(|n| n.div_ceil(POINTS_GRID).max(1));
    let voxels = volume.voxels();
    for k in (0..dims[2]).step_by(step[2]) {
        for j in (0..dims[1]).step_by(step[1]) {
            for i in (0..dims[0]).step_by(step[0]) {
                if object[usize::from(voxels[i + dims[0] * (j + dims[1] * k)])] {
                    f(geometry.world_of(DVec3::new(i as f64, j as f64, k as f64)));
                }
            }
        }
    }
}

/// The world box (lowest and highest corner, LPS mm) holding the object of `volume` (see
/// [`object_points`]) between its `q` and `1 − q` quantiles along each world axis — the
/// object's own extent, not the box around a tilted grid's corners; `None` for a volume
/// without object.
pub fn object_world_extent(volume: &Volume, scan: &ScanValues, q: f64) -> Option<(DVec3, DVec3)> {
    let (lo, hi) = volume.geometry().world_bounds();
    let bin_mm = volume.geometry().spacing_mm().min_element();
    let bins = ((hi - lo) / bin_mm).ceil().as_uvec3();
    let mut counts = [0, 1, 2].map(|a| vec![0u64; bins[a] as usize + 1]);
    object_points(volume, scan, |p| {
        let bin = ((p - lo) / bin_mm).round().as_uvec3();
        for a in 0..3 {
            counts[a][(bin[a] as usize).min(bins[a] as usize)] += 1;
        }
    });
    let corner = |f: f64| -> Option<DVec3> {
        let b = [0, 1, 2].map(|a| quantile(&counts[a], f).map(|n| n as f64 * bin_mm));
        Some(lo + DVec3::new(b[0]?, b[1]?, b[2]?))
    };
    Some((corner(q)?, corner(1.0 - q)?))
}
