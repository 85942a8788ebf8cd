//! The window: the endoscopic view large in the middle, the three slices through the camera on
//! the right, the control panel on the left and the frame time and quality at the bottom.
//! [`ViewerApp::frame_ui`] draws one UI frame on any [`egui::Context`], so tests run it headlessly
//! with synthetic input; [`run`] puts it in a native window (eframe, OpenGL).

use crate::case::Autosave;
use crate::case_choice::{choose_case, default_case_path, CaseChoice};
use crate::compare::Compare;
use crate::compare_ui::{compare_ui, CompareView};
use crate::flight_ui::FlightTools;
use crate::geometry_ui::MeshLoader;
use crate::jobs::Polled;
use crate::loading::{Loading, Request};
use crate::mark_tool::MarkTool;
use crate::overview::OverviewView;
use crate::panel::controls_ui;
use crate::review::ReviewTools;
use crate::scene::ScanSource;
use crate::session::Session;
use crate::slice_viewer::{slice_viewer_ui, SliceViewer};
use crate::slices::{SliceClicked, SlicesView};
use crate::state::{Action, Ready};
use crate::view::view_ui;
use endocast_core::look::LookKind;
use endocast_core::pose::Pose;
use endocast_core::presets::Preset;
use endocast_core::render::progressive::Stage;
use endocast_core::views::slices::Plane;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long a status message is shown as new.
const STALE_MESSAGE: Duration = Duration::from_secs(15);

/// How often the case is autosaved when it changed.
pub const AUTOSAVE_INTERVAL: Duration = Duration::from_secs(10);

/// What to open and how.
#[derive(Debug, Clone)]
pub struct ViewerOptions {
    /// The scan.
    pub source: ScanSource,
    /// The procedure's defaults.
    pub preset: Option<&'static Preset>,
    /// The starting camera; `None`: inside the preset's largest lumen.
    pub pose: Option<Pose>,
    /// A case file to reopen (its scan replaces `source`) and to save to.
    pub case: Option<PathBuf>,
    /// Write a screenshot of the window here once the view has refined, then quit.
    pub screenshot: Option<PathBuf>,
    /// Called with the session when the screenshot is taken (e.g. to print what it resolved).
    pub on_screenshot: Option<ScreenshotHook>,
    /// The endoscope's look to start with; `None`: the preset's (or the case's).
    pub look: Option<LookKind>,
    /// A slice to show large beside the endoscope from the start; `None`: the endoscope alone.
    pub layout: Option<Plane>,
    /// A second scan of the patient (prone beside supine) to show beside the endoscope, its
    /// camera following the first's; `None`: none.
    pub compare: Option<ScanSource>,
}

/// What to do with the session when `--screenshot` grabs the window.
#[derive(Clone)]
pub struct ScreenshotHook(pub Arc<dyn Fn(&Session) + Send + Sync>);

impl std::fmt::Debug for ScreenshotHook {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ScreenshotHook")
    }
}

/// The application.
pub struct ViewerApp {
    ctx: egui::Context,
    options: ViewerOptions,
    loading: Option<Loading>,
    ready: Option<Ready>,
    /// One line for the status bar: the last error or what was saved.
    message: String,
    /// The message as last drawn and when it first was (older ones are greyed).
    message_since: (String, Instant),
    /// The path typed in "Open".
    open_path: String,
    screenshot_requested: bool,
    /// Where the session being loaded will save, and what to say about it.
    case_choice: Option<CaseChoice>,
}

impl ViewerApp {
    /// The application on `ctx`, starting to load `options`' scan (or case).
    pub fn new(ctx: egui::Context, options: ViewerOptions) -> Self {
        let mut app = Self {
            ctx,
            open_path: String::new(),
            loading: None,
            ready: None,
            message: String::new(),
            message_since: (String::new(), Instant::now()),
            screenshot_requested: false,
            case_choice: None,
            options: options.clone(),
        };
        app.start_loading(options.source, options.case);
        app
    }

