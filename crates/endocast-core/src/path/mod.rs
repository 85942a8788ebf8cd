//! Smooth camera paths in world millimetres (LPS): from the staircase of voxel centres a
//! centreline search returns, to a centripetal Catmull-Rom curve resampled at a constant step
//! with rotation-minimising camera frames and look-ahead poses.
//!
//! ```
//! use endocast_core::path::{Path, SmoothOptions};
//! use glam::DVec3;
//!
//! // A staircase of voxel centres along a diagonal, 1 mm voxels.
//! let raw: Vec<DVec3> = (0..40)
//!     .map(|i| DVec3::new(((i + 1) / 2) as f64, (i / 2) as f64, 0.0))
//!     .collect();
//! let path = Path::smooth(&raw, &SmoothOptions::default())?;
//! let pose = path.pose_at(path.len_mm() / 2.0, 5.0)?;
//! assert!((pose.look_at_mm - pose.eye_mm).normalize().dot(DVec3::new(1.0, 1.0, 0.0).normalize()) > 0.99);
//! # Ok::<(), endocast_core::path::PathError>(())
//! ```

mod frames;
pub mod spline;
#[cfg(test)]
mod tests;

use crate::pose::Pose;
use glam::DVec3;
use spline::{ArcTable, CatmullRom};
use thiserror::Error;

/// Table pieces per output step: linear interpolation of the spline parameter inside a piece
/// one eighth of a step long misplaces a sample by far less than 1 % of the step.
const PIECES_PER_STEP: f64 = 8.0;
/// Consecutive input points closer than this (mm) are one point.
const DUPLICATE_MM: f64 = 1e-9;

/// A path that cannot be built or sampled.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PathError {
    /// Fewer than two distinct points.
    #[error("a path needs at least two distinct points, found {0}")]
    TooFewPoints(usize),
    /// A point has a NaN or infinite coordinate.
    #[error("path point {index} {point:?} is not finite")]
    NotFinite {
        /// Index of the point in the input.
        index: usize,
        /// Its coordinates, mm.
        point: [f64; 3],
    },
    /// An option or argument is out of its range.
    #[error("{0} must be finite and positive (not negative for look-ahead and arc positions), found {1}")]
    BadOption(&'static str, f64),
    /// The path would need more samples than the limit (usually a step in the wrong unit).
    #[error("the path needs {requested} samples, more than the limit of {limit}")]
    TooManySamples {
        /// Samples needed.
        requested: usize,
        /// The limit.
        limit: usize,
    },
    /// The path's length overflows f64 (points near f64's limits, e.g. 1e308 mm).
    #[error("the path is too long to measure: are its points in millimetres?")]
    TooLong,
    /// [`Path::smooth_until`] found no smoothing the caller accepted, down to passing through
    /// every raw point.
    #[error("no smoothing of the path was accepted, down to a control point at every raw point")]
    NotAccepted,
}

/// How [`Path::smooth`] turns raw points into a path. Defaults suit a centreline through
/// voxels of about 0.5–1 mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SmoothOptions {
    /// Raw points averaged on each side of a point before control points are chosen, which
    /// flattens the voxel staircase (the ends keep their position). Default 2.
    pub average_radius: usize,
    /// Arc length between control points of the spline, mm. Larger is smoother but may cut
    /// corners; [`Path::smooth_until`] halves it until the caller accepts the path. Default 5.
    pub control_spacing_mm: f64,
    /// Arc length between consecutive samples, mm. Default 0.5.
    pub step_mm: f64,
    /// Up direction wanted at the start (made perpendicular to the path); `None` takes the world
    /// axis least aligned with the start of the path. Default `None`.
    pub initial_up: Option<DVec3>,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        Self {
            average_radius: 2,
            control_spacing_mm: 5.0,
            step_mm: 0.5,
            initial_up: None,
        }
    }
}

/// One sample of a path: where the camera is, the unit tangent and the unit up vector of its
/// rotation-minimising frame (perpendicular to the tangent).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathSample {
    /// Position, world mm.
    pub position_mm: DVec3,
    /// Unit tangent, in the direction of travel.
    pub tangent: DVec3,
    /// Unit up vector, perpendicular to the tangent; it never flips or twists needlessly.
    pub up: DVec3,
    /// Arc length from the start of the path, mm.
    pub arc_mm: f64,
}

/// A smooth camera path: a centripetal Catmull-Rom spline with its arc length tabulated and
/// samples with rotation-minimising frames every [`SmoothOptions::step_mm`] of arc length (the
/// last step is shorter unless the length is a multiple of the step).
#[derive(Debug, Clone, PartialEq)]
pub struct Path {
    /// The points the path was made from, duplicates removed (kept for re-smoothing).
    raw_mm: Vec<DVec3>,
    options: SmoothOptions,
    spline: CatmullRom,
    table: ArcTable,
    samples: Vec<PathSample>,
}

