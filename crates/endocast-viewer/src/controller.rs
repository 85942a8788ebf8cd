//! The flying camera: an eye and an orthonormal frame, turned by the mouse and moved by the keys,
//! sliding along the wall through the navigation library's [`Collider`] when collision is on.

use endocast_core::navigate::Collider;
use endocast_core::pose::Pose;
use glam::{DQuat, DVec3};

/// Smallest |forward · up| at which a new up vector is still usable; closer to parallel, the old
/// frame is kept.
const PARALLEL_LIMIT: f64 = 0.999;

/// How far from unit length and perpendicular a given frame may be to be kept as it is.
const ORTHONORMAL_EPS: f64 = 1e-12;

/// The endoscope's pose while flying: eye (world mm, LPS) and unit forward, up and right axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlyCamera {
    eye_mm: DVec3,
    forward: DVec3,
    up: DVec3,
}

/// A motion in the camera's own axes, mm: `right`, `up` and `forward`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct LocalMove {
    /// Along the image's right, mm.
    pub right_mm: f64,
    /// Along the image's up, mm.
    pub up_mm: f64,
    /// Along the view direction, mm.
    pub forward_mm: f64,
}

impl FlyCamera {
    /// The camera of `pose`; `None` when it has no view direction or its up is parallel to it.
    pub fn from_pose(pose: &Pose) -> Option<Self> {
        let forward = (pose.look_at_mm - pose.eye_mm).try_normalize()?;
        Self::new(pose.eye_mm, forward, pose.up)
    }

    /// The camera at `eye_mm` looking along `forward` with `up` (only its part perpendicular to
    /// `forward` counts); `None` when they are not finite or are parallel.
    pub fn new(eye_mm: DVec3, forward: DVec3, up: DVec3) -> Option<Self> {
        if !eye_mm.is_finite() {
            return None;
        }
        let unit = |v: DVec3| (v.length() - 1.0).abs() < ORTHONORMAL_EPS;
        if unit(forward) && unit(up) && forward.dot(up).abs() < ORTHONORMAL_EPS {
            // Already a frame (a saved camera): kept bit for bit, so a case reopens exactly.
            return Some(Self {
                eye_mm,
                forward,
                up,
            });
        }
        let forward = forward.try_normalize()?;
        let up = up.try_normalize()?;
        if forward.dot(up).abs() > PARALLEL_LIMIT {
            return None;
        }
        let right = forward.cross(up).normalize();
        Some(Self {
            eye_mm,
            forward,
            up: right.cross(forward),
        })
    }

    /// The eye, world mm.
    pub fn eye_mm(&self) -> DVec3 {
        self.eye_mm
    }

    /// Unit view direction.
    pub fn forward(&self) -> DVec3 {
        self.forward
    }

    /// Unit up direction of the image.
    pub fn up(&self) -> DVec3 {
        self.up
    }

    /// Unit right direction of the image (`forward × up`).
    pub fn right(&self) -> DVec3 {
        self.forward.cross(self.up)
    }

    /// The pose, looking at the point 1 mm ahead.
    pub fn pose(&self) -> Pose {
        Pose {
            eye_mm: self.eye_mm,
            look_at_mm: self.eye_mm + self.forward,
            up: self.up,
        }
    }

    /// Turns the view: `yaw_rad` to the right about the image's up, then `pitch_rad` upwards
    /// about its right (mouse-look).
    pub fn turn(&mut self, yaw_rad: f64, pitch_rad: f64) {
        let yaw = DQuat::from_axis_angle(self.up, -yaw_rad);
        self.rotate(yaw);
        let pitch = DQuat::from_axis_angle(self.right(), pitch_rad);
        self.rotate(pitch);
    }

    /// Rolls the image clockwise by `rad` about the view direction.
    pub fn roll(&mut self, rad: f64) {
        self.rotate(DQuat::from_axis_angle(self.forward, rad));
    }