    /// Starts reading `source` (or the scan of the case file `case`, or the case already saved
    /// beside the scan: see [`choose_case`]) in the background; the current session stays
    /// usable meanwhile and if it fails.
    pub fn start_loading(&mut self, source: ScanSource, case: Option<PathBuf>) {
        let choice = choose_case(&source, case);
        let request = Request {
            source,
            case: choice.open.clone(),
            preset: self.options.preset,
            pose: self.options.pose,
        };
        self.loading = Some(Loading::start(request, &self.ctx));
        self.case_choice = Some(choice);
    }

    /// The open session, once loaded.
    pub fn session(&self) -> Option<&Session> {
        self.ready.as_ref().map(|r| &r.session)
    }

    /// The open session, mutably.
    pub fn session_mut(&mut self) -> Option<&mut Session> {
        self.ready.as_mut().map(|r| &mut r.session)
    }

    /// The second scan beside the first (`--compare`, or the panel's "Compare"), once open.
    pub fn compare(&self) -> Option<&Compare> {
        self.ready.as_ref().and_then(|r| r.compare.compare())
    }

    /// Whether a scan is being read.
    pub fn is_loading(&self) -> bool {
        self.loading.is_some()
    }

    /// The status line's message (the last error, or what was saved).
    pub fn message(&self) -> &str {
        &self.message
    }

    /// The virtual dissection (its flat image once made), once a scan is open.
    pub fn dissection(&self) -> Option<&crate::dissection::DissectionTools> {
        self.ready.as_ref().map(|r| &r.dissection.tools)
    }

    /// Whether the scan shown is cleansed of tagged fluid, and whether a switch is being made.
    pub fn cleansing(&self) -> Option<(bool, bool)> {
        self.ready
            .as_ref()
            .map(|r| (r.cleanse.is_on(), r.cleanse.running()))
    }

    /// Where the case is (auto)saved.
    pub fn case_path(&self) -> Option<PathBuf> {
        self.ready.as_ref().map(|r| r.autosave.path().to_owned())
    }

    /// Draws one frame of the UI on `ctx` and acts on its input.
    pub fn frame_ui(&mut self, ctx: &egui::Context) {
        self.poll_loading();
        egui::TopBottomPanel::bottom("status").show(ctx, |ui| self.status_ui(ui));
        if let Some(ready) = &mut self.ready {
            let mut action = None;
            // Along the bottom, under the side panels too: the flat wall is long.
            let flat_said =
                crate::dissection_ui::flat_view_ui(ctx, &mut ready.dissection, &mut ready.session);
            egui::SidePanel::left("controls")
                .resizable(false)
                .exact_width(290.0)
                .show(ctx, |ui| {
                    egui::ScrollArea::vertical().show(ui, |ui| {
                        action = controls_ui(ui, ready, &mut self.open_path);
                    });
                });
            egui::SidePanel::right("slices")
                .resizable(false)
                .exact_width(250.0)
                .show(ctx, |ui| side_ui(ui, ready));
            if ready.compare.is_shown() {
                egui::SidePanel::right("compare")
                    .resizable(false)
                    .exact_width(ctx.available_rect().width() / 2.0)
                    .frame(egui::Frame::NONE.fill(egui::Color32::BLACK))
                    .show(ctx, |ui| compare_ui(ui, &mut ready.compare, &ready.session));
            }
            if let Some(viewer) = &mut ready.large_slice {
                // The rest of the window shared between the large slice and the endoscope.
                egui::SidePanel::right("large slice")
                    .resizable(false)
                    .exact_width(ctx.available_rect().width() / 2.0)
                    .frame(egui::Frame::NONE.fill(egui::Color32::from_gray(24)))
                    .show(ctx, |ui| {
                        slice_viewer_ui(ui, viewer, &mut ready.session, &mut ready.tools)
                    });
            }
            egui::CentralPanel::default()
                .frame(egui::Frame::NONE.fill(egui::Color32::BLACK))
                .show(ctx, |ui| view_ui(ui, ready));
            if let Some(action) = action {
                self.act(action);
            }
            if let Some(said) = flat_said {
                self.message = said;
            }
            self.poll_tasks();
            self.autosave(false);
        } else {
            egui::CentralPanel::default().show(ctx, |ui| {
                ui.heading("endocast");
                if let Some(loading) = &self.loading {
                    ui.horizontal(|ui| loading.ui(ui));
                }
                ui.label(&self.message);
            });
        }
        self.screenshot(ctx);
    }

