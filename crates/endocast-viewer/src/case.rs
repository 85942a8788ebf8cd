//! Case files as the viewer uses them: the one case format of `endocast_io::case` (scan
//! reference and fingerprint, controls with the transfer function, peel settings and geometry
//! toggles, camera, key frames, annotations; written atomically),
//! made from a session and applied to one, and autosaved.

use crate::controller::FlyCamera;
use crate::geometry::{with_mesh, Toggles};
use crate::session::{Controls, Session, NO_PRESET};
use endocast_core::animation::KeyFrame;
use endocast_core::camera::Projection;
use endocast_core::look::{Lighting, LookKind};
use endocast_core::presets::Preset;
use endocast_core::render::Mode;
use endocast_core::views::slices::Window;
pub use endocast_io::case::{
    Case, CaseCamera, CaseControls, CaseError, CaseGeometry, CaseKeyFrame, CasePeel, CaseTransfer,
    FORMAT, VERSION,
};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A case made from a session and applied to one.
pub trait SessionCase: Sized {
    /// The case of `session` now.
    fn of(session: &Session, revision: u64) -> Self;
    /// The controls this case sets, resolved on `session`'s scan; `path` names the file in
    /// errors.
    fn controls(&self, path: &Path, session: &Session) -> Result<Option<Controls>, CaseError>;
    /// Puts `session` (open on this case's scan; refused for another scan) in this case's
    /// state.
    fn apply(&self, session: &mut Session, path: &Path) -> Result<(), CaseError>;
}

fn camera_of(camera: &FlyCamera) -> CaseCamera {
    CaseCamera {
        eye: camera.eye_mm().to_array(),
        forward: camera.forward().to_array(),
        up: camera.up().to_array(),
    }
}

fn fly_camera(c: &CaseCamera) -> Option<FlyCamera> {
    let v = DVec3::from_array;
    FlyCamera::new(v(c.eye), v(c.forward), v(c.up))
}

fn controls_of(c: &Controls, mesh_files: &[PathBuf]) -> CaseControls {
    CaseControls {
        preset: c.preset_name().into(),
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
        tf: Some(CaseTransfer::from(&c.tf)),
        peel: Some(CasePeel::of(&c.peel)),
        geometry: Some(geometry_of(c.geometry, mesh_files)),
        look: Some(c.look.name().into()),
        lighting: Some(c.lighting.name().into()),
    }
}

fn geometry_of(t: Toggles, mesh_files: &[PathBuf]) -> CaseGeometry {
    CaseGeometry {
        grid: t.grid,
        endoscope: t.endoscope,
        markers: t.markers,
        meshes: t.meshes,
        mesh_files: mesh_files.to_vec(),
    }
}

fn toggles(g: &CaseGeometry) -> Toggles {
    Toggles {
        grid: g.grid,
        endoscope: g.endoscope,
        markers: g.markers,
        meshes: g.meshes,
    }
}

impl SessionCase for Case {
    fn of(session: &Session, revision: u64) -> Self {
        let scene = session.scene();
        let mut case = Case::new(scene.source.clone(), Some(&scene.identity));
        let mesh_files = session.geometry().mesh_files();
        case.controls = Some(controls_of(&session.controls, mesh_files));
        case.camera = Some(camera_of(session.fly_camera()));
        case.key_frames = session.key_frames().iter().map(key_to_case).collect();
        case.set_annotations(session.marks());
        case.revision = revision;
        case
    }

    fn controls(&self, path: &Path, session: &Session) -> Result<Option<Controls>, CaseError> {
        let Some(c) = &self.controls else {
            return Ok(None);
        };
        let bad = |what: &str, name: &str| CaseError::new(path, format!("unknown {what} {name:?}"));
        let preset = match c.preset.as_str() {
            NO_PRESET => None,
            name => Some(Preset::find(name).ok_or_else(|| bad("preset", name))?),
        };
        let window = Window::new(c.window_level_hu, c.window_width_hu)
            .map_err(|e| CaseError::new(path, e))?;
        // Cases before version 3 keep none of these: the preset's apply.
        let here = session.study_here(preset);
        let defaults = here.settings().clone();
        let tf = match &c.tf {
            Some(tf) => tf.transfer_function(),
            None => Ok(defaults.tf.clone()),
        };
        let peel = match &c.peel {
            Some(peel) => peel.apply(&defaults.peel),
            None => Ok(defaults.peel.clone()),
        };
        let to_case_error = |e| CaseError::new(path, e);
        let look = match &c.look {
            Some(name) => LookKind::from_name(name).ok_or_else(|| bad("look", name))?,
            None => here.look().kind,
        };
        let lighting = match &c.lighting {
            Some(name) => endocast_io::lit_sphere::named_or_file(name)
                .map_err(|e| CaseError::new(path, format!("lighting: {e}")))?,
            None => Lighting::Phong,
        };
        Ok(Some(Controls {
            preset,
            base: defaults.clone(),
            mode: Mode::from_name(&c.mode).ok_or_else(|| bad("mode", &c.mode))?,
            iso_hu: c.iso_hu,
            iso_opacity: c.iso_opacity,
            projection: Projection::from_name(&c.lens).ok_or_else(|| bad("lens", &c.lens))?,
            fov_deg: c.fov_deg,
            stereo: c.stereo,
            collision: c.collision,
            speed_mm_s: c.speed_mm_s,
            window,
            tf: tf.map_err(to_case_error)?,
            peel: peel.map_err(to_case_error)?,
            geometry: c.geometry.as_ref().map(toggles).unwrap_or_default(),
            look,
            lighting,
            // A viewing preference of the workstation, not of the case: kept as it is.
            still_filter: session.controls.still_filter,
        }))
    }

