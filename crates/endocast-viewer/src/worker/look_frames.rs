//! The endoscope's clinical or realistic look in the workstation: the look's ray pass (kept
//! while its settings stay) traced at half resolution while the camera moves, then the full
//! frame, both with the view's geometry composited, then jittered frames averaged into a still (of
//! the stills' filter: B-spline stills start again after the trilinear full frame), each level
//! delivered as it finishes; a new view stops it between levels and between still frames.

use super::{Deliver, View, STILL_FRAMES};
use endocast_core::look::{shade_reduced_with_scene, still_frame, Look, RayPass, RayPassSettings};
use endocast_core::render::progressive::Stage;
use endocast_core::render::quality::reduced_camera;
use endocast_core::render::{Filter, Frame, Quality, RenderSettings, Renderer, Still};
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

/// Renders `view` in `look` level by level, its still's frames reconstructed by `still_filter`,
/// handing each to `deliver`; stops (without error) as soon as `superseded` says a newer view
/// waits, between levels and still frames.
pub(crate) fn render_look(
    passes: &mut LookPass,
    renderer: &Arc<Renderer>,
    view: &View,
    (look, still_filter): (&Look, Filter),
    superseded: &dyn Fn() -> bool,
    deliver: &Deliver<'_>,
) -> Result<(), String> {
    let pass = passes.get(renderer, &view.settings, look)?;
    let (camera, shading) = (&view.camera, &look.shading);
    let scene = view.scene.0.as_deref();
    let background = view.settings.background;
    let show = |stage: Stage, frame: &Frame, start: Instant| {
        if let Ok(image) = Image::from_frame(frame, background) {
            deliver(stage, image, &frame.depth_mm, start.elapsed());
        }
    };
    let start = Instant::now();
    // Both stages at half size (the deferred stage too), the shaded frame upsampled.
    let small = reduced_camera(camera, Quality::Half.reduced_size(camera.size()));
    let preview = pass.trace(&small, Quality::Full);
    let frame =
        shade_reduced_with_scene(&preview, camera, shading, scene).map_err(|e| e.to_string())?;
    show(Stage::Preview(Quality::Half), &frame, start);
    if view.moving {
        return Ok(());
    }
    let frame_of = |k: usize, filter: Filter| {
        still_frame(pass, camera, shading, scene, k, filter).map_err(|e| e.to_string())
    };
    if superseded() {
        return Ok(());
    }
    let start = Instant::now();
    let full = frame_of(0, Filter::Trilinear)?;
    show(Stage::Full, &full, start);
    let mut still = Still::new();
    if still_filter == Filter::Trilinear {
        still.add(&full);
    }
    while still.frames() < STILL_FRAMES {
        if superseded() {
            return Ok(());
        }
        let start = Instant::now();
        still.add(&frame_of(still.frames(), still_filter)?);
        show(Stage::Still(still.frames()), still.frame(), start);
    }
    Ok(())
}