    /// Turns the view direction toward `target_mm` (keeping the up vector as close as it can);
    /// nothing when the target is the eye.
    pub fn look_toward(&mut self, target_mm: DVec3) {
        if let Some(turned) = Self::new(self.eye_mm, target_mm - self.eye_mm, self.up) {
            *self = turned;
        }
    }

    /// Moves the eye to `eye_mm` (a jump), keeping the view direction.
    pub fn jump_to(&mut self, eye_mm: DVec3) {
        if eye_mm.is_finite() {
            self.eye_mm = eye_mm;
        }
    }

    /// Moves by `step` in the camera's axes, sliding along the wall when a `collider` is given;
    /// returns the distance actually travelled, mm.
    pub fn translate(&mut self, step: LocalMove, collider: Option<&Collider<'_>>) -> f64 {
        let motion =
            self.right() * step.right_mm + self.up * step.up_mm + self.forward * step.forward_mm;
        let target = self.eye_mm + motion;
        let reached = match collider {
            Some(collider) => collider.slide(self.eye_mm, target),
            None => target,
        };
        let travelled = reached.distance(self.eye_mm);
        self.eye_mm = reached;
        travelled
    }

    fn rotate(&mut self, q: DQuat) {
        let forward = (q * self.forward).normalize();
        let up = q * self.up;
        // Re-orthonormalise so that rounding never lets the frame drift.
        let right = forward.cross(up).normalize();
        self.forward = forward;
        self.up = right.cross(forward);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn camera() -> FlyCamera {
        FlyCamera::new(DVec3::ZERO, DVec3::X, DVec3::Z).unwrap()
    }

    #[test]
    fn yaw_pitch_and_roll_turn_the_frame_the_way_the_user_expects() {
        let mut c = camera();
        assert!((c.right() - DVec3::NEG_Y).length() < 1e-12);
        c.turn(FRAC_PI_2, 0.0);
        assert!((c.forward() - DVec3::NEG_Y).length() < 1e-12, "yaw right");
        let mut c = camera();
        c.turn(0.0, FRAC_PI_2);
        assert!((c.forward() - DVec3::Z).length() < 1e-12, "pitch up");
        assert!((c.up() - DVec3::NEG_X).length() < 1e-12);
        let mut c = camera();
        c.roll(FRAC_PI_2);
        assert!((c.forward() - DVec3::X).length() < 1e-12);
        assert!(c.up().dot(DVec3::Z).abs() < 1e-12);
    }

    #[test]
    fn many_small_turns_keep_the_frame_orthonormal() {
        let mut c = camera();
        for k in 0..10_000 {
            c.turn(0.013, 0.007 * f64::from(k % 3) - 0.006);
            c.roll(0.011);
        }
        assert!((c.forward().length() - 1.0).abs() < 1e-9);
        assert!((c.up().length() - 1.0).abs() < 1e-9);
        assert!(c.forward().dot(c.up()).abs() < 1e-9);
    }

    #[test]
    fn translation_without_collider_follows_the_camera_axes() {
        let mut c = camera();
        let moved = c.translate(
            LocalMove {
                right_mm: 1.0,
                up_mm: 2.0,
                forward_mm: 3.0,
            },
            None,
        );
        assert!((c.eye_mm() - DVec3::new(3.0, -1.0, 2.0)).length() < 1e-12);
        assert!((moved - 14f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn degenerate_frames_are_refused() {
        assert!(FlyCamera::new(DVec3::ZERO, DVec3::X, DVec3::X).is_none());
        assert!(FlyCamera::new(DVec3::ZERO, DVec3::ZERO, DVec3::Z).is_none());
        assert!(FlyCamera::new(DVec3::NAN, DVec3::X, DVec3::Z).is_none());
        let mut c = camera();
        c.look_toward(DVec3::ZERO);
        assert_eq!(c, camera());
        c.look_toward(DVec3::new(0.0, 5.0, 0.0));
        assert!((c.forward() - DVec3::Y).length() < 1e-12);
    }
}
