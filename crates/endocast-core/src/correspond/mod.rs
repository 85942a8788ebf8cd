//! Supine/prone correspondence: the colon's centrelines in two scans of one patient matched, so
//! that a finding in one scan gives its counterpart and a view of it in the other.
//!
//! Each scan's path (the study's automatic colonoscopy path, or any two paths) is sampled every
//! 2 mm with its tangent direction measured over 20 mm. The paths are first paired by arc length
//! normalised between their ends; the patient's turn about the long axis (the world z axis,
//! head–foot in LPS; 180° from supine to prone, 0° when the scanner's frame follows the patient)
//! is the rotation about z that best lines up the paired tangents; then dynamic time warping of
//! the tangent directions, the ends fixed to the ends, re-pairs the samples so that the turns —
//! the flexures, where the direction changes fastest — line up; the turn is fitted again on
//! that pairing and the warp repeated.
//! Paths planned from opposite ends are recognised (both orders are tried, the cheaper kept).
//!
//! A point X in the first scan maps to: the arc length s of the nearest point of the first path,
//! its matched arc s′ on the second, and the point at the same angle around the path and the
//! same distance from it there — the offset from the path turned by the patient's turn and then
//! by the rotation-minimising turn that takes the first path's (turned) tangent onto the
//! second's, as a rotation-minimising frame is carried along a curve. Each scan's view has its
//! eye on its path at s (or s′) looking at the point; the second view's up is the first's turned
//! the same way, so that the two views show the wall in the same orientation.

mod track;
mod views;
mod warp;

use crate::navigate::looking_along;
use crate::path::{Path, SmoothOptions};
use crate::pose::Pose;
use crate::study::{Study, StudyPathError};
use crate::Volume;
use glam::{DQuat, DVec3};
use thiserror::Error;
use track::{Track, STEP_MM};
pub use views::{side_by_side, PairError, Scan};

/// How far from the eye a view along the path looks when the point is on the path, mm.
const LOOK_MM: f64 = 10.0;
/// Samples averaged on each side when the warp's matched arc lengths are smoothed (the warp
/// moves in whole samples of 2 mm).
const SMOOTH_SAMPLES: usize = 2;

/// Why two paths or a point cannot be matched.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum MatchError {
    /// A scan's study planned no path.
    #[error("no path in the {which} scan: {error}")]
    NoPath {
        /// "first" or "second".
        which: &'static str,
        /// Why.
        error: StudyPathError,
    },
    /// A path is too short to match.
    #[error(
        "the {which} path is {length_mm:.1} mm long: too short to match (at least {min_mm} mm)"
    )]
    TooShort {
        /// "first" or "second".
        which: &'static str,
        /// Its length, mm.
        length_mm: f64,
        /// The shortest path matched, mm.
        min_mm: f64,
    },
    /// The finding's coordinates are not finite numbers.
    #[error("the point {0} is not three finite numbers (mm)")]
    BadPoint(String),
}

/// Two paths matched (see the module documentation).
#[derive(Debug, Clone)]
pub struct Correspondence {
    a: Track,
    /// The second path's track, run in the direction matching the first.
    b: Track,
    /// For each sample of `a`, its matched arc length along `b`'s track, mm.
    matched_mm: Vec<f64>,
    /// The patient's turn about the long axis from the first scan to the second.
    turn: DQuat,
    /// Whether the second path runs the other way.
    reversed: bool,
    /// Mean squared tangent difference of the warp's pairs (0: identical; at most 4).
    cost: f64,
}

/// Where a point of the first scan is in the second, and the views of it in both.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Counterpart {
    /// Arc length of the first path's point nearest the finding, mm from its start.
    pub arc_first_mm: f64,
    /// The finding's distance from the first path, mm.
    pub distance_mm: f64,
    /// The matched arc length along the second path, mm from its start.
    pub arc_mm: f64,
    /// The counterpart in the second scan, world mm (LPS).
    pub point_mm: DVec3,
    /// The first scan's view: on its path at `arc_first_mm`, looking at the finding.
    pub view_first: Pose,
    /// The second scan's view: on its path at `arc_mm`, looking at the counterpart.
    pub view: Pose,
}

impl Correspondence {
    /// The shortest path matched, mm: five samples.
    pub const MIN_LENGTH_MM: f64 = 5.0 * STEP_MM;