    fn poll_loading(&mut self) {
        let Some(loading) = &self.loading else {
            return;
        };
        match loading.poll() {
            None => {
                self.ctx.request_repaint_after(Duration::from_millis(200));
            }
            Some(Err(e)) => {
                self.message = e;
                self.loading = None;
            }
            Some(Ok((mut session, case, problems))) => {
                self.message = format!("opened {}", loading.what);
                for problem in problems {
                    self.message += &format!("; mesh not read: {problem}");
                }
                let choice = self.case_choice.take();
                if let Some(note) = choice.as_ref().and_then(|c| c.note.as_ref()) {
                    self.message += &format!("; {note}");
                }
                if let Some(look) = self.options.look {
                    session.controls.look = look;
                }
                let path = match (case, choice) {
                    (Some(path), _) => path,
                    (None, Some(choice)) => choice.save_to,
                    (None, None) => default_case_path(&session.scene().source),
                };
                // A --screenshot run only looks: it never writes a case.
                let autosave = if self.options.screenshot.is_some() {
                    Autosave::never(path)
                } else {
                    Autosave::opened(path, AUTOSAVE_INTERVAL, &session)
                };
                self.ready = Some(Ready {
                    session,
                    slices: SlicesView::default(),
                    large_slice: self.options.layout.map(SliceViewer::new),
                    overview: OverviewView::default(),
                    tools: FlightTools::default(),
                    meshes: MeshLoader::default(),
                    tasks: Vec::new(),
                    autosave,
                    view_texture: None,
                    shown: None,
                    marks: MarkTool::default(),
                    last_input: None,
                    review: ReviewTools::default(),
                    dissection: Default::default(),
                    cleanse: Default::default(),
                    compare: CompareView::default(),
                });
                self.loading = None;
                if let (Some(source), Some(ready)) = (self.options.compare.clone(), &mut self.ready)
                {
                    ready.compare.start(&ready.session, source, &self.ctx);
                }
            }
        }
    }

    /// Picks up what finished off the UI thread: planned paths, exports, screenshots.
    fn poll_tasks(&mut self) {
        let Some(ready) = &mut self.ready else {
            return;
        };
        let finished = [
            ready.tools.poll(&mut ready.session),
            ready.meshes.poll(&mut ready.session),
            ready.review.poll(),
            ready.dissection.tools.poll(),
            ready.compare.poll(),
        ];
        if let Some(message) = finished.into_iter().flatten().last() {
            self.message = message;
        }
        if let Some((said, changed)) = ready.cleanse.poll(&mut ready.session) {
            if changed {
                ready.scene_changed();
            }
            self.message = said;
        }
        ready.tasks.retain(|job| match job.poll() {
            Polled::Running => true,
            Polled::Done(message) => {
                self.message = message;
                false
            }
            Polled::Lost => false,
        });
    }

    /// The frame's status and the last message, wrapped onto more lines when long, the message
    /// greyed once it is [`STALE_MESSAGE`] old.
    fn status_ui(&mut self, ui: &mut egui::Ui) {
        if self.message_since.0 != self.message {
            self.message_since = (self.message.clone(), Instant::now());
        }
        let stale = self.message_since.1.elapsed() > STALE_MESSAGE;
        ui.horizontal_wrapped(|ui| {
            if let Some(loading) = &self.loading {
                loading.ui(ui);
            }
            if let Some(ready) = &self.ready {
                ui.label(frame_status(ready));
            }
            if !self.message.is_empty() {
                ui.separator();
                let text = egui::RichText::new(&self.message);
                ui.label(if stale { text.weak() } else { text });
            }
        });
    }

