//! The coverage review as JSON, as `endocast coverage --json` prints it and Python's
//! `endocast.coverage` returns it: the unseen patches (largest first, each with the pose that
//! sees it) and the coverage before and after their views.

use endocast_core::flight::{PatchView, Review, REVIEW_AREA_MM2};
use glam::DVec3;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The review as JSON: `min_area_mm2` the smallest patch listed, `both_ways` whether the
/// flight flew back too, `views` the folder the patches' views were written to (if any).
pub fn to_json(review: &Review, min_area_mm2: f64, both_ways: bool, views: Option<&Path>) -> Value {
    let v = |p: DVec3| [p.x, p.y, p.z];
    let patches: Vec<Value> = review
        .views
        .iter()
        .zip(&review.seen_by_view)
        .enumerate()
        .map(|(n, (view, seen))| {
            json!({
                "area_mm2": view.patch.area_mm2,
                "centroid": v(view.patch.centroid_mm),
                "eye": v(view.pose.eye_mm),
                "look_at": v(view.pose.look_at_mm),
                "up": v(view.pose.up),
                "fov_deg": view.fov_deg,
                "clear": view.clear,
                "voxels": view.patch.voxels.len(),
                "voxels_seen_by_view": seen,
                "view": views.map(|d| view_file(d, n)),
            })
        })
        .collect();
    let flight = &review.flight;
    json!({
        "patches": patches,
        "patches_total": review.patches_total,
        "patches_at_least_300_mm2": at_least(review, REVIEW_AREA_MM2),
        "min_area_mm2": min_area_mm2,
        "both_ways": both_ways,
        "wall_voxels": flight.wall_voxels(),
        "reach_mm": review.reach_mm,
        "coverage_forward": flight.fraction_forward(),
        "coverage_before": review.before().seen_fraction(),
        "coverage_after": review.after.seen_fraction(),
    })
}

/// How many listed patches have at least `area_mm2`.
pub fn at_least(review: &Review, area_mm2: f64) -> usize {
    let big = |v: &&PatchView| v.patch.area_mm2 >= area_mm2;
    review.views.iter().filter(big).count()
}

/// The view file of patch `n` in the folder `dir`: `patch_000.png`, …
pub fn view_file(dir: &Path, n: usize) -> PathBuf {
    dir.join(format!("patch_{n:03}.png"))
}
