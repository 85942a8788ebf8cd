//! A camera's pose as the vision tools write it: nerfstudio's camera-to-world matrix in the
//! OpenGL camera frame, COLMAP's world-to-camera rotation (a quaternion) and translation in
//! the OpenCV one. World millimetres, LPS.

use super::{check, DatasetError};
use crate::camera::Camera;
use glam::{DMat3, DMat4, DQuat, DVec3};

/// A camera's pose.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Extrinsics {
    /// OpenCV camera axes (x right, y down, z forward) in world coordinates.
    axes: DMat3,
    /// The eye, world mm.
    eye_mm: DVec3,
}

impl Extrinsics {
    /// The pose of `camera` (refused for a stereo eye, whose frustum is off-axis).
    pub fn of(camera: &Camera) -> Result<Self, DatasetError> {
        check(camera)?;
        Ok(Self {
            axes: DMat3::from_cols(camera.right(), -camera.up(), camera.forward()),
            eye_mm: camera.eye_mm(),
        })
    }

    /// nerfstudio's `transform_matrix`: camera to world, the camera in the OpenGL convention
    /// (x right, y up, looking along −z), rows of a row-major 4 × 4 matrix, mm.
    pub fn camera_to_world_opengl(&self) -> [[f64; 4]; 4] {
        let gl = DMat3::from_cols(self.axes.x_axis, -self.axes.y_axis, -self.axes.z_axis);
        let m = DMat4::from_cols(
            gl.x_axis.extend(0.0),
            gl.y_axis.extend(0.0),
            gl.z_axis.extend(0.0),
            self.eye_mm.extend(1.0),
        );
        // glam stores columns; the JSON wants rows.
        m.transpose().to_cols_array_2d()
    }

    /// COLMAP's `QW QX QY QZ` and `TX TY TZ`: world to camera in the OpenCV convention,
    /// `x_cam = R·x_world + t`, `t` in mm, the quaternion with `QW ≥ 0`.
    pub fn world_to_camera_opencv(&self) -> ([f64; 4], [f64; 3]) {
        let rotation = self.axes.transpose();
        let mut q = DQuat::from_mat3(&rotation).normalize();
        if q.w < 0.0 {
            q = -q;
        }
        let t = -(rotation * self.eye_mm);
        ([q.w, q.x, q.y, q.z], t.to_array())
    }

    /// World point `p_mm` in the OpenCV camera frame, mm.
    pub fn to_camera(&self, p_mm: DVec3) -> DVec3 {
        self.axes.transpose() * (p_mm - self.eye_mm)
    }
}
