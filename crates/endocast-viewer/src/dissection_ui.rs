//! The virtual dissection in the window: the panel's section that makes it ([`DissectionTools`])
//! and says its scale, and the flat view, a strip along the bottom of the window with the wall
//! laid flat (its millimetre axis and scale drawn in the image), a line where the endoscope is
//! along the path, the place under the pointer in words, and a click on a pixel taking the
//! endoscope to look at its wall point.

use crate::dissection::{DissectionTools, Flat};
use crate::session::Session;
use egui::{Color32, Pos2, Rect, Sense, Stroke, TextureOptions, Vec2};
use std::sync::Arc;

/// Height of the flat view's image, points (the image is scaled to it; it scrolls across).
const STRIP_HEIGHT: f32 = 200.0;
/// Room under the image for the scroll bar across, points.
const SCROLL_BAR: f32 = 16.0;
/// The endoscope's place along the path in the flat view.
const ENDOSCOPE_LINE: Color32 = Color32::from_rgb(255, 220, 0);
/// The texture's name (the tests find the image by it).
pub(crate) const TEXTURE_NAME: &str = "virtual dissection";

/// The dissection and its flat view.
#[derive(Default)]
pub(crate) struct DissectionView {
    /// The dissection made (or being made).
    pub tools: DissectionTools,
    /// Whether the flat view is shown, once there is one.
    pub shown: bool,
    /// The flat image uploaded, and the revision of the tools it shows.
    texture: Option<(u64, egui::TextureHandle)>,
}

/// The panel's section: make the dissection, show or hide the flat view, its scale.
pub(crate) fn dissection_ui(view: &mut DissectionView, ui: &mut egui::Ui, session: &Session) {
    let running = view.tools.running();
    ui.horizontal(|ui| {
        let hint = "cut the wall open along the key frames' path (or the automatic path) and \
                    lay it flat; click the flat view to look at a point";
        let start = ui.add_enabled(!running, egui::Button::new("Dissect"));
        if start.on_hover_text(hint).clicked() {
            let ctx = ui.ctx().clone();
            view.tools
                .start(session, Arc::new(move || ctx.request_repaint()));
            view.shown = true;
        }
        if view.tools.flat().is_some() {
            ui.checkbox(&mut view.shown, "show the flat view");
        }
    });
    if running {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label("laying the wall flat…");
        });
    }
    if let Some(flat) = view.tools.flat() {
        let s = flat.dissection.scale;
        ui.label(format!(
            "{:.0} mm of path: {} mm/px along, {}°/px around ({:.2} mm at the wall)",
            flat.path.len_mm(),
            s.along_mm_per_px,
            s.around_deg_per_px,
            s.around_mm_per_px
        ));
    }
}

/// The flat view along the bottom of the window, while there is one to show; returns a line
/// for the status bar when a pixel was clicked.
pub(crate) fn flat_view_ui(
    ctx: &egui::Context,
    view: &mut DissectionView,
    session: &mut Session,
) -> Option<String> {
    if !view.shown {
        return None;
    }
    let flat = view.tools.flat()?;
    let revision = view.tools.revision();
    if view.texture.as_ref().is_none_or(|(r, _)| *r != revision) {
        let image = &flat.dissection.image;
        let pixels = egui::ColorImage::from_rgb([image.width(), image.height()], image.rgb());
        let texture = ctx.load_texture(TEXTURE_NAME, pixels, TextureOptions::NEAREST);
        view.texture = Some((revision, texture));
    }
    let texture = view.texture.as_ref().map(|(_, t)| t.id())?;
    let mut clicked = None;
    egui::TopBottomPanel::bottom("flat view")
        .resizable(false)
        .exact_height(STRIP_HEIGHT + SCROLL_BAR)
        .show(ctx, |ui| {
            egui::ScrollArea::horizontal()
                .id_salt("flat view")
                .show(ui, |ui| {
                    let column = view.tools.endoscope_column(session);
                    clicked = strip_ui(ui, flat, texture, column);
                });
        });
    let (x, y) = clicked?;
    Some(view.tools.visit(session, x, y))
}

/// The flat image scaled to [`STRIP_HEIGHT`], the endoscope's `column` marked; returns the
/// pixel clicked.
fn strip_ui(
    ui: &mut egui::Ui,
    flat: &Flat,
    texture: egui::TextureId,
    column: Option<usize>,
) -> Option<(usize, usize)> {
    let image = &flat.dissection.image;
    let scale = STRIP_HEIGHT / image.height() as f32;
    let size = Vec2::new(image.width() as f32, image.height() as f32) * scale;
    let (rect, response) = ui.allocate_exact_size(size, Sense::click());
    let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
    ui.painter().image(texture, rect, uv, Color32::WHITE);
    let plot = flat.dissection.plot;
    if let Some(column) = column {
        let x = rect.min.x + (column as f32 + 0.5) * scale;
        let top = rect.min.y + plot.y as f32 * scale;
        let bottom = top + plot.rows as f32 * scale;
        let line = [Pos2::new(x, top), Pos2::new(x, bottom)];
        ui.painter()
            .line_segment(line, Stroke::new(1.5, ENDOSCOPE_LINE));
    }
    let pixel = |pos: Pos2| {
        let p = (pos - rect.min) / scale;
        (p.x.max(0.0) as usize, p.y.max(0.0) as usize)
    };
    if let Some(pos) = response.hover_pos() {
        let (x, y) = pixel(pos);
        response.clone().on_hover_text_at_pointer(place(flat, x, y));
    }
    let pos = response
        .clicked()
        .then(|| response.interact_pointer_pos())??;
    Some(pixel(pos))
}

/// Where pixel `(x, y)` is, in words: its arc length and angle, or that it shows no wall.
fn place(flat: &Flat, x: usize, y: usize) -> String {
    let d = &flat.dissection;
    let Some(arc_mm) = d.arc_mm_of_column(x, &flat.path) else {
        return "outside the flat wall".into();
    };
    let row = y.saturating_sub(d.plot.y);
    let degrees = (row as f64 + 0.5) * d.scale.around_deg_per_px;
    let wall = if d.map.at(x, y).is_some() {
        "click to look at it"
    } else {
        "no wall found here"
    };
    format!("{arc_mm:.1} mm along, {degrees:.0}° around: {wall}")
}
