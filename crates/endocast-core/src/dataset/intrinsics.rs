//! A camera's intrinsics in COLMAP's and nerfstudio's models.
//!
//! With `t = tan(fov/2)` (pinhole) or `φ` = half the field in radians (equidistant fisheye),
//! [`Camera::project`] puts a point at normalised position `u = (X/Z)/t` (pinhole) or radius
//! `r = θ/φ` (fisheye), `(u, v)` in units of half the image height and `v` up, then distorts it
//! by `1 + k1 r² + k2 r⁴`, then `x = w/2 + u·h/2`, `y = h/2 − v·h/2`. So `fx = fy = h/(2t)`
//! (`h/(2φ)`), `cx = w/2`, `cy = h/2`, and our radial polynomial in `u` is OpenCV's in
//! `X/Z` (in `θ` for the fisheye) with `k1' = k1/t²`, `k2' = k2/t⁴` (`k1/φ²`, `k2/φ⁴`).

use super::{check, DatasetError};
use crate::camera::{Camera, Projection};
use glam::DVec3;

/// The camera models written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CameraModel {
    /// OpenCV's pinhole with radial and tangential distortion: parameters `k1, k2, p1, p2`
    /// (COLMAP's and nerfstudio's `OPENCV`).
    OpenCv,
    /// OpenCV's equidistant fisheye: parameters `k1, k2, k3, k4` on the angle θ from the axis
    /// (COLMAP's and nerfstudio's `OPENCV_FISHEYE`).
    OpenCvFisheye,
}

impl CameraModel {
    /// The name COLMAP and nerfstudio give it.
    pub fn name(self) -> &'static str {
        match self {
            Self::OpenCv => "OPENCV",
            Self::OpenCvFisheye => "OPENCV_FISHEYE",
        }
    }
}

/// A camera's intrinsics: model, image size, focal lengths and principal point in pixels, and
/// the model's four distortion parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Intrinsics {
    /// The camera model.
    pub model: CameraModel,
    /// Image width, pixels.
    pub width: usize,
    /// Image height, pixels.
    pub height: usize,
    /// Horizontal focal length, pixels.
    pub fx: f64,
    /// Vertical focal length, pixels.
    pub fy: f64,
    /// Principal point, pixels from the left edge (pixel centres at half-integers).
    pub cx: f64,
    /// Principal point, pixels from the top edge.
    pub cy: f64,
    /// `k1, k2, p1, p2` ([`CameraModel::OpenCv`]) or `k1, k2, k3, k4`
    /// ([`CameraModel::OpenCvFisheye`]).
    pub distortion: [f64; 4],
}

impl Intrinsics {
    /// The intrinsics of `camera` (see the module doc); refused for a projection the formats
    /// have no model for, and for a stereo eye.
    pub fn of(camera: &Camera) -> Result<Self, DatasetError> {
        check(camera)?;
        let projection = camera.projection();
        let half_angle = camera.field().to_radians() / 2.0;
        let (model, scale) = match projection {
            Projection::Pinhole => (CameraModel::OpenCv, half_angle.tan()),
            Projection::Equidistant => (CameraModel::OpenCvFisheye, half_angle),
            other => return Err(DatasetError::Projection(other.name())),
        };
        let [width, height] = camera.size();
        let (w, h) = (width as f64, height as f64);
        let [k1, k2] = camera.lens().distortion;
        let f = h / (2.0 * scale);
        Ok(Self {
            model,
            width,
            height,
            fx: f,
            fy: f,
            cx: w / 2.0,
            cy: h / 2.0,
            distortion: [k1 / scale.powi(2), k2 / scale.powi(4), 0.0, 0.0],
        })
    }

    /// The pixel position of point `p` given in the OpenCV camera frame (x right, y down,
    /// z forward), by the model's own formula: `None` behind a pinhole. What a COLMAP or
    /// nerfstudio user computes from the written numbers.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        let [k1, k2, k3, k4] = self.distortion;
        let (a, b) = match self.model {
            CameraModel::OpenCv => {
                if p.z <= 0.0 {
                    return None;
                }
                let (a, b) = (p.x / p.z, p.y / p.z);
                let r2 = a * a + b * b;
                let radial = 1.0 + k1 * r2 + k2 * r2 * r2;
                let (p1, p2) = (k3, k4);
                (
                    a * radial + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a),
                    b * radial + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b,
                )
            }
            CameraModel::OpenCvFisheye => {
                let across = p.x.hypot(p.y);
                if across == 0.0 {
                    return (p.z > 0.0).then_some((self.cx, self.cy));
                }
                let theta = across.atan2(p.z);
                let t2 = theta * theta;
                let theta_d = theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
                (theta_d * p.x / across, theta_d * p.y / across)
            }
        };
        Some((self.fx * a + self.cx, self.fy * b + self.cy))
    }
}
