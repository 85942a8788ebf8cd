//! A fly-through: the camera shots along a smooth [`Path`] or a key-frame [`Animation`], and
//! the frames of the flight — the endoscopic view alone or a dashboard with the three slices
//! and an overview of the lumen — while the [`Coverage`](crate::coverage::Coverage) of the wall
//! is tracked; the settings of each shot ([`ShotSettings`]: a key frame's look); and the
//! coverage measurement, forward and back ([`wall_coverage`], [`BackwardPass`], [`WallSeen`]);
//! and the review of the wall it missed ([`review`]).

mod error;
mod frames;
mod looks;
mod overview;
mod review;
pub(crate) use review::up_for;
mod wall;

pub use error::FlightError;
pub use frames::{Flight, FlightOptions, FlightStereo, Layout};
pub use looks::ShotSettings;
pub use overview::{lumen_overview, Overview};
pub use review::{
    review, PatchView, Review, ReviewRequest, ReviewSite, DEFAULT_MIN_AREA_MM2, MAX_FOV_DEG,
    MIN_FOV_DEG, REVIEW_AREA_MM2, REVIEW_FRAME_PX, REVIEW_STEP_MM, SAFE_MM, VIEW_TINT,
};
pub use wall::{
    wall_coverage, wall_coverage_near, BackwardPass, WallSeen, BACK_ONLY_TINT,
    LABEL_SEEN_BACK_ONLY, LABEL_SEEN_FORWARD, LABEL_UNSEEN, MASK_LABELS, REPORT_TINT,
};

use crate::animation::{Animation, AnimationError, KeyFrame};
use crate::path::{Path, PathError};
use crate::pose::Pose;
use glam::DVec3;

/// One frame's camera and, for key frames, its render parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct Shot {
    /// Where the camera is and looks.
    pub pose: Pose,
    /// Position along the route, mm of arc from its start.
    pub arc_mm: f64,
    /// Direction of the route at the camera (unit): the normal of the cross-section.
    pub tangent: DVec3,
    /// Vertical field of view, degrees; `None` keeps the flight's.
    pub fov_deg: Option<f64>,
    /// Render parameters of a key-frame animation; `None` keeps the flight's.
    pub look: Option<ShotLook>,
}

/// The render parameters a key frame carries.
#[derive(Debug, Clone, PartialEq)]
pub struct ShotLook {
    /// Isovalue, physical units.
    pub iso_hu: f64,
    /// Isosurface opacity, 0–1.
    pub iso_opacity: f32,
    /// Transfer function (preset name or file) when the key names one.
    pub tf: Option<String>,
}

/// What the camera follows.
#[derive(Debug, Clone)]
pub enum Route {
    /// A path, looked along with a look-ahead.
    Path(Path),
    /// Key frames, played at constant speed.
    Keys(Animation),
}

/// Sample step of the spline through a route's given points, mm (frames are taken from it at
/// any spacing).
pub const ROUTE_STEP_MM: f64 = 0.5;

impl Route {
    /// A path through `points_mm` (world mm), passing through each exactly, sampled every
    /// [`ROUTE_STEP_MM`].
    pub fn through_points(points_mm: &[DVec3]) -> Result<Self, PathError> {
        Path::from_points_exact(points_mm, ROUTE_STEP_MM).map(Self::Path)
    }

    /// Key frames, played at constant speed.
    pub fn from_key_frames(keys: Vec<KeyFrame>) -> Result<Self, AnimationError> {
        Animation::new(keys).map(Self::Keys)
    }

    /// `frames` camera poses spread evenly from the start to the end of the route (both
    /// included when `frames` ≥ 2), a path looking `look_ahead_mm` ahead: a benchmark's fixed
    /// number of frames.
    pub fn spread_poses(&self, frames: usize, look_ahead_mm: f64) -> Result<Vec<Pose>, PathError> {
        let step_mm = self.len_mm() / frames.saturating_sub(1).max(1) as f64;
        let shots = self.shots(step_mm, look_ahead_mm)?;
        Ok(shots
            .into_iter()
            .take(frames)
            .map(|shot| shot.pose)
            .collect())
    }

