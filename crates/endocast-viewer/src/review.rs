//! The workstation's review of what a flight missed (issue 36): the key frames' route (the
//! study's automatic path when there are fewer than two key frames) flown with the view's lens
//! as `endocast coverage` flies it, the unseen wall split into patches by the same core
//! [`review`], and "next unseen patch" (N, or the button) jumping the endoscope to each
//! patch's pose in turn, largest first, with the coverage the patches visited so far give.

use crate::controller::FlyCamera;
use crate::jobs::{Job, Notify, Polled};
use crate::planner::automatic_path;
use crate::session::Session;
use endocast_core::animation::KeyFrame;
use endocast_core::camera::Projection;
use endocast_core::flight::{
    review, FlightError, FlightOptions, Layout, PatchView, ReviewRequest, Route,
    DEFAULT_MIN_AREA_MM2, REVIEW_FRAME_PX, REVIEW_STEP_MM,
};
use endocast_core::study::Study;
use endocast_core::study::LOOK_AHEAD_MM;
use endocast_core::views::Image;
use endocast_core::Volume;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// What a finished review found.
#[derive(Debug)]
struct Found {
    views: Vec<PatchView>,
    /// The flight's coverage, 0–1.
    before: f64,
    /// The coverage once the views `0..=n` are added, 0–1.
    after_each: Vec<f64>,
    /// Every unseen patch, however small.
    patches_total: usize,
}

/// The review running off the UI thread.
type ReviewJob = Job<Result<Found, String>>;

/// The review tools' state.
#[derive(Debug, Default)]
pub struct ReviewTools {
    /// Fly the route back too before listing (default: forward only, as flown).
    pub both_ways: bool,
    job: Option<(ReviewJob, Arc<AtomicUsize>)>,
    found: Option<Found>,
    /// Which listed patches the endoscope has been taken to.
    visited: Vec<bool>,
    /// A line for the next [`ReviewTools::poll`] to say.
    said: Option<String>,
}

impl ReviewTools {
    /// Starts the review of the session's route off the UI thread (`notify` when done).
    pub fn start(&mut self, session: &Session, notify: Notify) {
        let keys = session.key_frames().to_vec();
        let study = session.shared_study();
        let scene = Arc::clone(session.scene());
        let request = request(session, self.both_ways);
        let frames = Arc::new(AtomicUsize::new(0));
        let counter = Arc::clone(&frames);
        let job = Job::spawn("review", notify, move || {
            let route = route(keys, &study, scene.volume())?;
            let start = route.points_mm(1.0).map_err(|e| e.to_string())?[0];
            let (lumen, _) = study
                .lumen_from(scene.volume(), start)
                .map_err(|e| format!("the route's start is not in the lumen: {e}"))?;
            let progress = || {
                counter.fetch_add(1, Ordering::Relaxed);
            };
            let ignore = |_: usize, _: &PatchView, _: &Image| Ok::<_, FlightError>(());
            let found = review(&scene.renderer, &lumen, &route, &request, progress, ignore)
                .map_err(|e| e.to_string())?;
            Ok(Found {
                before: found.before().seen_fraction(),
                after_each: found.after_each,
                patches_total: found.patches_total,
                views: found.views,
            })
        });
        self.job = Some((job, frames));
    }

    /// Picks up a finished review; returns a line for the status bar when one ended.
    pub fn poll(&mut self) -> Option<String> {
        if let Some(said) = self.said.take() {
            return Some(said);
        }
        let (job, _) = self.job.as_ref()?;
        let result = match job.poll() {
            Polled::Running => return None,
            Polled::Done(result) => result,
            Polled::Lost => Err("the review stopped".into()),
        };
        self.job = None;
        Some(match result {
            Ok(found) => {
                let said = format!(
                    "flight coverage {:.1} %: {} unseen patches of at least {DEFAULT_MIN_AREA_MM2} mm² \
                     (N jumps to the next)",
                    100.0 * found.before,
                    found.views.len()
                );
                self.visited = vec![false; found.views.len()];
                self.found = Some(found);
                said
            }
            Err(e) => e,
        })
    }

