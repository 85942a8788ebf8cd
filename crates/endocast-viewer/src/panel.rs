//! The control panel: the scan, the view's controls with clinical defaults per preset, the
//! flight, the key frames, the marks and the case.

use crate::jobs::Job;
use crate::keys::HELP;
use crate::scene::ScanSource;
use crate::session::{Session, NO_PRESET};
use crate::state::{Action, Ready};
use crate::tf_colours::colour_strip_ui;
use crate::tf_editor::histogram_ui;
use endocast_core::camera::Projection;
use endocast_core::look::{Lighting, LookKind};
use endocast_core::navigate::LumenSide;
use endocast_core::presets;
use endocast_core::render::{Filter, Mode, PeelLayer, PeelSettings, Unpeeled};
use endocast_io::SeriesSummary;
use std::path::Path;
use std::sync::Arc;

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
                .desired_width(150.0),
        );
        if ui.button("Open").clicked() {
            action = Some(Action::Open);
        }
        let compare = ui.button("Compare").on_hover_text(
            "open the scan typed as a second scan of the patient (prone beside supine): its \
             view beside this one, its camera following this one",
        );
        if compare.clicked() {
            action = Some(Action::Compare);
        }
    });
    if let Some(uid) = series_ui(ui, &ready.session) {
        action = Some(Action::OpenSeries(uid));
    }
    if let Some(code) = orientation_ui(ui, &ready.session) {
        action = Some(Action::Reorient(code));
    }
    warnings_ui(ui, &ready.session.scene().warnings);
    crate::cleansing_ui::cleanse_ui(ui, &mut ready.cleanse, &ready.session);
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
    egui::CollapsingHeader::new("Geometry")
        .default_open(false)
        .show(ui, |ui| {
            if let Some(m) = ready.meshes.geometry_ui(ui, &mut ready.session) {
                action = Some(Action::Message(m));
            }
        });
    egui::CollapsingHeader::new("Planned path")
        .default_open(true)
        .show(ui, |ui| {
            if let Some(m) = ready.tools.path_ui(ui, &ready.session) {
                action = Some(Action::Message(m));
            }
        });
    egui::CollapsingHeader::new("Unseen patches")
        .default_open(false)
        .show(ui, |ui| {
            if let Some(m) = crate::review_ui::review_ui(&mut ready.review, ui, &mut ready.session)
            {
                action = Some(Action::Message(m));
            }
        });
    egui::CollapsingHeader::new("Virtual dissection")
        .default_open(false)
        .show(ui, |ui| {
            crate::dissection_ui::dissection_ui(&mut ready.dissection, ui, &ready.session);
        });
    egui::CollapsingHeader::new("Export the flight")
        .default_open(false)
        .show(ui, |ui| {
            if let Some(m) = ready.tools.export_ui(ui, &mut ready.session) {
                action = Some(Action::Message(m));
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
            let path = ready.autosave.path().display();
            ui.label(if ready.autosave.saves() {
                format!("autosaved to {path}")
            } else {
                format!("not saved (a --screenshot run): {path}")
            });
            ui.horizontal(|ui| {
                if ui.button("Save case").clicked() {
                    action = Some(Action::SaveCase);
                }
                if ui.button("Screenshot").clicked() {
                    let job = screenshot(ui, &ready.session, ready.autosave.path());
                    ready.tasks.push(job);
                }
            });
        });
    // One key a line, what it does wrapped under it: a table would be wider than the panel.
    egui::CollapsingHeader::new("Keys").show(ui, |ui| {
        for (key, what) in HELP {
            ui.label(egui::RichText::new(*key).strong());
            ui.indent(key, |ui| ui.label(*what));
        }
    });
    action
}

