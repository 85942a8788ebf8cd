//! The workstation's virtual dissection (issue 36): the current path — through the key frames'
//! eyes when there are at least two, else the study's automatic path, as the review takes its
//! route — laid flat by the core [`dissect`] off the UI thread (the wall as the view shows it,
//! `endocast dissect`'s defaults), and a click on a flat pixel taking the endoscope to the
//! camera that sees its wall point ([`Dissection::pose_of_pixel`]: on the path at the pixel's
//! arc length, looking at the point).

use crate::controller::FlyCamera;
use crate::jobs::{Job, Notify, Polled};
use crate::planner::automatic_path;
use crate::session::Session;
use endocast_core::animation::KeyFrame;
use endocast_core::dissect::{dissect, DissectOptions, Dissection, Wall};
use endocast_core::flight::ROUTE_STEP_MM;
use endocast_core::path::Path;
use endocast_core::study::Study;
use endocast_core::Volume;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A dissection and the path it was made along.
#[derive(Debug)]
pub struct Flat {
    /// The flat image, its map to the wall and its scale.
    pub dissection: Dissection,
    /// The path cut along.
    pub path: Path,
    /// How long the rays and the image took (not the path).
    pub took: Duration,
}

/// The dissection running off the UI thread.
type DissectJob = Job<Result<Flat, String>>;

/// The dissection's state.
#[derive(Debug, Default)]
pub struct DissectionTools {
    job: Option<DissectJob>,
    flat: Option<Flat>,
    /// Grows with every new flat image (the window uploads its picture when it changes).
    revision: u64,
}

impl DissectionTools {
    /// Starts laying the session's current path flat off the UI thread (`notify` when done).
    pub fn start(&mut self, session: &Session, notify: Notify) {
        let keys = session.key_frames().to_vec();
        let study = session.shared_study();
        let scene = Arc::clone(session.scene());
        let wall = Wall::of(&session.controls.settings());
        self.job = Some(Job::spawn("dissect", notify, move || {
            let path = current_path(&keys, &study, scene.volume())?;
            let clock = Instant::now();
            let dissection = dissect(scene.volume(), &path, &wall, &DissectOptions::default())
                .map_err(|e| format!("no dissection: {e}"))?;
            Ok(Flat {
                dissection,
                path,
                took: clock.elapsed(),
            })
        }));
    }

    /// Picks up a finished dissection; returns a line for the status bar when one ended.
    pub fn poll(&mut self) -> Option<String> {
        let result = match self.job.as_ref()?.poll() {
            Polled::Running => return None,
            Polled::Done(result) => result,
            Polled::Lost => Err("the dissection stopped".into()),
        };
        self.job = None;
        Some(match result {
            Ok(flat) => {
                let d = &flat.dissection;
                let said = format!(
                    "{:.0} mm of path laid flat in {:.1} s, wall in {:.1} % of the pixels \
                     (click one to look at it)",
                    flat.path.len_mm(),
                    flat.took.as_secs_f64(),
                    100.0 * d.hit_fraction
                );
                self.flat = Some(flat);
                self.revision += 1;
                said
            }
            Err(e) => e,
        })
    }

    /// Whether a dissection is being made.
    pub fn running(&self) -> bool {
        self.job.is_some()
    }

    /// The last dissection made, with its path.
    pub fn flat(&self) -> Option<&Flat> {
        self.flat.as_ref()
    }

    /// A number that grows with every new flat image.
    pub fn revision(&self) -> u64 {
        self.revision
    }

    /// Forgets the flat image and any dissection running (the scan shown changed).
    pub fn clear(&mut self) {
        self.job = None;
        self.flat = None;
        self.revision += 1;
    }

    /// Takes the endoscope to the camera that sees the wall point of flat pixel `(x, y)`; a
    /// pixel without one leaves it where it is. Says which.
    pub fn visit(&self, session: &mut Session, x: usize, y: usize) -> String {
        let Some(flat) = &self.flat else {
            return "no dissection yet: press \"Dissect\"".into();
        };
        let pose = match flat.dissection.pose_of_pixel(&flat.path, x, y) {
            Ok(pose) => pose,
            Err(e) => return format!("{e}: the endoscope stays"),
        };
        let Some(camera) = FlyCamera::from_pose(&pose) else {
            return format!("pixel ({x}, {y}) gives no camera: its wall point is on the path");
        };
        session.stop();
        session.set_camera(camera);
        let (p, arc) = (
            pose.look_at_mm,
            flat.dissection.arc_mm_of_column(x, &flat.path),
        );
        format!(
            "looking at the wall point ({:.1}, {:.1}, {:.1}) mm from {:.0} mm along the path, \
             {:.1} mm away",
            p.x,
            p.y,
            p.z,
            arc.unwrap_or_default(),
            p.distance(pose.eye_mm)
        )
    }

    /// The flat image's column where the endoscope is along the path (its nearest path
    /// point's), while it is within the dissection's reach of the path.
    pub fn endoscope_column(&self, session: &Session) -> Option<usize> {
        let flat = self.flat.as_ref()?;
        let (sample, distance_mm) = flat.path.nearest_sample(session.fly_camera().eye_mm());
        let near = distance_mm <= DissectOptions::default().reach_mm;
        near.then(|| flat.dissection.column_of_arc(sample.arc_mm))
            .flatten()
    }
}

/// The path laid flat: through the key frames' eyes when there are at least two, else the
/// study's automatic path.
fn current_path(keys: &[KeyFrame], study: &Study, volume: &Volume) -> Result<Path, String> {
    if keys.len() >= 2 {
        let eyes: Vec<_> = keys.iter().map(|k| k.eye_mm).collect();
        return Path::from_points_exact(&eyes, ROUTE_STEP_MM)
            .map_err(|e| format!("no path through the key frames: {e}"));
    }
    automatic_path(study, volume).map_err(|e| format!("no path to lay flat: {e}"))
}
