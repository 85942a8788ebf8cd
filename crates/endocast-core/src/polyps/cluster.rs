//! Hysteresis region growing over the wall voxels and the measures of each region: the cap
//! voxels (seeds) start regions that grow through 26-adjacent wall voxels of looser shape.

use super::{Candidate, PolypOptions, WallPoint};
use crate::Geometry;
use glam::DVec3;

/// Directions across the wall along which a region's extent is measured.
const EXTENT_DIRECTIONS: usize = 32;
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
        let candidate = measure(geometry, wall, &region, &seeds);
        if candidate.size_mm >= options.min_size_mm {
            found.push(candidate);
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

/// The 26 neighbours of `v` inside the grid.
fn neighbours(dims: [usize; 3], v: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
    (0..27).filter(|&n| n != 13).filter_map(move |n| {
        let offset = [n % 3, n / 3 % 3, n / 9];
        let shifted = |a: usize| (v[a] + offset[a]).checked_sub(1).filter(|&c| c < dims[a]);
        Some([shifted(0)?, shifted(1)?, shifted(2)?])
    })
}

/// The candidate of `region` (indices into `wall`).
fn measure(
    geometry: &Geometry,
    wall: &[WallPoint],
    region: &[usize],
    seeds: &impl Fn(&WallPoint) -> bool,
) -> Candidate {
    let points: Vec<DVec3> = region
        .iter()
        .map(|&n| geometry.world_of(DVec3::from(wall[n].voxel.map(|c| c as f64))))
        .collect();
    let normal = region
        .iter()
        .map(|&n| wall[n].shape.normal)
        .sum::<DVec3>()
        .normalize_or_zero();
    let tip = points
        .iter()
        .copied()
        .max_by(|a, b| a.dot(normal).total_cmp(&b.dot(normal)))
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
    Candidate {
        centre_mm: tip,
        normal,
        size_mm: extent_across(&points, normal) + voxel_mm.min_element(),
        score: cap * (1.0 - (-seed_area / SCORE_SEED_AREA_MM2).exp()),
        voxels: region.len(),
    }
}

/// The largest extent of `points` perpendicular to `normal`, over [`EXTENT_DIRECTIONS`]
/// directions in that plane (within 0.5 % of the true width).
fn extent_across(points: &[DVec3], normal: DVec3) -> f64 {
    let (u, v) = if normal == DVec3::ZERO {
        (DVec3::X, DVec3::Y)
    } else {
        normal.any_orthonormal_pair()
    };
    (0..EXTENT_DIRECTIONS)
        .map(|n| {
            let angle = std::f64::consts::PI * n as f64 / EXTENT_DIRECTIONS as f64;
            let d = u * angle.cos() + v * angle.sin();
            let (lo, hi) = points.iter().fold((f64::MAX, f64::MIN), |(lo, hi), p| {
                (lo.min(p.dot(d)), hi.max(p.dot(d)))
            });
            hi - lo
        })
        .fold(0.0, f64::max)
}
