//! The overview: the lumen the camera is in (the study's structure while the wall is the
//! study's), seen from outside (the patient's front), with the
//! camera, its view cone and the flight's path drawn live over it. The lumen's picture is
//! rendered off the UI thread when the lumen changes; what is drawn over it follows every UI
//! frame.

use crate::jobs::{Derived, Job, Notify};
use crate::session::Session;
use egui::{Color32, Painter, Pos2, Rect, Sense, Stroke, TextureOptions, Vec2};
use endocast_core::flight::{lumen_overview, Overview};
use endocast_core::render::Camera;
use glam::DVec3;
use std::sync::Arc;

/// Edge of the overview image, pixels.
const OVERVIEW_PX: usize = 256;
/// Length of the view cone drawn, as a share of the overview's width.
const CONE_SHARE: f64 = 0.12;

const PATH_COLOR: Color32 = Color32::from_rgb(80, 200, 255);
const CAMERA_COLOR: Color32 = Color32::from_rgb(255, 220, 60);
const START_COLOR: Color32 = Color32::from_rgb(60, 220, 90);
const END_COLOR: Color32 = Color32::from_rgb(240, 70, 60);

/// The overview of the current lumen and its texture.
#[derive(Default)]
pub(crate) struct OverviewView {
    overview: Derived<u64, Option<Overview>>,
    texture: Option<egui::TextureHandle>,
}

impl OverviewView {
    /// Draws the overview `edge` points wide with the camera, its view cone, `path_mm` and the
    /// start and end picked for a new path; a note instead while there is no lumen (or it is
    /// being rendered).
    pub(crate) fn overview_ui(
        &mut self,
        ui: &mut egui::Ui,
        session: &Session,
        path_mm: &[DVec3],
        ends: [Option<DVec3>; 2],
        edge: f32,
    ) {
        self.refresh(ui.ctx(), session);
        let current = session.navigation().map(|n| n.id());
        let shown = self
            .overview
            .shown()
            .filter(|(id, _)| Some(*id) == current)
            .and_then(|(_, o)| o.as_ref());
        let (Some(overview), Some(texture)) = (shown, &self.texture) else {
            let note = if current.is_some() {
                "overview: rendering the lumen…"
            } else {
                "overview: the camera is not in a lumen"
            };
            ui.label(note);
            return;
        };
        let (response, painter) = ui.allocate_painter(Vec2::splat(edge), Sense::hover());
        let rect = response.rect;
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        painter.image(texture.id(), rect, uv, Color32::WHITE);
        let onto = OntoOverview {
            camera: &overview.camera,
            rect,
        };
        onto.path(&painter, path_mm);
        for (end, color) in ends.into_iter().zip([START_COLOR, END_COLOR]) {
            if let Some(p) = end.and_then(|p| onto.to_screen(p)) {
                painter.circle_filled(p, 4.0, color);
            }
        }
        if let Ok(camera) = session.camera() {
            onto.view_cone(&painter, &camera);
        }
        response.on_hover_text("overview: the lumen from the front, the camera and the path");
    }

    /// Starts rendering the overview when the lumen changed, and uploads a new one.
    fn refresh(&mut self, ctx: &egui::Context, session: &Session) {
        let Some(navigation) = session.navigation() else {
            return;
        };
        // While the wall is the study's, its structure (the navigable core the planner uses):
        // the lumen flooded from the eye may leak to the air around the patient (the sinuses'
        // through the nostrils) and would show the whole scan as a box.
        let study = session
            .wall_is_the_studys()
            .then(|| session.shared_study())
            .filter(|s| s.structure().is_some());
        let lumen = Arc::clone(navigation.lumen());
        let renderer = Arc::clone(&session.scene().renderer);
        let repaint = ctx.clone();
        let notify: Notify = Arc::new(move || repaint.request_repaint());
        let arrived = self.overview.refresh(&navigation.id(), |_| {
            Job::spawn("overview", notify, move || {
                let geometry = renderer.volume().geometry();
                let shown = study.as_ref().and_then(|s| s.structure()).unwrap_or(&lumen);
                lumen_overview(shown, geometry, [OVERVIEW_PX; 2]).ok()
            })
        });
        if let (true, Some((_, Some(overview)))) = (arrived, self.overview.shown()) {
            let image = &overview.image;
            let pixels = egui::ColorImage::from_rgb([image.width(), image.height()], image.rgb());
            self.texture = Some(ctx.load_texture("overview", pixels, TextureOptions::LINEAR));
        }
    }
}

/// World points onto the overview drawn in `rect`.
struct OntoOverview<'a> {
    camera: &'a Camera,
    rect: Rect,
}

impl OntoOverview<'_> {
    fn to_screen(&self, p_mm: DVec3) -> Option<Pos2> {
        let [w, h] = self.camera.size();
        let (x, y) = self.camera.project(p_mm)?;
        let (sx, sy) = (self.rect.width() / w as f32, self.rect.height() / h as f32);
        Some(self.rect.min + Vec2::new(x as f32 * sx, y as f32 * sy))
    }

    /// The path as a polyline (segments with an end behind the overview's camera left out).
    fn path(&self, painter: &Painter, path_mm: &[DVec3]) {
        for pair in path_mm.windows(2) {
            if let (Some(a), Some(b)) = (self.to_screen(pair[0]), self.to_screen(pair[1])) {
                painter.line_segment([a, b], Stroke::new(1.5, PATH_COLOR));
            }
        }
    }

    /// The eye as a dot and the view cone: the rays through the image's corners, cut at a
    /// length that reads at the overview's scale.
    fn view_cone(&self, painter: &Painter, camera: &Camera) {
        let eye_mm = camera.eye_mm();
        let Some(eye) = self.to_screen(eye_mm) else {
            return;
        };
        let width_mm = 2.0
            * (self.camera.fov_deg() / 2.0).to_radians().tan()
            * self.camera.eye_mm().distance(eye_mm);
        let reach_mm = CONE_SHARE * width_mm;
        let corners = self.cone_corners(camera, reach_mm);
        let stroke = Stroke::new(1.2, CAMERA_COLOR);
        for (i, &c) in corners.iter().enumerate() {
            painter.line_segment([eye, c], stroke);
            painter.line_segment([c, corners[(i + 1) % corners.len()]], stroke);
        }
        if let Some(ahead) = self.to_screen(eye_mm + camera.forward() * reach_mm) {
            painter.line_segment([eye, ahead], Stroke::new(2.0, CAMERA_COLOR));
        }
        painter.circle_filled(eye, 3.5, CAMERA_COLOR);
    }

    /// Where the rays through the image's corners (a fisheye's: through its edges' middles,
    /// which its circle reaches) are `reach_mm` from the eye, on the overview.
    fn cone_corners(&self, camera: &Camera, reach_mm: f64) -> Vec<Pos2> {
        let [w, h] = camera.size().map(|n| n as f64);
        let corners = [(0.0, 0.0), (w, 0.0), (w, h), (0.0, h)];
        let middles = [
            (w / 2.0, 0.5),
            (w - 0.5, h / 2.0),
            (w / 2.0, h - 0.5),
            (0.5, h / 2.0),
        ];
        let rays = |points: [(f64, f64); 4]| {
            points
                .into_iter()
                .map(|(x, y)| camera.ray(x, y))
                .collect::<Option<Vec<_>>>()
        };
        rays(corners)
            .or_else(|| rays(middles))
            .unwrap_or_default()
            .iter()
            .filter_map(|ray| self.to_screen(ray.at(reach_mm)))
            .collect()
    }
}
