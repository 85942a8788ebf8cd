//! The camera: a pose in world millimetres (LPS), a [`Projection`] with an optional real
//! [`Lens`], an image size and a near distance — and the one definition of pixel → ray
//! ([`Camera::ray`]) that the renderer, the slice views, coverage and animation share, with its
//! inverse ([`Camera::project`]). A [`StereoRig`] makes the two off-axis eyes of a stereo pair.
//!
//! The convention is the one the VTK peer uses (see `shared/peers/check_projection.py`):
//! `right = forward × up`, the field of view is the *vertical* one, row 0 is the top of the
//! image, and pixel `(x, y)` is sampled through its centre `(x + ½, y + ½)`.
//!
//! Image positions are normalised before projecting: `(u, v)` with the centre at `(0, 0)`,
//! `v = 1` at the top edge and `u` in the same unit (half the image height). Per projection,
//! with `φ` half the field:
//! - pinhole: the ray through `forward + right·u·tan φ + up·v·tan φ`;
//! - equidistant fisheye: the angle from the axis is `θ = r·φ` (`r = |(u, v)|`);
//! - equisolid fisheye: `r = sin(θ/2) / sin(φ/2)`;
//! - orthographic: parallel rays along `forward` from `eye + right·u·h + up·v·h`, `h` half the
//!   view height in mm;
//! - the all-round views map pixels to directions themselves: the unfolded cube's six 90°
//!   pinhole faces in a cross ([`cube`]), the 360° equirectangular panorama ([`panorama`]).
//!   Neither takes a lens's distortion or vignetting, nor stereo eyes: refused.
//!
//! A fisheye's image is the circle `r ≤ 1` (a real endoscope's round picture); pixels outside it
//! have no ray. The lens's distortion acts on `(u, v)` before the projection (see [`lens`]).

pub mod cube;
mod framing;
pub mod lens;
pub mod panorama;
mod projection;
mod stereo;

#[cfg(test)]
mod all_round_tests;
#[cfg(test)]
mod tests;

pub use cube::{CubeLayout, Face};
pub use framing::{default_up, framing_eye, framing_pose};
pub use lens::Lens;
pub use projection::Projection;
pub use stereo::{disparity_px, StereoRig, FALLBACK_FOCUS_MM, SEPARATION_PER_FOCUS};

use glam::DVec3;
use thiserror::Error;

/// Smallest and largest vertical field of view of a pinhole camera, degrees.
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
    /// The field lies outside its projection's range ([`Projection::field_range`]).
    #[error("a {projection} field of {field} lies outside {min}–{max} {unit}")]
    BadField {
        /// The projection's name.
        projection: &'static str,
        /// The rejected field.
        field: f64,
        /// Smallest accepted.
        min: f64,
        /// Largest accepted.
        max: f64,
        /// Degrees or mm.
        unit: &'static str,
    },
    /// A lens parameter is not finite or outside its range.
    #[error("lens {0} = {1} is outside {2}")]
    BadLens(&'static str, f64, &'static str),
    /// An image edge is zero or larger than [`MAX_IMAGE_EDGE`].
    #[error("image size {0}×{1} must be between 1 and 16384 pixels per edge")]
    BadSize(usize, usize),
    /// The near distance is negative or not finite.
    #[error("near distance {0} mm must be finite and not negative")]
    BadNear(f64),
    /// A stereo eye cannot be made.
    #[error("stereo: {0}")]
    BadStereo(String),
    /// An all-round view (cube, panorama) was given a lens's distortion or vignetting.
    #[error("a {0} view takes no lens distortion or vignetting")]
    AllRoundLens(&'static str),
}

/// Refuses stereo eyes for a projection that has none: orthographic (parallel rays) and the
/// all-round views (an eye offset along the camera's right is no offset at all for the right
/// and left faces, and a reversed one behind the eye).
fn no_stereo_eyes(projection: Projection) -> Result<(), CameraError> {
    match projection {
        Projection::Orthographic | Projection::Cube | Projection::Panorama => Err(
            CameraError::BadStereo(format!("a {} camera has no stereo eyes", projection.name())),
        ),
        _ => Ok(()),
    }
}

