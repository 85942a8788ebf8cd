//! Where a study starts: the user's camera, else inside the structure the procedure names,
//! looking along the automatic path planned from there, else the whole object framed.

use super::framing::object_framing;
use super::Values;
use crate::navigate::{
    default_view, plan_in, DefaultView, FramingReason, LumenChoice, PathEnd, PlannedPath,
};
use crate::path::SmoothOptions;
use crate::pose::Pose;
use crate::tissue;
use crate::Volume;

/// How far ahead on the path a camera looks, mm: the start pose looks at the automatic path's
/// point this far on, as a flight along it does (`endocast fly --look-ahead`'s default).
pub const LOOK_AHEAD_MM: f64 = 10.0;

/// The study's start (see [`Study::start_pose`]).
#[derive(Debug)]
pub(super) struct Start {
    /// The camera.
    pub pose: Pose,
    /// The default view the library chose; `None` when the user placed the camera.
    pub view: Option<DefaultView>,
    /// The automatic path through the structure, from the start.
    pub path: Option<PlannedPath>,
    /// Why a procedure in a lumen was asked for but the object is framed from outside.
    pub framing_reason: Option<String>,
    /// What could not be done, one line each.
    pub notes: Vec<String>,
}

impl Start {
    /// The start of the study of `study` on `volume`.
    pub fn resolve(volume: &Volume, study: &Values) -> Self {
        if let Some(pose) = study.request.pose {
            return Self::at(pose, None);
        }
        let Some(preset) = study.preset.filter(|p| p.lumen.is_some()) else {
            return Self::framed(volume, study, None);
        };
        let (threshold, _) = match &study.lumen {
            Ok(lumen) => *lumen,
            Err(error) => return Self::framed(volume, study, Some(error.to_string())),
        };
        let choice = LumenChoice {
            preset: Some(&preset),
            iso: Some(study.settings.iso_hu),
            threshold: Some(threshold),
            bright_lumen: study.request.bright_lumen,
            within: tissue::central_structure(&preset, volume, &study.scan),
        };
        match default_view(volume, Some(&choice), study.fov_deg()) {
            view @ DefaultView::InsideLumen { .. } => Self::inside(volume, view),
            DefaultView::Framing { reason, .. } => {
                Self::framed(volume, study, Some(framing_words(&reason)))
            }
        }
    }

    /// The whole object framed from the front, with `reason` when a structure was asked for.
    fn framed(volume: &Volume, study: &Values, reason: Option<String>) -> Self {
        let pose = object_framing(volume, &study.scan, study.fov_deg());
        let view = DefaultView::Framing {
            pose,
            reason: FramingReason::NoLumenAsked,
        };
        Self {
            framing_reason: reason,
            ..Self::at(pose, Some(view))
        }
    }

    /// A start at `pose`, chosen as `view` says (`None`: by the user).
    fn at(pose: Pose, view: Option<DefaultView>) -> Self {
        Self {
            pose,
            view,
            path: None,
            framing_reason: None,
            notes: Vec::new(),
        }
    }

    /// The camera inside the structure of `view`, turned to look along the automatic path
    /// planned from it (kept as it was, with a note, when no path can be planned).
    fn inside(volume: &Volume, mut view: DefaultView) -> Self {
        let (mut path, mut notes) = (None, Vec::new());
        if let DefaultView::InsideLumen {
            pose,
            lumen,
            end_mm,
            ..
        } = &mut view
        {
            let end = end_mm.map_or(PathEnd::Farthest, PathEnd::Point);
            match plan_in(volume, lumen, pose.eye_mm, end, &SmoothOptions::default()) {
                Ok((_, planned)) => {
                    if let Some(along) = along_path(&planned) {
                        *pose = along;
                    }
                    path = Some(planned);
                }
                Err(error) => notes.push(format!(
                    "no automatic path from the start ({error}); the start looks along the \
                     structure instead"
                )),
            }
        }
        Self {
            path,
            notes,
            ..Self::at(view.pose(), Some(view))
        }
    }
}

/// The camera at the start of `planned` looking [`LOOK_AHEAD_MM`] along it, up as near the
/// patient's anterior as the view allows; `None` for a path too short to give a direction.
fn along_path(planned: &PlannedPath) -> Option<Pose> {
    let path = &planned.path;
    let eye = path.point_at(0.0);
    let ahead = path.point_at(LOOK_AHEAD_MM.min(path.len_mm()));
    let forward = (ahead - eye).try_normalize()?;
    Some(crate::navigate::looking_along(
        eye,
        forward,
        eye.distance(ahead).max(1.0),
    ))
}

/// Why the library framed the volume, in words.
fn framing_words(reason: &FramingReason) -> String {
    match reason {
        FramingReason::Choice(error) => error.to_string(),
        FramingReason::NoLumen { threshold, side } => {
            format!("no lumen {side} {}", tissue::short(*threshold))
        }
        _ => "no structure found".to_owned(),
    }
}
