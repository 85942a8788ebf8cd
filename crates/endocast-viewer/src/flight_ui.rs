//! The panel's flight tools: planning the centred path between two points picked in the slices
//! (or from the eye, or to the farthest point) into key frames, and exporting the flight (a
//! film with progress and cancel; a path file, ours or 3D Slicer Markups, also read back as key
//! frames). Every long task runs off the UI thread.

use crate::export::{write_flight_path, ExportEnd, FilmExport, FilmOptions};
use crate::jobs::{Job, Notify, Polled};
use crate::planner::{key_look, read_key_frames, start_planning, PlannedFlight};
use crate::session::Session;
use endocast_core::navigate::PathEnd;
use endocast_io::route_file::read_target;
use glam::DVec3;
use std::path::Path;
use std::sync::Arc;

/// What a click in a slice does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) enum SliceClick {
    /// Jump the camera there.
    #[default]
    Jump,
    /// Set the path's start.
    Start,
    /// Set the path's end.
    End,
}

/// The flight tools' state.
pub(crate) struct FlightTools {
    /// What a click in a slice does.
    pub slice_click: SliceClick,
    start_mm: Option<DVec3>,
    end_mm: Option<DVec3>,
    planning: Option<Job<Result<PlannedFlight, String>>>,
    export: Option<FilmExport>,
    film_path: String,
    film: FilmOptions,
    path_file: String,
    /// What the last jump did, for the status line.
    said: Option<String>,
}

impl Default for FlightTools {
    fn default() -> Self {
        Self {
            slice_click: SliceClick::Jump,
            start_mm: None,
            end_mm: None,
            planning: None,
            export: None,
            film_path: "endocast-flight.mp4".into(),
            film: FilmOptions::default(),
            path_file: "endocast-flight.mrk.json".into(),
            said: None,
        }
    }
}

impl FlightTools {
    /// A click at `p_mm` in a slice: a jump (into the nearest lumen; what happened is said by
    /// the next [`FlightTools::poll`]), or the path's start or end.
    pub(crate) fn slice_clicked(&mut self, session: &mut Session, p_mm: DVec3) {
        match self.slice_click {
            SliceClick::Jump => self.said = session.jump_to(p_mm),
            SliceClick::Start => self.start_mm = Some(p_mm),
            SliceClick::End => self.end_mm = Some(p_mm),
        }
    }

    /// The path's start and end picked so far.
    pub(crate) fn ends(&self) -> [Option<DVec3>; 2] {
        [self.start_mm, self.end_mm]
    }

    /// Picks up finished jobs: a planned flight becomes the key frames (the camera goes to the
    /// first); returns a line for the status bar when something ended.
    pub(crate) fn poll(&mut self, session: &mut Session) -> Option<String> {
        if let Some(said) = self.said.take() {
            return Some(said);
        }
        if let Some(job) = &self.planning {
            let planned = match job.poll() {
                Polled::Running => None,
                Polled::Done(result) => Some(result),
                Polled::Lost => Some(Err("planning stopped".into())),
            };
            if let Some(result) = planned {
                self.planning = None;
                return Some(match result {
                    Ok(flight) => load_flight(session, flight),
                    Err(e) => e,
                });
            }
        }
        let ended = self.export.as_ref().and_then(FilmExport::poll)?;
        self.export = None;
        Some(match ended {
            ExportEnd::Written(path) => format!("wrote {}", path.display()),
            ExportEnd::Cancelled => "export cancelled".into(),
            ExportEnd::Failed(e) => e,
        })
    }

    /// The path section: slice-click mode, start and end, planning.
    pub(crate) fn path_ui(&mut self, ui: &mut egui::Ui, session: &Session) -> Option<String> {
        ui.horizontal(|ui| {
            ui.label("slice click:");
            ui.radio_value(&mut self.slice_click, SliceClick::Jump, "jump");
            ui.radio_value(&mut self.slice_click, SliceClick::Start, "start");
            ui.radio_value(&mut self.slice_click, SliceClick::End, "end");
        });
        let eye = session.fly_camera().eye_mm();
        for (name, point) in [("start", &mut self.start_mm), ("end", &mut self.end_mm)] {
            ui.horizontal(|ui| {
                let text = point.map_or("—".into(), |p| {
                    format!("{:.0}, {:.0}, {:.0}", p.x, p.y, p.z)
                });
                ui.label(format!("{name}: {text}"));
                if ui.small_button("= eye").clicked() {
                    *point = Some(eye);
                }
            });
        }
        if self.planning.is_some() {
            ui.horizontal(|ui| {
                ui.spinner();
                ui.label("planning the centreline…");
            });
            return None;
        }
        let mut end = None;
        ui.horizontal(|ui| {
            if ui
                .add_enabled(
                    self.end_mm.is_some(),
                    egui::Button::new("Plan start to end"),
                )
                .clicked()
            {
                end = self.end_mm.map(PathEnd::Point);
            }
            if ui.button("Plan to the farthest").clicked() {
                end = Some(PathEnd::Farthest);
            }
        });
        let end = end?;
        let start = self.start_mm.unwrap_or(eye);
        match start_planning(session, start, end, repaint(ui)) {
            Ok(job) => {
                self.planning = Some(job);
                None
            }
            Err(e) => Some(e),
        }
    }