    /// Length of the route, mm of arc (key frames: of playback, see [`Animation`]).
    pub fn len_mm(&self) -> f64 {
        match self {
            Self::Path(path) => path.len_mm(),
            Self::Keys(animation) => animation.len_mm(),
        }
    }

    /// Shots every `step_mm` of arc from the start to the end (both included); a path looks
    /// `look_ahead_mm` ahead.
    pub fn shots(&self, step_mm: f64, look_ahead_mm: f64) -> Result<Vec<Shot>, PathError> {
        let arcs = self.arcs(step_mm)?;
        match self {
            Self::Path(path) => arcs
                .map(|arc_mm| {
                    Ok(Shot {
                        pose: path.pose_at(arc_mm, look_ahead_mm)?,
                        arc_mm,
                        tangent: path_tangent(path, arc_mm),
                        fov_deg: None,
                        look: None,
                    })
                })
                .collect(),
            Self::Keys(animation) => Ok(arcs
                .map(|arc_mm| {
                    let key = animation.sample_at_arc(arc_mm);
                    Shot {
                        pose: key.pose(look_ahead_mm.max(1.0)),
                        arc_mm,
                        tangent: key.forward(),
                        fov_deg: Some(key.fov_deg),
                        look: Some(ShotLook {
                            iso_hu: key.iso_hu,
                            iso_opacity: key.iso_opacity as f32,
                            tf: key.tf,
                        }),
                    }
                })
                .collect()),
        }
    }

    /// The route's points every `step_mm` (for drawing it), world mm.
    pub fn points_mm(&self, step_mm: f64) -> Result<Vec<DVec3>, PathError> {
        let arcs = self.arcs(step_mm)?;
        Ok(match self {
            Self::Path(path) => arcs.map(|s| path.point_at(s)).collect(),
            Self::Keys(animation) => arcs.map(|s| animation.sample_at_arc(s).eye_mm).collect(),
        })
    }

    /// Arc positions every `step_mm` from the start to the end, both included.
    fn arcs(&self, step_mm: f64) -> Result<impl Iterator<Item = f64>, PathError> {
        if !(step_mm.is_finite() && step_mm > 0.0) {
            return Err(PathError::BadOption("step_mm", step_mm));
        }
        let len = self.len_mm();
        // A length a hair over a whole number of steps (rounding) gets no extra last frame.
        let count = (len / step_mm - 1e-6).ceil().max(0.0) as usize + 1;
        if count > MAX_SHOTS {
            return Err(PathError::TooManySamples {
                requested: count,
                limit: MAX_SHOTS,
            });
        }
        Ok((0..count).map(move |n| (n as f64 * step_mm).min(len)))
    }

    /// The same path flown the other way (for the backward pass of coverage); `None` for key
    /// frames, whose views have no natural reverse.
    pub fn reversed(&self, step_mm: f64) -> Option<Result<Route, PathError>> {
        match self {
            Self::Path(path) => {
                let mut points: Vec<DVec3> = path.samples().iter().map(|s| s.position_mm).collect();
                points.reverse();
                Some(Path::from_points_exact(&points, step_mm).map(Route::Path))
            }
            Self::Keys(_) => None,
        }
    }
}

/// The unit direction of `path` at arc `s_mm` (a central difference over half a millimetre,
/// one-sided at the ends).
fn path_tangent(path: &Path, s_mm: f64) -> DVec3 {
    let h = 0.25;
    let a = path.point_at((s_mm - h).max(0.0));
    let b = path.point_at((s_mm + h).min(path.len_mm()));
    (b - a).normalize_or(DVec3::Z)
}

/// At most this many frames in one flight (a step in the wrong unit would ask for millions).
pub const MAX_SHOTS: usize = 200_000;

#[cfg(test)]
mod tests;