/// A ray in world millimetres: where it starts and its unit direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start, world mm (the eye, or for an orthographic camera a point of its image plane).
    pub origin: DVec3,
    /// Unit direction, world.
    pub dir: DVec3,
}

impl Ray {
    /// The point `t_mm` along the ray.
    pub fn at(&self, t_mm: f64) -> DVec3 {
        self.origin + self.dir * t_mm
    }
}

/// One eye of an off-axis stereo pair: its position `offset_mm` along the camera's right
/// vector (negative for the left eye), and the distance of the zero-parallax (focus) surface.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EyeShift {
    /// Signed distance of this eye from the centre along `right`, mm.
    pub offset_mm: f64,
    /// Distance of the focus plane (pinhole) or sphere (fisheye) from the centre eye, mm.
    pub focus_mm: f64,
}

/// Everything about a camera but its pose and image size: projection, field, lens and near
/// distance (what a command's options or a preset say once for every frame of a flight).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Optics {
    /// The projection.
    pub projection: Projection,
    /// Degrees across the image height, or mm of view height (orthographic).
    pub field: f64,
    /// Distortion and vignetting.
    pub lens: Lens,
    /// Near distance, mm.
    pub near_mm: f64,
}

impl Default for Optics {
    /// A pinhole with a 90° vertical field of view and a perfect lens.
    fn default() -> Self {
        Self {
            projection: Projection::Pinhole,
            field: 90.0,
            lens: Lens::default(),
            near_mm: 0.0,
        }
    }
}

impl Optics {
    /// The same optics with the field of an angular projection set to `fov_deg` (a key frame's
    /// field of view); an orthographic view keeps its height.
    pub fn with_fov(self, fov_deg: f64) -> Self {
        match self.projection {
            Projection::Orthographic | Projection::Cube | Projection::Panorama => self,
            _ => Self {
                field: fov_deg,
                ..self
            },
        }
    }

    /// The camera at `eye_mm` looking at `look_at_mm` with `up`, of `size` pixels.
    pub fn camera(
        &self,
        eye_mm: DVec3,
        look_at_mm: DVec3,
        up: DVec3,
        size: [usize; 2],
    ) -> Result<Camera, CameraError> {
        Camera::look_at(eye_mm, look_at_mm, up, 90.0, size)?
            .with_projection(self.projection, self.field)?
            .with_lens(self.lens)?
            .with_near_mm(self.near_mm)
    }
}

/// A camera: pose, projection, lens, image size and near distance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    eye_mm: DVec3,
    forward: DVec3,
    right: DVec3,
    up: DVec3,
    projection: Projection,
    /// The field: degrees for the angular projections, mm of view height for orthographic.
    field: f64,
    /// Pinhole: tan(fov / 2), the half height of the image plane at distance 1; fisheye: half
    /// the field in radians; orthographic: half the view height in mm.
    half: f64,
    lens: Lens,
    width: usize,
    height: usize,
    near_mm: f64,
    eye_shift: Option<EyeShift>,
    /// Added to every image position before it becomes a ray (sub-pixel jitter).
    pixel_offset: [f64; 2],
}

/// What the four-ray set-up of a pinhole camera with an ideal lens needs
/// ([`Camera::fast_pinhole`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PinholeRays {
    /// Every ray's start (the eye, or a stereo eye).
    pub origin: DVec3,
    pub forward: DVec3,
    pub right: DVec3,
    pub up: DVec3,
    pub tan_half_fov: f64,
    /// Subtracted from the horizontal image-plane coordinate (an off-axis stereo eye), if any.
    pub shift: Option<f64>,
    pub pixel_offset: [f64; 2],
}

