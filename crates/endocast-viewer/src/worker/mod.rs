//! The render worker: a thread that owns the [`Prepared`] renderer and renders the latest view
//! the UI asked for through the library's progressive driver, so the UI never waits for a frame.
//!
//! [`RenderWorker::submit`] bumps a shared generation counter and leaves the view in a one-slot
//! mailbox (older requests are dropped: only the newest view matters). The frame in flight sees
//! the counter change after its next tile and is abandoned. While the camera moves the driver
//! starts at a reduced quality; once it stands still it refines to the full frame and then
//! accumulates jittered stills. Every finished level replaces the shown [`Delivered`] frame and
//! wakes the UI through a callback.

use crate::geometry::SceneRef;
use crate::jobs::Notify;
mod look_frames;

use endocast_core::camera::StereoRig;
use endocast_core::look::Look;
use endocast_core::render::progressive::{progressive, PreviewPlanner, ProgressiveOptions, Stage};
use endocast_core::render::{
    Camera, Cancelled, Filter, Frame, Layers, Prepared, Progress, Quality, RenderOptions,
    RenderSettings, Renderer,
};
use endocast_core::views::stereo::{combine, StereoOutput};
use endocast_core::views::{lens_marks, Image};
use endocast_io::Limits;
use look_frames::{render_look, LookPass};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard, PoisonError};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Hands a finished stage of a frame to the UI: its quality, image, depths and render time.
pub(crate) type Deliver<'a> = dyn Fn(Stage, Image, &[f32], Duration) + 'a;

/// Frames averaged into the still when the view stands (the full frame included where the
/// still is trilinear; B-spline stills average this many frames of the spline after it).
pub const STILL_FRAMES: usize = 8;

/// The time the first preview after an input may take: a mode whose quarter-resolution frame
/// is predicted to take longer starts at an eighth of the resolution.
pub const PREVIEW_BUDGET: Duration = Duration::from_millis(25);

/// What the UI wants on screen.
#[derive(Debug, Clone, PartialEq)]
pub struct View {
    /// The camera, image size included.
    pub camera: Camera,
    /// The render settings.
    pub settings: RenderSettings,
    /// A red/cyan anaglyph of two off-axis eyes instead of one image.
    pub stereo: Option<StereoRig>,
    /// The camera is moving: render a quick preview first and no still.
    pub moving: bool,
    /// Geometry drawn with the scan.
    pub scene: SceneRef,
    /// The endoscope's clinical or realistic look instead of the renderer's own image (with
    /// stereo on, in both eyes).
    pub look: Option<Look>,
    /// How the still's frames after the full frame reconstruct the volume (B-splines fall
    /// back to trilinear where their coefficients would not fit the memory).
    pub still_filter: Filter,
}

/// A finished frame of some view.
#[derive(Debug, Clone)]
pub struct Delivered {
    /// The generation of the view it shows.
    pub generation: u64,
    /// Which level it is.
    pub stage: Stage,
    /// The picture (RGB, over the settings' background).
    pub image: Image,
    /// Distance to the first isosurface hit per pixel, mm (NaN where none; the left eye's in
    /// stereo).
    pub depth_mm: Vec<f32>,
    /// The camera it was rendered for.
    pub camera: Camera,
    /// Time the renderer took for this level.
    pub render_time: Duration,
    /// Time from the request to this level's delivery.
    pub since_request: Duration,
}

/// The one-slot mailbox, the shown frame and the worker's state.
struct Shared {
    generation: AtomicU64,
    stop: AtomicBool,
    request: Mutex<Option<Request>>,
    wake: Condvar,
    latest: Mutex<Latest>,
    delivered: Condvar,
    on_frame: Box<dyn Fn() + Send + Sync>,
}

struct Request {
    generation: u64,
    view: View,
    at: Instant,
}

#[derive(Default)]
struct Latest {
    frame: Option<Delivered>,
    error: Option<String>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    // A panic in the worker is a bug already reported; the data is still the last good frame.
    m.lock().unwrap_or_else(PoisonError::into_inner)
}

/// The handle of the render thread; dropping it stops the thread.
pub struct RenderWorker {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
}

impl std::fmt::Debug for RenderWorker {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RenderWorker")
            .field("generation", &self.generation())
            .finish()
    }
}

impl RenderWorker {
    /// Starts the thread rendering with `renderer`; `on_frame` is called (from the worker) after
    /// every delivered frame, e.g. to ask the UI to repaint.
    pub fn start(renderer: Arc<Renderer>, on_frame: impl Fn() + Send + Sync + 'static) -> Self {
        let shared = Arc::new(Shared {
            generation: AtomicU64::new(0),
            stop: AtomicBool::new(false),
            request: Mutex::new(None),
            wake: Condvar::new(),
            latest: Mutex::new(Latest::default()),
            delivered: Condvar::new(),
            on_frame: Box::new(on_frame),
        });
        let worker = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("endocast-render".into())
            .spawn(move || run(&worker, &renderer))
            .ok();
        Self { shared, thread }
    }