/// With a DICOM folder of several series: the one shown, and the others to choose from;
/// returns the SeriesInstanceUID chosen.
fn series_ui(ui: &mut egui::Ui, session: &Session) -> Option<String> {
    let scene = session.scene();
    if scene.series_found.len() < 2 {
        return None;
    }
    let shown = match &scene.source {
        ScanSource::File { series, .. } => series.clone(),
        ScanSource::Phantom { .. } => None,
    };
    let name = |s: &SeriesSummary| {
        let what = if s.description.is_empty() {
            &s.uid
        } else {
            &s.description
        };
        format!("{} {what} ({} images)", s.modality, s.images)
    };
    // Without a choice the reader took the largest series, listed first.
    let current = shown.or_else(|| scene.series_found.first().map(|s| s.uid.clone()));
    let mut chosen = current.clone();
    egui::ComboBox::from_label("series")
        .selected_text(
            scene
                .series_found
                .iter()
                .find(|s| Some(&s.uid) == current.as_ref())
                .map_or_else(|| "?".into(), name),
        )
        .show_ui(ui, |ui| {
            for s in &scene.series_found {
                ui.selectable_value(&mut chosen, Some(s.uid.clone()), name(s));
            }
        });
    chosen.filter(|uid| Some(uid) != current.as_ref())
}

/// The reader's warnings, folded under a header that counts them.
fn warnings_ui(ui: &mut egui::Ui, warnings: &[String]) {
    if warnings.is_empty() {
        return;
    }
    let header = format!("⚠ {} reader warning(s)", warnings.len());
    egui::CollapsingHeader::new(header)
        .default_open(false)
        .show(ui, |ui| {
            for warning in warnings {
                ui.add(egui::Label::new(warning.as_str()).wrap());
            }
        });
}

/// For a file that declares no orientation: the one in force (guessed from the anatomy or
/// given) and a button that turns the scan the other way up; returns the code asked for.
fn orientation_ui(ui: &mut egui::Ui, session: &Session) -> Option<String> {
    let scene = session.scene();
    if scene.orientation_declared {
        return None;
    }
    let code = scene.volume().geometry().orientation_code();
    let flipped: String = code
        .chars()
        .map(|c| match c {
            'S' => 'I',
            'I' => 'S',
            other => other,
        })
        .collect();
    let mut asked = None;
    ui.horizontal_wrapped(|ui| {
        ui.label(format!("orientation {code} (not in the file)"))
            .on_hover_text("guessed from the anatomy, or as given with --orientation");
        if ui
            .button("Flip upside down")
            .on_hover_text(format!("read the scan again as {flipped}"))
            .clicked()
        {
            asked = Some(flipped.clone());
        }
    });
    asked
}

