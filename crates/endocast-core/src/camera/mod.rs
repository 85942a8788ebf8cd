//! The pinhole camera: a pose in world millimetres (LPS) and a perspective projection.
//!
//! The convention is the one the VTK peer uses (see `shared/peers/check_projection.py`):
//! `right = forward × up`, the field of view is the *vertical* one, row 0 is the top of the
//! image, and pixel `(x, y)` is sampled through its centre `(x + ½, y + ½)`.

use glam::DVec3;
use thiserror::Error;

/// Smallest and largest vertical field of view accepted, degrees.
pub const FOV_RANGE_DEG: (f64, f64) = (10.0, 170.0);
/// Largest image edge accepted, pixels.
pub const MAX_IMAGE_EDGE: usize = 16384;

/// A camera that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum CameraError {
    /// A position or vector has a NaN or infinite coordinate.
    #[error("camera {0} {1:?} is not finite")]
    NotFinite(&'static str, [f64; 3]),
    /// The eye and the look-at point coincide.
    #[error("eye and look-at point coincide at {0:?} mm")]
    NoDirection([f64; 3]),
    /// The up vector is zero or parallel to the viewing direction.
    #[error("up vector {0:?} is zero or parallel to the viewing direction")]
    BadUp([f64; 3]),
    /// The field of view lies outside [`FOV_RANGE_DEG`].
    #[error("vertical field of view {0}° lies outside 10°–170°")]
    BadFov(f64),
    /// An image edge is zero or larger than [`MAX_IMAGE_EDGE`].
    #[error("image size {0}×{1} must be between 1 and 16384 pixels per edge")]
    BadSize(usize, usize),
    /// The near distance is negative or not finite.
    #[error("near distance {0} mm must be finite and not negative")]
    BadNear(f64),
}

/// How a camera maps view directions to image positions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Projection {
    /// Perspective (a rectilinear lens): straight lines stay straight; field of view < 180°.
    #[default]
    Pinhole,
    /// Fisheye, equidistant: the image radius grows with the angle from the axis (r = f·θ).
    Equidistant,
    /// Fisheye, equisolid-angle: r = 2f·sin(θ/2), equal solid angles get equal areas.
    Equisolid,
    /// Parallel rays along the view direction (overviews and checks); the field of view is a
    /// height in mm.
    Orthographic,
}

impl Projection {
    /// Every projection, in a fixed order.
    pub const ALL: [Projection; 4] = [
        Self::Pinhole,
        Self::Equidistant,
        Self::Equisolid,
        Self::Orthographic,
    ];

    /// The name the CLI uses: `pinhole`, `equidistant`, `equisolid`, `orthographic`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Pinhole => "pinhole",
            Self::Equidistant => "equidistant",
            Self::Equisolid => "equisolid",
            Self::Orthographic => "orthographic",
        }
    }

    /// The projection called `name` (ASCII case ignored).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|p| p.name().eq_ignore_ascii_case(name.trim()))
    }
}

/// A pinhole perspective camera.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye_mm: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    /// tan(fov / 2): the half height of the image plane at distance 1.
    tan_half_fov: f64,
    width: usize,
    height: usize,
    near_mm: f64,
}

