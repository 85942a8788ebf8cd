//! What the front ends show of the candidates: a camera looking at each from the lumen, and
//! the candidates as annotations (markers in the endoscope view, records in a case).

use super::Candidate;
use crate::annotate::{Annotation, Shape};
use crate::flight::up_for;
use crate::navigate::Lumen;
use crate::pose::Pose;
use crate::Geometry;
use glam::DVec3;

/// How far from a candidate its view's eye stands at most, mm.
pub const VIEW_DISTANCE_MM: f64 = 20.0;
/// Field of view of a candidate's view, degrees.
pub const VIEW_FOV_DEG: f64 = 60.0;
/// Colour of the candidates' markers.
pub const CANDIDATE_COLOR: [u8; 3] = [255, 80, 200];
/// Steps of the walk from the tip into the lumen, mm.
const WALK_STEP_MM: f64 = 0.5;

/// A camera looking at `candidate` from the lumen along its normal: the eye walks from the
/// tip along the normal while in `lumen`, up to [`VIEW_DISTANCE_MM`], and stands at three
/// quarters of the way it went (clear of the wall across).
pub fn view_pose(candidate: &Candidate, lumen: &Lumen, geometry: &Geometry) -> Pose {
    let to_voxel = geometry.voxel_from_world();
    let in_lumen = |p: DVec3| {
        let v = to_voxel.transform_point3(p).round();
        v.cmpge(DVec3::ZERO).all() && lumen.contains(v.to_array().map(|c| c as usize))
    };
    let tip = candidate.centre_mm;
    let normal = if candidate.normal == DVec3::ZERO {
        DVec3::Z
    } else {
        candidate.normal
    };
    let steps = (VIEW_DISTANCE_MM / WALK_STEP_MM) as usize;
    let reached = (1..=steps)
        .map(|n| n as f64 * WALK_STEP_MM)
        .skip_while(|&d| !in_lumen(tip + normal * d))
        .take_while(|&d| in_lumen(tip + normal * d))
        .last()
        .unwrap_or(VIEW_DISTANCE_MM);
    let eye = tip + normal * (0.75 * reached).max(2.0 * WALK_STEP_MM);
    Pose {
        eye_mm: eye,
        look_at_mm: tip,
        up: up_for(tip - eye),
    }
}

/// The candidates as point annotations labelled `polyp N, S mm` (N from 1, in their order).
pub fn annotations(candidates: &[Candidate]) -> Vec<Annotation> {
    candidates
        .iter()
        .enumerate()
        .map(|(n, c)| {
            let mut mark = Annotation::new(Shape::Point(c.centre_mm)).labelled(&format!(
                "polyp {}, {:.1} mm",
                n + 1,
                c.size_mm
            ));
            mark.color = CANDIDATE_COLOR;
            mark
        })
        .collect()
}