fn view_controls_ui(ui: &mut egui::Ui, session: &mut Session) {
    let mut preset = session.controls.preset;
    egui::ComboBox::from_label("preset")
        .selected_text(session.controls.preset_name())
        .show_ui(ui, |ui| {
            ui.selectable_value(&mut preset, None, NO_PRESET)
                .on_hover_text("no procedure: the whole object, the wall between air and tissue");
            for p in presets::iter() {
                ui.selectable_value(&mut preset, Some(p), p.name)
                    .on_hover_text(p.description);
            }
        });
    let same = match (preset, session.controls.preset) {
        (Some(a), Some(b)) => std::ptr::eq(a, b),
        (a, b) => a.is_none() && b.is_none(),
    };
    if !same {
        session.apply_preset(preset);
    }
    let scene = Arc::clone(session.scene());
    let c = &mut session.controls;
    ui.horizontal(|ui| {
        egui::ComboBox::from_label("mode")
            .selected_text(c.mode.name())
            .show_ui(ui, |ui| {
                for m in Mode::ALL {
                    ui.selectable_value(&mut c.mode, m, m.name());
                }
            });
        // The histogram's help on a mark of its own, so that it covers no slider.
        ui.weak("(?)").on_hover_text(
            "histogram below — click: isovalue · drag a dot: opacity · double-click: add a dot · \
             right-click: remove it",
        );
    });
    let (lo, hi) = scene.value_range;
    histogram_ui(ui, &scene.histogram, (lo, hi), &mut c.iso_hu, &mut c.tf);
    colour_strip_ui(ui, (lo, hi), &mut c.tf);
    ui.add(egui::Slider::new(&mut c.iso_hu, lo..=hi).text("isovalue"));
    ui.add(egui::Slider::new(&mut c.iso_opacity, 0.0..=1.0).text("surface opacity"));
    let before = c.projection;
    egui::ComboBox::from_label("lens")
        .selected_text(c.projection.name())
        .show_ui(ui, |ui| {
            for p in [
                Projection::Pinhole,
                Projection::Equidistant,
                Projection::Equisolid,
                Projection::Cube,
                Projection::Panorama,
            ] {
                ui.selectable_value(&mut c.projection, p, p.name());
            }
        });
    // The cube's fixed 90° and the panorama's whole sphere, not the last lens's field.
    if c.projection != before {
        c.fov_deg = c.projection.default_field().unwrap_or(c.fov_deg);
    }
    let (fov_lo, fov_hi) = c.projection.field_range();
    // A pinhole cannot take a fisheye's field.
    c.fov_deg = c.fov_deg.clamp(fov_lo, fov_hi);
    ui.add(egui::Slider::new(&mut c.fov_deg, fov_lo..=fov_hi.min(220.0)).text("field of view °"));
    egui::ComboBox::from_label("look")
        .selected_text(c.look.name())
        .show_ui(ui, |ui| {
            for kind in LookKind::ALL {
                ui.selectable_value(&mut c.look, kind, kind.name());
            }
        });
    if c.look != LookKind::Plain {
        let was = matches!(c.lighting, Lighting::LitSphere(_));
        let mut ibl = was;
        ui.checkbox(&mut ibl, "image-based lighting (lit sphere)");
        if ibl != was {
            c.lighting = if ibl {
                Lighting::built_in_ibl()
            } else {
                Lighting::Phong
            };
        }
    }
    let mut spline = c.still_filter == Filter::BSpline;
    ui.checkbox(&mut spline, "B-spline stills (sharper, slower)");
    c.still_filter = if spline {
        Filter::BSpline
    } else {
        Filter::Trilinear
    };
    ui.checkbox(&mut c.stereo, "stereo (red/cyan anaglyph)");
    if c.mode == Mode::Peel {
        peel_ui(ui, &mut c.peel, c.iso_hu, (lo, hi));
    }
}

/// The depth-peeling settings (`peel` mode): which peel, its threshold and direction, how much
/// of what lies before it stays, and what rays without it show.
fn peel_ui(ui: &mut egui::Ui, peel: &mut PeelSettings, iso_hu: f64, (lo, hi): (f64, f64)) {
    let mut last = peel.layer == PeelLayer::Last;
    let mut n = match peel.layer {
        PeelLayer::Nth(n) => n,
        PeelLayer::Last => 1,
    };
    ui.horizontal(|ui| {
        ui.label("peel");
        ui.add_enabled(!last, egui::DragValue::new(&mut n).range(1..=16));
        ui.checkbox(&mut last, "last");
    });
    peel.layer = if last {
        PeelLayer::Last
    } else {
        PeelLayer::Nth(n)
    };
    let mut own = peel.threshold_hu.is_some();
    let mut threshold = peel.threshold_hu.unwrap_or(iso_hu);
    ui.horizontal(|ui| {
        ui.checkbox(&mut own, "own threshold");
        ui.add_enabled(own, egui::Slider::new(&mut threshold, lo..=hi));
    });
    peel.threshold_hu = own.then_some(threshold);
    ui.checkbox(&mut peel.falling, "count crossings into darker material");
    ui.add(egui::Slider::new(&mut peel.keep, 0.0..=1.0).text("keep in front"));
    let mut context = peel.unpeeled == Unpeeled::Context;
    ui.checkbox(&mut context, "rays without the peel show context");
    peel.unpeeled = if context {
        Unpeeled::Context
    } else {
        Unpeeled::Discard
    };
}

