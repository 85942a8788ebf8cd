//! A look below full quality: both stages at the reduced size, the shaded frame upsampled
//! depth-aware to the camera's, as the renderer's own quality levels do — so the deferred stage
//! costs a quarter (half quality) or a sixteenth (quarter quality) of its full-size cost.

use super::gbuffer::GBuffer;
use super::geometry::shade_with_scene;
use super::shading::Shading;
use super::LookError;
use crate::camera::Camera;
use crate::render::quality::{reduced_camera, upsample};
use crate::render::Frame;
use crate::scene::Scene;

/// Shades `gbuffer`, traced by `camera` reduced to the G-buffer's size
/// ([`crate::render::quality::reduced_camera`]; the camera itself at full size), at that size
/// — the smoothing radius scaled down with it, rounded up — and upsamples the frame depth-aware
/// to the camera's size. Fails as [`super::shade`] does, and when the G-buffer is larger than
/// the camera.
pub fn shade_reduced(
    gbuffer: &GBuffer,
    camera: &Camera,
    shading: &Shading,
) -> Result<Frame, LookError> {
    shade_reduced_with_scene(gbuffer, camera, shading, None)
}

/// [`shade_reduced`] with `scene` composited by depth at the reduced size, as
/// [`shade_with_scene`] does at full size: the workstation's preview while the camera moves
/// shows the meshes, marks and instruments the full frame shows.
pub fn shade_reduced_with_scene(
    gbuffer: &GBuffer,
    camera: &Camera,
    shading: &Shading,
    scene: Option<&Scene>,
) -> Result<Frame, LookError> {
    let size = camera.size();
    let small = [gbuffer.width, gbuffer.height];
    if small == size {
        return shade_with_scene(gbuffer, camera, shading, scene);
    }
    if small[0] > size[0] || small[1] > size[1] || gbuffer.is_empty() {
        return Err(LookError::SizeMismatch {
            gbuffer: small,
            camera: size,
        });
    }
    let factor = size[0].div_ceil(small[0]);
    let scaled = Shading {
        smoothing_px: shading.smoothing_px.div_ceil(factor),
        ..shading.clone()
    };
    let low = shade_with_scene(gbuffer, &reduced_camera(camera, small), &scaled, scene)?;
    let mut frame = Frame::default();
    upsample(&low, size, &mut frame);
    Ok(frame)
}
