//! The study: one scan understood for one procedure, resolved once and shared by every front end
//! (`render`, `path`, `fly`, `bench`, `annotate`, the viewer, Python).
//!
//! A [`Study`] is built from a loaded [`Volume`], an optional preset and the user's overrides
//! ([`StudyRequest`]). It resolves, in this order and once:
//! - what the scan's values are ([`ScanValues`]: HU, HU + 1024, MR intensities) and the preset
//!   carried into them ([`tissue::resolve`]): isovalues, transfer function, slice window, look;
//! - the lumen the procedure flies through (threshold and side), following the isovalue by a
//!   stated rule that never puts it beyond the lumen's own value ([`Study::lumen`]);
//! - the structure the preset names and the start pose inside it, looking along the automatic
//!   path's first tangent ([`Study::start`]), or, without a preset, the whole object framed;
//! - the automatic path itself ([`Study::path`]), planned once and kept.
//!
//! A front end changes only what its user named on top of it: the same scan and preset give the
//! same values and pose everywhere.
//!
//! ```
//! use endocast_core::navigate::seed_voxel;
//! use endocast_core::phantom::{Phantom, PhantomOptions};
//! use endocast_core::presets::Preset;
//! use endocast_core::study::{Study, StudyRequest};
//!
//! let volume = Phantom::Colon.build(&PhantomOptions { size: 64, ..Default::default() });
//! let request = StudyRequest::preset(Preset::find("colonoscopy").unwrap());
//! let study = Study::resolve(&volume, &request);
//! assert!(study.found().is_some(), "{}", study.summary());
//! let eye = seed_voxel(&volume, study.start_pose().eye_mm).unwrap();
//! assert!(study.structure().unwrap().contains(eye));
//! ```

mod airway;
mod framing;
mod lens;
mod options;
mod route;
mod start;

pub use airway::{TargetPath, TargetPathError};
pub use framing::{object_bounds, object_framing};
pub use lens::LensOptions;
pub use options::{named, LookOptions, OptionError, PeelOptions, ViewOptions};
pub use route::{StudyPath, StudyPathError};
pub use start::LOOK_AHEAD_MM;

use crate::look::PresetLook;
use crate::navigate::{DefaultView, Lumen, LumenChoice, LumenChoiceError, LumenSide};
use crate::pose::Pose;
use crate::presets::{Preset, DEFAULT_FOV_DEG};
use crate::render::RenderSettings;
use crate::tissue::{self, short, ScanValues};
use crate::views::slices::Window;
use crate::Volume;
use start::Start;
use std::time::{Duration, Instant};

/// What the user asked for: a procedure and the values they set themselves. Everything left
/// `None` is the study's to resolve.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StudyRequest {
    /// The procedure (as the table has it, on its reference scale); `None`: no procedure, the
    /// whole object framed.
    pub preset: Option<&'static Preset>,
    /// The wall isovalue, in the scan's units.
    pub iso: Option<f64>,
    /// The lumen's region-growing threshold, in the scan's units.
    pub lumen_threshold: Option<f64>,
    /// The lumen is brighter than the wall (contrast, CSF on T2).
    pub bright_lumen: bool,
    /// The field of view the start is framed for, degrees (default: the preset's, else 90).
    pub fov_deg: Option<f64>,
    /// The user's own camera: no structure is searched for the start.
    pub pose: Option<Pose>,
}

impl StudyRequest {
    /// A request for `preset` with nothing overridden.
    pub fn preset(preset: &'static Preset) -> Self {
        Self {
            preset: Some(preset),
            ..Self::default()
        }
    }
}

/// One scan understood for one procedure (see the module documentation).
#[derive(Debug)]
pub struct Study {
    values: Values,
    start: Start,
    took: Duration,
}

/// What a study resolves before its start: the scan's values and the procedure in them.
#[derive(Debug)]
struct Values {
    request: StudyRequest,
    scan: ScanValues,
    preset: Option<Preset>,
    settings: RenderSettings,
    look: PresetLook,
    summary: String,
    lumen: Result<(f64, LumenSide), LumenChoiceError>,
    notes: Vec<String>,
}