    /// The export section: the film (its file, size, rate and step; progress, time left and
    /// cancel) and the path file, written or read back. The rows stay where they are whether a
    /// film is being made or not, so that a click never lands on a row that moved.
    pub(crate) fn export_ui(&mut self, ui: &mut egui::Ui, session: &mut Session) -> Option<String> {
        let mut message = None;
        let filming = self.export.is_some();
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut self.film_path).desired_width(170.0))
                .on_hover_text(".mp4, .gif, or a folder for PNG frames");
            if ui
                .add_enabled(!filming, egui::Button::new("Film"))
                .clicked()
            {
                let path = Path::new(self.film_path.trim());
                match FilmExport::start(session, path, &self.film, repaint(ui)) {
                    Ok(export) => self.export = Some(export),
                    Err(e) => message = Some(e),
                }
            }
        });
        film_options_ui(ui, &mut self.film);
        ui.horizontal(|ui| {
            let (done, total) = self.export.as_ref().map_or((0, 0), FilmExport::progress);
            let share = done as f32 / total.max(1) as f32;
            let text = match &self.export {
                Some(export) => match export.time_left() {
                    Some(left) => format!("{done} / {total} · {:.0} s left", left.as_secs_f64()),
                    None => format!("{done} / {total} frames"),
                },
                None => "no film being made".into(),
            };
            ui.add(
                egui::ProgressBar::new(share)
                    .text(text)
                    .desired_width(180.0),
            );
            if ui
                .add_enabled(filming, egui::Button::new("Cancel"))
                .clicked()
            {
                if let Some(export) = &self.export {
                    export.cancel();
                }
            }
        });
        ui.horizontal(|ui| {
            ui.add(egui::TextEdit::singleline(&mut self.path_file).desired_width(170.0))
                .on_hover_text(".mrk.json: a 3D Slicer curve; .json: the key frames");
            if ui.button("Write path").clicked() {
                let path = Path::new(self.path_file.trim());
                message = Some(match write_flight_path(session, path) {
                    Ok(()) => format!("wrote {} (endocast fly --path reads it)", path.display()),
                    Err(e) => e,
                });
            }
            if ui.button("Read path").clicked() {
                message = Some(read_flight_path(session, Path::new(self.path_file.trim())));
            }
        });
        message
    }
}

/// Makes `flight` the key frames and goes to the first; says what was loaded.
fn load_flight(session: &mut Session, flight: PlannedFlight) -> String {
    let keys = flight.key_frames.len();
    session.set_key_frames(flight.key_frames);
    session.go_to_key_frame(0);
    format!(
        "planned {:.0} mm (narrowest {:.1} mm from the wall): {keys} key frames, P plays",
        flight.length_mm, flight.min_radius_mm
    )
}

/// The film's size, rate and step.
fn film_options_ui(ui: &mut egui::Ui, film: &mut FilmOptions) {
    ui.horizontal(|ui| {
        ui.add(
            egui::DragValue::new(&mut film.size[0])
                .range(16..=4096)
                .suffix(" w"),
        );
        ui.add(
            egui::DragValue::new(&mut film.size[1])
                .range(16..=4096)
                .suffix(" h"),
        );
        ui.add(
            egui::DragValue::new(&mut film.fps)
                .range(1.0..=120.0)
                .suffix(" fps"),
        );
        ui.add(
            egui::DragValue::new(&mut film.step_mm)
                .range(0.05..=100.0)
                .speed(0.05)
                .suffix(" mm/frame"),
        );
    });
}

/// Replaces the key frames by the path in `file` (ours or 3D Slicer Markups) and goes to the
/// first; says what was read, or why not.
pub(crate) fn read_flight_path(session: &mut Session, file: &Path) -> String {
    let target = match read_target(file) {
        Ok(target) => target,
        Err(e) => return e.to_string(),
    };
    match read_key_frames(file, key_look(session)) {
        Ok(keys) => {
            let count = keys.len();
            session.set_key_frames(keys);
            session.go_to_key_frame(0);
            session.set_target(target);
            let ringed = if target.is_some() {
                ", its target ringed"
            } else {
                ""
            };
            format!(
                "read {}: {count} key frames{ringed}, P plays",
                file.display()
            )
        }
        Err(e) => e,
    }
}

/// Asks `ui`'s window to repaint (from a job's thread).
fn repaint(ui: &egui::Ui) -> Notify {
    let ctx = ui.ctx().clone();
    Arc::new(move || ctx.request_repaint())
}
