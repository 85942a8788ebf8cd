//! Default camera poses from outside the scan: framing the whole volume, and which way is up
//! when the user did not say.

use super::FOV_RANGE_DEG;
use crate::pose::Pose;
use crate::Geometry;
use glam::DVec3;

/// The up vector when none is given for a view along `forward` (any length): superior (+z in
/// LPS), as on a radiograph, or posterior (+y) when looking (nearly, within about 8°) straight
/// up or down, where superior would be parallel to the view.
pub fn default_up(forward: DVec3) -> DVec3 {
    let forward = forward.normalize_or_zero();
    if forward.dot(DVec3::Z).abs() > 0.99 {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

/// An eye in front of the patient (anterior, −y in LPS) and the point it looks at, the centre of
/// the volume's voxel-centre bounds, placed so that the bounds' bounding sphere (radius at least
/// 1 mm) just fills the vertical field of view `fov_deg` (clamped to [`FOV_RANGE_DEG`]).
/// Returns `(eye_mm, look_at_mm)`.
pub fn framing_eye(geometry: &Geometry, fov_deg: f64) -> (DVec3, DVec3) {
    let (lo, hi) = geometry.world_bounds();
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1.0);
    let half_fov = (fov_deg.clamp(FOV_RANGE_DEG.0, FOV_RANGE_DEG.1) / 2.0).to_radians();
    let distance = radius / half_fov.sin();
    (centre - DVec3::Y * distance, centre)
}

/// The pose of [`framing_eye`] with [`default_up`]: the whole volume seen from the front,
/// superior up.
pub fn framing_pose(geometry: &Geometry, fov_deg: f64) -> Pose {
    let (eye_mm, look_at_mm) = framing_eye(geometry, fov_deg);
    Pose {
        eye_mm,
        look_at_mm,
        up: default_up(look_at_mm - eye_mm),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    #[test]
    fn up_is_superior_unless_looking_along_the_body_axis() {
        assert_eq!(default_up(DVec3::new(0.0, 3.0, 0.0)), DVec3::Z);
        assert_eq!(default_up(DVec3::new(1.0, 1.0, 1.0)), DVec3::Z);
        // Looking along z (from the feet, or from above the head): up is posterior.
        assert_eq!(default_up(DVec3::new(0.0, 0.0, 5.0)), DVec3::Y);
        assert_eq!(default_up(DVec3::new(0.01, 0.0, -1.0)), DVec3::Y);
        // Never parallel to the view, so a camera can always be built from it.
        for forward in [DVec3::X, DVec3::Y, DVec3::Z, DVec3::NEG_Z, DVec3::ONE] {
            assert!(forward.normalize().cross(default_up(forward)).length() > 0.1);
        }
    }

    #[test]
    fn the_framed_volume_fits_the_field_of_view() {
        // An oblique, anisotropic volume away from the origin.
        let direction = DMat3::from_rotation_z(0.3) * DMat3::from_rotation_x(0.2);
        let geometry = Geometry::new(
            [64, 40, 30],
            DVec3::new(0.8, 0.8, 2.5),
            DVec3::new(-100.0, 20.0, 300.0),
            direction,
        )
        .unwrap();
        let (lo, hi) = geometry.world_bounds();
        for fov_deg in [30.0, 90.0, 150.0] {
            let pose = framing_pose(&geometry, fov_deg);
            assert_eq!(pose.look_at_mm, (lo + hi) / 2.0);
            let forward = (pose.look_at_mm - pose.eye_mm).normalize();
            // Anterior of the volume, looking posterior, superior up.
            assert!(forward.abs_diff_eq(DVec3::Y, 1e-12));
            assert_eq!(pose.up, DVec3::Z);
            let half_fov = (fov_deg / 2.0_f64).to_radians();
            let mut widest = 0.0_f64;
            for corner in 0..8 {
                let pick = |bit: usize, l: f64, h: f64| if corner >> bit & 1 == 0 { l } else { h };
                let c = DVec3::new(
                    pick(0, lo.x, hi.x),
                    pick(1, lo.y, hi.y),
                    pick(2, lo.z, hi.z),
                );
                let angle = (c - pose.eye_mm).angle_between(forward);
                assert!(
                    angle <= half_fov + 1e-9,
                    "fov {fov_deg}: corner at {angle} rad"
                );
                widest = widest.max(angle);
            }
            // The bounding sphere fills the view exactly; the box's corners lie on that sphere
            // but, seen from the front, not on its silhouette, so they come close.
            let radius = (hi - lo).length() / 2.0;
            let distance = (pose.look_at_mm - pose.eye_mm).length();
            assert!((radius / distance - half_fov.sin()).abs() < 1e-12);
            assert!(widest > 0.5 * half_fov, "fov {fov_deg}: the volume is tiny");
        }
        // Out-of-range fields of view are clamped, not turned into an eye at infinity.
        let (eye, _) = framing_eye(&geometry, 0.0);
        assert!(eye.is_finite());
    }
}
