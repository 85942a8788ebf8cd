//! Case files: the scan reference, the controls, the camera, the key frames and the
//! annotations, as JSON, written atomically (a temporary file renamed over the old one, so a
//! crash or a kill during a save leaves the previous case intact), and autosaved.
//!
//! ```json
//! {"format": "endocast-case", "version": 1,
//!  "scan": {"kind": "file", "path": "chest-ct"},
//!  "controls": {"preset": "bronchoscopy", "mode": "hybrid", "iso_hu": -500, ...},
//!  "camera": {"eye": [0, 0, 0], "forward": [0, 0, 1], "up": [0, -1, 0]},
//!  "key_frames": [], "annotations": []}
//! ```

use crate::controller::FlyCamera;
use crate::geometry::Toggles;
use crate::scene::ScanSource;
use crate::session::{Annotation, Controls, Session};
use endocast_core::animation::KeyFrame;
use endocast_core::camera::Projection;
use endocast_core::presets::Preset;
use endocast_core::render::Mode;
use endocast_core::views::slices::Window;
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// The `"format"` value of case files.
pub const FORMAT: &str = "endocast-case";
/// The version this code reads and writes.
pub const VERSION: u32 = 1;
/// A case file larger than this is refused unread.
const MAX_BYTES: u64 = 64 << 20;

/// A case as the file holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Always [`FORMAT`].
    pub format: String,
    /// Always [`VERSION`].
    pub version: u32,
    /// The scan.
    pub scan: ScanSource,
    /// The control panel.
    pub controls: CaseControls,
    /// The camera.
    pub camera: CaseCamera,
    /// The key frames, in playback order.
    #[serde(default)]
    pub key_frames: Vec<CaseKeyFrame>,
    /// The annotations.
    #[serde(default)]
    pub annotations: Vec<CaseAnnotation>,
    /// A number that grows with every save of a session (the autosave test reads it).
    #[serde(default)]
    pub revision: u64,
}

/// The controls by name, so the file reads as the CLI's options do.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseControls {
    pub preset: String,
    pub mode: String,
    pub iso_hu: f64,
    pub iso_opacity: f32,
    pub lens: String,
    pub fov_deg: f64,
    pub stereo: bool,
    pub collision: bool,
    pub speed_mm_s: f64,
    pub window_level_hu: f64,
    pub window_width_hu: f64,
}

/// A camera: eye (world mm, LPS), view direction and image up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseCamera {
    pub eye: [f64; 3],
    pub forward: [f64; 3],
    pub up: [f64; 3],
}

/// A key frame as path files have it (see `docs/path-format.md`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseKeyFrame {
    pub eye: [f64; 3],
    pub forward: [f64; 3],
    pub up: [f64; 3],
    pub fov_deg: f64,
    pub iso_hu: f64,
    pub iso_opacity: f64,
}

/// A labelled point, world mm.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(missing_docs)]
pub struct CaseAnnotation {
    pub label: String,
    pub point: [f64; 3],
}

/// Why a case cannot be read or applied.
#[derive(Debug, thiserror::Error)]
#[error("case file {path}: {problem}")]
pub struct CaseError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong, one line.
    pub problem: String,
}

impl CaseError {
    fn new(path: &Path, problem: impl Into<Problem>) -> Self {
        Self {
            path: path.to_owned(),
            problem: problem.into().0,
        }
    }
}

/// A case error's problem in words (from any error or text).
struct Problem(String);

impl<T: std::fmt::Display> From<T> for Problem {
    fn from(problem: T) -> Self {
        Self(problem.to_string())
    }
}

impl CaseCamera {
    fn of(camera: &FlyCamera) -> Self {
        Self {
            eye: camera.eye_mm().to_array(),
            forward: camera.forward().to_array(),
            up: camera.up().to_array(),
        }
    }

    fn fly_camera(&self) -> Option<FlyCamera> {
        let v = DVec3::from_array;
        FlyCamera::new(v(self.eye), v(self.forward), v(self.up))
    }
}

impl Case {
    /// The case of `session` now.
    pub fn of(session: &Session, revision: u64) -> Self {
        let c = &session.controls;
        Self {
            format: FORMAT.into(),
            version: VERSION,
            scan: session.scene().source.clone(),
            controls: CaseControls {
                preset: c.preset.name.into(),
                mode: c.mode.name().into(),
                iso_hu: c.iso_hu,
                iso_opacity: c.iso_opacity,
                lens: c.projection.name().into(),
                fov_deg: c.fov_deg,
                stereo: c.stereo,
                collision: c.collision,
                speed_mm_s: c.speed_mm_s,
                window_level_hu: c.window.level_hu,
                window_width_hu: c.window.width_hu,
            },
            camera: CaseCamera::of(session.fly_camera()),
            key_frames: session.key_frames().iter().map(key_to_case).collect(),
            annotations: session
                .annotations()
                .iter()
                .map(|a| CaseAnnotation {
                    label: a.label.clone(),
                    point: a.point_mm.to_array(),
                })
                .collect(),
            revision,
        }
    }