impl Camera {
    /// A camera at `eye_mm` looking at `look_at_mm`, `up` giving the image's upward direction
    /// (only its part perpendicular to the view matters), with a vertical field of view of
    /// `fov_deg` (10°–170°) and an image of `width × height` pixels. The near distance starts at
    /// 0; see [`Camera::with_near_mm`].
    pub fn look_at(
        eye_mm: DVec3,
        look_at_mm: DVec3,
        up: DVec3,
        fov_deg: f64,
        [width, height]: [usize; 2],
    ) -> Result<Self, CameraError> {
        for (what, v) in [("eye", eye_mm), ("look-at point", look_at_mm), ("up", up)] {
            if !v.is_finite() {
                return Err(CameraError::NotFinite(what, v.to_array()));
            }
        }
        let forward = (look_at_mm - eye_mm).try_normalize();
        let forward = forward.ok_or(CameraError::NoDirection(eye_mm.to_array()))?;
        let right = forward.cross(up).try_normalize();
        let right = right.ok_or(CameraError::BadUp(up.to_array()))?;
        if right.cross(forward).dot(up.normalize_or_zero()) < 1e-6 {
            return Err(CameraError::BadUp(up.to_array()));
        }
        if !(FOV_RANGE_DEG.0..=FOV_RANGE_DEG.1).contains(&fov_deg) {
            return Err(CameraError::BadFov(fov_deg));
        }
        if !(1..=MAX_IMAGE_EDGE).contains(&width) || !(1..=MAX_IMAGE_EDGE).contains(&height) {
            return Err(CameraError::BadSize(width, height));
        }
        Ok(Self {
            eye_mm,
            forward,
            right,
            up: right.cross(forward),
            tan_half_fov: (fov_deg.to_radians() / 2.0).tan(),
            width,
            height,
            near_mm: 0.0,
        })
    }

    /// The same camera with rays starting on the plane `near_mm` in front of the eye (which may
    /// lie inside tissue: nothing nearer is rendered).
    pub fn with_near_mm(self, near_mm: f64) -> Result<Self, CameraError> {
        if !near_mm.is_finite() || near_mm < 0.0 {
            return Err(CameraError::BadNear(near_mm));
        }
        Ok(Self { near_mm, ..self })
    }

    /// Eye position, world mm.
    pub fn eye_mm(&self) -> DVec3 {
        self.eye_mm
    }

    /// Unit viewing direction (world).
    pub fn forward(&self) -> DVec3 {
        self.forward
    }

    /// Unit direction of increasing column (world): `forward × up`.
    pub fn right(&self) -> DVec3 {
        self.right
    }

    /// Unit direction of decreasing row (world), perpendicular to `forward` and `right`.
    pub fn up(&self) -> DVec3 {
        self.up
    }

    /// Tangent of half the vertical field of view.
    pub(crate) fn tan_half_fov(&self) -> f64 {
        self.tan_half_fov
    }

    /// Vertical field of view, degrees.
    pub fn fov_deg(&self) -> f64 {
        2.0 * self.tan_half_fov.atan().to_degrees()
    }

