//! Planned flights: the centred path through the lumen between two points (or from one to the
//! farthest point), found off the UI thread with the navigation library's planner (as
//! `endocast path` does), and turned into key frames the session plays, edits and exports;
//! and paths read back from files (ours, 3D Slicer Markups) as key frames.

use crate::jobs::{Job, Notify};
use crate::session::Session;
use endocast_core::animation::KeyFrame;
use endocast_core::flight::Route;
use endocast_core::navigate::{plan_path, LumenSide, PathEnd};
use endocast_core::path::{Path, SmoothOptions};
use endocast_core::study::Study;
use endocast_core::Volume;
use endocast_io::route_file::read_route;
use glam::DVec3;
use std::sync::Arc;

/// Distance between the key frames laid along a planned path, mm.
pub const KEY_STEP_MM: f64 = 5.0;
/// How far ahead on the path each key frame looks, mm (as `endocast fly`'s default).
pub const LOOK_AHEAD_MM: f64 = 10.0;

/// A planned flight.
#[derive(Debug, Clone)]
pub struct PlannedFlight {
    /// Key frames every [`KEY_STEP_MM`] from the start to the end, looking ahead along it.
    pub key_frames: Vec<KeyFrame>,
    /// Length of the path, mm.
    pub length_mm: f64,
    /// Smallest distance from the path to the wall, mm.
    pub min_radius_mm: f64,
}

/// What each planned key frame carries besides its pose: the field of view and the wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KeyLook {
    /// Field of view, degrees.
    pub fov_deg: f64,
    /// Wall isovalue, physical units.
    pub iso_hu: f64,
    /// Wall opacity, 0–1.
    pub iso_opacity: f64,
}

/// Where a flight is planned: in the study's structure (or the lumen at its threshold), as
/// `endocast path` plans, while the wall is the study's; else in the lumen of the wall as moved.
pub enum Lumen {
    /// The study's own (see [`Study::plan`]).
    Study(Arc<Study>),
    /// The lumen on `side` of a threshold grown from the start.
    Threshold(f64, LumenSide),
}

/// Plans the flight through `lumen` from `start_mm` to `end`. The error says why in one line
/// (the start is in the wall, the end in another lumen, …).
pub fn plan_flight(
    volume: &Volume,
    lumen: &Lumen,
    start_mm: DVec3,
    end: PathEnd,
    look: KeyLook,
) -> Result<PlannedFlight, String> {
    let options = SmoothOptions::default();
    let planned = match lumen {
        Lumen::Study(study) => {
            let to = match end {
                PathEnd::Point(p) => Some(p),
                PathEnd::Farthest => None,
            };
            let path = study.plan(volume, Some(start_mm), to, &options);
            path.map_err(|e| e.to_string())?.planned
        }
        Lumen::Threshold(threshold, side) => {
            let planned = plan_path(volume, *threshold, *side, start_mm, end, &options);
            let failed = |e| format!("no path in the lumen {side} {threshold}: {e}");
            planned.map_err(failed)?.2
        }
    };
    Ok(PlannedFlight {
        key_frames: key_frames_along(&planned.path, look)?,
        length_mm: planned.path.len_mm(),
        min_radius_mm: planned.min_radius_mm,
    })
}

/// The study's automatic path through the structure its preset found, as `endocast path` plans
/// it without a start or an end: the route of the review and the dissection when there are
/// fewer than two key frames.
pub fn automatic_path(study: &Study, volume: &Volume) -> Result<Path, String> {
    let planned = study.plan(volume, None, None, &SmoothOptions::default());
    Ok(planned.map_err(|e| e.to_string())?.planned.path)
}

/// Key frames every [`KEY_STEP_MM`] along `path`, each looking [`LOOK_AHEAD_MM`] ahead on it,
/// with `look`.
fn key_frames_along(path: &Path, look: KeyLook) -> Result<Vec<KeyFrame>, String> {
    let length_mm = path.len_mm();
    let count = (length_mm / KEY_STEP_MM).ceil().max(1.0) as usize;
    (0..=count)
        .map(|k| {
            let s = (k as f64 * KEY_STEP_MM).min(length_mm);
            let pose = path.pose_at(s, LOOK_AHEAD_MM).map_err(|e| e.to_string())?;
            KeyFrame::from_pose(&pose, look.fov_deg, look.iso_hu, look.iso_opacity)
                .map_err(|e| e.to_string())
        })
        .collect()
}

/// The key frames of the route in `file`, read as `endocast fly --path` reads it (endocast's
/// path file, or a 3D Slicer Markups curve or point list, LPS or RAS): its own key frames when
/// it has them, else key frames along its points with `look`. The error names the file.
pub fn read_key_frames(file: &std::path::Path, look: KeyLook) -> Result<Vec<KeyFrame>, String> {
    match read_route(file).map_err(|e| e.to_string())? {
        Route::Keys(animation) => Ok(animation.keys().to_vec()),
        Route::Path(path) => key_frames_along(&path, look),
    }
}

/// The field of view and wall of `session` now, for new key frames.
pub fn key_look(session: &Session) -> KeyLook {
    let c = &session.controls;
    KeyLook {
        fov_deg: c.fov_deg,
        iso_hu: c.iso_hu,
        iso_opacity: f64::from(c.iso_opacity),
    }
}

/// Starts planning the flight from `start_mm` to `end` in `session`'s lumen (the study's, as
/// `endocast path` plans, while the wall is the study's; else the lumen of the wall as set) on
/// its own thread, with the current field of view and wall; `notify` is called when it is
/// done.
pub fn start_planning(
    session: &Session,
    start_mm: DVec3,
    end: PathEnd,
    notify: Notify,
) -> Result<Job<Result<PlannedFlight, String>>, String> {
    let (threshold, side) = session
        .lumen_threshold()
        .ok_or("this preset and isovalue name no lumen")?;
    let lumen = if session.wall_is_the_studys() {
        Lumen::Study(session.shared_study())
    } else {
        Lumen::Threshold(threshold, side)
    };
    let look = key_look(session);
    let renderer = Arc::clone(&session.scene().renderer);
    Ok(Job::spawn("path", notify, move || {
        plan_flight(renderer.volume(), &lumen, start_mm, end, look)
    }))
}
