//! The endoscope's clinical or realistic look in the workstation: the look's ray pass (kept
//! while its settings stay) traced at half resolution while the camera moves, then the full
//! frame, both with the view's geometry composited, then jittered frames averaged into a still
//! (of the stills' filter: B-spline stills start again after the trilinear full frame), each
//! level delivered as it finishes (with stereo on, both eyes as a red/cyan anaglyph); a new
//! view stops it between levels and between still frames.

use super::{Deliver, View, STILL_FRAMES};
use endocast_core::look::{
    shade_reduced_with_scene, stereo_frame, still_frame, Look, RayPass, RayPassSettings,
};
use endocast_core::render::progressive::Stage;
use endocast_core::render::quality::reduced_camera;
use endocast_core::render::{
    Camera, Filter, Frame, Quality, RenderSettings, Renderer, StereoFrames, Still,
};
use endocast_core::views::stereo::{combine, StereoOutput};
use endocast_core::views::Image;
use std::sync::Arc;
use std::time::Instant;

/// The look's ray pass for the settings it was made for, made again only when they change.
#[derive(Default)]
pub(crate) struct LookPass {
    made: Option<(RenderSettings, RayPassSettings, RayPass)>,
}

impl LookPass {
    /// The ray pass of `look` over `renderer` with `settings`.
    fn get(
        &mut self,
        renderer: &Arc<Renderer>,
        settings: &RenderSettings,
        look: &Look,
    ) -> Result<&RayPass, String> {
        let current = self
            .made
            .as_ref()
            .is_some_and(|(s, r, _)| s == settings && *r == look.ray);
        if !current {
            let pass = RayPass::new(renderer, settings, &look.ray).map_err(|e| e.to_string())?;
            self.made = Some((settings.clone(), look.ray.clone(), pass));
        }
        Ok(&self.made.as_ref().expect("made above").2)
    }
}

/// Renders `view` in `look` level by level, its still's frames after the full frame
/// reconstructed by `still_filter`, handing each to `deliver` (with stereo on, both eyes
/// combined into a red/cyan anaglyph); stops (without error) as soon as `superseded` says a
/// newer view waits, between levels and still frames.
pub(crate) fn render_look(
    passes: &mut LookPass,
    renderer: &Arc<Renderer>,
    view: &View,
    (look, still_filter): (&Look, Filter),
    superseded: &dyn Fn() -> bool,
    deliver: &Deliver<'_>,
) -> Result<(), String> {
    let pass = passes.get(renderer, &view.settings, look)?;
    let background = view.settings.background;
    let show = |stage: Stage, frames: &[&Frame], start: Instant| {
        let images: Result<Vec<_>, _> = frames
            .iter()
            .map(|f| Image::from_frame(f, background))
            .collect();
        let image = images.and_then(|i| match &i[..] {
            [left, right] => combine(left, right, StereoOutput::RedCyan),
            _ => Ok(i[0].clone()),
        });
        if let Ok(image) = image {
            deliver(stage, image, &frames[0].depth_mm, start.elapsed());
        }
    };
    let start = Instant::now();
    let eyes = match view.stereo {
        Some(rig) => rig.eyes(&view.camera).map_err(|e| e.to_string())?.to_vec(),
        None => vec![view.camera],
    };
    let previews = eyes
        .iter()
        .map(|eye| preview(pass, eye, look, view))
        .collect::<Result<Vec<_>, _>>()?;
    show(
        Stage::Preview(Quality::Half),
        &previews.iter().collect::<Vec<_>>(),
        start,
    );
    if view.moving {
        return Ok(());
    }
    let mut stills = vec![Still::new(); eyes.len()];
    let mut pair = StereoFrames::default();
    // A B-spline still averages `STILL_FRAMES` frames of its own after the full frame.
    let frames = STILL_FRAMES + usize::from(still_filter != Filter::Trilinear);
    for k in 0..frames {
        if superseded() {
            return Ok(());
        }
        let start = Instant::now();
        // The full frame is trilinear; a B-spline still starts again after it.
        let filter = if k == 0 {
            Filter::Trilinear
        } else {
            still_filter
        };
        if k == 1 && filter != Filter::Trilinear {
            stills.iter_mut().for_each(|s| *s = Still::new());
        }
        let frames = still_frames(pass, view, look, (k, filter), &mut pair)?;
        for (still, frame) in stills.iter_mut().zip(&frames) {
            still.add(frame);
        }
        let stage = if k == 0 {
            Stage::Full
        } else {
            Stage::Still(stills[0].frames())
        };
        show(
            stage,
            &stills.iter().map(Still::frame).collect::<Vec<_>>(),
            start,
        );
    }
    Ok(())
}

/// The half-size preview of `eye` in `look`: both stages at half size (the deferred stage
/// too), the shaded frame upsampled, with `view`'s geometry.
fn preview(pass: &RayPass, eye: &Camera, look: &Look, view: &View) -> Result<Frame, String> {
    let small = reduced_camera(eye, Quality::Half.reduced_size(eye.size()));
    let traced = pass.trace(&small, Quality::Full);
    let scene = view.scene.0.as_deref();
    shade_reduced_with_scene(&traced, eye, &look.shading, scene).map_err(|e| e.to_string())
}

/// Still frame `k` of `view` in `look`, reconstructed by `filter`: one eye, or both of a
/// stereo view (their searches shared through `pair`'s buffers).
fn still_frames(
    pass: &RayPass,
    view: &View,
    look: &Look,
    (k, filter): (usize, Filter),
    pair: &mut StereoFrames,
) -> Result<Vec<Frame>, String> {
    let (camera, shading) = (&view.camera, &look.shading);
    let scene = view.scene.0.as_deref();
    let frames = match &view.stereo {
        Some(rig) => {
            stereo_frame(pass, (camera, rig), shading, scene, (k, filter), pair).map(Vec::from)
        }
        None => still_frame(pass, camera, shading, scene, k, filter).map(|f| vec![f]),
    };
    frames.map_err(|e| e.to_string())
}