impl Values {
    /// The field of view the start is framed for, degrees.
    fn fov_deg(&self) -> f64 {
        self.request
            .fov_deg
            .unwrap_or_else(|| self.preset.map_or(DEFAULT_FOV_DEG, |p| p.fov_deg))
    }
}

/// How close a lumen threshold moved with the isovalue may come to the lumen's own value (air,
/// for a dark lumen), as a share of the way from that value to the wall: never closer than a
/// quarter of the way, so that noise in the lumen does not break it up.
const LUMEN_MARGIN: f64 = 0.25;

impl Study {
    /// Resolves `request` on `volume` (see the module documentation): the values, the lumen,
    /// the structure and the start pose. The automatic path is planned here too when the start
    /// is inside a structure, since the start looks along it.
    pub fn resolve(volume: &Volume, request: &StudyRequest) -> Self {
        let clock = Instant::now();
        let scan = ScanValues::measure(volume);
        let (mut settings, preset, summary) = match request.preset {
            Some(preset) => {
                let resolved = tissue::resolve(preset, volume, &scan);
                (resolved.settings(), Some(resolved.preset), resolved.summary)
            }
            None => {
                let s = tissue::default_settings(&scan);
                let summary = format!("wall at {} ({scan})", short(s.iso_hu));
                (s, None, summary)
            }
        };
        if let Some(iso) = request.iso {
            settings.iso_hu = iso;
        }
        let look = preset.map_or_else(|| tissue::default_look(&scan), |p| p.look);
        let mut notes = Vec::new();
        let lumen = resolve_lumen(request, preset.as_ref(), &scan, &mut notes);
        let values = Values {
            request: *request,
            scan,
            preset,
            settings,
            look,
            summary,
            lumen,
            notes,
        };
        let start = Start::resolve(volume, &values);
        Self {
            values,
            start,
            took: clock.elapsed(),
        }
    }

    /// How long resolving took.
    pub fn resolve_time(&self) -> Duration {
        self.took
    }

    /// What was asked.
    pub fn request(&self) -> &StudyRequest {
        &self.values.request
    }

    /// What the scan's values are.
    pub fn scan(&self) -> &ScanValues {
        &self.values.scan
    }

    /// The procedure with every value in the scan's units; `None` without one.
    pub fn preset(&self) -> Option<&Preset> {
        self.values.preset.as_ref()
    }

