//! One slice large beside the endoscope, as radiology workstations show it (3D Slicer's slice
//! views, Horos's MPR): the wheel pages through parallel planes a voxel apart, Ctrl+wheel or a
//! right drag zooms, a middle or Shift drag pans, a left drag sets the window (across: width,
//! up and down: level), a double click frames the whole volume again, and a click jumps the
//! camera there (snapped into the lumen, or saying why not). The camera, the key frames' path
//! and the planned path's ends are drawn over it, crisp at any zoom.
//!
//! The slice follows the camera: its plane passes through the eye, moved by the pages turned,
//! and the pages go back to zero when the eye moves. The grey image is reformatted off the UI
//! thread at the panel's pixel size; the drawing on it is the painter's.

use crate::flight_ui::FlightTools;
use crate::jobs::{Derived, Job, Notify};
use crate::session::Session;
use egui::{Color32, Pos2, Rect, Sense, Stroke, TextureOptions, Vec2};
use endocast_core::views::slices::Window;
use endocast_core::views::slices::{framing, reformat, Plane, Slice, SliceOptions, SlicePlane};
use endocast_core::Volume;
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// Wheel travel, points, that turns one page (one notch of a mouse wheel).
const POINTS_PER_PAGE: f32 = 40.0;
/// Largest zoom over the framed volume.
const MAX_ZOOM: f64 = 32.0;
/// A left drag over this many points changes the window by its own width.
const POINTS_PER_WIDTH: f64 = 250.0;
/// A right drag up by this many points zooms in by e.
const POINTS_PER_E_ZOOM: f64 = 200.0;
/// Path points within this distance of the plane are drawn solid, mm; farther ones fade.
const NEAR_PLANE_MM: f64 = 3.0;
/// The camera's colour (as the thumbnails draw it).
const CAMERA: Color32 = Color32::from_rgb(255, 220, 0);
/// The key frames' path.
const PATH: Color32 = Color32::from_rgb(80, 200, 255);

/// What the image is reformatted for: the plane, the field's centre and edge, the image's edge
/// in pixels and the window.
type ImageKey = (SlicePlane, DVec3, f64, usize, Window);

/// The large slice: which plane, how it is paged, zoomed and panned, and its image.
pub(crate) struct SliceViewer {
    plane: Plane,
    /// Offset of the plane from the eye along its normal, mm.
    page_mm: f64,
    /// Wheel travel not yet turned into a page, points.
    wheel: f32,
    /// Magnification over the framed volume (1: the whole volume).
    zoom: f64,
    /// The field's centre moved from the framed volume's, along the image's right and down, mm.
    pan_mm: DVec2,
    /// The eye the pages were turned from.
    eye_mm: DVec3,
    image: Derived<ImageKey, Option<Slice>>,
    texture: Option<egui::TextureHandle>,
}

impl SliceViewer {
    /// `plane`, through the eye, the whole volume framed.
    pub(crate) fn new(plane: Plane) -> Self {
        Self {
            plane,
            page_mm: 0.0,
            wheel: 0.0,
            zoom: 1.0,
            pan_mm: DVec2::ZERO,
            eye_mm: DVec3::NAN,
            image: Derived::default(),
            texture: None,
        }
    }

    /// The plane shown.
    pub(crate) fn plane(&self) -> Plane {
        self.plane
    }

    /// Reformats the slice again (the scan shown changed), keeping the page, zoom and pan.
    pub(crate) fn forget_image(&mut self) {
        self.image = Derived::default();
    }
}

/// Draws the large slice in `ui`'s space and acts on its input (a click goes to `tools`, as a
/// click in the small slices does).
pub(crate) fn slice_viewer_ui(
    ui: &mut egui::Ui,
    viewer: &mut SliceViewer,
    session: &mut Session,
    tools: &mut FlightTools,
) {
    let eye = session.fly_camera().eye_mm();
    if eye != viewer.eye_mm {
        viewer.eye_mm = eye;
        viewer.page_mm = 0.0;
    }
    let area = ui.available_rect_before_wrap();
    let side = area.width().min(area.height() - 40.0).max(16.0);
    let rect = Rect::from_center_size(area.center(), Vec2::splat(side));
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    let volume = session.scene().renderer.volume();
    let step = page_step_mm(volume, viewer.plane);
    let window = &mut session.controls.window;
    let clicked = viewer.input(ui, &response, step, window);
    let px = ((side * ui.ctx().pixels_per_point()) as usize / 16 * 16).clamp(64, 1024);
    let volume = Arc::clone(&session.scene().renderer);
    viewer.refresh(ui.ctx(), volume, px, session.controls.window);
    let Some(slice) = viewer.image.shown().and_then(|(_, s)| s.as_ref()) else {
        ui.painter().rect_filled(rect, 0.0, Color32::from_gray(16));
        return;
    };
    if let Some(texture) = &viewer.texture {
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        ui.painter().image(texture.id(), rect, uv, Color32::WHITE);
    }
    let to_screen = |p: DVec3| {
        let (x, y) = slice.pixel_of(p);
        let scale = rect.width() / slice.image().width() as f32;
        rect.min + Vec2::new(x as f32, y as f32) * scale
    };
    let painter = ui.painter().with_clip_rect(rect);
    let path: Vec<DVec3> = session.key_frames().iter().map(|k| k.eye_mm).collect();
    draw_path(&painter, slice, &path, &to_screen);
    for (end, colour) in tools.ends().iter().zip([Color32::GREEN, Color32::RED]) {
        if let Some(p) = end {
            painter.circle_stroke(to_screen(*p), 5.0, Stroke::new(2.0, colour));
        }
    }
    let camera = session.fly_camera();
    draw_camera(
        &painter,
        slice,
        camera.eye_mm(),
        camera.forward(),
        &to_screen,
    );
    caption(ui, rect, viewer, &session.controls.window);
    if let Some((x, y)) = clicked {
        let scale = slice.image().width() as f64 / f64::from(rect.width());
        let p = slice.world_at(f64::from(x) * scale, f64::from(y) * scale);
        tools.slice_clicked(session, p);
    }
}