    /// Reads `path`; the error names the file and the problem.
    pub fn read(path: &Path) -> Result<Self, CaseError> {
        let size = std::fs::metadata(path)
            .map_err(|e| CaseError::new(path, e))?
            .len();
        if size > MAX_BYTES {
            return Err(CaseError::new(path, format!("{size} bytes is too large")));
        }
        let text = std::fs::read_to_string(path).map_err(|e| CaseError::new(path, e))?;
        let case: Self = serde_json::from_str(&text).map_err(|e| CaseError::new(path, e))?;
        if case.format != FORMAT || case.version != VERSION {
            return Err(CaseError::new(
                path,
                format!(
                    "format {:?} version {} is not {FORMAT:?} version {VERSION}",
                    case.format, case.version
                ),
            ));
        }
        Ok(case)
    }

    /// Writes the case to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<(), CaseError> {
        let json = serde_json::to_vec_pretty(self).map_err(|e| CaseError::new(path, e))?;
        endocast_io::atomic::write_file(path, |w| w.write_all(&json))
            .map_err(|e| CaseError::new(path, e))
    }

    /// The controls this case sets; `path` names the file in errors.
    pub fn controls(&self, path: &Path) -> Result<Controls, CaseError> {
        let c = &self.controls;
        let bad = |what: &str, name: &str| CaseError::new(path, format!("unknown {what} {name:?}"));
        let preset = Preset::find(&c.preset).ok_or_else(|| bad("preset", &c.preset))?;
        let window = Window::new(c.window_level_hu, c.window_width_hu)
            .map_err(|e| CaseError::new(path, e))?;
        let defaults = preset.settings();
        Ok(Controls {
            preset,
            mode: Mode::from_name(&c.mode).ok_or_else(|| bad("mode", &c.mode))?,
            iso_hu: c.iso_hu,
            iso_opacity: c.iso_opacity,
            projection: Projection::from_name(&c.lens).ok_or_else(|| bad("lens", &c.lens))?,
            fov_deg: c.fov_deg,
            stereo: c.stereo,
            collision: c.collision,
            speed_mm_s: c.speed_mm_s,
            window,
            tf: defaults.tf,
            peel: defaults.peel,
            geometry: Toggles::default(),
        })
    }

    /// Puts `session` (open on this case's scan) in this case's state.
    pub fn apply(&self, session: &mut Session, path: &Path) -> Result<(), CaseError> {
        let controls = self.controls(path)?;
        let camera = self
            .camera
            .fly_camera()
            .ok_or_else(|| CaseError::new(path, "the camera has no valid frame"))?;
        let keys = self
            .key_frames
            .iter()
            .map(|k| key_from_case(k).map_err(|e| CaseError::new(path, e)))
            .collect::<Result<Vec<_>, _>>()?;
        session.controls = controls;
        session.set_camera(camera);
        session.set_key_frames(keys);
        session.set_annotations(
            self.annotations
                .iter()
                .map(|a| Annotation {
                    label: a.label.clone(),
                    point_mm: DVec3::from_array(a.point),
                })
                .collect(),
        );
        Ok(())
    }
}

fn key_to_case(k: &KeyFrame) -> CaseKeyFrame {
    CaseKeyFrame {
        eye: k.eye_mm.to_array(),
        forward: k.forward().to_array(),
        up: k.up().to_array(),
        fov_deg: k.fov_deg,
        iso_hu: k.iso_hu,
        iso_opacity: k.iso_opacity,
    }
}

fn key_from_case(k: &CaseKeyFrame) -> Result<KeyFrame, String> {
    let v = DVec3::from_array;
    KeyFrame::new(
        v(k.eye),
        v(k.forward),
        v(k.up),
        k.fov_deg,
        k.iso_hu,
        k.iso_opacity,
    )
    .map_err(|e| e.to_string())
}

/// Saves the case every so often when it changed, atomically.
#[derive(Debug)]
pub struct Autosave {
    path: PathBuf,
    interval: Duration,
    last_saved: Option<Case>,
    last_time: Option<Instant>,
    revision: u64,
}

impl Autosave {
    /// Autosaves to `path` at most once per `interval`.
    pub fn new(path: PathBuf, interval: Duration) -> Self {
        Self {
            path,
            interval,
            last_saved: None,
            last_time: None,
            revision: 0,
        }
    }

    /// Where it saves.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Saves to another file from now on (after "Save as").
    pub fn set_path(&mut self, path: PathBuf) {
        self.path = path;
        self.last_saved = None;
    }

    /// Saves `session` when it changed since the last save and the interval has passed (or
    /// `force`); returns whether it wrote.
    pub fn tick(&mut self, session: &Session, force: bool) -> Result<bool, CaseError> {
        let due = self.last_time.is_none_or(|t| t.elapsed() >= self.interval);
        if !(force || due) {
            return Ok(false);
        }
        // Compared without the revision, which every save bumps.
        let case = Case::of(session, 0);
        if self.last_saved.as_ref() == Some(&case) {
            return Ok(false);
        }
        let written = Case {
            revision: self.revision + 1,
            ..case.clone()
        };
        written.write(&self.path)?;
        self.revision += 1;
        self.last_saved = Some(case);
        self.last_time = Some(Instant::now());
        Ok(true)
    }
}