    /// The procedure's name, `None` without one.
    pub fn preset_name(&self) -> Option<&'static str> {
        self.values.request.preset.map(|p| p.name)
    }

    /// The render settings in the scan's units: the preset's (or the view without one), with
    /// the isovalue the user set.
    pub fn settings(&self) -> &RenderSettings {
        &self.values.settings
    }

    /// The look's thresholds and material in the scan's units.
    pub fn look(&self) -> PresetLook {
        self.values.look
    }

    /// The slice window in the scan's units: the preset's, else air to soft tissue.
    pub fn window(&self) -> Window {
        match &self.values.preset {
            Some(p) => p.window,
            None => {
                let map = self.values.scan.from_hounsfield();
                let w = Window::AIR_TISSUE;
                Window {
                    level_hu: map.apply(w.level_hu),
                    width_hu: w.width_hu * map.scale.abs(),
                }
            }
        }
    }

    /// The field of view the start was framed for, degrees.
    pub fn fov_deg(&self) -> f64 {
        self.values.fov_deg()
    }

    /// The lumen's region-growing threshold and side, in the scan's units: the user's
    /// threshold, else the preset's moved by as much as the user moved the wall — but never
    /// closer to the lumen's own value (air, for a dark lumen) than a quarter of the way from it
    /// to the wall, so the lumen cannot vanish when the wall moves — else, without a preset,
    /// the isovalue.
    pub fn lumen(&self) -> Result<(f64, LumenSide), LumenChoiceError> {
        self.values.lumen.clone()
    }

    /// The lumen (see [`Study::lumen`]) for the wall at `iso` instead, as when the user moves
    /// the wall in the viewer; a preset that names no lumen counts as none (the lumen is below
    /// the wall).
    pub fn lumen_at(&self, iso: f64) -> Result<(f64, LumenSide), LumenChoiceError> {
        let request = StudyRequest {
            iso: Some(iso),
            ..self.values.request
        };
        let preset = self.values.preset.filter(|p| p.lumen.is_some());
        resolve_lumen(
            &request,
            preset.as_ref(),
            &self.values.scan,
            &mut Vec::new(),
        )
    }

    /// What was resolved, in one line: the preset in the scan's units and why.
    pub fn summary(&self) -> &str {
        &self.values.summary
    }

    /// What the study adjusted or could not do, one line each (a threshold held back from the
    /// lumen's value, a finder that is not confident, a path that could not be planned).
    pub fn notes(&self) -> impl Iterator<Item = &str> {
        self.values
            .notes
            .iter()
            .chain(self.start.notes.iter())
            .map(String::as_str)
    }

    /// The structure found and the camera in it; `None` when the user placed the camera, no
    /// procedure in a lumen was asked for, or nothing was found (see [`Study::framing`]).
    pub fn found(&self) -> Option<&DefaultView> {
        self.start
            .view
            .as_ref()
            .filter(|v| matches!(v, DefaultView::InsideLumen { .. }))
    }

    /// The default view as the library chose it (inside the structure, or framing), `None`
    /// when the user placed the camera.
    pub fn view(&self) -> Option<&DefaultView> {
        self.start.view.as_ref()
    }

    /// The structure's lumen, when one was found.
    pub fn structure(&self) -> Option<&Lumen> {
        match self.found()? {
            DefaultView::InsideLumen { lumen, .. } => Some(lumen),
            DefaultView::Framing { .. } => None,
        }
    }

    /// What the structure is, in words, when one was found.
    pub fn structure_name(&self) -> Option<&str> {
        match self.found()? {
            DefaultView::InsideLumen { what, .. } => Some(what),
            DefaultView::Framing { .. } => None,
        }
    }

    /// Where a path through the structure ends, when its far end is known (the aorta's lowest
    /// section); `None`: at the farthest point.
    pub fn end_mm(&self) -> Option<glam::DVec3> {
        match self.found()? {
            DefaultView::InsideLumen { end_mm, .. } => *end_mm,
            DefaultView::Framing { .. } => None,
        }
    }

    /// Whether the structure was found with confidence; `false` also when none was found.
    pub fn confident(&self) -> bool {
        self.found().is_some_and(DefaultView::confident)
    }

    /// The camera the study starts at: the user's, else inside the structure looking along the
    /// automatic path, else the whole object framed.
    pub fn start_pose(&self) -> Pose {
        self.start.pose
    }

    /// Why the start frames the object from outside, in words, when it does although a
    /// procedure in a lumen was asked for.
    pub fn framing(&self) -> Option<&str> {
        self.start.framing_reason.as_deref()
    }

    /// The automatic path from the start through the structure, when one was planned.
    pub fn path(&self) -> Option<&crate::navigate::PlannedPath> {
        self.start.path.as_ref()
    }
}

/// The lumen of `request` on `scan` (see [`Study::lumen`]), with a note when the threshold was
/// held back from the lumen's own value.
fn resolve_lumen(
    request: &StudyRequest,
    preset: Option<&Preset>,
    scan: &ScanValues,
    notes: &mut Vec<String>,
) -> Result<(f64, LumenSide), LumenChoiceError> {
    let choice = LumenChoice {
        preset,
        iso: request.iso,
        threshold: request.lumen_threshold,
        bright_lumen: request.bright_lumen,
        within: None,
    };
    let (threshold, side) = choice.resolve()?;
    let moved = request.lumen_threshold.is_none() && preset.is_some();
    let Some(iso) = request.iso.filter(|_| moved) else {
        return Ok((threshold, side));
    };
    let own = match side {
        LumenSide::Below => scan.background,
        LumenSide::Above => scan.range.1,
    };
    let limit = own + LUMEN_MARGIN * (iso - own);
    let beyond = match side {
        LumenSide::Below => threshold < limit,
        LumenSide::Above => threshold > limit,
    };
    if !beyond {
        return Ok((threshold, side));
    }
    notes.push(format!(
        "the lumen threshold {} (the preset's, moved with the wall to {}) comes too close to \
         the lumen's own value {}; using {}, a quarter of the way from it to the wall",
        short(threshold),
        short(iso),
        short(own),
        short(limit)
    ));
    Ok((limit, side))
}

#[cfg(test)]
mod tests;