    /// The two scans' paths from end to end of their studies' structures, matched: each
    /// study's automatic path (as `endocast path` plans it, with the default smoothing) runs
    /// from the structure's widest point to its farthest end, so the path is planned again
    /// from that end to the farthest point from it, the other end.
    pub fn of_studies(
        (volume_a, study_a): (&Volume, &Study),
        (volume_b, study_b): (&Volume, &Study),
    ) -> Result<Self, MatchError> {
        let a = end_to_end(volume_a, study_a).map_err(|error| MatchError::NoPath {
            which: "first",
            error,
        })?;
        let b = end_to_end(volume_b, study_b).map_err(|error| MatchError::NoPath {
            which: "second",
            error,
        })?;
        Self::between(&a, &b)
    }

    /// Matches path `a` (first scan) with path `b` (second scan), both in world mm.
    pub fn between(a: &Path, b: &Path) -> Result<Self, MatchError> {
        for (which, path) in [("first", a), ("second", b)] {
            if path.len_mm().is_nan() || path.len_mm() < Self::MIN_LENGTH_MM {
                return Err(MatchError::TooShort {
                    which,
                    length_mm: path.len_mm(),
                    min_mm: Self::MIN_LENGTH_MM,
                });
            }
        }
        let a_track = Track::new(a, false);
        let fit = |reversed| Self::fit(a_track.clone(), Track::new(b, reversed), reversed);
        let (forward, backward) = (fit(false), fit(true));
        Ok(if backward.cost < forward.cost {
            backward
        } else {
            forward
        })
    }

    /// The match of `a` with `b` (already run the matching way): pairs by normalised arc
    /// length, fits the turn, warps, fits the turn again and warps again.
    fn fit(a: Track, b: Track, reversed: bool) -> Self {
        let ratio = b.length_mm / a.length_mm;
        let proportional: Vec<f64> = (0..a.points.len()).map(|n| a.arc_mm(n) * ratio).collect();
        let (first, _) = warp::warp(&a, &b, fit_turn(&a, &b, &proportional));
        let (matched, cost) = warp::warp(&a, &b, fit_turn(&a, &b, &first));
        let turn = fit_turn(&a, &b, &matched);
        Self {
            matched_mm: smooth(&matched),
            a,
            b,
            turn,
            reversed,
            cost,
        }
    }

    /// The patient's turn about the long axis from the first scan to the second, degrees in
    /// (−180, 180] (about 180 between supine and prone in the scanner's frame).
    pub fn turn_deg(&self) -> f64 {
        let (axis, angle) = self.turn.to_axis_angle();
        let signed = if axis.z < 0.0 { -angle } else { angle };
        let deg = signed.to_degrees();
        if deg <= -180.0 {
            deg + 360.0
        } else {
            deg
        }
    }

    /// Whether the second path runs from the end where the first one ends.
    pub fn reversed(&self) -> bool {
        self.reversed
    }

    /// How well the paths' directions agree after matching: the mean squared difference of the
    /// paired unit tangents (0 for identical paths; about 0.1 for the phantom pair).
    pub fn cost(&self) -> f64 {
        self.cost
    }

    /// The lengths of the first and second paths, mm.
    pub fn lengths_mm(&self) -> (f64, f64) {
        (self.a.length_mm, self.b.length_mm)
    }

    /// The arc length along the second path (from its own start) matched with arc length
    /// `s_mm` along the first.
    pub fn arc_in_second(&self, s_mm: f64) -> f64 {
        self.own_arc(self.track_arc_in_second(s_mm))
    }

    /// The counterpart in the second scan of the point `x_mm` (world mm) of the first.
    pub fn counterpart(&self, x_mm: DVec3) -> Result<Counterpart, MatchError> {
        if !x_mm.is_finite() {
            return Err(MatchError::BadPoint(format!(
                "{},{},{}",
                x_mm.x, x_mm.y, x_mm.z
            )));
        }
        let local = self.local(x_mm);
        let point_mm = local.carry(x_mm);
        let view_first = view(local.centre_a, x_mm, local.tangent_a, None);
        let up = local.rotation * view_first.up;
        Ok(Counterpart {
            arc_first_mm: local.s_a,
            distance_mm: local.distance_mm,
            arc_mm: self.own_arc(local.s_b),
            point_mm,
            view_first,
            view: view(local.centre_b, point_mm, local.tangent_b, Some(up)),
        })
    }

    /// A camera of the first scan carried to the second (the side-by-side views): its eye to
    /// the eye's counterpart, its view and up directions turned as the wall around the eye is
    /// turned (the patient's turn, then the paths' rotation-minimising turn at the matched arc
    /// length), so that the second view shows the counterpart of what the first shows, the
    /// same way up, at the same distance.
    pub fn follow(&self, pose: &Pose) -> Result<Pose, MatchError> {
        let finite = pose.eye_mm.is_finite() && pose.look_at_mm.is_finite() && pose.up.is_finite();
        if !finite {
            let e = pose.eye_mm;
            return Err(MatchError::BadPoint(format!("{},{},{}", e.x, e.y, e.z)));
        }
        let local = self.local(pose.eye_mm);
        let eye_mm = local.carry(pose.eye_mm);
        Ok(Pose {
            eye_mm,
            look_at_mm: eye_mm + local.rotation * (pose.look_at_mm - pose.eye_mm),
            up: local.rotation * pose.up,
        })
    }

