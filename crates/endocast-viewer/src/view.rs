//! The endoscopic view: shows the newest delivered frame, flies with the keys and the mouse,
//! and sends every change of view to the render worker.

use crate::keys::{held_motion, Commands};
use crate::session::Session;
use crate::state::Ready;
use egui::{Color32, Pos2, Rect, Sense, TextureOptions, Vec2};
use std::time::Instant;

/// The longest UI frame step the flight integrates, seconds (a stalled frame never jumps the
/// camera far).
const MAX_DT_S: f64 = 0.1;

/// Draws the view and flies the camera by this frame's input.
pub(crate) fn view_ui(ui: &mut egui::Ui, ready: &mut Ready) {
    let rect = ui.available_rect_before_wrap();
    let ppp = f64::from(ui.ctx().pixels_per_point());
    let size = [
        (f64::from(rect.width()) * ppp).round() as usize,
        (f64::from(rect.height()) * ppp).round() as usize,
    ];
    ready.session.set_view_size(size);
    let response = ui.allocate_rect(rect, Sense::click_and_drag());
    let marking = crate::marks::view_input(&response, ready, rect, ppp);
    let mut moved = false;
    if response.dragged() && !marking {
        let d = response.drag_delta();
        let fov = ready.session.controls.fov_deg.to_radians();
        let rad_per_point = fov / f64::from(rect.height().max(1.0));
        ready.session.turn(
            f64::from(d.x) * rad_per_point,
            -f64::from(d.y) * rad_per_point,
        );
        moved |= d != Vec2::ZERO;
    }
    if response.clicked() && !marking {
        if let Some(pos) = response.interact_pointer_pos() {
            moved |= click(ready, rect, pos, ppp);
        }
    }
    moved |= keyboard(ui, &mut ready.session);
    moved |= next_patch_key(ui, ready);
    if moved {
        ready.last_input = Some(Instant::now());
    }
    // Any change of view (input, a control, a jump, playback) renders at moving quality first;
    // the first UI frame without one sends the same view to refine.
    let moving = moved || ready.session.view_changed();
    ready.session.sync(moving);
    show_frame(ui, ready, rect);
    crate::marks::rubber_band(ui, &response, ready, rect, ppp);
}

/// A click in the view: turn toward the surface point there.
fn click(ready: &mut Ready, rect: Rect, pos: Pos2, ppp: f64) -> bool {
    let x = (f64::from(pos.x - rect.min.x) * ppp) as usize;
    let y = (f64::from(pos.y - rect.min.y) * ppp) as usize;
    ready.session.look_at_pixel(x, y)
}

/// Flies by the held keys and runs the pressed commands; true when the camera moved.
fn keyboard(ui: &egui::Ui, session: &mut Session) -> bool {
    if ui.ctx().wants_keyboard_input() {
        return false;
    }
    let (dt, commands) = ui.input(|i| (f64::from(i.stable_dt).min(MAX_DT_S), Commands::pressed(i)));
    let (step, roll) = ui.input(|i| held_motion(i, session.controls.speed_mm_s, dt));
    let mut moved = false;
    if step != Default::default() {
        session.stop();
        session.fly(step);
        moved = true;
    }
    if roll != 0.0 {
        session.roll(roll);
        moved = true;
    }
    moved |= run_commands(session, commands);
    if session.advance_playback(dt) {
        ui.ctx().request_repaint();
        moved = true;
    }
    if moved {
        ui.ctx().request_repaint();
    }
    moved
}

/// N: the endoscope to the next unseen patch of the review (the status bar says which); true
/// when pressed.
fn next_patch_key(ui: &egui::Ui, ready: &mut Ready) -> bool {
    if ui.ctx().wants_keyboard_input() || !ui.input(|i| i.key_pressed(egui::Key::N)) {
        return false;
    }
    ready.review.next_said_later(&mut ready.session);
    true
}

/// Acts on the command keys; true when the camera moved.
fn run_commands(session: &mut Session, c: Commands) -> bool {
    if c.record_key_frame {
        let _ = session.record_key_frame();
    }
    if c.toggle_collision {
        session.controls.collision = !session.controls.collision;
    }
    if c.faster {
        session.controls.speed_mm_s = (session.controls.speed_mm_s * 2.0).min(400.0);
    }
    if c.slower {
        session.controls.speed_mm_s = (session.controls.speed_mm_s / 2.0).max(0.5);
    }
    if c.play_pause {
        match session.playback() {
            Some(p) if !p.finished() => session.toggle_pause(),
            _ => {
                let _ = session.play();
            }
        }
    }
    if c.reset {
        session.reset();
    }
    let centred = c.centre && session.centre_in_lumen();
    c.reset || c.play_pause || centred
}

/// Uploads the newest frame when it is new and draws it, aspect kept, in `rect`.
fn show_frame(ui: &egui::Ui, ready: &mut Ready, rect: Rect) {
    let worker = ready.session.worker();
    let marks = ready.session.marks_revision();
    let update = worker.with_latest(|f| {
        let f = f?;
        if ready.shown == Some((f.generation, f.stage, marks)) {
            return None;
        }
        let shown = crate::marks::with_marks(&ready.session, f);
        let image = egui::ColorImage::from_rgb([shown.width(), shown.height()], shown.rgb());
        Some((f.generation, f.stage, image))
    });
    if let Some((generation, stage, image)) = update {
        ready.shown = Some((generation, stage, marks));
        match &mut ready.view_texture {
            Some(t) => t.set(image, TextureOptions::LINEAR),
            None => {
                ready.view_texture = Some(ui.ctx().load_texture(
                    "endoscope",
                    image,
                    TextureOptions::LINEAR,
                ));
            }
        }
    }
    picture_ui(ui, ready.view_texture.as_ref(), rect, worker.error());
}

/// Draws `texture` in `rect`, aspect kept, and `error` in red over its top left corner.
pub(crate) fn picture_ui(
    ui: &egui::Ui,
    texture: Option<&egui::TextureHandle>,
    rect: Rect,
    error: Option<String>,
) {
    if let Some(texture) = texture {
        let uv = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        let shown = fit(rect, texture.aspect_ratio());
        ui.painter().image(texture.id(), shown, uv, Color32::WHITE);
    }
    if let Some(error) = error {
        ui.painter().text(
            rect.left_top() + Vec2::splat(8.0),
            egui::Align2::LEFT_TOP,
            error,
            egui::FontId::proportional(14.0),
            Color32::LIGHT_RED,
        );
    }
}

/// The largest rectangle of `aspect` (width / height) centred in `rect`.
fn fit(rect: Rect, aspect: f32) -> Rect {
    let size = if rect.width() / rect.height().max(1.0) > aspect {
        Vec2::new(rect.height() * aspect, rect.height())
    } else {
        Vec2::new(rect.width(), rect.width() / aspect.max(1e-3))
    };
    Rect::from_center_size(rect.center(), size)
}