    fn act(&mut self, action: Action) {
        match action {
            Action::Open => {
                let path = PathBuf::from(self.open_path.trim());
                if path.extension().is_some_and(|e| e == "json") {
                    self.start_loading(self.options.source.clone(), Some(path));
                } else {
                    let source = ScanSource::File {
                        path,
                        series: None,
                        orientation: None,
                    };
                    self.start_loading(source, None);
                }
            }
            Action::OpenSeries(uid) => {
                let Some(ScanSource::File {
                    path, orientation, ..
                }) = self.session().map(|s| s.scene().source.clone())
                else {
                    return;
                };
                let source = ScanSource::File {
                    path,
                    series: Some(uid),
                    orientation,
                };
                self.start_loading(source, None);
            }
            Action::Reorient(code) => {
                let Some(ScanSource::File { path, series, .. }) =
                    self.session().map(|s| s.scene().source.clone())
                else {
                    return;
                };
                let source = ScanSource::File {
                    path,
                    series,
                    orientation: Some(code),
                };
                self.start_loading(source, None);
            }
            Action::Compare => {
                let path = PathBuf::from(self.open_path.trim());
                let source = ScanSource::File {
                    path,
                    series: None,
                    orientation: None,
                };
                if let Some(ready) = &mut self.ready {
                    ready.compare.start(&ready.session, source, &self.ctx);
                }
            }
            Action::SaveCase => self.autosave(true),
            Action::Message(m) => self.message = m,
        }
    }

    fn autosave(&mut self, force: bool) {
        let Some(ready) = &mut self.ready else {
            return;
        };
        match ready.autosave.tick(&ready.session, force) {
            Ok(true) if force => {
                self.message = format!("saved {}", ready.autosave.path().display());
            }
            Ok(_) => {}
            Err(e) => self.message = e.to_string(),
        }
    }