    /// Asks for `view`, superseding whatever is being rendered; returns its generation.
    pub fn submit(&self, view: View) -> u64 {
        let mut slot = lock(&self.shared.request);
        let generation = self.shared.generation.fetch_add(1, Ordering::AcqRel) + 1;
        *slot = Some(Request {
            generation,
            view,
            at: Instant::now(),
        });
        self.shared.wake.notify_one();
        generation
    }

    /// Calls the worker's `on_frame` callback (for other threads that have something to show,
    /// e.g. a lumen found).
    pub fn notifier(&self) -> Notify {
        let shared = Arc::clone(&self.shared);
        Arc::new(move || (shared.on_frame)())
    }

    /// The generation of the newest request.
    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::Acquire)
    }

    /// The newest delivered frame, if any.
    pub fn latest(&self) -> Option<Delivered> {
        lock(&self.shared.latest).frame.clone()
    }

    /// Calls `f` with the newest delivered frame without copying it.
    pub fn with_latest<R>(&self, f: impl FnOnce(Option<&Delivered>) -> R) -> R {
        f(lock(&self.shared.latest).frame.as_ref())
    }

    /// The last settings error (e.g. an isovalue out of range), cleared by the next good frame.
    pub fn error(&self) -> Option<String> {
        lock(&self.shared.latest).error.clone()
    }

    /// Waits up to `timeout` for a frame of `generation` or newer that `accept` takes; returns
    /// it, or `None` on timeout.
    pub fn wait_for(
        &self,
        generation: u64,
        timeout: Duration,
        accept: impl Fn(&Delivered) -> bool,
    ) -> Option<Delivered> {
        let deadline = Instant::now() + timeout;
        let mut latest = lock(&self.shared.latest);
        loop {
            if let Some(frame) = &latest.frame {
                if frame.generation >= generation && accept(frame) {
                    return Some(frame.clone());
                }
            }
            let left = deadline.checked_duration_since(Instant::now())?;
            latest = self
                .shared
                .delivered
                .wait_timeout(latest, left)
                .unwrap_or_else(PoisonError::into_inner)
                .0;
        }
    }
}

impl Drop for RenderWorker {
    fn drop(&mut self) {
        self.shared.stop.store(true, Ordering::Release);
        // Supersede the frame in flight so the thread notices at once.
        self.shared.generation.fetch_add(1, Ordering::AcqRel);
        self.shared.wake.notify_one();
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}

/// The worker's loop: wait for a request, render it level by level until superseded.
fn run(shared: &Shared, renderer: &Arc<Renderer>) {
    let mut prepared: Option<Prepared> = None;
    let mut scene = SceneRef::default();
    let mut planner = PreviewPlanner::default();
    let mut look_pass = LookPass::default();
    // Read once: the memory limit comes from /proc and the cgroup files.
    let limits = Limits::default();
    let mut warned = false;
    while let Some(request) = next_request(shared) {
        let requested = request.view.still_filter;
        let still_filter = still_filter(&limits, renderer, requested, &mut warned);
        if let Some(look) = &request.view.look {
            let superseded = || shared.generation.load(Ordering::Acquire) != request.generation;
            let deliver = deliverer(shared, &request);
            let view = &request.view;
            let looks = (look, still_filter);
            if let Err(e) =
                render_look(&mut look_pass, renderer, view, looks, &superseded, &deliver)
            {
                lock(&shared.latest).error = Some(e);
                (shared.on_frame)();
            }
            continue;
        }
        let settings = &request.view.settings;
        let ready = match prepared.as_mut() {
            Some(p) if p.settings() == settings => Ok(()),
            Some(p) => p.update(settings),
            None => renderer.prepare(settings).map(|p| prepared = Some(p)),
        };
        if let Err(e) = ready {
            lock(&shared.latest).error = Some(e.to_string());
            (shared.on_frame)();
            continue;
        }
        if let Some(p) = &mut prepared {
            if request.view.scene != scene {
                scene = request.view.scene.clone();
                p.set_scene(scene.0.clone());
            }
        }
        if let Some(p) = &prepared {
            // A superseded frame simply ends; the next request is already waiting.
            let _ = render_request(shared, p, &request, &mut planner, still_filter);
        }
    }
}

/// The filter of the stills of a standing view: `requested`, or trilinear (and a warning, the
/// first time, `warned` after it) where the B-spline's coefficients would not fit `limits`.
fn still_filter(
    limits: &Limits,
    renderer: &Renderer,
    requested: Filter,
    warned: &mut bool,
) -> Filter {
    let voxels = renderer.volume().voxels().len();
    let (filter, warning) = limits.still_filter(requested, voxels);
    if let Some(warning) = warning.filter(|_| !*warned) {
        eprintln!("warning: {warning}");
        *warned = true;
    }
    filter
}

/// Blocks until a request is waiting (and takes it) or the worker is told to stop.
fn next_request(shared: &Shared) -> Option<Request> {
    let mut slot = lock(&shared.request);
    loop {
        if shared.stop.load(Ordering::Acquire) {
            return None;
        }
        if let Some(request) = slot.take() {
            return Some(request);
        }
        slot = shared
            .wake
            .wait(slot)
            .unwrap_or_else(PoisonError::into_inner);
    }
}

/// Hands a finished level of `request`'s frame to the UI: the shown frame and a wake-up.
fn deliverer<'a>(
    shared: &'a Shared,
    request: &'a Request,
) -> impl Fn(Stage, Image, &[f32], Duration) + 'a {
    move |stage: Stage, mut image: Image, depth_mm: &[f32], time: Duration| {
        // The cube's faces and the panorama's directions labelled, as every front end shows them.
        lens_marks::draw(&mut image, &request.view.camera);
        let frame = Delivered {
            generation: request.generation,
            stage,
            image,
            depth_mm: depth_mm.to_vec(),
            camera: request.view.camera,
            render_time: time,
            since_request: request.at.elapsed(),
        };
        let mut latest = lock(&shared.latest);
        latest.frame = Some(frame);
        latest.error = None;
        drop(latest);
        shared.delivered.notify_all();
        (shared.on_frame)();
    }
}

