//! The workstation's cleansing switch (issue 36): the scan shown with its tagged fluid removed
//! by the core [`cleanse`] (what `--cleanse on` runs), or as acquired again, to compare the
//! two. The cleansed scan is made off the UI thread and kept, as is the scan as read, so
//! switching back and forth only resolves the study again on the scan shown (as every command
//! resolves it on the scan it cleansed); the camera, controls, key frames and marks stay.
//! It is off by default and offered only for a CT in Hounsfield units.

use crate::jobs::{Job, Notify, Polled};
use crate::scene::Scene;
use crate::session::Session;
use endocast_core::cleanse::{cleanse, hounsfield_offset};
use endocast_core::study::Study;
use std::sync::Arc;

/// What a switch produced: the scene to show, its study, and the line to say.
type Switched = (bool, Arc<Scene>, Study, String);

/// The switch's state.
#[derive(Debug, Default)]
pub struct CleanseSwitch {
    /// Whether the scan shown is the cleansed one.
    on: bool,
    /// The scan as read, kept once a cleansed one was made.
    original: Option<Arc<Scene>>,
    /// The cleansed scan, kept once made.
    cleansed: Option<Arc<Scene>>,
    job: Option<Job<Result<Switched, String>>>,
}

impl CleanseSwitch {
    /// Whether the scan shown is cleansed.
    pub fn is_on(&self) -> bool {
        self.on
    }

    /// Whether a switch is being made.
    pub fn running(&self) -> bool {
        self.job.is_some()
    }

    /// Why the session's scan cannot be cleansed (not a CT in Hounsfield units); `None` when it
    /// can.
    pub fn unavailable(session: &Session) -> Option<String> {
        let modality = session.scene().volume().modality();
        hounsfield_offset(modality, session.study().scan())
            .err()
            .map(|e| e.to_string())
    }

    /// Starts showing the scan cleansed (`on`) or as acquired, off the UI thread (`notify` when
    /// done); nothing when it is shown so already or a switch is being made.
    pub fn set(&mut self, on: bool, session: &Session, notify: Notify) {
        if on == self.on || self.running() {
            return;
        }
        let shown = Arc::clone(session.scene());
        let original = Arc::clone(self.original.get_or_insert(shown));
        let kept = if on {
            self.cleansed.clone()
        } else {
            Some(original.clone())
        };
        let request = *session.study().request();
        self.job = Some(Job::spawn("cleanse", notify, move || {
            let (scene, said) = match kept {
                Some(scene) => (scene, scene_said(on)),
                None => cleansed_scene(&original)?,
            };
            let study = Study::resolve(scene.volume(), &request);
            Ok((on, scene, study, said))
        }));
    }

    /// Shows the scan switched to in `session` once it is ready; returns a line for the status
    /// bar when a switch ended, and whether the scan shown changed.
    pub fn poll(&mut self, session: &mut Session) -> Option<(String, bool)> {
        let result = match self.job.as_ref()?.poll() {
            Polled::Running => return None,
            Polled::Done(result) => result,
            Polled::Lost => Err("the cleansing stopped".into()),
        };
        self.job = None;
        Some(match result {
            Ok((on, scene, study, said)) => {
                if on {
                    self.cleansed = Some(Arc::clone(&scene));
                }
                self.on = on;
                session.show_scene(scene, Arc::new(study));
                (said, true)
            }
            Err(e) => (e, false),
        })
    }
}

/// The line said when a kept scan is shown again.
fn scene_said(on: bool) -> String {
    if on {
        "showing the cleansed scan".into()
    } else {
        "showing the scan as acquired (tagged fluid not removed)".into()
    }
}

/// `original` cleansed, as the same scan for the case (its fingerprint is the scan's as read,
/// so the case still opens on it), with what was removed in words.
fn cleansed_scene(original: &Scene) -> Result<(Arc<Scene>, String), String> {
    let cleansed = cleanse(original.volume()).map_err(|e| e.to_string())?;
    let said = cleansed.summary();
    let mut scene = Scene::new(original.source.clone(), cleansed.volume);
    scene.identity = original.identity.clone();
    scene.series_found.clone_from(&original.series_found);
    scene.orientation_declared = original.orientation_declared;
    scene.warnings.clone_from(&original.warnings);
    Ok((Arc::new(scene), said))
}
