//! The value histogram with the isovalue and a simple transfer-function editor on it: the
//! opacity curve (0 at the bottom, 1 per mm at the top) drawn over the log counts. Click sets
//! the isovalue; drag a handle to move a point; double-click adds one; right-click removes one.
//! The axis' ends are labelled with their values, and the pointer's value and opacity shown.

use egui::{Align2, Color32, Painter, Pos2, Rect, Sense, Stroke, Vec2};
use endocast_core::render::TransferFunction;

/// How near (points) the pointer must be to a handle to grab it.
const GRAB: f32 = 8.0;
/// Height of the histogram, points.
const HEIGHT: f32 = 72.0;

const ISO_COLOR: Color32 = Color32::from_rgb(255, 120, 80);
const CURVE_COLOR: Color32 = Color32::from_rgb(120, 220, 255);
const LABEL_COLOR: Color32 = Color32::from_gray(200);

/// The value axis and the opacity axis of the histogram's rectangle.
#[derive(Clone, Copy)]
struct Axes {
    rect: Rect,
    lo: f64,
    span: f64,
}

impl Axes {
    fn x(&self, value: f64) -> f32 {
        let t = ((value - self.lo) / self.span).clamp(0.0, 1.0) as f32;
        self.rect.left() + t * self.rect.width()
    }

    fn point(&self, (value, opacity): (f64, f32)) -> Pos2 {
        let y = self.rect.bottom() - opacity.clamp(0.0, 1.0) * self.rect.height();
        Pos2::new(self.x(value), y)
    }

    fn value(&self, pos: Pos2) -> (f64, f32) {
        let t = f64::from((pos.x - self.rect.left()) / self.rect.width()).clamp(0.0, 1.0);
        let a = ((self.rect.bottom() - pos.y) / self.rect.height()).clamp(0.0, 1.0);
        (self.lo + t * self.span, a)
    }
}

/// Draws the histogram of `counts` over `(lo, hi)` with the isovalue and `tf`'s opacity, and
/// applies the user's clicks and drags to them; returns the histogram's response.
pub(crate) fn histogram_ui(
    ui: &mut egui::Ui,
    counts: &[u64],
    (lo, hi): (f64, f64),
    iso: &mut f64,
    tf: &mut TransferFunction,
) -> egui::Response {
    let size = Vec2::new(ui.available_width(), HEIGHT);
    let (response, painter) = ui.allocate_painter(size, Sense::click_and_drag());
    let axes = Axes {
        rect: response.rect,
        lo,
        span: (hi - lo).max(1e-9),
    };
    draw_counts(&painter, axes.rect, counts);
    let mut points = tf.opacity_points().to_vec();
    draw_curve(&painter, &axes, &points);
    let x = axes.x(*iso);
    painter.line_segment(
        [
            Pos2::new(x, axes.rect.top()),
            Pos2::new(x, axes.rect.bottom()),
        ],
        Stroke::new(2.0, ISO_COLOR),
    );
    let grabbed = ui.id().with("tf handle");
    let nearest = |points: &[(f64, f32)], pos: Pos2| {
        points
            .iter()
            .map(|&p| axes.point(p).distance(pos))
            .enumerate()
            .filter(|&(_, d)| d <= GRAB)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(i, _)| i)
    };
    draw_labels(&painter, &axes, response.hover_pos());
    let Some(pos) = response.interact_pointer_pos() else {
        return response;
    };
    let changed = if response.drag_started() {
        // The handle under the press, not under the pointer once the drag threshold is passed:
        // a quick drag would otherwise start beside the handle and miss it.
        let pressed = ui.input(|i| i.pointer.press_origin()).unwrap_or(pos);
        ui.data_mut(|d| d.insert_temp(grabbed, nearest(&points, pressed)));
        false
    } else if response.dragged() {
        match ui.data(|d| d.get_temp::<Option<usize>>(grabbed)).flatten() {
            Some(i) => move_point(&mut points, i, axes.value(pos)),
            None => false,
        }
    } else if response.double_clicked() {
        insert_point(&mut points, axes.value(pos));
        true
    } else if response.secondary_clicked() {
        match nearest(&points, pos) {
            Some(i) if points.len() > 2 => {
                points.remove(i);
                true
            }
            _ => false,
        }
    } else if response.clicked() && nearest(&points, pos).is_none() {
        *iso = axes.value(pos).0;
        false
    } else {
        false
    };
    if changed {
        if let Ok(edited) = TransferFunction::from_points(&points, tf.color_points()) {
            *tf = edited;
        }
    }
    response
}

