//! The axial, coronal and sagittal slices through the camera, with the camera drawn and the
//! orientation letters, in the slice window; a click jumps the camera there.

use crate::session::Session;
use egui::{Sense, TextureOptions, Vec2};
use endocast_core::views::slices::{camera_slices, Slice, SliceOptions, Window};
use glam::DVec3;

/// Edge of each slice image, pixels.
const SLICE_PX: usize = 256;

/// The slices shown, and what they were drawn for (redrawn when the camera or window changes).
#[derive(Default)]
pub(crate) struct SlicesView {
    drawn_for: Option<(DVec3, DVec3, Window)>,
    slices: Vec<Slice>,
    textures: Vec<egui::TextureHandle>,
}

impl SlicesView {
    /// Draws the three slices in a column; a click in one jumps the camera to that point.
    pub(crate) fn slices_ui(&mut self, ui: &mut egui::Ui, session: &mut Session) {
        self.refresh(ui.ctx(), session);
        let edge = (ui.available_width()).min(ui.available_height() / 3.3);
        let mut jump = None;
        for ((slice, texture), name) in self
            .slices
            .iter()
            .zip(&self.textures)
            .zip(["axial", "coronal", "sagittal"])
        {
            let image =
                egui::Image::from_texture((texture.id(), Vec2::splat(edge))).sense(Sense::click());
            let response = ui
                .add(image)
                .on_hover_text(format!("{name}: click to jump here"));
            if response.clicked() {
                if let Some(pos) = response.interact_pointer_pos() {
                    let scale = SLICE_PX as f64 / f64::from(response.rect.width());
                    let d = pos - response.rect.min;
                    jump = Some(slice.world_at(f64::from(d.x) * scale, f64::from(d.y) * scale));
                }
            }
        }
        if let Some(p) = jump {
            session.jump_to(p);
        }
        let c = session.fly_camera();
        let (e, f) = (c.eye_mm(), c.forward());
        ui.label(format!("eye  {:7.1} {:7.1} {:7.1} mm", e.x, e.y, e.z));
        ui.label(format!("view {:7.2} {:7.2} {:7.2}", f.x, f.y, f.z));
    }

    fn refresh(&mut self, ctx: &egui::Context, session: &Session) {
        let c = session.fly_camera();
        let key = (c.eye_mm(), c.forward(), session.controls.window);
        if self.drawn_for == Some(key) {
            return;
        }
        let Ok(camera) = session.camera() else {
            return;
        };
        let mut options = SliceOptions::default();
        options.size_px = SLICE_PX;
        options.window = session.controls.window;
        let Ok(slices) = camera_slices(session.scene().volume(), &camera, &options) else {
            return;
        };
        self.drawn_for = Some(key);
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
        self.slices = slices.into();
    }
}