fn flight_controls_ui(ui: &mut egui::Ui, session: &mut Session) {
    let lumen = session.lumen_threshold();
    let c = &mut session.controls;
    ui.checkbox(&mut c.collision, "collision (slide along the wall)");
    if c.collision {
        ui.label(match lumen {
            Some((value, side)) => format!(
                "  lumen {} {value:.0} (moves with the wall)",
                if side == LumenSide::Below {
                    "below"
                } else {
                    "above"
                }
            ),
            None => "  no lumen for this wall: collision is off".into(),
        });
    }
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
    ui.horizontal(|ui| {
        if ui.button("Centre in lumen (Z)").clicked() {
            session.centre_in_lumen();
        }
        if ui.button("Reset view (H)").clicked() {
            session.reset();
        }
    });
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
    if let Some(edit) = key_frame_rows(ui, session) {
        if let Err(e) = edit.apply(session) {
            action = Some(Action::Message(e));
        }
    }
    action
}

/// What a key frame's row asks for.
enum KeyEdit {
    GoTo(usize),
    InsertBefore(usize),
    Move(usize, usize),
    Delete(usize),
    Undo,
}

impl KeyEdit {
    fn apply(self, session: &mut Session) -> Result<(), String> {
        match self {
            Self::GoTo(i) => session.go_to_key_frame(i),
            Self::InsertBefore(i) => session.insert_key_frame(i)?,
            Self::Move(from, to) => session.move_key_frame(from, to),
            Self::Delete(i) => session.delete_key_frame(i),
            Self::Undo => {
                session.undo_key_frames();
            }
        }
        Ok(())
    }
}

/// The key frames, a row each (go to it; insert the current view before it; move it up or
/// down; delete it), and Undo for the last change.
fn key_frame_rows(ui: &mut egui::Ui, session: &Session) -> Option<KeyEdit> {
    let mut edit = None;
    let n = session.key_frames().len();
    for (i, k) in session.key_frames().iter().enumerate() {
        ui.horizontal(|ui| {
            let e = k.eye_mm;
            let go = ui.button(format!("{} ({:.0}, {:.0}, {:.0})", i + 1, e.x, e.y, e.z));
            if go.on_hover_text("go to this key frame").clicked() {
                edit = Some(KeyEdit::GoTo(i));
            }
            let insert = ui
                .small_button("+")
                .on_hover_text("insert the view before it");
            if insert.clicked() {
                edit = Some(KeyEdit::InsertBefore(i));
            }
            if ui
                .add_enabled(i > 0, egui::Button::new("up").small())
                .clicked()
            {
                edit = Some(KeyEdit::Move(i, i - 1));
            }
            if ui
                .add_enabled(i + 1 < n, egui::Button::new("down").small())
                .clicked()
            {
                edit = Some(KeyEdit::Move(i, i + 1));
            }
            if ui.small_button("×").on_hover_text("delete it").clicked() {
                edit = Some(KeyEdit::Delete(i));
            }
        });
    }
    let undo = egui::Button::new("Undo key frames").small();
    if ui
        .add_enabled(session.can_undo_key_frames(), undo)
        .clicked()
    {
        edit = Some(KeyEdit::Undo);
    }
    edit
}

/// Renders the current view at full quality (with its annotations) off the UI thread and
/// writes it beside the case file; the job's result is the status line.
fn screenshot(ui: &egui::Ui, session: &Session, case: &Path) -> Job<String> {
    let path = case.with_extension("png");
    let work = session.screenshot_work();
    let ctx = ui.ctx().clone();
    Job::spawn(
        "screenshot",
        Arc::new(move || ctx.request_repaint()),
        move || {
            let written = work().and_then(|image| {
                let [w, h] = [image.width() as u32, image.height() as u32];
                endocast_io::write_png_rgb8(&path, w, h, image.rgb()).map_err(|e| e.to_string())
            });
            match written {
                Ok(()) => format!("wrote {}", path.display()),
                Err(e) => e,
            }
        },
    )
}
