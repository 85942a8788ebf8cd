//! The transfer function's colours, in a strip under the histogram painted with the colour at
//! each value, a handle under each colour point. Click a handle to choose its colour (egui's
//! colour picker, in the row below); drag it along the values; double-click the strip to add a
//! point there, coloured as the strip was; right-click a handle to remove it (one stays).

use crate::tf_editor::{insert_point, move_point};
use egui::{Color32, Pos2, Rect, Sense, Stroke, Vec2};
use endocast_core::render::TransferFunction;

/// Height of the strip, points.
const HEIGHT: f32 = 12.0;
/// Height of the handles under it, points.
const HANDLE: f32 = 7.0;
/// How near (points, along the values) the pointer must be to a handle to take it.
const GRAB: f32 = 6.0;
/// Pieces the strip is painted in.
const PIECES: usize = 96;

/// The strip's value axis.
struct Axis {
    rect: Rect,
    lo: f64,
    span: f64,
}

impl Axis {
    fn x(&self, value: f64) -> f32 {
        let t = ((value - self.lo) / self.span).clamp(0.0, 1.0) as f32;
        self.rect.left() + t * self.rect.width()
    }

    fn value(&self, x: f32) -> f64 {
        let t = f64::from((x - self.rect.left()) / self.rect.width()).clamp(0.0, 1.0);
        self.lo + t * self.span
    }

    /// The colour point whose handle is nearest `x`, within [`GRAB`].
    fn nearest(&self, points: &[(f64, [f32; 3])], x: f32) -> Option<usize> {
        points
            .iter()
            .map(|p| (self.x(p.0) - x).abs())
            .enumerate()
            .filter(|&(_, d)| d <= GRAB)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    }
}

/// Draws the colour strip of `tf` over `(lo, hi)` and applies the user's edits to it.
pub(crate) fn colour_strip_ui(ui: &mut egui::Ui, (lo, hi): (f64, f64), tf: &mut TransferFunction) {
    let size = Vec2::new(ui.available_width(), HEIGHT + HANDLE);
    let (response, painter) = ui.allocate_painter(size, Sense::click_and_drag());
    let axis = Axis {
        rect: Rect::from_min_size(response.rect.min, Vec2::new(size.x, HEIGHT)),
        lo,
        span: (hi - lo).max(1e-9),
    };
    paint_strip(&painter, &axis, tf);
    let mut points = tf.color_points().to_vec();
    let selected_id = ui.id().with("tf colour selected");
    let grabbed_id = ui.id().with("tf colour grabbed");
    let mut selected: Option<usize> = ui.data(|d| d.get_temp(selected_id)).flatten();
    let mut changed = false;
    if let Some(pos) = response.interact_pointer_pos() {
        if response.drag_started() {
            let pressed = ui.input(|i| i.pointer.press_origin()).unwrap_or(pos);
            let grabbed = axis.nearest(&points, pressed.x);
            ui.data_mut(|d| d.insert_temp(grabbed_id, grabbed));
            selected = grabbed.or(selected);
        } else if response.dragged() {
            let grabbed = ui
                .data(|d| d.get_temp::<Option<usize>>(grabbed_id))
                .flatten();
            if let Some(i) = grabbed.filter(|&i| i < points.len()) {
                let colour = points[i].1;
                changed = move_point(&mut points, i, (axis.value(pos.x), colour));
            }
        } else if response.double_clicked() {
            let value = axis.value(pos.x);
            selected = Some(insert_point(&mut points, (value, tf.color_at(value))));
            changed = true;
        } else if response.secondary_clicked() {
            if let Some(i) = axis.nearest(&points, pos.x).filter(|_| points.len() > 1) {
                points.remove(i);
                (selected, changed) = (None, true);
            }
        } else if response.clicked() {
            selected = axis.nearest(&points, pos.x);
        }
    }
    let selected = selected.filter(|&i| i < points.len());
    paint_handles(&painter, &axis, &points, selected);
    if let Some(i) = selected {
        ui.horizontal(|ui| {
            changed |= egui::color_picker::color_edit_button_rgb(ui, &mut points[i].1).changed();
            ui.label(format!("colour at {:.0}", points[i].0));
        });
    }
    ui.data_mut(|d| d.insert_temp(selected_id, selected));
    if changed {
        if let Ok(edited) = TransferFunction::from_points(tf.opacity_points(), &points) {
            *tf = edited;
        }
    }
}

/// The strip: the colour at each piece's middle value.
fn paint_strip(painter: &egui::Painter, axis: &Axis, tf: &TransferFunction) {
    let r = axis.rect;
    let w = r.width() / PIECES as f32;
    for k in 0..PIECES {
        let x = r.left() + k as f32 * w;
        let piece = Rect::from_min_max(Pos2::new(x, r.top()), Pos2::new(x + w + 0.5, r.bottom()));
        painter.rect_filled(piece, 0.0, colour32(tf.color_at(axis.value(x + w / 2.0))));
    }
}

/// A triangle under the strip at each colour point, filled with its colour, outlined white
/// when selected.
fn paint_handles(
    painter: &egui::Painter,
    axis: &Axis,
    points: &[(f64, [f32; 3])],
    selected: Option<usize>,
) {
    let top = axis.rect.bottom();
    for (i, &(value, rgb)) in points.iter().enumerate() {
        let x = axis.x(value);
        let outline = if selected == Some(i) {
            Color32::WHITE
        } else {
            Color32::from_gray(120)
        };
        painter.add(egui::Shape::convex_polygon(
            vec![
                Pos2::new(x, top),
                Pos2::new(x + HANDLE * 0.6, top + HANDLE),
                Pos2::new(x - HANDLE * 0.6, top + HANDLE),
            ],
            colour32(rgb),
            Stroke::new(1.0, outline),
        ));
    }
}

/// A display colour from components in [0, 1].
fn colour32(rgb: [f32; 3]) -> Color32 {
    let [r, g, b] = rgb.map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
    Color32::from_rgb(r, g, b)
}
