//! What a study resolved, said the same way by every command: one line each on stderr, and as
//! JSON for `--json` (`render`, `path`, `view --screenshot`), so that scripts and the tests can
//! compare the front ends.

use endocast_core::navigate::LumenSide;
use endocast_core::pose::Pose;
use endocast_core::study::Study;
use glam::DVec3;
use serde_json::{json, Value};

/// Says on stderr what `study` resolved: the values, the structure and the start (with the
/// options that reproduce it), what it adjusted, and why it frames the object when it does.
pub fn say(study: &Study) {
    eprintln!("{}", study.summary());
    if let Some(what) = study.structure_name() {
        if study.confident() {
            eprintln!("found the {what}");
        } else {
            eprintln!("warning: {what}");
        }
        let p = study.start_pose();
        let along = if study.path().is_some() {
            "looking along the automatic path"
        } else {
            "looking along the structure"
        };
        eprintln!(
            "start inside it, {along}: --eye {} --look-at {} --up {}",
            triple(p.eye_mm),
            triple(p.look_at_mm),
            triple(p.up)
        );
    }
    if let Some(reason) = study.framing() {
        eprintln!("warning: {reason}; framing the whole object instead");
    }
    for note in study.notes() {
        eprintln!("note: {note}");
    }
}

/// What `study` resolved, as JSON: the preset and the scan's units, the values in them, the
/// lumen, the structure, the start pose and the automatic path's length.
pub fn to_json(study: &Study) -> Value {
    let s = study.settings();
    let window = study.window();
    let lumen = study.lumen().ok().map(|(threshold, side)| {
        json!({
            "threshold": threshold,
            "side": if side == LumenSide::Below { "below" } else { "above" },
        })
    });
    json!({
        "preset": study.preset_name(),
        "scan": study.scan().to_string(),
        "summary": study.summary(),
        "iso": s.iso_hu,
        "iso2": s.iso2_hu,
        "lumen": lumen,
        "window": {"level": window.level_hu, "width": window.width_hu},
        "structure": study.structure_name(),
        "confident": study.confident(),
        "framing": study.framing(),
        "start": pose_json(&study.start_pose()),
        "path_mm": study.path().map(|p| p.path.len_mm()),
        "notes": study.notes().collect::<Vec<_>>(),
        "resolve_ms": study.resolve_time().as_secs_f64() * 1e3,
    })
}

/// A pose as JSON: eye, point looked at, up and the unit view direction, world mm (LPS).
pub fn pose_json(pose: &Pose) -> Value {
    let v = |v: DVec3| [v.x, v.y, v.z];
    let forward = (pose.look_at_mm - pose.eye_mm).normalize_or_zero();
    json!({
        "eye": v(pose.eye_mm),
        "look_at": v(pose.look_at_mm),
        "up": v(pose.up),
        "look_direction": v(forward),
    })
}

/// `x,y,z` with two decimals, as `--eye` takes it.
pub fn triple(v: DVec3) -> String {
    format!("{:.2},{:.2},{:.2}", v.x, v.y, v.z)
}
