//! Tagged fluid in the colon phantom: pools of oral-contrast-tagged fluid lying under air, for
//! electronic cleansing ([`crate::cleanse`]).
//!
//! The patient lies supine, so gravity points posterior (+`j`, LPS). A pool sits in each sump of
//! the colon (a local maximum of the centreline's `j`): its surface is the horizontal plane
//! `j = level_vox`, a quarter of the local radius below the axis, so the fluid is 0.75 of a
//! radius deep at the sump and the centreline stays in air. The pool spans the arc lengths where
//! the lumen's floor lies below that level, so it ends where the floor rises out of the fluid,
//! never against a cut across the tube. Both of its boundaries have the phantoms' two-voxel
//! ramps (air → fluid across the level, fluid → tissue at the wall), the partial volumes of a
//! blurred CT.

use super::profile::{ramp, REACH_VOX};
use super::Colon;

/// Tagged fluid (oral contrast in residual fluid), HU: mid-range of the 300–1000 HU seen in CT
/// colonography.
pub const TAGGED_FLUID_HU: f64 = 600.0;
/// How far below the axis the pool's level lies at its sump, as a fraction of the local radius.
const LEVEL_BELOW_AXIS: f64 = 0.25;
/// Half-width of the arc-length window in which a sump must be the deepest point, as a multiple
/// of the largest radius: keeps ripples of the centreline from making a pool each.
const SUMP_WINDOW_RADII: f64 = 4.0;

/// One pool of tagged fluid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pool {
    /// Arc lengths (voxels) between which the lumen holds this pool.
    pub arc_vox: (f64, f64),
    /// The fluid fills the lumen where `j > level_vox` (voxel index; gravity is +`j`).
    pub level_vox: f64,
}

impl Pool {
    /// The lumen's value at `p` (voxel index, `j` its second coordinate) when the closest axis
    /// point is at arc length `s_vox`, before the wall's ramp: fluid below the level, air above.
    pub(crate) fn lumen_hu(pools: &[Pool], air_hu: f64, j: f64, s_vox: f64) -> f64 {
        pools
            .iter()
            .find(|pool| (pool.arc_vox.0..=pool.arc_vox.1).contains(&s_vox))
            .map_or(air_hu, |pool| {
                ramp(pool.level_vox - j, TAGGED_FLUID_HU, air_hu)
            })
    }
}

/// The pools of `colon`: one per sump, deepest first, none overlapping another.
pub(crate) fn place(colon: &Colon) -> Vec<Pool> {
    let points = colon.centreline.points();
    let arcs = colon.centreline.arc_vox();
    let floor = |n: usize| points[n].y + colon.radius_vox_at(arcs[n]);
    let window = SUMP_WINDOW_RADII * colon.max_radius_vox();
    let mut sumps: Vec<usize> = (0..points.len())
        .filter(|&n| {
            (0..points.len())
                .filter(|&m| (arcs[m] - arcs[n]).abs() <= window)
                .all(|m| points[m].y <= points[n].y)
        })
        .collect();
    sumps.sort_by(|&a, &b| points[b].y.total_cmp(&points[a].y));
    let mut pools: Vec<Pool> = Vec::new();
    for n in sumps {
        let level_vox = points[n].y + LEVEL_BELOW_AXIS * colon.radius_vox_at(arcs[n]);
        let wet = |m: usize| floor(m) + REACH_VOX > level_vox;
        let first = (0..=n).rev().take_while(|&m| wet(m)).last().unwrap_or(n);
        let last = (n..points.len())
            .take_while(|&m| wet(m))
            .last()
            .unwrap_or(n);
        // One more axis sample each way: the closest axis point of a wet voxel can lie just
        // past the last wet sample.
        let (first, last) = (first.saturating_sub(1), (last + 1).min(points.len() - 1));
        let pool = Pool {
            arc_vox: (arcs[first], arcs[last]),
            level_vox,
        };
        let apart =
            |other: &Pool| pool.arc_vox.1 < other.arc_vox.0 || other.arc_vox.1 < pool.arc_vox.0;
        if pools.iter().all(apart) {
            pools.push(pool);
        }
    }
    pools
}