impl Path {
    /// Smooths a raw polyline (world mm, e.g. voxel centres of a centreline): a moving average
    /// over `average_radius` points each side, control points every `control_spacing_mm` of
    /// its arc length (and at both ends), a centripetal Catmull-Rom spline through them.
    pub fn smooth(raw_points_mm: &[DVec3], options: &SmoothOptions) -> Result<Self, PathError> {
        check_options(options)?;
        let raw = distinct_points(raw_points_mm)?;
        let averaged = moving_average(&raw, options.average_radius);
        let control = resample_polyline(&averaged, options.control_spacing_mm);
        Self::build(raw, options, control)
    }

    /// A path through exactly `points_mm` (e.g. read from a file), sampled every `step_mm`;
    /// repeated consecutive points count once.
    pub fn from_points_exact(points_mm: &[DVec3], step_mm: f64) -> Result<Self, PathError> {
        let options = SmoothOptions {
            average_radius: 0,
            step_mm,
            ..SmoothOptions::default()
        };
        check_options(&options)?;
        let raw = distinct_points(points_mm)?;
        Self::build(raw.clone(), &options, raw)
    }

    /// The same raw points smoothed again with control points every `control_spacing_mm`
    /// (e.g. finer, when the caller found the smoother path leaving the lumen).
    pub fn resmoothed(&self, control_spacing_mm: f64) -> Result<Self, PathError> {
        let options = SmoothOptions {
            control_spacing_mm,
            ..self.options
        };
        Self::smooth(&self.raw_mm, &options)
    }

    /// [`Path::smooth`], then again with the control spacing halved while `accept` refuses the
    /// path (e.g. because a sample leaves the lumen), down to about the raw point spacing; as a
    /// last resort the spline through every raw point, unaveraged. [`PathError::NotAccepted`]
    /// when even that is refused.
    pub fn smooth_until(
        raw_points_mm: &[DVec3],
        options: &SmoothOptions,
        mut accept: impl FnMut(&Path) -> bool,
    ) -> Result<Self, PathError> {
        let mut path = Self::smooth(raw_points_mm, options)?;
        let finest_mm = mean_spacing_mm(&path.raw_mm);
        while !accept(&path) {
            let spacing = path.options.control_spacing_mm / 2.0;
            if spacing < finest_mm {
                let exact = Self::build(path.raw_mm.clone(), options, path.raw_mm.clone())?;
                return if accept(&exact) {
                    Ok(exact)
                } else {
                    Err(PathError::NotAccepted)
                };
            }
            path = path.resmoothed(spacing)?;
        }
        Ok(path)
    }

    /// The spline, its arc table and its framed samples.
    fn build(
        raw_mm: Vec<DVec3>,
        options: &SmoothOptions,
        control: Vec<DVec3>,
    ) -> Result<Self, PathError> {
        let spline = CatmullRom::new(control)?;
        let table = ArcTable::new(&spline, options.step_mm / PIECES_PER_STEP)?;
        let samples = framed_samples(&spline, &table, options)?;
        Ok(Self {
            raw_mm,
            options: *options,
            spline,
            table,
            samples,
        })
    }

    /// Total arc length, mm.
    pub fn len_mm(&self) -> f64 {
        self.table.len_mm()
    }

    /// The spline's control points (the path passes through each), mm.
    pub fn control_points(&self) -> &[DVec3] {
        self.spline.points()
    }

    /// The options the path was built with.
    pub fn options(&self) -> &SmoothOptions {
        &self.options
    }

    /// Samples every `step_mm` of arc length from the start, and one at the end.
    pub fn samples(&self) -> &[PathSample] {
        &self.samples
    }

    /// The sample (every [`SmoothOptions::step_mm`] of arc length) nearest `p_mm`, and its
    /// distance from `p_mm`, mm: where along the path a camera off it stands.
    pub fn nearest_sample(&self, p_mm: DVec3) -> (&PathSample, f64) {
        self.samples
            .iter()
            .map(|sample| (sample, sample.position_mm.distance(p_mm)))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or_else(|| unreachable!("a path has at least two samples"))
    }

    /// Position at arc length `s_mm` (clamped to the path), mm.
    pub fn point_at(&self, s_mm: f64) -> DVec3 {
        self.spline.point(self.table.parameter_at(s_mm))
    }