    fn apply(&self, session: &mut Session, path: &Path) -> Result<(), CaseError> {
        self.check_scan(&session.scene().identity, path)?;
        let controls = SessionCase::controls(self, path, session)?;
        let camera = match &self.camera {
            Some(c) => Some(
                fly_camera(c)
                    .ok_or_else(|| CaseError::new(path, "the camera has no valid frame"))?,
            ),
            None => None,
        };
        let keys = self
            .key_frames
            .iter()
            .map(|k| key_from_case(k).map_err(|e| CaseError::new(path, e)))
            .collect::<Result<Vec<_>, _>>()?;
        let marks = self.annotations(path)?;
        if let Some(controls) = controls {
            session.controls = controls;
        }
        if let Some(camera) = camera {
            session.set_camera(camera);
        }
        session.set_key_frames(keys);
        session.set_marks(marks);
        Ok(())
    }
}

/// Reads again the meshes `case` lists into `session` (after [`SessionCase::apply`]; slow for
/// large meshes, so off the UI thread). A mesh that cannot be read is skipped, not fatal: the
/// case still opens, and the returned lines say which and why.
pub fn read_case_meshes(case: &Case, session: &mut Session) -> Vec<String> {
    let files = case.controls.as_ref().and_then(|c| c.geometry.as_ref());
    let mut problems = Vec::new();
    for file in files.map_or(&[][..], |g| &g.mesh_files) {
        let meshes = session.geometry_mut().meshes().clone();
        match with_mesh(meshes, file) {
            Ok(meshes) => session.geometry_mut().set_meshes(meshes, file.clone()),
            Err(e) => problems.push(format!("{}: {e}", file.display())),
        }
    }
    problems
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

/// Saves the case every so often when it changed, atomically, and never over what another
/// program saved to the same file meanwhile (see [`Case::write_over`]).
#[derive(Debug)]
pub struct Autosave {
    path: PathBuf,
    interval: Duration,
    last_saved: Option<Case>,
    last_time: Option<Instant>,
    /// The revision of the file as last read or written (`None`: there was none).
    revision: Option<u64>,
    /// Whether it saves at all ([`Autosave::never`] does not).
    saves: bool,
}

impl Autosave {
    /// Autosaves to `path` at most once per `interval`, over the file as it is now.
    pub fn new(path: PathBuf, interval: Duration) -> Self {
        Self {
            revision: Case::revision_at(&path).ok().flatten(),
            path,
            interval,
            last_saved: None,
            last_time: None,
            saves: true,
        }
    }

    /// [`Autosave::new`] for a session just opened (on its case, or on a scan without one):
    /// nothing is written until the session changes, so opening and closing a case leaves
    /// its file as it was, byte for byte.
    pub fn opened(path: PathBuf, interval: Duration, session: &Session) -> Self {
        Self {
            last_saved: Some(Case::of(session, 0)),
            ..Self::new(path, interval)
        }
    }

    /// An autosave that never writes (a `--screenshot` run, which only looks).
    pub fn never(path: PathBuf) -> Self {
        Self {
            saves: false,
            ..Self::new(path, Duration::MAX)
        }
    }

    /// Whether it writes the case at all.
    pub fn saves(&self) -> bool {
        self.saves
    }

    /// Where it saves.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Saves to another file from now on (after "Save as").
    pub fn set_path(&mut self, path: PathBuf) {
        self.revision = Case::revision_at(&path).ok().flatten();
        self.path = path;
        self.last_saved = None;
    }

    /// Saves `session` when it changed since the last save and the interval has passed (or
    /// `force`); returns whether it wrote. Refused when another program saved the file since
    /// it was opened or last saved here.
    pub fn tick(&mut self, session: &Session, force: bool) -> Result<bool, CaseError> {
        if !self.saves {
            return Ok(false);
        }
        let due = self.last_time.is_none_or(|t| t.elapsed() >= self.interval);
        if !(force || due) {
            return Ok(false);
        }
        // Compared without the revision, which every save bumps.
        let case = Case::of(session, 0);
        if self.last_saved.as_ref() == Some(&case) {
            return Ok(false);
        }
        self.revision = Some(case.write_over(&self.path, self.revision)?);
        self.last_saved = Some(case);
        self.last_time = Some(Instant::now());
        Ok(true)
    }
}