    /// With `--screenshot`: once the view has refined to its still, grab the window and quit.
    fn screenshot(&mut self, ctx: &egui::Context) {
        let Some(path) = self.options.screenshot.clone() else {
            return;
        };
        let refined = self.ready.as_ref().is_some_and(|r| {
            matches!(r.shown, Some((_, Stage::Still(n), _)) if n >= 4) && r.compare.settled()
        });
        if refined && !self.screenshot_requested {
            self.screenshot_requested = true;
            ctx.send_viewport_cmd(egui::ViewportCommand::Screenshot(egui::UserData::default()));
        }
        let image = ctx.input(|i| {
            i.raw.events.iter().find_map(|e| match e {
                egui::Event::Screenshot { image, .. } => Some(Arc::clone(image)),
                _ => None,
            })
        });
        if let Some(image) = image {
            let [w, h] = image.size;
            let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
            if let Err(e) = endocast_io::write_png_rgba8(&path, w as u32, h as u32, &rgba) {
                eprintln!("error: {e}");
            }
            if let (Some(hook), Some(ready)) = (&self.options.on_screenshot, &self.ready) {
                (hook.0)(&ready.session);
            }
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        } else if self.screenshot_requested || self.loading.is_some() || self.ready.is_some() {
            ctx.request_repaint_after(Duration::from_millis(50));
        }
        if self.ready.is_none() && self.loading.is_none() {
            // Nothing will ever be shown: report and quit.
            eprintln!("error: {}", self.message);
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }
}

/// The right column: the three slices through the camera and the overview, each `edge`
/// wide, with the camera's position and direction.
fn side_ui(ui: &mut egui::Ui, ready: &mut Ready) {
    large_slice_choice(ui, ready);
    let edge = ui.available_width().min(ui.available_height() / 4.5);
    match ready.slices.slices_ui(ui, &ready.session, edge) {
        Some(SliceClicked::Point(p)) => ready.tools.slice_clicked(&mut ready.session, p),
        Some(SliceClicked::Enlarge(plane)) => ready.large_slice = Some(SliceViewer::new(plane)),
        None => {}
    }
    let path: Vec<_> = ready
        .session
        .key_frames()
        .iter()
        .map(|k| k.eye_mm)
        .collect();
    ready
        .overview
        .overview_ui(ui, &ready.session, &path, ready.tools.ends(), edge);
    let c = ready.session.fly_camera();
    let (e, f) = (c.eye_mm(), c.forward());
    ui.label(format!("eye  {:7.1} {:7.1} {:7.1} mm", e.x, e.y, e.z));
    ui.label(format!("view {:7.2} {:7.2} {:7.2}", f.x, f.y, f.z));
}

/// "large: off axial coronal sagittal": which slice is shown large beside the endoscope.
fn large_slice_choice(ui: &mut egui::Ui, ready: &mut Ready) {
    let shown = ready.large_slice.as_ref().map(SliceViewer::plane);
    ui.horizontal(|ui| {
        ui.label("large:");
        if ui.selectable_label(shown.is_none(), "off").clicked() {
            ready.large_slice = None;
        }
        for plane in Plane::ALL {
            if ui
                .selectable_label(shown == Some(plane), plane.name())
                .clicked()
                && shown != Some(plane)
            {
                ready.large_slice = Some(SliceViewer::new(plane));
            }
        }
    });
}

/// "frame 12.3 ms · quarter · 41 ms after the request · eye (…) mm · wall 4.1 mm" (a still's
/// frame time is its frames' mean); "not in a lumen" instead of the wall's distance where the
/// eye is in tissue or outside the scan.
fn frame_status(ready: &Ready) -> String {
    let session = &ready.session;
    let frame = session.worker().with_latest(|f| {
        f.map(|f| {
            let stage = match f.stage {
                Stage::Preview(q) => q.name().to_owned(),
                Stage::Full => "full".to_owned(),
                Stage::Still(n) => format!("still ×{n}"),
            };
            // A still's time is its frames' sum.
            let frames = match f.stage {
                Stage::Still(n) => n.max(1) as f64,
                _ => 1.0,
            };
            format!(
                "frame {:.1} ms · {stage} · {:.0} ms after the request",
                f.render_time.as_secs_f64() * 1e3 / frames,
                f.since_request.as_secs_f64() * 1e3
            )
        })
    });
    let eye = session.fly_camera().eye_mm();
    let wall = match session.navigation().map(|n| n.distance_mm(eye)) {
        Some(d) if d > 0.0 => format!(" · wall {d:.1} mm"),
        _ if session.finding_lumen() => " · finding the lumen…".into(),
        _ if session.lumen_threshold().is_none() => " · no lumen for this wall".into(),
        _ => " · not in a lumen".into(),
    };
    format!(
        "{} · eye ({:.1}, {:.1}, {:.1}) mm{wall}",
        frame.unwrap_or_else(|| "rendering…".into()),
        eye.x,
        eye.y,
        eye.z
    )
}

/// Opens the window and runs until it is closed.
pub fn run(options: ViewerOptions) -> Result<(), String> {
    let native = eframe::NativeOptions {
        renderer: eframe::Renderer::Glow,
        viewport: egui::ViewportBuilder::default()
            .with_title("endocast")
            .with_inner_size([1360.0, 820.0]),
        ..eframe::NativeOptions::default()
    };
    eframe::run_native(
        "endocast",
        native,
        Box::new(|cc| Ok(Box::new(ViewerApp::new(cc.egui_ctx.clone(), options)))),
    )
    .map_err(|e| format!("cannot open the window: {e}"))
}

impl eframe::App for ViewerApp {
    fn update(&mut self, ctx: &egui::Context, _frame: &mut eframe::Frame) {
        self.frame_ui(ctx);
    }

    fn on_exit(&mut self, _gl: Option<&eframe::glow::Context>) {
        self.autosave(true);
    }
}
