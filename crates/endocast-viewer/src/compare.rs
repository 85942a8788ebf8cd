//! Supine/prone side by side (issue 36): a second scan of the same patient (e.g. prone beside
//! supine), its endoscope view shown beside the first's, its camera following the first's.
//!
//! Opening it reads the second scan, resolves its study for the first's preset, and matches
//! the two scans' colon paths with the core [`Correspondence`] (as `endocast match` does), all
//! off the UI thread. From then on every change of the first camera is carried to the second
//! scan by [`Correspondence::follow`] — its eye to the eye's counterpart, its view turned as the
//! wall around it is turned — and rendered by a worker of its own at lower priority: at
//! [`COMPARE_SCALE`] of the view's resolution, with no accumulated stills.

use crate::geometry::SceneRef;
use crate::jobs::{Job, Notify};
use crate::scene::{ScanSource, Scene};
use crate::session::Session;
use crate::worker::{RenderWorker, View};
use endocast_core::correspond::Correspondence;
use endocast_core::look::Look;
use endocast_core::pose::Pose;
use endocast_core::render::Filter;
use endocast_core::study::{Study, StudyRequest};
use std::sync::Arc;

/// The second view's resolution, as a fraction of the first's in each direction.
pub const COMPARE_SCALE: f64 = 0.5;

/// The second scan, opened and matched with the first.
#[derive(Debug)]
pub struct Compare {
    scene: Arc<Scene>,
    study: Study,
    matched: Correspondence,
    worker: RenderWorker,
    /// The first camera's pose last followed and the second's pose it gave.
    followed: Option<(Pose, Pose)>,
    last_view: Option<View>,
}

/// Opening the second scan (reading, its study, the match) off the UI thread.
pub type CompareJob = Job<Result<Compare, String>>;

impl Compare {
    /// Starts opening `source` as the second scan beside `session`'s, for the session's
    /// preset; `notify` is called when it is open and after each of its frames.
    pub fn open(session: &Session, source: ScanSource, notify: Notify) -> CompareJob {
        let first = Arc::clone(session.scene());
        let first_study = session.shared_study();
        let request = StudyRequest {
            preset: session.controls.preset,
            ..StudyRequest::default()
        };
        let on_frame = Arc::clone(&notify);
        Job::spawn("compare", notify, move || {
            let volume = source.load()?;
            let study = Study::resolve(&volume, &request);
            let matched =
                Correspondence::of_studies((first.volume(), &first_study), (&volume, &study))
                    .map_err(|e| format!("cannot match {} with this scan: {e}", source.label()))?;
            let scene = Arc::new(Scene::new(source, volume));
            let worker = RenderWorker::start(Arc::clone(&scene.renderer), move || on_frame());
            Ok(Self {
                scene,
                study,
                matched,
                worker,
                followed: None,
                last_view: None,
            })
        })
    }

    /// The second scan.
    pub fn scene(&self) -> &Arc<Scene> {
        &self.scene
    }

    /// The two scans' paths matched.
    pub fn matched(&self) -> &Correspondence {
        &self.matched
    }

    /// The second view's renderer.
    pub fn worker(&self) -> &RenderWorker {
        &self.worker
    }

    /// The second camera's pose, once it has followed the first.
    pub fn pose(&self) -> Option<Pose> {
        self.followed.map(|(_, pose)| pose)
    }

    /// Carries `session`'s camera to the second scan and sends the second view (at
    /// [`COMPARE_SCALE`] of `size`, the session's lens and look in the second scan's study)
    /// when it changed; returns the new request's generation, or why the camera cannot be
    /// carried there.
    pub fn follow(&mut self, session: &Session, size: [usize; 2]) -> Result<Option<u64>, String> {
        let first = session.fly_camera().pose();
        let pose = match self.followed {
            Some((was, pose)) if was == first => pose,
            _ => {
                let pose = self.matched.follow(&first).map_err(|e| e.to_string())?;
                self.followed = Some((first, pose));
                pose
            }
        };
        let view = self.view(session, &pose, size)?;
        if self.last_view.as_ref() == Some(&view) {
            return Ok(None);
        }
        self.last_view = Some(view.clone());
        Ok(Some(self.worker.submit(view)))
    }

    /// The second scan's view from `pose`: the session's lens and look, the second study's
    /// settings (its own units), a quick preview then the full frame and no still.
    fn view(&self, session: &Session, pose: &Pose, size: [usize; 2]) -> Result<View, String> {
        let size = size.map(|n| ((n as f64 * COMPARE_SCALE).round() as usize).clamp(16, 2048));
        let camera = session
            .controls
            .optics()
            .camera(pose.eye_mm, pose.look_at_mm, pose.up, size)
            .map_err(|e| e.to_string())?;
        let look = Look::of_kind(session.controls.look, &self.study.look()).map(|mut look| {
            look.shading.lighting.clone_from(&session.controls.lighting);
            look
        });
        Ok(View {
            camera,
            settings: self.study.settings().clone(),
            stereo: None,
            moving: true,
            scene: SceneRef::default(),
            look,
            still_filter: Filter::Trilinear,
        })
    }
}
