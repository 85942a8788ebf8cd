//! The axial, coronal and sagittal slices through the camera, with the camera drawn and the
//! orientation letters, in the slice window; a click jumps the camera there (or, in path mode,
//! sets the path's start or end). The slices are reformatted off the UI thread ([`Derived`]):
//! the UI shows the last ones until the new ones are there.

use crate::jobs::{Derived, Job, Notify};
use crate::session::Session;
use egui::{Sense, TextureOptions, Vec2};
use endocast_core::render::Camera;
use endocast_core::views::slices::{camera_slices, Plane, Slice, SliceOptions, Window};
use glam::DVec3;
use std::sync::Arc;

/// Edge of each slice image, pixels.
const SLICE_PX: usize = 256;

/// What the slices are drawn for: the eye, the view direction and the window.
type SliceKey = (DVec3, DVec3, Window);

/// What a click on a thumbnail asks for.
pub(crate) enum SliceClicked {
    /// Jump there (or set the path's end there).
    Point(DVec3),
    /// Show this plane large.
    Enlarge(Plane),
}

/// The slices shown and their textures.
#[derive(Default)]
pub(crate) struct SlicesView {
    slices: Derived<SliceKey, Option<[Slice; 3]>>,
    textures: Vec<egui::TextureHandle>,
}

impl SlicesView {
    /// Draws the three slices in a column, each `edge` points wide; returns the world point of
    /// a click in one, or the plane double-clicked to be shown large.
    pub(crate) fn slices_ui(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        edge: f32,
    ) -> Option<SliceClicked> {
        self.refresh(ui.ctx(), session);
        let slices = self.slices.shown().and_then(|(_, s)| s.as_ref())?;
        let mut clicked = None;
        for ((slice, texture), plane) in slices.iter().zip(&self.textures).zip(Plane::ALL) {
            let image =
                egui::Image::from_texture((texture.id(), Vec2::splat(edge))).sense(Sense::click());
            let response = ui.add(image).on_hover_text(format!(
                "{}: click to jump, double click to show it large",
                plane.name()
            ));
            if response.double_clicked() {
                clicked = Some(SliceClicked::Enlarge(plane));
            } else if response.clicked() {
                if let Some(pos) = response.interact_pointer_pos() {
                    let scale = SLICE_PX as f64 / f64::from(response.rect.width());
                    let d = pos - response.rect.min;
                    let p = slice.world_at(f64::from(d.x) * scale, f64::from(d.y) * scale);
                    clicked = Some(SliceClicked::Point(p));
                }
            }
        }
        clicked
    }

    /// Starts reformatting when the camera or the window changed, and uploads new slices.
    fn refresh(&mut self, ctx: &egui::Context, session: &Session) {
        let c = session.fly_camera();
        let key = (c.eye_mm(), c.forward(), session.controls.window);
        let Ok(camera) = session.camera() else {
            return;
        };
        let renderer = Arc::clone(&session.scene().renderer);
        let repaint = ctx.clone();
        let notify: Notify = Arc::new(move || repaint.request_repaint());
        let arrived = self.slices.refresh(&key, |&(_, _, window)| {
            Job::spawn("slices", notify, move || {
                reformat(renderer.volume(), &camera, window)
            })
        });
        if !arrived {
            return;
        }
        let Some((_, Some(slices))) = self.slices.shown() else {
            return;
        };
        self.textures = slices
            .iter()
            .zip(["axial", "coronal", "sagittal"])
            .map(|(s, name)| {
                let image = s.image();
                let pixels =
                    egui::ColorImage::from_rgb([image.width(), image.height()], image.rgb());
                ctx.load_texture(name, pixels, TextureOptions::LINEAR)
            })
            .collect();
    }
}

/// The three slices through `camera` in `window`; `None` when the camera is outside the volume.
fn reformat(volume: &endocast_core::Volume, camera: &Camera, window: Window) -> Option<[Slice; 3]> {
    let mut options = SliceOptions::default();
    options.size_px = SLICE_PX;
    options.window = window;
    camera_slices(volume, camera, &options).ok()
}
