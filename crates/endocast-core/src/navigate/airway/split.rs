//! Where a fork's two largest branches part in the lumen: the top of the spur of wall between
//! them (at the trachea's end, the carina). The centrelines fork about a radius higher, where
//! the lumen's medial axis forks (the centre of the largest ball touching both branches' walls
//! and the spur), and a route must fork there to pass the spur centred; the split is the
//! anatomical landmark, where the lumen's section stops being one.
//!
//! Walking down the two branches' centrelines from their common branch point at equal arc
//! lengths, the straight chord between their points crosses only lumen until the spur rises
//! between them; the split is the first wall voxel on the first chord that meets one.

use super::branches::{largest_two, lengths_below};
use super::AirwayBranch;
use crate::navigate::distance::DistanceField;
use glam::DVec3;

/// Step along the centrelines and the chords, in smallest voxel spacings.
const STEP_VOXELS: f64 = 0.25;

/// The split of each branch's fork ([`split_mm`] of its two largest branches by the length of
/// the centrelines below them), `None` for a branch that does not fork.
pub(super) fn splits(branches: &[AirwayBranch], field: &DistanceField) -> Vec<Option<DVec3>> {
    let parents: Vec<Option<usize>> = branches.iter().map(|b| b.parent).collect();
    let own_mm = branches.iter().map(AirwayBranch::length_mm).collect();
    let below = lengths_below(&parents, own_mm);
    (0..branches.len())
        .map(|p| {
            let kids: Vec<usize> = (0..branches.len())
                .filter(|&c| parents[c] == Some(p))
                .collect();
            let [a, b] = largest_two(&kids, &below)?;
            split_mm(&branches[a].points_mm, &branches[b].points_mm, field)
        })
        .collect()
}

/// Where branches `a` and `b` (centreline points from the branch point they both leave)
/// part: the first wall voxel centre's point on the first chord between their points at equal
/// arc lengths that meets the wall; `None` when none does before the shorter one ends.
pub(super) fn split_mm(a: &[DVec3], b: &[DVec3], field: &DistanceField) -> Option<DVec3> {
    let step_mm = STEP_VOXELS * field.min_spacing_mm();
    let length_mm = length(a).min(length(b));
    (0..)
        .map(|n| f64::from(n) * step_mm)
        .take_while(|&s| s <= length_mm)
        .find_map(|s| first_wall(at(a, s), at(b, s), field, step_mm))
}

/// The first point from `p` to `q` (every `step_mm`) whose nearest voxel is not lumen.
fn first_wall(p: DVec3, q: DVec3, field: &DistanceField, step_mm: f64) -> Option<DVec3> {
    let steps = (p.distance(q) / step_mm).ceil() as u32;
    (0..=steps)
        .map(|n| p.lerp(q, f64::from(n) / f64::from(steps.max(1))))
        .find(|&x| {
            let v = field.voxel_of_world(x).round().max(DVec3::ZERO);
            field.distance_at_voxel([v.x as usize, v.y as usize, v.z as usize]) == 0.0
        })
}

/// Length of a polyline, mm.
fn length(points: &[DVec3]) -> f64 {
    points.windows(2).map(|w| w[0].distance(w[1])).sum()
}

/// The point `s_mm` along a polyline (its last point beyond its end).
fn at(points: &[DVec3], s_mm: f64) -> DVec3 {
    let mut left = s_mm;
    for w in points.windows(2) {
        let d = w[0].distance(w[1]);
        if left <= d && d > 0.0 {
            return w[0].lerp(w[1], left / d);
        }
        left -= d;
    }
    points[points.len() - 1]
}
