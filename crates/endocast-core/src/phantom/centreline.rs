//! [`Centreline`]: the analytic axis of the tube phantoms, a polyline parametrised by arc length.

use super::shape::segment_closest;
use glam::DVec3;

/// A tube's axis in voxel index space: a polyline with its arc length. The phantoms are built
/// from this very polyline (distance to it), so it is the exact truth, not an approximation of
/// one; for the colon its vertices are close enough (a few voxels at paper size) that its kinks
/// turn by a few degrees at most.
#[derive(Debug, Clone, PartialEq)]
pub struct Centreline {
    points: Vec<DVec3>,
    /// Arc length at each point, voxels; `arc_vox[0] == 0`.
    arc_vox: Vec<f64>,
}

impl Centreline {
    /// The polyline through `points` (at least two, consecutive points distinct).
    pub(crate) fn new(points: Vec<DVec3>) -> Self {
        debug_assert!(points.len() >= 2);
        let mut arc_vox = Vec::with_capacity(points.len());
        let mut s = 0.0;
        arc_vox.push(s);
        for pair in points.windows(2) {
            s += pair[0].distance(pair[1]);
            arc_vox.push(s);
        }
        Self { points, arc_vox }
    }

    /// The polyline's vertices, voxel index space, from one end to the other.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }

    /// Arc length of each vertex from the first, voxels (same order as [`Centreline::points`]).
    pub fn arc_vox(&self) -> &[f64] {
        &self.arc_vox
    }

    /// Total length, voxels.
    pub fn length_vox(&self) -> f64 {
        self.arc_vox.last().copied().unwrap_or(0.0)
    }

    /// The segment holding arc length `s_vox` (clamped to the ends) and the fraction along it.
    fn locate(&self, s_vox: f64) -> (usize, f64) {
        let s = s_vox.clamp(0.0, self.length_vox());
        let upper = self.arc_vox.partition_point(|&a| a <= s);
        let seg = upper.saturating_sub(1).min(self.points.len() - 2);
        let len = self.arc_vox[seg + 1] - self.arc_vox[seg];
        let t = if len > 0.0 {
            (s - self.arc_vox[seg]) / len
        } else {
            0.0
        };
        (seg, t.clamp(0.0, 1.0))
    }

    /// The point at arc length `s_vox` from the first vertex (clamped to the ends).
    pub fn point_at(&self, s_vox: f64) -> DVec3 {
        let (seg, t) = self.locate(s_vox);
        self.points[seg].lerp(self.points[seg + 1], t)
    }

    /// Unit tangent (direction of increasing arc length) at `s_vox`: the direction of the
    /// segment holding it.
    pub fn tangent_at(&self, s_vox: f64) -> DVec3 {
        let (seg, _) = self.locate(s_vox);
        (self.points[seg + 1] - self.points[seg]).normalize_or_zero()
    }

    /// The arc length of the polyline point closest to `p`, and the distance to it (voxels).
    /// Brute force over all segments: meant for tests and set-up, not per voxel.
    pub fn closest(&self, p: DVec3) -> (f64, f64) {
        let mut best = (0.0, f64::INFINITY);
        for (seg, pair) in self.points.windows(2).enumerate() {
            let (t, d2) = segment_closest(pair[0], pair[1], p);
            if d2 < best.1 {
                let len = self.arc_vox[seg + 1] - self.arc_vox[seg];
                best = (self.arc_vox[seg] + t * len, d2);
            }
        }
        (best.0, best.1.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arc_length_parametrisation() {
        let c = Centreline::new(vec![DVec3::ZERO, DVec3::X * 3.0, DVec3::new(3.0, 4.0, 0.0)]);
        assert_eq!(c.length_vox(), 7.0);
        assert_eq!(c.point_at(1.5), DVec3::new(1.5, 0.0, 0.0));
        assert_eq!(c.point_at(5.0), DVec3::new(3.0, 2.0, 0.0));
        assert_eq!(c.point_at(99.0), DVec3::new(3.0, 4.0, 0.0));
        assert_eq!(c.point_at(-1.0), DVec3::ZERO);
        assert_eq!(c.tangent_at(5.0), DVec3::Y);
        assert_eq!(c.tangent_at(7.0), DVec3::Y);
        let (s, d) = c.closest(DVec3::new(5.0, 2.0, 0.0));
        assert_eq!((s, d), (5.0, 2.0));
    }
}
