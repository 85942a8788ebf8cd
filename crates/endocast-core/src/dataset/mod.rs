//! Training data from a flight (issue 37): per frame the metric depth along each ray and along
//! the view axis, the wall's normals in the camera frame and the structure mask
//! ([`FrameLayers`]), and the camera as vision tools take it — intrinsics in COLMAP's and
//! nerfstudio's camera models ([`Intrinsics`]) and extrinsics in their conventions
//! ([`Extrinsics`]). The files (PNGs, `transforms.json`, COLMAP's text model) are written by
//! `endocast_io::dataset`; the format is docs/dataset-format.md.
//!
//! Conventions: world millimetres in the patient's LPS frame; the OpenCV camera frame is
//! x right, y down, z forward (COLMAP), the OpenGL one x right, y up, z backward (nerfstudio);
//! pixel centres at half-integers with `(0, 0)` the top-left corner of the image, as both
//! COLMAP and nerfstudio count them (and as [`Camera::project`] does).

mod extrinsics;
mod intrinsics;
mod layers;

#[cfg(test)]
mod tests;

pub use extrinsics::Extrinsics;
pub use intrinsics::{CameraModel, Intrinsics};
pub use layers::{depth_scale_mm, depth_to_u16, FrameLayers, DEPTH_CODES};

use crate::camera::Camera;
use thiserror::Error;

/// A camera that the dataset formats cannot describe.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum DatasetError {
    /// A projection with no camera model in COLMAP and nerfstudio (equisolid fisheye,
    /// orthographic, cube, panorama).
    #[error(
        "{0} camera: COLMAP and nerfstudio have no model for it; training data takes a \
         pinhole (OPENCV) or equidistant fisheye (OPENCV_FISHEYE) camera"
    )]
    Projection(&'static str),
    /// A stereo eye (an off-axis frustum): export one eye.
    #[error("a stereo eye's off-axis camera cannot be exported: export a flight without stereo")]
    Stereo,
}

/// Refuses the cameras the formats cannot take (see [`DatasetError`]).
fn check(camera: &Camera) -> Result<(), DatasetError> {
    if camera.eye_shift().is_some() {
        return Err(DatasetError::Stereo);
    }
    Ok(())
}
