//! The control panel: the scan, the view's controls with clinical defaults per preset, the
//! flight, the key frames, the marks and the case.

use crate::keys::HELP;
use crate::session::Session;
use crate::state::{Action, Ready};
use egui::{Color32, Sense, Stroke, Vec2};
use endocast_core::camera::Projection;
use endocast_core::presets;
use endocast_core::render::Mode;
use std::path::Path;

/// Draws the panel; returns what the application must do.
pub(crate) fn controls_ui(
    ui: &mut egui::Ui,
    ready: &mut Ready,
    open_path: &mut String,
) -> Option<Action> {
    let mut action = None;
    ui.heading("endocast");
    ui.label(ready.session.scene().source.label());
    ui.horizontal(|ui| {
        ui.add(
            egui::TextEdit::singleline(open_path)
                .hint_text("scan or case .json")
                .desired_width(200.0),
        );
        if ui.button("Open").clicked() {
            action = Some(Action::Open);
        }
    });
    ui.separator();
    view_controls_ui(ui, &mut ready.session);
    ui.separator();
    flight_controls_ui(ui, &mut ready.session);
    egui::CollapsingHeader::new("Key frames")
        .default_open(true)
        .show(ui, |ui| {
            if let Some(a) = key_frames_ui(ui, &mut ready.session) {
                action = Some(a);
            }
        });
    egui::CollapsingHeader::new("Marks and measurement")
        .default_open(true)
        .show(ui, |ui| {
            crate::marks::marks_ui(ui, ready);
        });
    egui::CollapsingHeader::new("Case")
        .default_open(true)
        .show(ui, |ui| {
            ui.label(format!("autosaved to {}", ready.autosave.path().display()));
            ui.horizontal(|ui| {
                if ui.button("Save case").clicked() {
                    action = Some(Action::SaveCase);
                }
                if ui.button("Screenshot").clicked() {
                    action = Some(Action::Message(screenshot(
                        &ready.session,
                        ready.autosave.path(),
                    )));
                }
            });
        });
    egui::CollapsingHeader::new("Keys").show(ui, |ui| {
        egui::Grid::new("keys").show(ui, |ui| {
            for (key, what) in HELP {
                ui.label(*key);
                ui.label(*what);
                ui.end_row();
            }
        });
    });
    action
}

fn view_controls_ui(ui: &mut egui::Ui, session: &mut Session) {
    let mut preset = session.controls.preset;
    egui::ComboBox::from_label("preset")
        .selected_text(preset.name)
        .show_ui(ui, |ui| {
            for p in presets::iter() {
                ui.selectable_value(&mut preset, p, p.name)
                    .on_hover_text(p.description);
            }
        });
    if !std::ptr::eq(preset, session.controls.preset) {
        session.apply_preset(preset);
    }
    let scene = std::sync::Arc::clone(session.scene());
    let c = &mut session.controls;
    egui::ComboBox::from_label("mode")
        .selected_text(c.mode.name())
        .show_ui(ui, |ui| {
            for m in Mode::ALL {
                ui.selectable_value(&mut c.mode, m, m.name());
            }
        });
    let (lo, hi) = scene.value_range;
    histogram_ui(ui, &scene.histogram, (lo, hi), &mut c.iso_hu);
    ui.add(egui::Slider::new(&mut c.iso_hu, lo..=hi).text("isovalue"));
    ui.add(egui::Slider::new(&mut c.iso_opacity, 0.0..=1.0).text("surface opacity"));
    egui::ComboBox::from_label("lens")
        .selected_text(c.projection.name())
        .show_ui(ui, |ui| {
            for p in [
                Projection::Pinhole,
                Projection::Equidistant,
                Projection::Equisolid,
            ] {
                ui.selectable_value(&mut c.projection, p, p.name());
            }
        });
    let (fov_lo, fov_hi) = c.projection.field_range();
    // A pinhole cannot take a fisheye's field.
    c.fov_deg = c.fov_deg.clamp(fov_lo, fov_hi);
    ui.add(egui::Slider::new(&mut c.fov_deg, fov_lo..=fov_hi.min(220.0)).text("field of view °"));
    ui.checkbox(&mut c.stereo, "stereo (red/cyan anaglyph)");
}