impl Camera {
    /// A pinhole camera at `eye_mm` looking at `look_at_mm`, `up` giving the image's upward
    /// direction (only its part perpendicular to the view matters), with a vertical field of
    /// view of `fov_deg` (10°–170°) and an image of `width × height` pixels. The near distance
    /// starts at 0; see [`Camera::with_near_mm`], [`Camera::with_projection`] and
    /// [`Camera::with_lens`] for the rest.
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
            projection: Projection::Pinhole,
            field: fov_deg,
            half: (fov_deg.to_radians() / 2.0).tan(),
            lens: Lens::default(),
            width,
            height,
            near_mm: 0.0,
            eye_shift: None,
            pixel_offset: [0.0; 2],
        })
    }

    /// The same camera with another projection and field: degrees across the image height for
    /// pinhole (10°–170°) and fisheye (10°–360°), mm of view height for orthographic, 90° for
    /// the cube, degrees of latitude for the panorama (10°–180°).
    pub fn with_projection(self, projection: Projection, field: f64) -> Result<Self, CameraError> {
        let (min, max) = projection.field_range();
        if !(min..=max).contains(&field) {
            return Err(CameraError::BadField {
                projection: projection.name(),
                field,
                min,
                max,
                unit: projection.field_unit(),
            });
        }
        if self.eye_shift.is_some() {
            no_stereo_eyes(projection)?;
        }
        if projection.is_all_round() && !self.lens.is_plain() {
            return Err(CameraError::AllRoundLens(projection.name()));
        }
        let half = match projection {
            Projection::Pinhole | Projection::Cube => (field.to_radians() / 2.0).tan(),
            Projection::Equidistant | Projection::Equisolid => field.to_radians() / 2.0,
            Projection::Panorama => field.to_radians() / 2.0,
            Projection::Orthographic => field / 2.0,
        };
        Ok(Self {
            projection,
            field,
            half,
            ..self
        })
    }

    /// The same camera seen through `lens` (distortion coefficients within ±2, vignetting
    /// 0–1).
    pub fn with_lens(self, lens: Lens) -> Result<Self, CameraError> {
        for (name, k) in [("k1", lens.distortion[0]), ("k2", lens.distortion[1])] {
            if !k.is_finite() || k.abs() > lens::MAX_DISTORTION {
                return Err(CameraError::BadLens(name, k, "−2…2"));
            }
        }
        if !(0.0..=1.0).contains(&lens.vignetting) {
            return Err(CameraError::BadLens("vignetting", lens.vignetting, "0…1"));
        }
        if self.projection.is_all_round() && !lens.is_plain() {
            return Err(CameraError::AllRoundLens(self.projection.name()));
        }
        Ok(Self { lens, ..self })
    }

    /// The same camera with rays starting `near_mm` in front of the eye — on a plane for pinhole
    /// and orthographic cameras, on a sphere for a fisheye — which may lie inside tissue:
    /// nothing nearer is rendered.
    pub fn with_near_mm(self, near_mm: f64) -> Result<Self, CameraError> {
        if !near_mm.is_finite() || near_mm < 0.0 {
            return Err(CameraError::BadNear(near_mm));
        }
        Ok(Self { near_mm, ..self })
    }

    /// This camera as one eye of an off-axis stereo pair (see [`StereoRig`], which is the usual
    /// way to make one): the eye moves along `right` and every ray passes through the point
    /// where the centre camera's ray of the same pixel meets the focus surface, so that surface
    /// has zero parallax (an asymmetric frustum for a pinhole; never toe-in).
    pub fn with_eye_shift(self, shift: EyeShift) -> Result<Self, CameraError> {
        let EyeShift {
            offset_mm,
            focus_mm,
        } = shift;
        no_stereo_eyes(self.projection)?;
        if !offset_mm.is_finite() || !focus_mm.is_finite() || focus_mm <= offset_mm.abs() {
            return Err(CameraError::BadStereo(format!(
                "the focus distance {focus_mm} mm must be finite and larger than the eye offset {offset_mm} mm"
            )));
        }
        Ok(Self {
            eye_shift: Some(shift),
            ..self
        })
    }

    /// The same camera sampling each pixel `(dx, dy)` pixels away from its centre (sub-pixel
    /// jitter for accumulated still frames).
    pub fn with_pixel_offset(self, dx: f64, dy: f64) -> Self {
        Self {
            pixel_offset: [dx, dy],
            ..self
        }
    }

    /// The same camera with another image size (the field of view is kept).
    pub fn with_size(self, [width, height]: [usize; 2]) -> Result<Self, CameraError> {
        if !(1..=MAX_IMAGE_EDGE).contains(&width) || !(1..=MAX_IMAGE_EDGE).contains(&height) {
            return Err(CameraError::BadSize(width, height));
        }
        Ok(Self {
            width,
            height,
            ..self
        })
    }

    /// Eye position (the centre of a stereo pair), world mm.
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

    /// The projection.
    pub fn projection(&self) -> Projection {
        self.projection
    }

    /// The field: degrees across the image height, or mm of view height (orthographic).
    pub fn field(&self) -> f64 {
        self.field
    }

    /// The lens.
    pub fn lens(&self) -> Lens {
        self.lens
    }

    /// The stereo eye this camera is, if it is one.
    pub fn eye_shift(&self) -> Option<EyeShift> {
        self.eye_shift
    }

    /// Vertical field of view, degrees (0 for an orthographic camera).
    pub fn fov_deg(&self) -> f64 {
        match self.projection {
            Projection::Orthographic => 0.0,
            _ => self.field,
        }
    }

    /// Image width and height, pixels.
    pub fn size(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// Distance of the near plane (or sphere) from the eye, mm.
    pub fn near_mm(&self) -> f64 {
        self.near_mm
    }

    /// Where every ray starts, where they share a start (all but orthographic cameras).
    pub fn shared_origin(&self) -> Option<DVec3> {
        match self.projection {
            Projection::Orthographic => None,
            _ => Some(self.eye_origin()),
        }
    }

    /// The eye this camera's rays start from (shifted for a stereo eye).
    fn eye_origin(&self) -> DVec3 {
        match self.eye_shift {
            Some(e) => self.eye_mm + self.right * e.offset_mm,
            None => self.eye_mm,
        }
    }

    /// The numbers the four-ray set-up needs, for a pinhole camera with an ideal lens.
    pub(crate) fn fast_pinhole(&self) -> Option<PinholeRays> {
        (self.projection == Projection::Pinhole && self.lens.is_ideal()).then(|| PinholeRays {
            origin: self.eye_origin(),
            forward: self.forward,
            right: self.right,
            up: self.up,
            tan_half_fov: self.half,
            shift: self.eye_shift.map(|e| e.offset_mm / e.focus_mm),
            pixel_offset: self.pixel_offset,
        })
    }

    /// The ray through image point `(x, y)` in pixels (pixel centres at half-integers, row 0 at
    /// the top), or `None` where the lens forms no image (outside a fisheye's circle, beyond
    /// the fold of a strong barrel distortion, in an empty cell of the cube's cross). The one
    /// definition of pixel → ray.
    pub fn ray(&self, x: f64, y: f64) -> Option<Ray> {
        let (x, y) = (x + self.pixel_offset[0], y + self.pixel_offset[1]);
        if self.projection.is_all_round() {
            let dir = self.all_round_direction(x, y)?;
            return Some(Ray {
                origin: self.eye_mm,
                dir,
            });
        }
        let (w, h) = (self.width as f64, self.height as f64);
        let a = 2.0 * x / w - 1.0;
        let b = 1.0 - 2.0 * y / h;
        // An ideal lens leaves the radius as it is (and skips the `hypot`).
        let s = if self.lens.is_ideal() {
            1.0
        } else {
            self.lens.undistort_scale((a * w / h).hypot(b))?
        };
        let eye = self.eye_origin();
        match self.projection {
            Projection::Pinhole => {
                // Operation for operation as the four-ray set-up (render/simd/rays4.rs).
                let mut sx = a * self.half * w / h;
                let mut sy = b * self.half;
                if s != 1.0 {
                    (sx, sy) = (sx * s, sy * s);
                }
                if let Some(e) = self.eye_shift {
                    sx -= e.offset_mm / e.focus_mm;
                }
                let dir = (self.forward + self.right * sx + self.up * sy).normalize();
                Some(Ray { origin: eye, dir })
            }
            Projection::Equidistant | Projection::Equisolid => {
                let (u, v) = (a * w / h * s, b * s);
                let dir = self.fisheye_direction(u, v)?;
                Some(match self.eye_shift {
                    Some(e) => {
                        let focus = self.eye_mm + dir * e.focus_mm;
                        Ray {
                            origin: eye,
                            dir: (focus - eye).normalize(),
                        }
                    }
                    None => Ray { origin: eye, dir },
                })
            }
            Projection::Orthographic => {
                let (u, v) = (a * w / h * s, b * s);
                let origin = eye + self.right * (u * self.half) + self.up * (v * self.half);
                Some(Ray {
                    origin,
                    dir: self.forward,
                })
            }
            Projection::Cube | Projection::Panorama => unreachable!("handled above"),
        }
    }

    /// The camera's axes: forward, right, up.
    fn axes(&self) -> [DVec3; 3] {
        [self.forward, self.right, self.up]
    }

    /// The unit direction at image point `(x, y)` of the cube or the panorama, if any.
    fn all_round_direction(&self, x: f64, y: f64) -> Option<DVec3> {
        match self.projection {
            Projection::Cube => CubeLayout::new(self.size()).direction(self.axes(), x, y),
            _ => panorama::direction(self.axes(), self.size(), 2.0 * self.half, (x, y)),
        }
    }

    /// The image point of the cube or the panorama where direction `d` is seen, if any.
    fn all_round_position(&self, d: DVec3) -> Option<(f64, f64)> {
        if d == DVec3::ZERO {
            return None;
        }
        match self.projection {
            Projection::Cube => Some(CubeLayout::new(self.size()).position(self.axes(), d)),
            _ => panorama::position(self.axes(), self.size(), 2.0 * self.half, d),
        }
    }

    /// The unit direction at normalised position `(u, v)` of a fisheye (see the module doc).
    fn fisheye_direction(&self, u: f64, v: f64) -> Option<DVec3> {
        let r = u.hypot(v);
        if r > 1.0 {
            return None;
        }
        let theta = match self.projection {
            Projection::Equisolid => 2.0 * (r * (self.half / 2.0).sin()).asin(),
            _ => r * self.half,
        };
        if r == 0.0 {
            return Some(self.forward);
        }
        let across = (self.right * u + self.up * v) / r;
        Some((self.forward * theta.cos() + across * theta.sin()).normalize())
    }

    /// The ray through the centre of pixel `(column, row)`.
    pub fn pixel_ray(&self, column: usize, row: usize) -> Option<Ray> {
        self.ray(column as f64 + 0.5, row as f64 + 0.5)
    }

    /// The world point `depth_mm` along the ray of pixel `(column, row)` (a depth image's hit).
    pub fn point_at(&self, column: usize, row: usize, depth_mm: f64) -> Option<DVec3> {
        self.pixel_ray(column, row).map(|ray| ray.at(depth_mm))
    }

    /// Distance along a unit ray `direction` from its start to the near plane (pinhole,
    /// orthographic, each face of the cube) or sphere (fisheye, panorama), mm.
    pub fn near_distance_along(&self, direction: DVec3) -> f64 {
        match self.projection {
            _ if self.near_mm == 0.0 => 0.0,
            Projection::Equidistant | Projection::Equisolid | Projection::Panorama => self.near_mm,
            Projection::Cube => CubeLayout::near_along(self.axes(), direction, self.near_mm),
            _ => self.near_mm / direction.dot(self.forward).max(1e-9),
        }
    }

    /// The brightness (0–1) the lens leaves at image point `(x, y)`: its vignetting, and the
    /// soft edge of the round field stop where a strong barrel distortion folds
    /// ([`Lens::field_stop`]; beyond it [`Camera::ray`] gives no ray and the frame shows the
    /// background, as outside a fisheye's circle).
    pub fn vignetting(&self, x: f64, y: f64) -> f64 {
        if !self.lens.darkens() {
            return 1.0;
        }
        let (w, h) = (self.width as f64, self.height as f64);
        let (u, v) = ((2.0 * x / w - 1.0) * w / h, 1.0 - 2.0 * y / h);
        let edge2 = if self.projection.is_fisheye() {
            1.0
        } else {
            (w / h).powi(2) + 1.0
        };
        let r2 = u * u + v * v;
        self.lens.brightness(r2 / edge2) * self.lens.field_stop(r2.sqrt(), 2.0 / h)
    }

    /// The image position `(x, y)` in pixels where world point `p_mm` projects, or `None` where
    /// it is not seen (behind a pinhole or orthographic camera, outside a fisheye's field or
    /// the panorama's latitudes, at the eye of an all-round view). The inverse of
    /// [`Camera::ray`].
    pub fn project(&self, p_mm: DVec3) -> Option<(f64, f64)> {
        if self.projection.is_all_round() {
            let (x, y) = self.all_round_position(p_mm - self.eye_mm)?;
            return Some((x - self.pixel_offset[0], y - self.pixel_offset[1]));
        }
        let (u, v) = match self.projection {
            Projection::Pinhole => self.pinhole_uv(p_mm)?,
            Projection::Equidistant | Projection::Equisolid => self.fisheye_uv(p_mm)?,
            Projection::Orthographic => {
                let d = p_mm - self.eye_mm;
                if d.dot(self.forward) < 0.0 {
                    return None;
                }
                (d.dot(self.right) / self.half, d.dot(self.up) / self.half)
            }
            Projection::Cube | Projection::Panorama => unreachable!("handled above"),
        };
        let (u, v) = self.lens.distort((u, v));
        let (w, h) = (self.width as f64, self.height as f64);
        let x = (u * h / w + 1.0) / 2.0 * w;
        let y = (1.0 - v) / 2.0 * h;
        Some((x - self.pixel_offset[0], y - self.pixel_offset[1]))
    }

    /// Normalised position of `p_mm` seen through a pinhole.
    fn pinhole_uv(&self, p_mm: DVec3) -> Option<(f64, f64)> {
        let d = p_mm - self.eye_origin();
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let shift = self.eye_shift.map_or(0.0, |e| e.offset_mm / e.focus_mm);
        Some((
            (d.dot(self.right) / z + shift) / self.half,
            d.dot(self.up) / z / self.half,
        ))
    }

    /// Normalised position of `p_mm` seen through a fisheye.
    fn fisheye_uv(&self, p_mm: DVec3) -> Option<(f64, f64)> {
        // The direction from the centre eye to where this eye's ray meets the focus sphere.
        let d = match self.eye_shift {
            None => p_mm - self.eye_mm,
            Some(e) => {
                let o = self.right * e.offset_mm;
                let q = p_mm - (self.eye_mm + o);
                let (qq, oq) = (q.length_squared(), o.dot(q));
                if qq == 0.0 {
                    return None;
                }
                let disc = oq * oq - qq * (o.length_squared() - e.focus_mm * e.focus_mm);
                let lambda = (-oq + disc.max(0.0).sqrt()) / qq;
                o + q * lambda
            }
        };
        let (along, x, y) = (d.dot(self.forward), d.dot(self.right), d.dot(self.up));
        let across = x.hypot(y);
        let theta = across.atan2(along);
        if theta > self.half * (1.0 + 1e-12) {
            return None;
        }
        let r = match self.projection {
            Projection::Equisolid => (theta / 2.0).sin() / (self.half / 2.0).sin(),
            _ => theta / self.half,
        };
        if across == 0.0 {
            return Some((0.0, 0.0));
        }
        Some((r * x / across, r * y / across))
    }
}
