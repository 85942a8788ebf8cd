//! Exporting the flight along the key frames off the UI thread, with progress and cancel: the
//! film (an animated GIF, an MP4 or a folder of PNGs, by the output's ending, through the same
//! [`Flight`] and frame sinks as `endocast fly`), and the path files `endocast fly --path`
//! reads (our path JSON with the key frames, or a 3D Slicer Markups curve of the flight).

use crate::jobs::{Job, Notify, Polled};
use crate::session::Session;
use endocast_core::flight::{Flight, FlightOptions, Layout, Route, ShotSettings};
use endocast_core::views::slices::Window;
use endocast_io::path_file::{write_path_json, PathDocument};
use endocast_io::route_file::is_markups;
use endocast_io::video::{open_sink, SinkKind, VideoOptions};
use glam::DVec3;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Spacing of the points of an exported Markups curve, mm (as `endocast path`'s default).
pub const CURVE_STEP_MM: f64 = 2.0;

/// How a film is made.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilmOptions {
    /// Size of the frames, pixels (16–4096 each). Default 384 × 384.
    pub size: [usize; 2],
    /// Frames per second, 1–120. Default 25.
    pub fps: f64,
    /// Distance between frames along the flight, mm, 0.05–100. Default 1 (as `endocast fly`).
    pub step_mm: f64,
}

impl Default for FilmOptions {
    fn default() -> Self {
        Self {
            size: [384, 384],
            fps: 25.0,
            step_mm: 1.0,
        }
    }
}

impl FilmOptions {
    /// Refuses sizes, rates and steps outside their ranges, naming the one.
    fn check(&self) -> Result<(), String> {
        if !self.size.iter().all(|n| (16..=4096).contains(n)) {
            return Err(format!(
                "film size {:?}: each side must be 16–4096 pixels",
                self.size
            ));
        }
        if !(1.0..=120.0).contains(&self.fps) {
            return Err(format!("film rate {} fps: must be 1–120", self.fps));
        }
        if !(0.05..=100.0).contains(&self.step_mm) {
            return Err(format!("film step {} mm: must be 0.05–100", self.step_mm));
        }
        Ok(())
    }
}

/// A film being rendered and written.
#[derive(Debug)]
pub struct FilmExport {
    output: PathBuf,
    done: Arc<AtomicUsize>,
    total: usize,
    cancel: Arc<AtomicBool>,
    started: Instant,
    job: Job<Result<PathBuf, String>>,
}

/// How an export ended.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ExportEnd {
    /// Written here.
    Written(PathBuf),
    /// Cancelled: a GIF or MP4 is not written (PNG frames already written stay).
    Cancelled,
    /// Failed, in words.
    Failed(String),
}