    /// The stretch of both paths nearest `x_mm` (world mm, first scan) and the turn between.
    fn local(&self, x_mm: DVec3) -> Local {
        let (s_a, distance_mm) = self.a.closest(x_mm);
        let (centre_a, tangent_a) = (self.a.point_at(s_a), self.a.tangent_at(s_a));
        let s_b = self.track_arc_in_second(s_a);
        let (centre_b, tangent_b) = (self.b.point_at(s_b), self.b.tangent_at(s_b));
        let rotation = DQuat::from_rotation_arc(self.turn * tangent_a, tangent_b) * self.turn;
        Local {
            s_a,
            distance_mm,
            centre_a,
            tangent_a,
            s_b,
            centre_b,
            tangent_b,
            rotation,
        }
    }

    /// The matched arc length along the second path's track (as run for the match).
    fn track_arc_in_second(&self, s_mm: f64) -> f64 {
        let x = (s_mm / STEP_MM).clamp(0.0, (self.matched_mm.len() - 1) as f64);
        let n = (x.floor() as usize).min(self.matched_mm.len() - 2);
        let t = x - n as f64;
        self.matched_mm[n] + t * (self.matched_mm[n + 1] - self.matched_mm[n])
    }

    /// A track arc length of the second path as an arc length from its own start.
    fn own_arc(&self, s_mm: f64) -> f64 {
        if self.reversed {
            self.b.length_mm - s_mm
        } else {
            s_mm
        }
    }
}

/// Where a point of the first scan lies along the two paths: the nearest point of the first
/// path, its match on the second (track arc lengths), and the turn from one to the other.
struct Local {
    s_a: f64,
    distance_mm: f64,
    centre_a: DVec3,
    tangent_a: DVec3,
    s_b: f64,
    centre_b: DVec3,
    tangent_b: DVec3,
    rotation: DQuat,
}

impl Local {
    /// The counterpart of `x_mm` (first scan): the same offset from the path, turned.
    fn carry(&self, x_mm: DVec3) -> DVec3 {
        self.centre_b + self.rotation * (x_mm - self.centre_a)
    }
}

/// The path through `study`'s structure from one end to the other (see
/// [`Correspondence::of_studies`]).
pub fn end_to_end(volume: &Volume, study: &Study) -> Result<Path, StudyPathError> {
    let options = SmoothOptions::default();
    let half = study.plan(volume, None, None, &options)?.planned.path;
    let end = half.point_at(half.len_mm());
    Ok(study.plan(volume, Some(end), None, &options)?.planned.path)
}

/// The turn about the world z axis that best takes `a`'s tangents onto `b`'s at the arc lengths
/// `matched` (least squares over the tangents' components across z).
fn fit_turn(a: &Track, b: &Track, matched: &[f64]) -> DQuat {
    let (mut sin, mut cos) = (0.0, 0.0);
    for (&ta, &s) in a.tangents.iter().zip(matched) {
        let tb = b.tangent_at(s);
        sin += ta.x * tb.y - ta.y * tb.x;
        cos += ta.x * tb.x + ta.y * tb.y;
    }
    DQuat::from_rotation_z(sin.atan2(cos))
}

/// `values` averaged over [`SMOOTH_SAMPLES`] on each side (fewer at the ends, which stay put).
fn smooth(values: &[f64]) -> Vec<f64> {
    let last = values.len() - 1;
    (0..=last)
        .map(|n| {
            let half = SMOOTH_SAMPLES.min(n).min(last - n);
            let window = &values[n - half..=n + half];
            window.iter().sum::<f64>() / window.len() as f64
        })
        .collect()
}

/// The view from `eye` (on the path) of `target`: looking at it, or along `tangent` when it is
/// on the path; up as near `up` as the view allows, else as near the patient's front.
fn view(eye: DVec3, target: DVec3, tangent: DVec3, up: Option<DVec3>) -> Pose {
    let towards = target - eye;
    let (forward, distance) = match towards.try_normalize() {
        Some(forward) if towards.length() >= 1.0 => (forward, towards.length()),
        _ => (tangent, LOOK_MM),
    };
    let mut pose = looking_along(eye, forward, distance);
    if let Some(up) = up.and_then(|u| (u - forward * u.dot(forward)).try_normalize()) {
        pose.up = up;
    }
    pose
}

#[cfg(test)]
mod tests;