impl SliceViewer {
    /// Pages, zooms, pans and sets the window by this frame's input; returns the point of a
    /// click, in points from the image's top left.
    fn input(
        &mut self,
        ui: &egui::Ui,
        response: &egui::Response,
        step_mm: f64,
        window: &mut Window,
    ) -> Option<(f32, f32)> {
        if response.hovered() {
            // Ctrl (Cmd on a Mac) and the wheel zoom (egui counts that wheel in the raw scroll too).
            let (wheel, zoom, zooming) = ui.input(|i| {
                let zooming = i.modifiers.command;
                (i.raw_scroll_delta.y, i.zoom_delta(), zooming)
            });
            if !zooming {
                self.turn_pages(wheel, step_mm);
            }
            self.zoom_by(f64::from(zoom));
        }
        if response.double_clicked() {
            (self.zoom, self.pan_mm, self.page_mm) = (1.0, DVec2::ZERO, 0.0);
            return None;
        }
        let d = response.drag_delta();
        let shift = ui.input(|i| i.modifiers.shift);
        let mm_per_point = self.field_edge_mm_per_point(response.rect.width());
        if response.dragged_by(egui::PointerButton::Middle)
            || (shift && response.dragged_by(egui::PointerButton::Primary))
        {
            self.pan_mm -= DVec2::new(f64::from(d.x), f64::from(d.y)) * mm_per_point;
        } else if response.dragged_by(egui::PointerButton::Primary) {
            set_window(window, d);
        } else if response.dragged_by(egui::PointerButton::Secondary) {
            self.zoom_by((-f64::from(d.y) / POINTS_PER_E_ZOOM).exp());
        }
        if response.clicked() {
            let pos = response.interact_pointer_pos()?;
            let at = pos - response.rect.min;
            return Some((at.x, at.y));
        }
        None
    }

    /// Turns a page per [`POINTS_PER_PAGE`] of wheel travel (the wheel up: along the plane's
    /// [`normal`]).
    fn turn_pages(&mut self, wheel: f32, step_mm: f64) {
        self.wheel += wheel;
        let pages = (self.wheel / POINTS_PER_PAGE).trunc();
        self.wheel -= pages * POINTS_PER_PAGE;
        self.page_mm += f64::from(pages) * step_mm;
    }

    fn zoom_by(&mut self, factor: f64) {
        if factor.is_finite() && factor > 0.0 {
            self.zoom = (self.zoom * factor).clamp(1.0, MAX_ZOOM);
        }
    }

    /// Millimetres per point of the field when the image is `width` points wide (the framed
    /// edge is not known before the first image: then 1).
    fn field_edge_mm_per_point(&self, width: f32) -> f64 {
        let edge = self
            .image
            .shown()
            .map_or(f64::from(width), |((_, _, edge, _, _), _)| *edge);
        edge / f64::from(width.max(1.0))
    }

