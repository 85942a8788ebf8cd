//! Centripetal Catmull-Rom splines (α = ½) through points in world mm, and a table that maps
//! arc length to the spline parameter.
//!
//! The centripetal knot spacing (the square root of the chord length) is the one variant of
//! Catmull-Rom that never forms a cusp or a self-intersection inside a segment and stays close
//! to its control polygon (Yuksel, Schaefer & Keyser 2011): a camera path built on it does not
//! overshoot into the wall of a narrow lumen. Each segment is written in Hermite form with the
//! tangents of the non-uniform Catmull-Rom scheme (the same curve as the Barry–Goldman pyramid),
//! which makes the degenerate cases explicit: at the ends, or next to a repeated point, a tangent
//! falls back to the segment's chord, and a segment between two equal points stays put.

use super::PathError;
use glam::DVec3;

/// Chords shorter than this (mm) count as repeated points.
const TINY_MM: f64 = 1e-9;
/// Most arc-length table entries one spline may need (16 bytes each): a 2 m path tabulated every
/// 0.01 mm stays below it; a request far beyond it is a unit mistake, not a path.
pub const MAX_TABLE_ENTRIES: usize = 20_000_000;

/// A centripetal Catmull-Rom spline through two or more points. The parameter `u` runs from 0
/// at the first point to `points − 1` at the last, passing point `i` at `u = i`.
#[derive(Debug, Clone, PartialEq)]
pub struct CatmullRom {
    points: Vec<DVec3>,
    /// Hermite tangents (start, end) of each segment, per unit of `u`.
    tangents: Vec<[DVec3; 2]>,
}

impl CatmullRom {
    /// The spline through `points` (world mm), which must be at least two and finite; repeated
    /// consecutive points give a segment of zero length.
    pub fn new(points: Vec<DVec3>) -> Result<Self, PathError> {
        check_points(&points)?;
        let tangents = (0..points.len() - 1)
            .map(|i| {
                let p = |j: Option<usize>| j.and_then(|j| points.get(j).copied());
                let (p1, p2) = (points[i], points[i + 1]);
                let start = tangent(p(i.checked_sub(1)), p1, p2);
                // The end tangent is the start tangent of the reversed segment, reversed.
                let end = -tangent(p(Some(i + 2)), p2, p1);
                [start, end]
            })
            .collect();
        Ok(Self { points, tangents })
    }

    /// The points the spline passes through, mm.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// Number of segments (points − 1).
    pub fn segments(&self) -> usize {
        self.tangents.len()
    }

    /// Position at parameter `u` (clamped to `[0, segments]`), mm.
    pub fn point(&self, u: f64) -> DVec3 {
        let (i, t) = self.split(u);
        let [m1, m2] = self.tangents[i];
        let (p1, p2) = (self.points[i], self.points[i + 1]);
        let (t2, t3) = (t * t, t * t * t);
        p1 * (2.0 * t3 - 3.0 * t2 + 1.0)
            + m1 * (t3 - 2.0 * t2 + t)
            + p2 * (-2.0 * t3 + 3.0 * t2)
            + m2 * (t3 - t2)
    }

    /// Derivative of the position with respect to `u` (mm per unit of `u`).
    pub fn derivative(&self, u: f64) -> DVec3 {
        let (i, t) = self.split(u);
        let [m1, m2] = self.tangents[i];
        let (p1, p2) = (self.points[i], self.points[i + 1]);
        let t2 = t * t;
        p1 * (6.0 * t2 - 6.0 * t)
            + m1 * (3.0 * t2 - 4.0 * t + 1.0)
            + p2 * (-6.0 * t2 + 6.0 * t)
            + m2 * (3.0 * t2 - 2.0 * t)
    }

    /// Segment index and local parameter in [0, 1] of `u`.
    fn split(&self, u: f64) -> (usize, f64) {
        let last = self.segments() - 1;
        let u = u.clamp(0.0, self.segments() as f64);
        let i = (u.floor() as usize).min(last);
        (i, u - i as f64)
    }

    /// Upper bound of each segment's length: the length of its Bézier control polygon, mm.
    fn segment_bound_mm(&self, i: usize) -> f64 {
        let [m1, m2] = self.tangents[i];
        let (p1, p2) = (self.points[i], self.points[i + 1]);
        let (c1, c2) = (p1 + m1 / 3.0, p2 - m2 / 3.0);
        p1.distance(c1) + c1.distance(c2) + c2.distance(p2)
    }
}

/// Rejects fewer than two points and non-finite coordinates.
fn check_points(points: &[DVec3]) -> Result<(), PathError> {
    if points.len() < 2 {
        return Err(PathError::TooFewPoints(points.len()));
    }
    match points.iter().position(|p| !p.is_finite()) {
        Some(index) => Err(PathError::NotFinite {
            index,
            point: points[index].to_array(),
        }),
        None => Ok(()),
    }
}

/// Hermite tangent at `p1` of the segment `p1 → p2` (per unit of segment parameter), given the
/// previous point `p0` if any: the non-uniform Catmull-Rom tangent with knot intervals
/// `|chord|^½`, or the chord itself where `p0` is missing or repeats `p1`.
fn tangent(p0: Option<DVec3>, p1: DVec3, p2: DVec3) -> DVec3 {
    let d1 = p1.distance(p2).sqrt();
    if d1 < TINY_MM {
        return DVec3::ZERO;
    }
    match p0 {
        Some(p0) if p0.distance(p1) >= TINY_MM => {
            let d0 = p0.distance(p1).sqrt();
            d1 * ((p1 - p0) / d0 - (p2 - p0) / (d0 + d1) + (p2 - p1) / d1)
        }
        _ => p2 - p1,
    }
}

