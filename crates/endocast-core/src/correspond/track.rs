//! [`Track`]: a path resampled at a fixed step, with the features the matching compares.

use crate::path::Path;
use glam::DVec3;

/// Arc length between the samples of a track, mm.
pub(super) const STEP_MM: f64 = 2.0;
/// Half the arc length over which a tangent is measured, mm: long enough that the lumen's
/// wobble (a few mm) does not turn it, short enough to keep a flexure's turn.
const TANGENT_HALF_SPAN_MM: f64 = 10.0;

/// A path sampled every [`STEP_MM`] of arc length with its smoothed unit tangents.
#[derive(Debug, Clone)]
pub(super) struct Track {
    /// Sample positions, world mm.
    pub points: Vec<DVec3>,
    /// Unit tangents, the chord over [`TANGENT_HALF_SPAN_MM`] each side.
    pub tangents: Vec<DVec3>,
    /// The path's length, mm.
    pub length_mm: f64,
}

impl Track {
    /// The track of `path`, or of `path` run backwards when `reversed`.
    pub fn new(path: &Path, reversed: bool) -> Self {
        let length_mm = path.len_mm();
        let count = (length_mm / STEP_MM).ceil().max(1.0) as usize;
        let at = |n: usize| {
            let s = (n as f64 * STEP_MM).min(length_mm);
            path.point_at(if reversed { length_mm - s } else { s })
        };
        let points: Vec<DVec3> = (0..=count).map(at).collect();
        let half = (TANGENT_HALF_SPAN_MM / STEP_MM).round() as usize;
        let last = points.len() - 1;
        let tangents = (0..=last)
            .map(|n| {
                let chord = points[(n + half).min(last)] - points[n.saturating_sub(half)];
                chord.normalize_or_zero()
            })
            .collect();
        Self {
            points,
            tangents,
            length_mm,
        }
    }

    /// Arc length of sample `n`, mm.
    pub fn arc_mm(&self, n: usize) -> f64 {
        (n as f64 * STEP_MM).min(self.length_mm)
    }

    /// The point at arc length `s_mm` (clamped to the track), linear between samples.
    pub fn point_at(&self, s_mm: f64) -> DVec3 {
        let (n, t) = self.locate(s_mm);
        let next = self.points.get(n + 1).copied().unwrap_or(self.points[n]);
        self.points[n].lerp(next, t)
    }

    /// The sample before arc length `s_mm` (clamped) and the fraction of the way to the next.
    fn locate(&self, s_mm: f64) -> (usize, f64) {
        let last = self.points.len() - 1;
        let n = ((s_mm / STEP_MM).floor().max(0.0) as usize).min(last.saturating_sub(1));
        let span = self.arc_mm(n + 1) - self.arc_mm(n);
        let t = if span > 0.0 {
            (s_mm - self.arc_mm(n)) / span
        } else {
            0.0
        };
        (n, t.clamp(0.0, 1.0))
    }

    /// The tangent at arc length `s_mm`, interpolated between samples and normalised.
    pub fn tangent_at(&self, s_mm: f64) -> DVec3 {
        let (n, t) = self.locate(s_mm);
        let next = self
            .tangents
            .get(n + 1)
            .copied()
            .unwrap_or(self.tangents[n]);
        self.tangents[n].lerp(next, t).normalize_or_zero()
    }

    /// The arc length of the track point closest to `p` (world mm), and the distance to it.
    pub fn closest(&self, p: DVec3) -> (f64, f64) {
        let mut best = (0.0, f64::INFINITY);
        for (n, pair) in self.points.windows(2).enumerate() {
            let delta = pair[1] - pair[0];
            let len2 = delta.length_squared();
            let t = if len2 > 0.0 {
                ((p - pair[0]).dot(delta) / len2).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = p.distance(pair[0] + delta * t);
            if d < best.1 {
                let s = self.arc_mm(n) + t * (self.arc_mm(n + 1) - self.arc_mm(n));
                best = (s, d);
            }
        }
        best
    }
}