/// Moves point `i` to `(value, y)`, kept between its neighbours' values.
pub(crate) fn move_point<T: PartialEq>(
    points: &mut [(f64, T)],
    i: usize,
    (value, y): (f64, T),
) -> bool {
    let below = i.checked_sub(1).map_or(f64::NEG_INFINITY, |j| points[j].0);
    let above = points.get(i + 1).map_or(f64::INFINITY, |p| p.0);
    let moved = (value.clamp(below, above), y);
    let changed = points[i] != moved;
    points[i] = moved;
    changed
}

/// Adds `point` in value order; returns where.
pub(crate) fn insert_point<T>(points: &mut Vec<(f64, T)>, point: (f64, T)) -> usize {
    let at = points.partition_point(|p| p.0 <= point.0);
    points.insert(at, point);
    at
}

/// The value range at the axis' ends and, under the pointer, its value and opacity.
fn draw_labels(painter: &Painter, axes: &Axes, hover: Option<Pos2>) {
    let font = egui::FontId::proportional(11.0);
    let r = axes.rect;
    let ends = [
        (r.left_bottom(), Align2::LEFT_BOTTOM, axes.lo),
        (r.right_bottom(), Align2::RIGHT_BOTTOM, axes.lo + axes.span),
    ];
    for (at, align, value) in ends {
        painter.text(at, align, format!("{value:.0}"), font.clone(), LABEL_COLOR);
    }
    if let Some(pos) = hover.filter(|p| r.contains(*p)) {
        let (value, opacity) = axes.value(pos);
        let text = format!("{value:.0} · opacity {opacity:.2}");
        painter.text(r.center_top(), Align2::CENTER_TOP, text, font, LABEL_COLOR);
    }
}

/// The log counts as grey bars.
fn draw_counts(painter: &Painter, rect: Rect, counts: &[u64]) {
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let top = counts
        .iter()
        .map(|&c| ((c + 1) as f64).ln())
        .fold(1.0, f64::max);
    let w = rect.width() / counts.len().max(1) as f32;
    for (i, &c) in counts.iter().enumerate() {
        let h = (((c + 1) as f64).ln() / top) as f32 * rect.height();
        let x = rect.left() + i as f32 * w;
        let bar = Rect::from_min_max(
            Pos2::new(x, rect.bottom() - h),
            Pos2::new(x + w, rect.bottom()),
        );
        painter.rect_filled(bar, 0.0, Color32::from_gray(110));
    }
}

/// The opacity curve and its handles, held flat beyond its end points as the renderer does.
fn draw_curve(painter: &Painter, axes: &Axes, points: &[(f64, f32)]) {
    let (Some(first), Some(last)) = (points.first(), points.last()) else {
        return;
    };
    let mut line = vec![Pos2::new(axes.rect.left(), axes.point(*first).y)];
    line.extend(points.iter().map(|&p| axes.point(p)));
    line.push(Pos2::new(axes.rect.right(), axes.point(*last).y));
    painter.add(egui::Shape::line(line, Stroke::new(1.5, CURVE_COLOR)));
    for &p in points {
        painter.circle_stroke(axes.point(p), 3.5, Stroke::new(1.5, CURVE_COLOR));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_stay_in_value_order() {
        let mut points = vec![(0.0, 0.0), (100.0, 0.5), (200.0, 1.0)];
        assert!(move_point(&mut points, 1, (250.0, 0.7)));
        assert_eq!(points[1], (200.0, 0.7));
        assert!(move_point(&mut points, 0, (-50.0, 0.1)));
        assert_eq!(points[0], (-50.0, 0.1));
        insert_point(&mut points, (50.0, 0.2));
        let values: Vec<f64> = points.iter().map(|p| p.0).collect();
        assert_eq!(values, [-50.0, 50.0, 200.0, 200.0]);
    }
}