    /// Points every `step_mm` of arc length from the start, and the last point (what
    /// `endocast path` writes). Fails when the step is not a positive number or would give
    /// more points than a path's table holds.
    pub fn points_every(&self, step_mm: f64) -> Result<Vec<DVec3>, PathError> {
        if !(step_mm.is_finite() && step_mm > 0.0) {
            return Err(PathError::BadOption("step_mm", step_mm));
        }
        let count = (self.len_mm() / step_mm).ceil();
        if count >= spline::MAX_TABLE_ENTRIES as f64 {
            return Err(PathError::TooManySamples {
                requested: usize::MAX,
                limit: spline::MAX_TABLE_ENTRIES,
            });
        }
        let mut points: Vec<DVec3> = (0..count as usize)
            .map(|n| self.point_at(n as f64 * step_mm))
            .collect();
        points.push(self.point_at(self.len_mm()));
        Ok(points)
    }

    /// The camera pose at arc length `s_mm` (0 to [`Path::len_mm`]; beyond is clamped): the eye
    /// on the path, looking at the path point `look_ahead_mm` further on (clamped at the end;
    /// along the tangent where that leaves no distance), with the up vector of the
    /// rotation-minimising frame made perpendicular to the view.
    pub fn pose_at(&self, s_mm: f64, look_ahead_mm: f64) -> Result<Pose, PathError> {
        if !s_mm.is_finite() {
            return Err(PathError::BadOption("arc position s_mm", s_mm));
        }
        if !(look_ahead_mm >= 0.0 && look_ahead_mm.is_finite()) {
            return Err(PathError::BadOption("look_ahead_mm", look_ahead_mm));
        }
        let s = s_mm.clamp(0.0, self.len_mm());
        let frame = self.frame_at(s);
        let eye_mm = self.point_at(s);
        let ahead = self.point_at(s + look_ahead_mm) - eye_mm;
        let forward = ahead.try_normalize().unwrap_or(frame.tangent);
        let right = frame.tangent.cross(frame.up);
        let up = (frame.up - forward * frame.up.dot(forward))
            .try_normalize()
            // The path turns by 90° within the look-ahead, towards the up vector: use the
            // frame's right-hand side to keep the image upright.
            .unwrap_or_else(|| right.cross(forward).normalize());
        let look_at_mm = if ahead.length() > DUPLICATE_MM {
            eye_mm + ahead
        } else {
            eye_mm + forward
        };
        Ok(Pose {
            eye_mm,
            look_at_mm,
            up,
        })
    }

    /// Poses every `step_mm` of arc length from the start to the end (inclusive), each looking
    /// `look_ahead_mm` ahead as in [`Path::pose_at`]; computed lazily.
    pub fn poses(
        &self,
        step_mm: f64,
        look_ahead_mm: f64,
    ) -> Result<impl Iterator<Item = Pose> + '_, PathError> {
        if !(step_mm > 0.0 && step_mm.is_finite()) {
            return Err(PathError::BadOption("step_mm", step_mm));
        }
        self.pose_at(0.0, look_ahead_mm)?;
        let count = sample_count(self.len_mm(), step_mm)?;
        Ok((0..count).filter_map(move |k| {
            let s = (k as f64 * step_mm).min(self.len_mm());
            self.pose_at(s, look_ahead_mm).ok()
        }))
    }

    /// Tangent and up at arc `s` (within the path), interpolated between the two samples around
    /// it: consecutive frames differ by a small rotation, so a normalised blend is accurate.
    pub fn frame_at(&self, s: f64) -> PathSample {
        let step = self.options.step_mm;
        let k = ((s / step).floor() as usize).min(self.samples.len() - 1);
        let a = self.samples[k];
        let Some(b) = self.samples.get(k + 1) else {
            return a;
        };
        let f = ((s - a.arc_mm) / (b.arc_mm - a.arc_mm)).clamp(0.0, 1.0);
        let tangent = a
            .tangent
            .lerp(b.tangent, f)
            .try_normalize()
            .unwrap_or(a.tangent);
        let up = a.up.lerp(b.up, f);
        let up = (up - tangent * up.dot(tangent))
            .try_normalize()
            .unwrap_or(a.up);
        PathSample {
            position_mm: self.point_at(s),
            tangent,
            up,
            arc_mm: s,
        }
    }
}

/// Rejects non-finite or non-positive spacings and steps.
fn check_options(options: &SmoothOptions) -> Result<(), PathError> {
    for (name, v) in [
        ("control_spacing_mm", options.control_spacing_mm),
        ("step_mm", options.step_mm),
    ] {
        if !(v > 0.0 && v.is_finite()) {
            return Err(PathError::BadOption(name, v));
        }
    }
    if let Some(up) = options.initial_up.filter(|u| !u.is_finite()) {
        return Err(PathError::NotFinite {
            index: 0,
            point: up.to_array(),
        });
    }
    Ok(())
}