fn render_request(
    shared: &Shared,
    prepared: &Prepared,
    request: &Request,
    planner: &mut PreviewPlanner,
    still_filter: Filter,
) -> Result<(), Cancelled> {
    let view = &request.view;
    let deliver = deliverer(shared, request);
    let background = view.settings.background;
    match view.stereo {
        None => {
            let options = ProgressiveOptions {
                previews: if view.moving {
                    planner.previews(view.camera.size(), PREVIEW_BUDGET)
                } else {
                    vec![Quality::Half]
                },
                still_frames: if view.moving { 1 } else { STILL_FRAMES },
                layers: Layers::NONE,
                still_filter,
            };
            progressive(
                prepared,
                &view.camera,
                &shared.generation,
                request.generation,
                &options,
                |stage, frame| {
                    planner.observe(stage, frame);
                    if let Ok(image) = Image::from_frame(frame, background) {
                        deliver(stage, image, &frame.depth_mm, frame.stats.time);
                    }
                },
            )
        }
        Some(rig) => render_anaglyph(shared, prepared, request, &rig, planner, &deliver),
    }
}

/// Stereo: both eyes at a preview level (a quarter, or an eighth where the planner predicts a
/// pair of quarters over the budget), then at full quality, each pair combined into a red/cyan
/// anaglyph.
fn render_anaglyph(
    shared: &Shared,
    prepared: &Prepared,
    request: &Request,
    rig: &StereoRig,
    planner: &mut PreviewPlanner,
    deliver: &Deliver<'_>,
) -> Result<(), Cancelled> {
    let Ok(eyes) = rig.eyes(&request.view.camera) else {
        lock(&shared.latest).error = Some("this lens has no stereo eyes".into());
        return Err(Cancelled);
    };
    let cancel = AtomicBool::new(false);
    let watch = |_: Progress| {
        if shared.generation.load(Ordering::Acquire) != request.generation {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let background = request.view.settings.background;
    let size = request.view.camera.size();
    let preview = planner.previews(size, PREVIEW_BUDGET / 2)[0];
    for (quality, stage) in [
        (preview, Stage::Preview(preview)),
        (Quality::Full, Stage::Full),
    ] {
        let options = RenderOptions::new()
            .quality(quality)
            .cancel(&cancel)
            .progress(&watch);
        let start = Instant::now();
        let mut frames = [Frame::default(), Frame::default()];
        for (eye, frame) in eyes.iter().zip(&mut frames) {
            prepared.render_with(eye, &options, frame)?;
            planner.observe(stage, frame);
        }
        let images = frames
            .iter()
            .map(|f| Image::from_frame(f, background))
            .collect::<Result<Vec<_>, _>>();
        let combined = images.and_then(|i| combine(&i[0], &i[1], StereoOutput::RedCyan));
        if let Ok(image) = combined {
            deliver(stage, image, &frames[0].depth_mm, start.elapsed());
        }
    }
    Ok(())
}
