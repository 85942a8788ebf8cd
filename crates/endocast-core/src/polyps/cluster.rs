//! Hysteresis region growing over the wall voxels and the measures of each region: the cap
//! voxels (seeds) start regions that grow through 26-adjacent wall voxels of looser shape.

use super::protrusion::{diameter_mm, extent_across};
use super::{neighbours, Candidate, PolypOptions, WallPoint};
use crate::Geometry;
use glam::DVec3;

/// Seed area (mm²) at which the score's cap part reaches 1 − 1/e: about a 5 mm cap's.
const SCORE_SEED_AREA_MM2: f64 = 20.0;

/// The candidates of the wall points `wall` (sorted by linear index), unsorted.
pub(super) fn candidates(
    geometry: &Geometry,
    wall: &[WallPoint],
    options: &PolypOptions,
) -> Vec<Candidate> {
    let (cv_lo, cv_hi) = options.curvedness_per_mm;
    let in_band = |w: &WallPoint| (cv_lo..=cv_hi).contains(&w.shape.curvedness);
    let grows = |w: &WallPoint| in_band(w) && w.shape.shape_index >= options.grow_shape_index;
    let seeds = |w: &WallPoint| in_band(w) && w.shape.shape_index >= options.seed_shape_index;
    let mut taken = vec![false; wall.len()];
    let mut found = Vec::new();
    for start in 0..wall.len() {
        if taken[start] || !seeds(&wall[start]) {
            continue;
        }
        let region = grow(geometry.dims(), wall, start, &mut taken, &grows);
        let (mut candidate, tip) = measure(geometry, wall, &region, &seeds);
        if candidate.size_mm >= options.min_size_mm {
            let cap_mm = candidate.size_mm;
            candidate.size_mm =
                diameter_mm(geometry, wall, tip, candidate.normal, cap_mm).unwrap_or(cap_mm);
            if candidate.size_mm >= options.min_size_mm {
                found.push(candidate);
            }
        }
    }
    found
}

/// The wall points 26-connected to `start` through points that `grows` accepts, marked taken.
fn grow(
    dims: [usize; 3],
    wall: &[WallPoint],
    start: usize,
    taken: &mut [bool],
    grows: &impl Fn(&WallPoint) -> bool,
) -> Vec<usize> {
    let mut region = vec![start];
    taken[start] = true;
    let mut next = 0;
    while next < region.len() {
        let v = wall[region[next]].voxel;
        next += 1;
        for n in neighbours(dims, v) {
            let index = n[0] + dims[0] * (n[1] + dims[1] * n[2]);
            if let Ok(at) = wall.binary_search_by_key(&index, |w| w.index) {
                if !taken[at] && grows(&wall[at]) {
                    taken[at] = true;
                    region.push(at);
                }
            }
        }
    }
    region
}

/// The candidate of `region` (indices into `wall`), sized by its cap region's extent across
/// its normal, and its tip's index into `wall`.
fn measure(
    geometry: &Geometry,
    wall: &[WallPoint],
    region: &[usize],
    seeds: &impl Fn(&WallPoint) -> bool,
) -> (Candidate, usize) {
    let points: Vec<DVec3> = region
        .iter()
        .map(|&n| geometry.world_of(DVec3::from(wall[n].voxel.map(|c| c as f64))))
        .collect();
    let normal = region
        .iter()
        .map(|&n| wall[n].shape.normal)
        .sum::<DVec3>()
        .normalize_or_zero();
    let tip = (0..points.len())
        .max_by(|&a, &b| points[a].dot(normal).total_cmp(&points[b].dot(normal)))
        .unwrap_or_default();
    let voxel_mm = geometry.spacing_mm();
    let voxel_area = (voxel_mm.x * voxel_mm.y * voxel_mm.z).powf(2.0 / 3.0);
    let seed_area = region.iter().filter(|&&n| seeds(&wall[n])).count() as f64 * voxel_area;
    let mean_si = region
        .iter()
        .map(|&n| wall[n].shape.shape_index)
        .sum::<f64>()
        / region.len() as f64;
    let cap = ((mean_si - 0.5) / 0.5).clamp(0.0, 1.0);
    let candidate = Candidate {
        centre_mm: points[tip],
        normal,
        size_mm: extent_across(&points, normal) + voxel_mm.min_element(),
        score: cap * (1.0 - (-seed_area / SCORE_SEED_AREA_MM2).exp()),
        voxels: region.len(),
    };
    (candidate, region[tip])
}