impl FilmExport {
    /// Starts filming `session`'s key frames (as they are now, at the current controls, with
    /// the geometry and the marks the view draws) into `output` (`.gif`, `.mp4`, or a folder
    /// of PNGs) as `film` says; `notify` is called after every frame. Errors (fewer than two
    /// key frames, a bad output or option) come at once.
    pub fn start(
        session: &mut Session,
        output: &Path,
        film: &FilmOptions,
        notify: Notify,
    ) -> Result<Self, String> {
        film.check()?;
        let route = Route::from_key_frames(session.key_frames().to_vec())
            .map_err(|e| format!("cannot film the key frames: {e}"))?;
        let shots = route
            .shots(film.step_mm, 1.0)
            .map_err(|e| format!("cannot sample the flight: {e}"))?;
        let mut video = VideoOptions::default();
        video.fps = film.fps;
        // A bad ending is said at once; the sink itself is made on the export's thread.
        SinkKind::for_path(output).map_err(|e| e.to_string())?;
        let path = output.to_owned();
        let options = FlightOptions {
            size: film.size,
            optics: session.controls.optics(),
            stereo: None,
            layout: Layout::Endoscope,
            window: Window::AIR_TISSUE,
        };
        let mut flight = Flight::new(Arc::clone(&session.scene().renderer), options);
        flight.set_scene(session.drawn_scene().0);
        flight.set_annotations(Some(session.marks().clone()));
        let settings = session.controls.settings();
        let (done, cancel) = (
            Arc::new(AtomicUsize::new(0)),
            Arc::new(AtomicBool::new(false)),
        );
        let (counter, stop) = (Arc::clone(&done), Arc::clone(&cancel));
        let total = shots.len();
        let job = Job::spawn("export", Arc::clone(&notify), move || {
            let mut sink = open_sink(&path, &video).map_err(|e| e.to_string())?;
            let mut looks = ShotSettings::new(settings, |spec: &str| {
                endocast_io::transfer_json::transfer_function(spec).map_err(|e| e.to_string())
            });
            for (n, shot) in shots.iter().enumerate() {
                if stop.load(Ordering::Acquire) {
                    // Dropped unfinished, the sink removes what it wrote.
                    return Err("cancelled".into());
                }
                let settings = looks.for_shot(shot)?;
                let (image, _) = flight
                    .frame(n, shot, &settings)
                    .map_err(|e| e.to_string())?;
                sink.push_image(&image).map_err(|e| e.to_string())?;
                counter.store(n + 1, Ordering::Release);
                notify();
            }
            sink.finish().map_err(|e| e.to_string())
        });
        Ok(Self {
            output: output.to_owned(),
            done,
            total,
            cancel,
            started: Instant::now(),
            job,
        })
    }

    /// Frames written so far and in all.
    pub fn progress(&self) -> (usize, usize) {
        (self.done.load(Ordering::Acquire), self.total)
    }

    /// The time the frames left will take at the pace of those written so far (`None` before
    /// the first).
    pub fn time_left(&self) -> Option<Duration> {
        let (done, total) = self.progress();
        (done > 0).then(|| self.started.elapsed() * (total - done) as u32 / done as u32)
    }

    /// Where the film goes.
    pub fn output(&self) -> &Path {
        &self.output
    }

    /// Asks the export to stop after the frame in hand (what it wrote is removed).
    pub fn cancel(&self) {
        self.cancel.store(true, Ordering::Release);
    }

    /// How it ended, once it has.
    pub fn poll(&self) -> Option<ExportEnd> {
        match self.job.poll() {
            Polled::Running => None,
            Polled::Done(Ok(path)) => Some(ExportEnd::Written(path)),
            Polled::Done(Err(_)) if self.cancel.load(Ordering::Acquire) => {
                Some(ExportEnd::Cancelled)
            }
            Polled::Done(Err(e)) => Some(ExportEnd::Failed(e)),
            Polled::Lost => Some(ExportEnd::Failed("the export stopped".into())),
        }
    }
}

/// Writes `session`'s key frames as a path file `endocast fly --path` reads: a 3D Slicer
/// Markups curve of the flight (the eye every [`CURVE_STEP_MM`]) when `output` ends in
/// `.mrk.json`, else our path JSON with the key frames themselves.
pub fn write_flight_path(session: &Session, output: &Path) -> Result<(), String> {
    let keys = session.key_frames().to_vec();
    if is_markups(output) {
        let route = Route::from_key_frames(keys).map_err(|e| e.to_string())?;
        let points: Vec<DVec3> = route.points_mm(CURVE_STEP_MM).map_err(|e| e.to_string())?;
        let name = output
            .file_name()
            .and_then(|n| n.to_str())
            .map_or("flight", |n| n.split('.').next().unwrap_or(n));
        endocast_io::markups::write_markups_curve(output, name, &points)
    } else {
        let document = PathDocument {
            name: "key frames".into(),
            key_frames: keys,
            ..PathDocument::default()
        };
        write_path_json(output, &document)
    }
    .map_err(|e| e.to_string())
}
