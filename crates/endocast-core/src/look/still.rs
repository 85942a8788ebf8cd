//! A converged still of a look: jittered ray passes (each pixel's sample point moved inside the
//! pixel, the interleaved sample grid shifted along the ray), each shaded and averaged — the
//! library's still mode ([`crate::render::Still`]) for the two-stage look.

use super::deferred::shade;
use super::gbuffer::RayPass;
use super::shading::Shading;
use super::LookError;
use crate::camera::Camera;
use crate::render::{Frame, Jitter, Quality, Still};

/// The average of `frames` (at least one) shaded ray passes of `camera` by `pass`, frame `k`
/// jittered as [`Jitter::of_frame`]`(k)` says (frame 0 is the plain pass).
pub fn still(
    pass: &RayPass,
    camera: &Camera,
    shading: &Shading,
    frames: usize,
) -> Result<Frame, LookError> {
    let mut still = Still::new();
    for k in 0..frames.max(1) {
        let jitter = Jitter::of_frame(k);
        let (dx, dy) = jitter.pixel_offset;
        let jittered = camera.with_pixel_offset(dx, dy);
        let gbuffer = pass.trace_shifted(&jittered, Quality::Full, jitter.grid_shift);
        still.add(&shade(&gbuffer, &jittered, shading)?);
    }
    Ok(still.frame().clone())
}
