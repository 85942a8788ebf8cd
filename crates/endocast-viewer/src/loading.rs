//! Opening a scan (or a case and its scan) off the UI thread, and what the window shows
//! meanwhile: what is read and for how long, for a DICOM folder how many of its files are
//! done, then the view being prepared. The window stays usable (the open session too).

use crate::case::{read_case_meshes, Case, SessionCase};
use crate::scene::{ScanSource, Scene};
use crate::session::Session;
use endocast_core::pose::Pose;
use endocast_core::presets::Preset;
use endocast_io::{Progress, ReadProgress};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Receiver, TryRecvError};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// A session opened, the case file it came from, and what of the case could not be restored
/// (a mesh file gone).
pub(crate) type Opened = (Session, Option<PathBuf>, Vec<String>);

/// What to open: a scan, or a case file and its scan.
pub(crate) struct Request {
    pub source: ScanSource,
    pub case: Option<PathBuf>,
    pub preset: Option<&'static Preset>,
    pub pose: Option<Pose>,
}

/// A scan being read in the background.
pub(crate) struct Loading {
    /// What is read, for messages.
    pub what: String,
    started: Instant,
    progress: Progress,
    /// Set once the scan is read and the view (histogram, lumen) is being prepared.
    preparing: Arc<AtomicBool>,
    result: Receiver<Result<Opened, String>>,
}

impl Loading {
    /// Starts reading `request` on a thread of its own; `ctx` is repainted when it is done.
    pub fn start(request: Request, ctx: &egui::Context) -> Self {
        let (send, result) = channel();
        let what = match &request.case {
            Some(path) => format!("case {}", path.display()),
            None => request.source.label(),
        };
        let progress = Progress::default();
        let preparing = Arc::new(AtomicBool::new(false));
        let (reader, prepared, ctx) = (progress.clone(), Arc::clone(&preparing), ctx.clone());
        std::thread::spawn(move || {
            let loaded = load(request, &reader, &prepared, &ctx);
            let _ = send.send(loaded);
            ctx.request_repaint();
        });
        Self {
            what,
            started: Instant::now(),
            progress,
            preparing,
            result,
        }
    }

    /// The session once it is open, or why it could not be; `None` while it is read.
    pub fn poll(&self) -> Option<Result<Opened, String>> {
        match self.result.try_recv() {
            Err(TryRecvError::Empty) => None,
            Err(TryRecvError::Disconnected) => Some(Err(format!("reading {} failed", self.what))),
            Ok(result) => Some(result),
        }
    }

    /// A spinner, what is being done and for how long, and a bar when the fraction is known.
    pub fn ui(&self, ui: &mut egui::Ui) {
        let (line, fraction) = status_line(
            &self.what,
            self.progress.get(),
            self.preparing.load(Ordering::Acquire),
            self.started.elapsed(),
        );
        ui.spinner();
        if let Some(fraction) = fraction {
            ui.add(
                egui::ProgressBar::new(fraction)
                    .desired_width(120.0)
                    .show_percentage(),
            );
        }
        ui.label(line);
    }
}

/// The status line of a load and its bar's fraction: "reading chest: pixels 120 / 400 files ·
/// 3.2 s", "preparing the view of chest (histogram, lumen) · 4.0 s".
pub(crate) fn status_line(
    what: &str,
    progress: Option<ReadProgress>,
    preparing: bool,
    elapsed: Duration,
) -> (String, Option<f32>) {
    let seconds = elapsed.as_secs_f64();
    if preparing {
        let line = format!("preparing the view of {what} (histogram, lumen) · {seconds:.1} s");
        return (line, None);
    }
    match progress {
        Some(p) => (
            format!(
                "reading {what}: {} {} / {} files · {seconds:.1} s",
                p.step.name(),
                p.done,
                p.total
            ),
            Some(p.fraction()),
        ),
        None => (format!("reading {what} · {seconds:.1} s"), None),
    }
}

/// Reads the scan (or the case and its scan), counting in `progress`, and opens a session on
/// it, setting `preparing` between the two.
fn load(
    request: Request,
    progress: &Progress,
    preparing: &AtomicBool,
    ctx: &egui::Context,
) -> Result<Opened, String> {
    let Request {
        source,
        case,
        preset,
        pose,
    } = request;
    let case_file = match &case {
        Some(path) => Some(Case::read(path).map_err(|e| e.to_string())?),
        None => None,
    };
    let source = case_file.as_ref().map_or(source, |c| c.scan.clone());
    let (volume, facts) = source.load_with_facts(progress)?;
    preparing.store(true, Ordering::Release);
    ctx.request_repaint();
    let scene = Arc::new(Scene::new(source, volume).with_facts(facts));
    let repaint = ctx.clone();
    let mut session = Session::new(scene, preset, pose, move || repaint.request_repaint());
    let mut problems = Vec::new();
    if let (Some(file), Some(path)) = (&case_file, &case) {
        file.apply(&mut session, path).map_err(|e| e.to_string())?;
        problems = read_case_meshes(file, &mut session);
    }
    Ok((session, case, problems))
}

#[cfg(test)]
mod tests {
    use super::*;
    use endocast_io::ReadStep;

    #[test]
    fn the_line_says_what_is_read_how_far_and_for_how_long() {
        let t = Duration::from_millis(3200);
        let (line, bar) = status_line("chest", None, false, t);
        assert_eq!((line.as_str(), bar), ("reading chest · 3.2 s", None));
        let p = ReadProgress {
            step: ReadStep::Pixels,
            done: 100,
            total: 400,
        };
        let (line, bar) = status_line("chest", Some(p), false, t);
        assert_eq!(line, "reading chest: pixels 100 / 400 files · 3.2 s");
        assert_eq!(bar, Some(0.25));
        let (line, bar) = status_line("chest", Some(p), true, t);
        assert!(line.starts_with("preparing the view of chest"), "{line}");
        assert_eq!(bar, None);
    }
}
