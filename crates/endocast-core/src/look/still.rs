//! A converged still of a look: jittered ray passes (each pixel's sample point moved inside the
//! pixel, the interleaved sample grid shifted along the ray), each shaded and averaged — the
//! library's still mode ([`crate::render::Still`]) for the two-stage look.

use super::gbuffer::RayPass;
use super::geometry::shade_with_scene;
use super::shading::Shading;
use super::{Look, LookError};
use crate::camera::Camera;
use crate::render::{Filter, Frame, Jitter, Prepared, Quality, RenderOptions, Still};
use crate::scene::Scene;

/// The average of `frames` (at least one) shaded ray passes of `camera` by `pass`, with `scene`
/// composited ([`shade_with_scene`]), frame `k` jittered as [`Jitter::of_frame`]`(k)` says
/// (frame 0 is the plain pass), the volume reconstructed as `filter` says.
pub fn still(
    pass: &RayPass,
    camera: &Camera,
    shading: &Shading,
    scene: Option<&Scene>,
    frames: usize,
    filter: Filter,
) -> Result<Frame, LookError> {
    let mut still = Still::new();
    for k in 0..frames.max(1) {
        still.add(&still_frame(pass, camera, shading, scene, k, filter)?);
    }
    Ok(still.frame().clone())
}

/// Frame `k` of [`still`]: the shaded ray pass of `camera` jittered as
/// [`Jitter::of_frame`]`(k)` says, for callers that average frames one at a time (and may stop
/// between them, as the workstation does when the view changes).
pub fn still_frame(
    pass: &RayPass,
    camera: &Camera,
    shading: &Shading,
    scene: Option<&Scene>,
    k: usize,
    filter: Filter,
) -> Result<Frame, LookError> {
    let jitter = Jitter::of_frame(k);
    let (dx, dy) = jitter.pixel_offset;
    let jittered = camera.with_pixel_offset(dx, dy);
    let gbuffer = pass.trace_shifted(&jittered, Quality::Full, jitter.grid_shift, filter);
    shade_with_scene(&gbuffer, &jittered, shading, scene)
}

/// The most frames a still averages on request (`--still`, `still=`).
pub const MAX_STILL_FRAMES: usize = 256;

/// A converged still of `camera`: the average of `frames` (at least one) jittered frames, drawn
/// as `look` says over `prepared`'s settings with `prepared`'s scene composited, or
/// `prepared`'s own image without a look (the plain look, its geometry included); the volume
/// reconstructed as `filter` says.
pub fn still_view(
    prepared: &Prepared,
    look: Option<&Look>,
    camera: &Camera,
    frames: usize,
    filter: Filter,
) -> Result<Frame, LookError> {
    if let Some(look) = look {
        let pass = RayPass::new(prepared.renderer(), prepared.settings(), &look.ray)?;
        let scene = prepared.scene().map(|s| &**s);
        return still(&pass, camera, &look.shading, scene, frames, filter);
    }
    let mut still = Still::new();
    let options = RenderOptions::new().filter(filter);
    for _ in 0..frames.max(1) {
        // Nothing cancels it.
        let _ = still.render_next(prepared, camera, &options);
    }
    Ok(still.frame().clone())
}
