//! Drawing and measuring on the tissue in the window: the tools (look, label a point, draw a
//! stroke by dragging, measure with two clicks), the list in the panel, and the decals on the
//! shown frame — each drawn only where that frame sees the surface it was put on.

use crate::mark_tool::Tool;
use crate::session::Session;
use crate::state::Ready;
use crate::worker::Delivered;
use egui::{Align2, Color32, Pos2, Rect, Response, Stroke, Vec2};
use endocast_core::annotate::{draw, draw_target, Annotation, DrawOptions, Shape, SurfaceView};
use endocast_core::views::Image;
use glam::DVec3;

/// The pixel of the view under `pos`.
fn pixel(rect: Rect, pos: Pos2, ppp: f64) -> [usize; 2] {
    let x = (f64::from(pos.x - rect.min.x) * ppp).max(0.0) as usize;
    let y = (f64::from(pos.y - rect.min.y) * ppp).max(0.0) as usize;
    [x, y]
}

/// Handles the view's input when a marking tool is active; false when the look tool should
/// (the camera is flown as usual).
pub(crate) fn view_input(response: &Response, ready: &mut Ready, rect: Rect, ppp: f64) -> bool {
    let tools = &mut ready.marks;
    let session = &mut ready.session;
    let at = response.interact_pointer_pos().map(|p| pixel(rect, p, ppp));
    match tools.tool {
        Tool::Look => return false,
        Tool::Label => {
            if let (true, Some([x, y])) = (response.clicked(), at) {
                session.annotate_pixel(x, y, &tools.label);
            }
        }
        Tool::Draw => {
            if let (true, Some([x, y])) = (response.dragged() || response.clicked(), at) {
                session.stroke_to_pixel(x, y);
            }
            if response.drag_stopped() || response.clicked() {
                session.finish_stroke(&tools.label);
            }
        }
        Tool::Measure => {
            if let (true, Some(p)) = (response.clicked(), at) {
                match tools.measure_from.take() {
                    Some(first) => {
                        session.measure_pixels(first, p);
                    }
                    None => tools.measure_from = Some(p),
                }
            }
        }
    }
    true
}

/// While a measurement waits for its second point: a line from the first to the pointer, and
/// the distance between the surface points under them with how much deeper along the view the
/// second lies (two points at very different depths look close on the screen).
pub(crate) fn rubber_band(ui: &egui::Ui, response: &Response, ready: &Ready, rect: Rect, ppp: f64) {
    let (Some(first), Some(hover)) = (ready.marks.measure_from, response.hover_pos()) else {
        return;
    };
    let start = rect.min + Vec2::new(first[0] as f32, first[1] as f32) / ppp as f32;
    let painter = ui.painter_at(rect);
    painter.line_segment([start, hover], Stroke::new(1.5, BAND_COLOR));
    let [x, y] = pixel(rect, hover, ppp);
    let session = &ready.session;
    let camera = session.fly_camera();
    let depth = |p: DVec3| (p - camera.eye_mm()).dot(camera.forward());
    let text = match (
        session.surface_point(first[0], first[1]),
        session.surface_point(x, y),
    ) {
        (Some(a), Some(b)) => format!(
            "{:.1} mm · {:+.1} mm deeper",
            a.distance(b),
            depth(b) - depth(a)
        ),
        _ => "no surface under the pointer".into(),
    };
    let font = egui::FontId::proportional(14.0);
    painter.text(
        hover + Vec2::new(12.0, -12.0),
        Align2::LEFT_BOTTOM,
        text,
        font,
        BAND_COLOR,
    );
}

/// The measurement's line while it is placed.
const BAND_COLOR: Color32 = Color32::from_rgb(255, 220, 60);

/// The tools and the list of annotations, for the control panel.
pub(crate) fn marks_ui(ui: &mut egui::Ui, ready: &mut Ready) {
    let tools = &mut ready.marks;
    ui.horizontal(|ui| {
        for (tool, name) in [
            (Tool::Look, "look"),
            (Tool::Label, "label"),
            (Tool::Draw, "draw"),
            (Tool::Measure, "measure"),
        ] {
            if ui.selectable_label(tools.tool == tool, name).clicked() {
                tools.tool = tool;
                tools.measure_from = None;
            }
        }
    });
    ui.horizontal(|ui| {
        ui.label("label");
        ui.text_edit_singleline(&mut tools.label);
    });
    if tools.measure_from.is_some() {
        ui.label("click the second point");
    }
    let mut delete = None;
    for a in ready.session.annotations() {
        ui.horizontal(|ui| {
            ui.label(describe(a));
            if ui.small_button("delete").clicked() {
                delete = Some(a.id);
            }
        });
    }
    if let Some(id) = delete {
        ready.session.delete_annotation(id);
    }
}

/// One line about an annotation for the list.
fn describe(a: &Annotation) -> String {
    let p = a.anchor();
    let at = format!("({:.1}, {:.1}, {:.1})", p.x, p.y, p.z);
    match &a.shape {
        Shape::Point(_) => format!("{} {} {at}", a.id, a.label),
        Shape::Stroke(points) => format!("{} stroke {} · {} points", a.id, a.label, points.len()),
        Shape::Distance(..) => format!("{} {} {at}", a.id, a.caption()),
    }
}

/// The delivered frame's picture with the annotations, and the stroke being drawn in white,
/// drawn where that frame sees their tissue, and the target ringed.
pub(crate) fn with_marks(session: &Session, frame: &Delivered) -> Image {
    let mut image = frame.image.clone();
    let spacing = session.scene().volume().geometry().spacing_mm();
    let view = SurfaceView::new(&frame.camera, &frame.depth_mm, spacing);
    let options = DrawOptions::default();
    draw(&mut image, &view, session.annotations(), &options);
    if let [_, ..] = session.stroke_in_progress() {
        let mut stroke = Annotation::new(Shape::Stroke(session.stroke_in_progress().to_vec()));
        stroke.color = [255; 3];
        draw(&mut image, &view, [&stroke], &options);
    }
    if let Some(target) = session.target() {
        draw_target(&mut image, &view, target);
    }
    image
}