/// The points without repeated consecutive ones; errors for non-finite points or fewer than two
/// distinct ones.
fn distinct_points(points: &[DVec3]) -> Result<Vec<DVec3>, PathError> {
    if let Some(index) = points.iter().position(|p| !p.is_finite()) {
        return Err(PathError::NotFinite {
            index,
            point: points[index].to_array(),
        });
    }
    let mut distinct: Vec<DVec3> = Vec::with_capacity(points.len());
    for &p in points {
        if distinct.last().is_none_or(|q| q.distance(p) > DUPLICATE_MM) {
            distinct.push(p);
        }
    }
    if distinct.len() < 2 {
        return Err(PathError::TooFewPoints(distinct.len()));
    }
    Ok(distinct)
}

/// Each point replaced by the mean of itself and up to `radius` neighbours on each side, the
/// window shrunk symmetrically near the ends so that the end points stay and a straight run of
/// evenly spaced points stays where it is.
fn moving_average(points: &[DVec3], radius: usize) -> Vec<DVec3> {
    let n = points.len();
    (0..n)
        .map(|i| {
            let r = radius.min(i).min(n - 1 - i);
            let window = &points[i - r..=i + r];
            window.iter().sum::<DVec3>() / window.len() as f64
        })
        .collect()
}

/// Points every `spacing_mm` of arc length along a polyline, its first and last point included;
/// a last interval shorter than half the spacing is merged into the one before.
fn resample_polyline(points: &[DVec3], spacing_mm: f64) -> Vec<DVec3> {
    let mut out = vec![points[0]];
    let mut next_mm = spacing_mm;
    let mut travelled_mm = 0.0;
    for pair in points.windows(2) {
        let length = pair[0].distance(pair[1]);
        while length > 0.0 && travelled_mm + length >= next_mm {
            out.push(pair[0].lerp(pair[1], (next_mm - travelled_mm) / length));
            next_mm += spacing_mm;
        }
        travelled_mm += length;
    }
    let last = points[points.len() - 1];
    if out.len() > 1 && out[out.len() - 1].distance(last) < spacing_mm / 2.0 {
        out.pop();
    }
    out.push(last);
    out
}

/// Mean distance between consecutive points, mm.
fn mean_spacing_mm(points: &[DVec3]) -> f64 {
    let total: f64 = points.windows(2).map(|p| p[0].distance(p[1])).sum();
    total / (points.len() - 1).max(1) as f64
}

/// Samples at 0, step, 2·step, … and at the end: how many, or an error past the table limit.
fn sample_count(len_mm: f64, step_mm: f64) -> Result<usize, PathError> {
    let limit = spline::MAX_TABLE_ENTRIES;
    let whole = (len_mm / step_mm).floor();
    if whole >= limit as f64 {
        return Err(PathError::TooManySamples {
            requested: usize::MAX,
            limit,
        });
    }
    let whole = whole as usize;
    let ends_on_step = len_mm - whole as f64 * step_mm <= step_mm * 1e-9;
    Ok(whole + if ends_on_step { 1 } else { 2 })
}

/// Samples every `options.step_mm` with unit tangents and rotation-minimising up vectors.
fn framed_samples(
    spline: &CatmullRom,
    table: &ArcTable,
    options: &SmoothOptions,
) -> Result<Vec<PathSample>, PathError> {
    let len = table.len_mm();
    let count = sample_count(len, options.step_mm)?;
    let arcs: Vec<f64> = (0..count)
        .map(|k| (k as f64 * options.step_mm).min(len))
        .collect();
    let params: Vec<f64> = arcs.iter().map(|&s| table.parameter_at(s)).collect();
    let positions: Vec<DVec3> = params.iter().map(|&u| spline.point(u)).collect();
    let tangents: Vec<DVec3> = (0..count)
        .map(|k| {
            // The derivative vanishes only on a still segment; the chord to a neighbour serves.
            let chord = positions[(k + 1).min(count - 1)] - positions[k.saturating_sub(1)];
            spline
                .derivative(params[k])
                .try_normalize()
                .or_else(|| chord.try_normalize())
                .unwrap_or(DVec3::X)
        })
        .collect();
    let first_up = frames::initial_up(tangents[0], options.initial_up);
    let ups = frames::rotation_minimising(&positions, &tangents, first_up);
    Ok((0..count)
        .map(|k| PathSample {
            position_mm: positions[k],
            tangent: tangents[k],
            up: ups[k],
            arc_mm: arcs[k],
        })
        .collect())
}
