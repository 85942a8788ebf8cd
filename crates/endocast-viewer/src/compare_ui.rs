//! The second scan's view beside the endoscope ([`Compare`]): opened from `--compare` or the
//! panel's "Compare" button, shown with what it is and how the scans were matched, closed by
//! its button.

use crate::compare::{Compare, CompareJob};
use crate::jobs::Polled;
use crate::scene::ScanSource;
use crate::session::Session;
use crate::view::picture_ui;
use egui::{Rect, TextureOptions};
use endocast_core::render::progressive::Stage;
use std::sync::Arc;

/// The second scan beside the first: being opened, open, or neither.
#[derive(Default)]
pub(crate) struct CompareView {
    /// What is being opened, and the job opening it.
    opening: Option<(String, CompareJob)>,
    open: Option<Compare>,
    texture: Option<egui::TextureHandle>,
    /// The frame last uploaded: its generation and stage.
    shown: Option<(u64, Stage)>,
    /// Why the camera could not be carried to the second scan, if it could not.
    error: Option<String>,
}

impl CompareView {
    /// Starts opening `source` beside `session`'s scan (replacing any second scan).
    pub fn start(&mut self, session: &Session, source: ScanSource, ctx: &egui::Context) {
        let ctx = ctx.clone();
        let label = source.label();
        let job = Compare::open(session, source, Arc::new(move || ctx.request_repaint()));
        *self = Self {
            opening: Some((label, job)),
            ..Self::default()
        };
    }

    /// Takes the opened second scan; returns a line for the status bar when opening ended.
    pub fn poll(&mut self) -> Option<String> {
        let (label, job) = self.opening.as_ref()?;
        let said = match job.poll() {
            Polled::Running => return None,
            Polled::Done(Ok(compare)) => {
                let said = format!(
                    "{label} beside: patient turned {:.0}°, its camera follows this one",
                    compare.matched().turn_deg()
                );
                self.open = Some(compare);
                said
            }
            Polled::Done(Err(e)) => e,
            Polled::Lost => format!("opening {label} stopped"),
        };
        self.opening = None;
        Some(said)
    }

    /// Whether the second view takes part of the window (open or being opened).
    pub fn is_shown(&self) -> bool {
        self.opening.is_some() || self.open.is_some()
    }

    /// Whether nothing is left to wait for: no second scan, or its view shown at full
    /// resolution (a `--screenshot` waits for it).
    pub fn settled(&self) -> bool {
        let full = matches!(self.shown, Some((_, Stage::Full | Stage::Still(_))));
        self.opening.is_none() && (self.open.is_none() || full)
    }

    /// The second scan, once open.
    pub fn compare(&self) -> Option<&Compare> {
        self.open.as_ref()
    }
}

/// Draws the second view in `ui`, its camera following `session`'s.
pub(crate) fn compare_ui(ui: &mut egui::Ui, view: &mut CompareView, session: &Session) {
    if let Some((label, _)) = &view.opening {
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("opening {label} and matching it with this scan…"));
        });
        return;
    }
    let Some(compare) = &mut view.open else {
        return;
    };
    let mut close = false;
    ui.horizontal(|ui| {
        ui.label(format!(
            "{} · follows this camera",
            compare.scene().source.label()
        ));
        close = ui.small_button("Close").clicked();
    });
    let rect = ui.available_rect_before_wrap();
    let ppp = f64::from(ui.ctx().pixels_per_point());
    let size = [rect.width(), rect.height()].map(|n| (f64::from(n) * ppp).round() as usize);
    view.error = compare.follow(session, size).err();
    show_frame(ui, view, rect);
    if close {
        *view = CompareView::default();
    }
}

/// Uploads the second view's newest frame when it is new and draws it, aspect kept, in `rect`.
fn show_frame(ui: &egui::Ui, view: &mut CompareView, rect: Rect) {
    let Some(compare) = &view.open else {
        return;
    };
    let update = compare.worker().with_latest(|f| {
        let f = f?;
        if view.shown == Some((f.generation, f.stage)) {
            return None;
        }
        let [w, h] = [f.image.width(), f.image.height()];
        let image = egui::ColorImage::from_rgb([w, h], f.image.rgb());
        Some((f.generation, f.stage, image))
    });
    if let Some((generation, stage, image)) = update {
        view.shown = Some((generation, stage));
        match &mut view.texture {
            Some(t) => t.set(image, TextureOptions::LINEAR),
            None => {
                let texture = ui
                    .ctx()
                    .load_texture("compare", image, TextureOptions::LINEAR);
                view.texture = Some(texture);
            }
        }
    }
    let error = view.error.clone().or_else(|| compare.worker().error());
    picture_ui(ui, view.texture.as_ref(), rect, error);
}
