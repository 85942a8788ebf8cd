//! A spherical camera that slides along the wall instead of entering it.
//!
//! The camera is a ball of radius `r` mm around the eye. A move is walked in sub-steps of at most
//! half a voxel; a sub-step that would bring the eye closer than `r` to the wall (by the
//! [`DistanceField`]) loses the part of its motion that heads into the wall (against the
//! distance gradient, the wall's normal) and is then pushed back out along the gradient. What is
//! left of the motion runs along the wall, so a move aimed obliquely at the wall keeps going
//! along the lumen, as a hand-steered endoscope should.
//!
//! The guarantee is on the field: the returned eye is never closer than `r` to the centre of a
//! wall voxel (by the field's interpolation). The wall's actual surface lies up to about one
//! voxel nearer than those centres, so against the surface the bound is `r` less about a voxel;
//! choose `r` at least a voxel larger than the clearance needed.

use super::distance::DistanceField;
use super::error::{check_finite, NavError};
use glam::DVec3;

/// Attempts to push a sub-step back out of the wall before giving it up.
const PUSH_ATTEMPTS: usize = 4;
/// Extra push beyond the radius, as a fraction of a sub-step, so rounding does not leave the eye
/// a hair inside.
const PUSH_MARGIN: f64 = 1e-3;

/// A camera ball of a given radius moving through a lumen.
#[derive(Debug, Clone, Copy)]
pub struct Collider<'a> {
    field: &'a DistanceField,
    radius_mm: f64,
    step_mm: f64,
}

impl<'a> Collider<'a> {
    /// A camera of radius `radius_mm` (finite, greater than 0) in the lumen of `field`.
    pub fn new(field: &'a DistanceField, radius_mm: f64) -> Result<Self, NavError> {
        check_finite("camera radius (mm)", radius_mm, true)?;
        Ok(Self {
            field,
            radius_mm,
            step_mm: 0.5 * field.min_spacing_mm(),
        })
    }

    /// The camera's radius, mm.
    pub fn radius_mm(&self) -> f64 {
        self.radius_mm
    }

    /// True when a camera at `p_mm` is at least its radius from the wall.
    pub fn is_safe(&self, p_mm: DVec3) -> bool {
        self.field.distance_mm(p_mm) >= self.radius_mm
    }

    /// Moves the camera from `from_mm` towards `to_mm` (world mm), sliding along the wall where
    /// the straight move would hit it, and returns where it ends. The result is always safe
    /// ([`Collider::is_safe`]) when `from_mm` is; an unsafe start (or a non-finite target) is
    /// returned unchanged, since no safe position is known. Moves longer than the lumen box's
    /// diagonal are shortened to it.
    pub fn slide(&self, from_mm: DVec3, to_mm: DVec3) -> DVec3 {
        let motion = to_mm - from_mm;
        if !self.is_safe(from_mm) || !motion.is_finite() || motion == DVec3::ZERO {
            return from_mm;
        }
        let length = motion.length().min(self.field.diagonal_mm());
        let steps = (length / self.step_mm).ceil().max(1.0) as usize;
        let step = motion.normalize() * (length / steps as f64);
        let mut eye = from_mm;
        for _ in 0..steps {
            match self.advance(eye, step) {
                Some(next) => eye = next,
                // The same step would fail again from the same place.
                None => break,
            }
        }
        eye
    }

    /// One sub-step from the safe `eye`: straight when safe, else slid along the wall and pushed
    /// out; `None` when no safe position was found.
    fn advance(&self, eye: DVec3, step: DVec3) -> Option<DVec3> {
        let straight = eye + step;
        if self.is_safe(straight) {
            return Some(straight);
        }
        let normal = self
            .field
            .gradient(straight)
            .try_normalize()
            .or_else(|| self.field.gradient(eye).try_normalize())?;
        let mut next = eye + step - normal * step.dot(normal).min(0.0);
        for _ in 0..PUSH_ATTEMPTS {
            let d = self.field.distance_mm(next);
            if d >= self.radius_mm {
                return Some(next);
            }
            let out = self.field.gradient(next).try_normalize()?;
            next += out * (self.radius_mm - d + PUSH_MARGIN * self.step_mm);
        }
        self.is_safe(next).then_some(next)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::navigate::lumen::{Lumen, LumenSide};
    use crate::phantom::{self, PhantomOptions, Tube};
    use crate::test_rng::Rng;
    use crate::Volume;

    fn tube(size: usize) -> (Volume, Tube, DistanceField) {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size,
            ..Default::default()
        });
        let c = size / 2;
        let lumen = Lumen::from_seed(&volume, [c, c, c], -480.0, LumenSide::Below).unwrap();
        let field = DistanceField::new(&lumen, volume.geometry());
        (volume, tube, field)
    }

    /// Distance (mm) from a world point to the tube's analytic wall (the cylinder).
    fn to_wall(volume: &Volume, tube: &Tube, p_mm: DVec3) -> f64 {
        let v = volume.geometry().voxel_from_world().transform_point3(p_mm);
        let axis = tube.centreline.point_at(0.0);
        tube.radius_vox - (v - axis).truncate().length()
    }

    #[test]
    fn random_moves_never_come_closer_than_the_radius() {
        let (volume, tube, field) = tube(48);
        let radius = 3.0;
        let camera = Collider::new(&field, radius).unwrap();
        let mut rng = Rng::new(7);
        let mut worst = f64::INFINITY;
        for _ in 0..20 {
            // A safe random start: near the axis, away from the open ends.
            let mut eye = DVec3::new(0.0, 0.0, (rng.unit() - 0.5) * 30.0)
                + rng.vec().truncate().extend(0.0) * 3.0;
            assert!(camera.is_safe(eye));
            for _ in 0..30 {
                let target = eye + rng.vec() * 15.0;
                eye = camera.slide(eye, target);
                assert!(field.distance_mm(eye) >= radius);
                worst = worst.min(to_wall(&volume, &tube, eye));
            }
        }
        // The field measures to wall-voxel centres, up to about a voxel (1 mm) beyond the
        // surface: that is the discretisation allowed against the analytic wall.
        assert!(worst >= radius - 1.0, "closest approach {worst} mm");
        // The moves did reach the wall zone (the test would be empty otherwise).
        assert!(worst < radius + 0.5, "closest approach {worst} mm");
    }

    #[test]
    fn a_move_into_the_wall_slides_along_the_tube() {
        let (volume, tube, field) = tube(48);
        let camera = Collider::new(&field, 3.0).unwrap();
        let start = DVec3::new(0.0, 0.0, -15.0);
        // 45° into the wall: 30 mm sideways and 30 mm along the axis.
        let end = camera.slide(start, start + DVec3::new(30.0, 0.0, 30.0));
        assert!(end.z - start.z > 25.0, "stuck at {end}");
        assert!(to_wall(&volume, &tube, end) >= 2.0);
        assert!(end.x > 4.0, "did not reach the wall: {end}");
        // Bad input: nothing moves.
        assert_eq!(camera.slide(start, DVec3::NAN), start);
        let in_wall = DVec3::new(tube.radius_vox + 2.0, 0.0, 0.0);
        assert_eq!(camera.slide(in_wall, DVec3::ZERO), in_wall);
        assert!(Collider::new(&field, f64::NAN).is_err());
        assert!(Collider::new(&field, -1.0).is_err());
    }
}
