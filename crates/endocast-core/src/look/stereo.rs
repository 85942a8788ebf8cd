//! Stereo pairs of a look: both eyes of a [`StereoRig`] traced by one ray pass and shaded with
//! the scene composited from each eye's own camera ([`shade_with_scene`]), so each eye's
//! image is the look's mono image from that eye.
//!
//! The two first-threshold searches go through the renderer's stereo pair
//! ([`crate::render::StereoFrames`]): the right eye's searches start past the space the left
//! eye showed empty (del Río et al.'s shared visibility, see `render::stereo`), on their own
//! sample grids, so each eye's G-buffer is the one its mono trace writes. Where the rig's eyes
//! cannot share (a lens that is not an ideal pinhole, a near plane, an eye outside the volume)
//! the eyes are traced one after the other. Still frames past the first are jittered per eye
//! (their cameras move inside the pixel) and traced one eye at a time.

use super::gbuffer::RayPass;
use super::geometry::shade_with_scene;
use super::shading::Shading;
use super::still::{still_frame, still_view};
use super::{Look, LookError};
use crate::camera::{Camera, StereoRig};
use crate::render::{Filter, Frame, Prepared, StereoFrames, Still};
use crate::scene::Scene;
use std::time::Instant;

/// Frame `k` of a stereo still of `camera` under `rig` ([`stereo_still`]): the left and right
/// eyes shaded by `shading` with `scene` composited, each jittered as
/// [`super::still_frame`]`(k)` jitters a mono frame, the volume reconstructed by `filter`;
/// frame 0 shares the eyes' searches, its
/// ray-pass frames and start-up buffers kept in `pair` (reused from call to call). Fails on a
/// rig without eyes (see [`StereoRig::eyes`]) and as [`shade_with_scene`] does.
pub fn stereo_frame(
    pass: &RayPass,
    (camera, rig): (&Camera, &StereoRig),
    shading: &Shading,
    scene: Option<&Scene>,
    (k, filter): (usize, Filter),
    pair: &mut StereoFrames,
) -> Result<[Frame; 2], LookError> {
    let eyes = rig.eyes(camera)?;
    if k > 0 {
        let [left, right] = eyes.map(|eye| still_frame(pass, &eye, shading, scene, k, filter));
        return Ok([left?, right?]);
    }
    let options = pass.first_options(0.0, filter);
    pass.prepared()
        .render_stereo_with(camera, rig, &options, pair)?;
    let mut shaded = [Frame::default(), Frame::default()];
    for ((eye, first), out) in eyes.iter().zip(&mut pair.eyes).zip(&mut shaded) {
        let start = Instant::now();
        let searched = first.stats.time;
        let mut gbuffer = pass.finish(eye, std::mem::take(first), eye, filter);
        gbuffer.stats.time = searched + start.elapsed();
        *out = shade_with_scene(&gbuffer, eye, shading, scene)?;
    }
    Ok(shaded)
}

/// The left and right eyes of `camera` under `rig` in a look, each the average of `frames`
/// (at least one) jittered frames reconstructed by `filter` ([`stereo_frame`]): the stereo
/// pair of [`super::still`].
pub fn stereo_still(
    pass: &RayPass,
    (camera, rig): (&Camera, &StereoRig),
    shading: &Shading,
    scene: Option<&Scene>,
    (frames, filter): (usize, Filter),
) -> Result<[Frame; 2], LookError> {
    let mut pair = StereoFrames::default();
    let mut stills = [Still::new(), Still::new()];
    for k in 0..frames.max(1) {
        let eyes = stereo_frame(pass, (camera, rig), shading, scene, (k, filter), &mut pair)?;
        for (still, eye) in stills.iter_mut().zip(&eyes) {
            still.add(eye);
        }
    }
    Ok(stills.map(|s| s.frame().clone()))
}

/// The stereo pair of [`still_view`]: the left and right eyes of `camera` under `rig`, each
/// the average of `frames` jittered frames reconstructed by `filter`, drawn as `look` says
/// with `prepared`'s scene composited from each eye, or `prepared`'s own pair without a look
/// (one frame: the renderer's shared pair, [`Prepared::render_stereo`]).
pub fn stereo_view(
    prepared: &Prepared,
    look: Option<&Look>,
    (camera, rig): (&Camera, &StereoRig),
    (frames, filter): (usize, Filter),
) -> Result<[Frame; 2], LookError> {
    if let Some(look) = look {
        let pass = RayPass::new(prepared.renderer(), prepared.settings(), &look.ray)?;
        let scene = prepared.scene().map(|s| &**s);
        return stereo_still(&pass, (camera, rig), &look.shading, scene, (frames, filter));
    }
    if frames <= 1 {
        return Ok(prepared.render_stereo(camera, rig)?);
    }
    let [left, right] = rig
        .eyes(camera)?
        .map(|eye| still_view(prepared, None, &eye, frames, filter));
    Ok([left?, right?])
}