/// Arc length along a spline, tabulated finely enough that linear interpolation of the
/// parameter between entries places a point within a small fraction of `max_piece_mm`.
#[derive(Debug, Clone, PartialEq)]
pub struct ArcTable {
    /// (parameter u, arc length from the start in mm), increasing in both.
    entries: Vec<(f64, f64)>,
    /// Index in `entries` of the start of each segment, plus one for the end.
    segment_starts: Vec<usize>,
}

impl ArcTable {
    /// Tabulates `spline` in pieces no longer than `max_piece_mm` (finite, > 0).
    pub fn new(spline: &CatmullRom, max_piece_mm: f64) -> Result<Self, PathError> {
        if !(max_piece_mm > 0.0 && max_piece_mm.is_finite()) {
            return Err(PathError::BadOption("step_mm", max_piece_mm));
        }
        let pieces: Vec<usize> = (0..spline.segments())
            .map(|i| (spline.segment_bound_mm(i) / max_piece_mm).ceil().max(1.0) as usize)
            .collect();
        let total = pieces.iter().fold(1usize, |a, &n| a.saturating_add(n));
        if total > MAX_TABLE_ENTRIES {
            return Err(PathError::TooManySamples {
                requested: total,
                limit: MAX_TABLE_ENTRIES,
            });
        }
        let mut entries = Vec::with_capacity(total);
        let mut segment_starts = Vec::with_capacity(pieces.len() + 1);
        let mut previous = spline.point(0.0);
        let mut arc_mm = 0.0;
        entries.push((0.0, 0.0));
        for (i, &n) in pieces.iter().enumerate() {
            segment_starts.push(entries.len() - 1);
            for k in 1..=n {
                let u = i as f64 + k as f64 / n as f64;
                let p = spline.point(u);
                arc_mm += p.distance(previous);
                previous = p;
                entries.push((u, arc_mm));
            }
        }
        segment_starts.push(entries.len() - 1);
        if !arc_mm.is_finite() {
            return Err(PathError::TooLong);
        }
        Ok(Self {
            entries,
            segment_starts,
        })
    }

    /// Total arc length, mm.
    pub fn len_mm(&self) -> f64 {
        self.entries.last().map_or(0.0, |e| e.1)
    }

    /// Arc length from the start to spline point `i` (the start of segment `i`), mm.
    pub fn arc_at_point_mm(&self, i: usize) -> f64 {
        let last = self.segment_starts.len() - 1;
        self.entries[self.segment_starts[i.min(last)]].1
    }

    /// The parameter `u` at arc length `s_mm` (clamped to `[0, len_mm]`).
    pub fn parameter_at(&self, s_mm: f64) -> f64 {
        let s = s_mm.clamp(0.0, self.len_mm());
        let j = self.entries.partition_point(|e| e.1 < s);
        if j == 0 {
            return self.entries[0].0;
        }
        let Some(&(u1, s1)) = self.entries.get(j) else {
            return self.entries[j - 1].0;
        };
        let (u0, s0) = self.entries[j - 1];
        if s1 > s0 {
            u0 + (u1 - u0) * (s - s0) / (s1 - s0)
        } else {
            u0
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passes_through_its_points_and_stays_straight_on_a_line() {
        let points: Vec<DVec3> = [0.0, 1.0, 5.0, 5.5, 9.0]
            .iter()
            .map(|&x| DVec3::new(x, 2.0 * x, -x))
            .collect();
        let spline = CatmullRom::new(points.clone()).unwrap();
        for (i, p) in points.iter().enumerate() {
            assert!(spline.point(i as f64).distance(*p) < 1e-12);
        }
        // Collinear points with uneven spacing: the curve stays on the line and moves forward.
        let dir = DVec3::new(1.0, 2.0, -1.0).normalize();
        let mut previous = -1.0;
        for k in 0..=400 {
            let p = spline.point(f64::from(k) / 100.0);
            assert!(p.cross(dir).length() < 1e-9, "{p}");
            assert!(p.dot(dir) > previous);
            previous = p.dot(dir);
        }
        let table = ArcTable::new(&spline, 0.1).unwrap();
        assert!((table.len_mm() - 9.0 * 6f64.sqrt()).abs() < 1e-9);
        assert!((table.arc_at_point_mm(2) - 5.0 * 6f64.sqrt()).abs() < 1e-9);
    }

    #[test]
    fn repeated_points_make_a_still_segment_without_nan() {
        let a = DVec3::new(1.0, 2.0, 3.0);
        let b = DVec3::new(4.0, 0.0, 3.0);
        let spline = CatmullRom::new(vec![a, b, b, a + DVec3::Z]).unwrap();
        for k in 0..=300 {
            assert!(spline.point(f64::from(k) / 100.0).is_finite());
        }
        assert!(spline.point(1.5).distance(b) < 1e-12);
        assert!(CatmullRom::new(vec![a]).is_err());
        assert!(CatmullRom::new(vec![a, DVec3::new(f64::NAN, 0.0, 0.0)]).is_err());
    }
}