    /// Takes the endoscope to the next patch not yet visited (largest first); says where.
    pub fn next(&mut self, session: &mut Session) -> String {
        let Some(n) = self.visited.iter().position(|v| !v) else {
            return match &self.found {
                Some(found) if found.views.is_empty() => {
                    format!("no unseen patch of at least {DEFAULT_MIN_AREA_MM2} mm²")
                }
                Some(_) => "every listed patch has been visited".into(),
                None => "no review yet: press \"Review unseen\"".into(),
            };
        };
        self.visit(session, n)
    }

    /// [`ReviewTools::next`], what happened said by the next [`ReviewTools::poll`] (a key).
    pub fn next_said_later(&mut self, session: &mut Session) {
        self.said = Some(self.next(session));
    }

    /// Takes the endoscope to listed patch `n` (its view's pose, and its field of view on a
    /// pinhole lens); says where.
    pub fn visit(&mut self, session: &mut Session, n: usize) -> String {
        let Some(view) = self.found.as_ref().and_then(|f| f.views.get(n)) else {
            return format!("no patch {n}");
        };
        let Some(camera) = FlyCamera::from_pose(&view.pose) else {
            return format!("patch {} has no valid pose", n + 1);
        };
        session.stop();
        session.set_camera(camera);
        if session.controls.projection == Projection::Pinhole {
            session.controls.fov_deg = view.fov_deg;
        }
        self.visited[n] = true;
        format!(
            "patch {} of {}: {:.0} mm², {} left",
            n + 1,
            self.visited.len(),
            view.patch.area_mm2,
            self.visited.iter().filter(|v| !**v).count()
        )
    }

    /// The flight's coverage and the coverage with the listed patches visited in order so far
    /// (0–1 each), once a review has been found.
    pub fn coverage(&self) -> Option<(f64, f64)> {
        let found = self.found.as_ref()?;
        let done = self.visited.iter().take_while(|v| **v).count();
        let now = match done {
            0 => found.before,
            n => found.after_each[n - 1],
        };
        Some((found.before, now))
    }

    /// The listed patches' views, largest patch first (none before a review).
    pub fn views(&self) -> &[PatchView] {
        self.found.as_ref().map_or(&[], |f| &f.views)
    }

    /// Which listed patches have been visited (same order as [`ReviewTools::views`]).
    pub fn visited(&self) -> &[bool] {
        &self.visited
    }

    /// Every unseen patch after the flight, however small (none before a review).
    pub fn patches_total(&self) -> usize {
        self.found.as_ref().map_or(0, |f| f.patches_total)
    }

    /// Frames flown so far while a review runs.
    pub fn frames_flown(&self) -> Option<usize> {
        self.job.as_ref().map(|(_, n)| n.load(Ordering::Relaxed))
    }
}

/// The review of the session's view as `endocast coverage` makes it by default: its render
/// settings and lens (the cube's or the panorama's rays counted when one is chosen), the
/// study's window, and the review's frame size, step and smallest patch.
fn request(session: &Session, both_ways: bool) -> ReviewRequest {
    ReviewRequest {
        settings: session.controls.settings(),
        look: None,
        flight: FlightOptions {
            size: REVIEW_FRAME_PX,
            optics: session.controls.optics(),
            stereo: None,
            layout: Layout::Endoscope,
            window: session.study().window(),
        },
        step_mm: REVIEW_STEP_MM,
        look_ahead_mm: LOOK_AHEAD_MM,
        both_ways,
        min_area_mm2: DEFAULT_MIN_AREA_MM2,
    }
}

/// The route reviewed: the key frames when there are at least two, else the study's automatic
/// path (as `endocast path` plans it).
fn route(keys: Vec<KeyFrame>, study: &Study, volume: &Volume) -> Result<Route, String> {
    if keys.len() >= 2 {
        return Route::from_key_frames(keys).map_err(|e| e.to_string());
    }
    let path = automatic_path(study, volume).map_err(|e| format!("no route to review: {e}"))?;
    Ok(Route::Path(path))
}