/// The value histogram (log counts) with the isovalue marked; a click sets the isovalue.
fn histogram_ui(ui: &mut egui::Ui, counts: &[u64], (lo, hi): (f64, f64), iso: &mut f64) {
    let (response, painter) =
        ui.allocate_painter(Vec2::new(ui.available_width(), 56.0), Sense::click());
    let rect = response.rect;
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    let top = counts
        .iter()
        .map(|&c| ((c + 1) as f64).ln())
        .fold(1.0, f64::max);
    let w = rect.width() / counts.len() as f32;
    for (i, &c) in counts.iter().enumerate() {
        let h = (((c + 1) as f64).ln() / top) as f32 * rect.height();
        let x = rect.left() + i as f32 * w;
        painter.rect_filled(
            egui::Rect::from_min_max(
                egui::pos2(x, rect.bottom() - h),
                egui::pos2(x + w, rect.bottom()),
            ),
            0.0,
            Color32::from_gray(150),
        );
    }
    let span = (hi - lo).max(1e-9);
    let x = rect.left() + ((*iso - lo) / span) as f32 * rect.width();
    painter.line_segment(
        [egui::pos2(x, rect.top()), egui::pos2(x, rect.bottom())],
        Stroke::new(2.0, Color32::from_rgb(255, 120, 80)),
    );
    if let Some(pos) = response
        .interact_pointer_pos()
        .filter(|_| response.clicked())
    {
        *iso = lo + f64::from((pos.x - rect.left()) / rect.width()) * span;
    }
}

fn flight_controls_ui(ui: &mut egui::Ui, session: &mut Session) {
    let c = &mut session.controls;
    ui.checkbox(&mut c.collision, "collision (slide along the wall)");
    ui.add(
        egui::Slider::new(&mut c.speed_mm_s, 0.5..=400.0)
            .logarithmic(true)
            .text("speed mm/s"),
    );
    let mut level = c.window.level_hu;
    let mut width = c.window.width_hu;
    ui.horizontal(|ui| {
        ui.label("slice window");
        ui.add(egui::DragValue::new(&mut level).speed(5.0).prefix("L "));
        ui.add(egui::DragValue::new(&mut width).speed(5.0).prefix("W "));
    });
    if let Ok(window) = endocast_core::views::slices::Window::new(level, width) {
        c.window = window;
    }
    if ui.button("Reset view (H)").clicked() {
        session.reset();
    }
}

fn key_frames_ui(ui: &mut egui::Ui, session: &mut Session) -> Option<Action> {
    let mut action = None;
    ui.horizontal(|ui| {
        if ui.button("Record (K)").clicked() {
            if let Err(e) = session.record_key_frame() {
                action = Some(Action::Message(e));
            }
        }
        let playing = session.playback().is_some_and(|p| p.playing);
        if ui
            .button(if playing { "Pause" } else { "Play (P)" })
            .clicked()
        {
            if session.playback().is_some_and(|p| !p.finished()) {
                session.toggle_pause();
            } else if let Err(e) = session.play() {
                action = Some(Action::Message(e));
            }
        }
        if ui.button("Stop").clicked() {
            session.stop();
        }
    });
    if let Some(p) = session.playback() {
        let (mut s, len) = (p.s_mm, p.len_mm());
        if ui
            .add(egui::Slider::new(&mut s, 0.0..=len).text("mm"))
            .changed()
        {
            session.scrub(s);
        }
    }
    let mut go = None;
    let mut delete = None;
    for (i, k) in session.key_frames().iter().enumerate() {
        ui.horizontal(|ui| {
            let e = k.eye_mm;
            if ui
                .button(format!("{} ({:.0}, {:.0}, {:.0})", i + 1, e.x, e.y, e.z))
                .clicked()
            {
                go = Some(i);
            }
            if ui.small_button("✕").clicked() {
                delete = Some(i);
            }
        });
    }
    if let Some(i) = go {
        session.go_to_key_frame(i);
    }
    if let Some(i) = delete {
        session.delete_key_frame(i);
    }
    if !session.key_frames().is_empty() && ui.button("Export key frames (path JSON)").clicked() {
        let path = Path::new("endocast-key-frames.json");
        let document = endocast_io::path_file::PathDocument {
            name: "key frames".into(),
            key_frames: session.key_frames().to_vec(),
            ..Default::default()
        };
        action = Some(Action::Message(
            match endocast_io::path_file::write_path_json(path, &document) {
                Ok(()) => format!("wrote {} (endocast fly --path reads it)", path.display()),
                Err(e) => e.to_string(),
            },
        ));
    }
    action
}

/// Renders the current view at full quality and writes it beside the case file.
fn screenshot(session: &Session, case: &Path) -> String {
    let path = case.with_extension("png");
    let written = session.screenshot().and_then(|image| {
        let [w, h] = [image.width() as u32, image.height() as u32];
        endocast_io::write_png_rgb8(&path, w, h, image.rgb()).map_err(|e| e.to_string())
    });
    match written {
        Ok(()) => format!("wrote {}", path.display()),
        Err(e) => e,
    }
}