    /// Image width and height, pixels.
    pub fn size(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// Distance of the near plane from the eye along `forward`, mm.
    pub fn near_mm(&self) -> f64 {
        self.near_mm
    }

    /// Unit world direction of the ray through image point `(x, y)` in pixels (pixel centres at
    /// half-integers, row 0 at the top).
    pub fn direction(&self, x: f64, y: f64) -> DVec3 {
        let (w, h) = (self.width as f64, self.height as f64);
        let sy = (1.0 - 2.0 * y / h) * self.tan_half_fov;
        let sx = (2.0 * x / w - 1.0) * self.tan_half_fov * w / h;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Unit world direction of the ray through the centre of pixel `(column, row)`.
    pub fn pixel_direction(&self, column: usize, row: usize) -> DVec3 {
        self.direction(column as f64 + 0.5, row as f64 + 0.5)
    }

    /// Distance along a unit ray `direction` from the eye to the near plane, mm.
    pub fn near_distance_along(&self, direction: DVec3) -> f64 {
        if self.near_mm == 0.0 {
            0.0
        } else {
            self.near_mm / direction.dot(self.forward).max(1e-9)
        }
    }

    /// The image position `(x, y)` in pixels where world point `p_mm` projects, or `None`
    /// behind the eye. The inverse of [`Camera::direction`].
    pub fn project(&self, p_mm: DVec3) -> Option<(f64, f64)> {
        let d = p_mm - self.eye_mm;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let (w, h) = (self.width as f64, self.height as f64);
        let sx = d.dot(self.right) / z / self.tan_half_fov * h / w;
        let sy = d.dot(self.up) / z / self.tan_half_fov;
        Some(((sx + 1.0) / 2.0 * w, (1.0 - sy) / 2.0 * h))
    }

    /// The same camera with every pixel sampled `(dx, dy)` pixels away from its centre (`+x`
    /// right, `+y` down): pixel `(x, y)` looks along [`Camera::direction`]`(x + ½ + dx,
    /// y + ½ + dy)` of this camera, up to rounding (sub-pixel jitter for still frames). The
    /// shift moves the image plane's centre, stored in `forward`, which is then no longer of
    /// unit length: the near plane and [`Camera::project`] move with it by a part in `height`
    /// per pixel of offset. `(0, 0)` gives the camera back unchanged.
    pub fn with_pixel_offset(self, dx: f64, dy: f64) -> Self {
        if dx == 0.0 && dy == 0.0 {
            return self;
        }
        let per_pixel = 2.0 * self.tan_half_fov / self.height as f64;
        Self {
            forward: self.forward + self.right * (dx * per_pixel) - self.up * (dy * per_pixel),
            ..self
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn follows_the_peer_convention() {
        // The peers' default: eye (128,128,10) looking along +z with up +y, 90° vertical fov.
        let cam = Camera::look_at(
            DVec3::new(128.0, 128.0, 10.0),
            DVec3::new(128.0, 128.0, 11.0),
            DVec3::Y,
            90.0,
            [512, 256],
        )
        .unwrap();
        assert_eq!(cam.right(), DVec3::Z.cross(DVec3::Y)); // −x
                                                           // A point 45° up from the axis lands on the top edge; 45° right (of a 2:1 image whose
                                                           // horizontal half-tangent is 2) lands a quarter of the width from the centre.
        let (x, y) = cam.project(DVec3::new(128.0, 138.0, 20.0)).unwrap();
        assert!((x - 256.0).abs() < 1e-9 && y.abs() < 1e-9);
        let (x, y) = cam.project(DVec3::new(118.0, 128.0, 20.0)).unwrap();
        assert!((x - 384.0).abs() < 1e-9 && (y - 128.0).abs() < 1e-9);
        let d = cam.direction(100.0, 30.0);
        let (x, y) = cam.project(cam.eye_mm() + d * 7.0).unwrap();
        assert!((x - 100.0).abs() < 1e-9 && (y - 30.0).abs() < 1e-9);
        assert!(cam.project(DVec3::new(128.0, 128.0, 0.0)).is_none());
        assert!((cam.fov_deg() - 90.0).abs() < 1e-9);
    }

    #[test]
    fn rejects_bad_cameras() {
        let ok = |eye, at, up, fov, size| Camera::look_at(eye, at, up, fov, size);
        let (e, a) = (DVec3::ZERO, DVec3::Z);
        assert!(ok(e, a, DVec3::Y, 90.0, [4, 4]).is_ok());
        assert!(ok(DVec3::NAN, a, DVec3::Y, 90.0, [4, 4]).is_err());
        assert!(ok(e, e, DVec3::Y, 90.0, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::Z, 90.0, [4, 4]).is_err());
        assert!(ok(e, a, -DVec3::Z * 3.0, 90.0, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::ZERO, 90.0, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::Y, 9.0, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::Y, 171.0, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::Y, f64::NAN, [4, 4]).is_err());
        assert!(ok(e, a, DVec3::Y, 90.0, [0, 4]).is_err());
        let cam = ok(e, a, DVec3::Y, 170.0, [4, 4]).unwrap();
        assert!(cam.with_near_mm(-1.0).is_err());
        assert!(cam.with_near_mm(f64::INFINITY).is_err());
        let near = cam.with_near_mm(2.0).unwrap();
        assert!((near.near_distance_along(DVec3::Z) - 2.0).abs() < 1e-12);
    }
}
