//! Signed distances (voxels, negative inside) of the few shapes the phantoms are made of, and
//! [`Ball`], the one shape that is also part of several phantoms' analytic truth.

use glam::DVec3;

/// A ball in voxel index space (polyps, calcifications).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ball {
    /// Centre, continuous voxel index.
    pub centre_vox: DVec3,
    /// Radius, voxels.
    pub radius_vox: f64,
}

impl Ball {
    /// Signed distance from `p` to the sphere (negative inside).
    #[inline]
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        p.distance(self.centre_vox) - self.radius_vox
    }

    /// Axis-aligned bounds of the ball grown by `margin` voxels.
    pub(crate) fn bounds(&self, margin: f64) -> (DVec3, DVec3) {
        let r = DVec3::splat(self.radius_vox + margin);
        (self.centre_vox - r, self.centre_vox + r)
    }
}

/// The parameter `t ∈ [0, 1]` of the point of segment `a`–`b` closest to `p`, and the squared
/// distance to it.
#[inline]
pub(crate) fn segment_closest(a: DVec3, b: DVec3, p: DVec3) -> (f64, f64) {
    let ab = b - a;
    let len2 = ab.length_squared();
    let t = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (t, p.distance_squared(a + ab * t))
}

/// Signed distance to a torus: the ring of radius `ring_radius` around `axis` (unit) through
/// `centre`, thickened by `tube_radius`. Exact.
#[inline]
pub(crate) fn torus(
    p: DVec3,
    centre: DVec3,
    axis: DVec3,
    ring_radius: f64,
    tube_radius: f64,
) -> f64 {
    let q = p - centre;
    let along = q.dot(axis);
    let across = (q - axis * along).length();
    (across - ring_radius).hypot(along) - tube_radius
}

/// Signed distance to a box of half extents `half` centred at `centre` whose edges are rounded
/// by `corner` (`corner <= half`). Exact.
#[inline]
pub(crate) fn rounded_box(p: DVec3, centre: DVec3, half: DVec3, corner: f64) -> f64 {
    let q = (p - centre).abs() - (half - DVec3::splat(corner));
    q.max(DVec3::ZERO).length() + q.max_element().min(0.0) - corner
}

/// Signed distance to the slab of `thickness` centred on the plane through `point` with unit
/// `normal`. Exact.
#[inline]
pub(crate) fn slab(p: DVec3, point: DVec3, normal: DVec3, thickness: f64) -> f64 {
    (p - point).dot(normal).abs() - thickness / 2.0
}

/// Distance from `p` to the line through `point` along unit `axis`, and `p`'s coordinate along it.
#[inline]
pub(crate) fn cylindrical(p: DVec3, point: DVec3, axis: DVec3) -> (f64, f64) {
    let q = p - point;
    let along = q.dot(axis);
    ((q - axis * along).length(), along)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_of_known_points() {
        let ball = Ball {
            centre_vox: DVec3::ONE,
            radius_vox: 2.0,
        };
        assert_eq!(ball.signed_distance(DVec3::new(1.0, 1.0, 4.0)), 1.0);
        let (t, d2) = segment_closest(DVec3::ZERO, DVec3::X * 4.0, DVec3::new(1.0, 3.0, 0.0));
        assert_eq!((t, d2), (0.25, 9.0));
        assert_eq!(
            segment_closest(DVec3::ZERO, DVec3::X, DVec3::X * 3.0),
            (1.0, 4.0)
        );
        let d = torus(DVec3::new(5.0, 0.0, 1.0), DVec3::ZERO, DVec3::Z, 5.0, 0.5);
        assert!((d - 0.5).abs() < 1e-12);
        let h = DVec3::new(2.0, 3.0, 4.0);
        assert!((rounded_box(DVec3::new(0.0, 4.0, 0.0), DVec3::ZERO, h, 1.0) - 1.0).abs() < 1e-12);
        assert!((rounded_box(DVec3::ZERO, DVec3::ZERO, h, 1.0) + 2.0).abs() < 1e-12);
        let corner = rounded_box(DVec3::new(3.0, 4.0, 0.0), DVec3::ZERO, h, 1.0);
        assert!((corner - (8f64.sqrt() - 1.0)).abs() < 1e-12);
        assert_eq!(
            slab(DVec3::new(0.0, 0.0, 3.0), DVec3::Z, DVec3::Z, 1.0),
            1.5
        );
        assert_eq!(
            cylindrical(DVec3::new(3.0, 4.0, 7.0), DVec3::ZERO, DVec3::Z),
            (5.0, 7.0)
        );
    }
}