    /// Starts reformatting when the plane, field or window changed; uploads a new image.
    fn refresh(
        &mut self,
        ctx: &egui::Context,
        renderer: Arc<endocast_core::render::Renderer>,
        size_px: usize,
        window: Window,
    ) {
        let through = self.eye_mm + normal(self.plane) * self.page_mm;
        let Ok(plane) = SlicePlane::standard(self.plane, through) else {
            return;
        };
        // The field's centre lies in the plane: the framed centre moved along the plane's axes.
        let (home, home_edge) = framing(renderer.volume(), &plane);
        let centre = home + plane.right() * self.pan_mm.x + plane.down() * self.pan_mm.y;
        let key = (plane, centre, home_edge / self.zoom, size_px, window);
        let which = self.plane;
        let repaint = ctx.clone();
        let notify: Notify = Arc::new(move || repaint.request_repaint());
        let arrived = self
            .image
            .refresh(&key, |&(_, centre, edge, size_px, window)| {
                Job::spawn("large slice", notify, move || {
                    let on = SlicePlane::standard(which, centre).ok()?;
                    let mut options = SliceOptions::default();
                    (options.size_px, options.field_mm, options.window) =
                        (size_px, Some(edge), window);
                    reformat(renderer.volume(), &on, &options).ok()
                })
            });
        if let (true, Some((_, Some(slice)))) = (arrived, self.image.shown()) {
            let image = slice.image();
            let pixels = egui::ColorImage::from_rgb([image.width(), image.height()], image.rgb());
            self.texture = Some(ctx.load_texture("large slice", pixels, TextureOptions::LINEAR));
        }
    }
}

/// The unit normal of a standard plane, right × down: superior (axial), posterior (coronal) or
/// the patient's right (sagittal), the way a positive page moves.
fn normal(plane: Plane) -> DVec3 {
    let (right, down) = plane.axes();
    right.cross(down)
}

/// One page: the distance along `plane`'s normal over which the voxel index changes by one
/// along the axis that changes fastest (the slice spacing for an axial CT).
pub(crate) fn page_step_mm(volume: &Volume, plane: Plane) -> f64 {
    let along = volume
        .geometry()
        .voxel_from_world()
        .transform_vector3(normal(plane));
    1.0 / along.abs().max_element().max(1e-9)
}

/// A left drag: across sets the width, up and down the level, both by the window's own width
/// per [`POINTS_PER_WIDTH`].
fn set_window(window: &mut Window, drag: Vec2) {
    let rate = window.width_hu / POINTS_PER_WIDTH;
    let width = (window.width_hu + f64::from(drag.x) * rate).max(1.0);
    let level = window.level_hu - f64::from(drag.y) * rate;
    if let Ok(w) = Window::new(level, width) {
        *window = w;
    }
}

/// The key frames' path: each segment solid where it runs near the plane, faint farther away.
fn draw_path(
    painter: &egui::Painter,
    slice: &Slice,
    path: &[DVec3],
    to_screen: &impl Fn(DVec3) -> Pos2,
) {
    let plane = slice.plane();
    let normal = plane.right().cross(plane.down());
    for pair in path.windows(2) {
        let off = ((pair[0] + pair[1]) / 2.0 - plane.point_mm())
            .dot(normal)
            .abs();
        let alpha = if off <= NEAR_PLANE_MM { 255 } else { 70 };
        let colour = Color32::from_rgba_unmultiplied(PATH.r(), PATH.g(), PATH.b(), alpha);
        painter.line_segment(
            [to_screen(pair[0]), to_screen(pair[1])],
            Stroke::new(2.0, colour),
        );
    }
}

/// The camera: a dot at the eye and a line along the view's projection.
fn draw_camera(
    painter: &egui::Painter,
    slice: &Slice,
    eye: DVec3,
    forward: DVec3,
    to_screen: &impl Fn(DVec3) -> Pos2,
) {
    let at = to_screen(eye);
    let reach = 12.0 * slice.mm_per_px() * slice.image().width() as f64 / 256.0;
    painter.line_segment(
        [at, to_screen(eye + forward * reach)],
        Stroke::new(2.0, CAMERA),
    );
    painter.circle_filled(at, 4.0, CAMERA);
}

/// "axial · 3.0 mm below the camera · ×2.0 · W 1500 L −500" above the image, and the keys
/// below it.
fn caption(ui: &egui::Ui, rect: Rect, viewer: &SliceViewer, window: &Window) {
    let page = if viewer.page_mm.abs() < 1e-6 {
        "through the camera".to_owned()
    } else {
        format!("{:+.1} mm from the camera", viewer.page_mm)
    };
    let text = format!(
        "{} · {page} · ×{:.1} · W {:.0} L {:.0}",
        viewer.plane.name(),
        viewer.zoom,
        window.width_hu,
        window.level_hu
    );
    let painter = ui.painter();
    painter.text(
        rect.left_top() - Vec2::new(0.0, 2.0),
        egui::Align2::LEFT_BOTTOM,
        text,
        egui::FontId::proportional(13.0),
        Color32::LIGHT_GRAY,
    );
    let keys = painter.layout(
        "wheel: page · Ctrl+wheel or right drag: zoom · Shift or middle drag: pan · drag: window \
         · click: jump there · double click: the whole volume"
            .to_owned(),
        egui::FontId::proportional(11.0),
        Color32::GRAY,
        rect.width(),
    );
    painter.galley(
        rect.left_bottom() + Vec2::new(0.0, 2.0),
        keys,
        Color32::GRAY,
    );
}
