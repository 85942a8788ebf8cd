//! The progressive driver of an interactive view: for one camera and settings it delivers a
//! quarter-resolution frame, then a half, then the full one, then ever better stills
//! (averages of jittered frames), and gives up as soon as the view changes.
//!
//! The front end bumps a shared *generation* counter whenever the camera or the settings
//! change; the worker that owns the [`Prepared`] renderer reads the counter together with the
//! view it renders and passes that value on. After every finished tile the driver compares the
//! counter with it and, once they differ, sets the render's cancel flag: the tiles not yet
//! started return at once, so the frame in flight is dropped within about one tile's time.
//!
//! ```
//! use endocast_core::phantom::{self, PhantomOptions};
//! use endocast_core::render::progressive::{progressive, ProgressiveOptions, Stage};
//! use endocast_core::render::{Camera, Mode, RenderSettings, Renderer};
//! use glam::DVec3;
//! use std::sync::atomic::AtomicU64;
//! use std::sync::Arc;
//!
//! let (volume, shell) = phantom::sphere_shell(&PhantomOptions { size: 32, ..Default::default() });
//! let centre_mm = volume.geometry().world_of(shell.centre_vox);
//! let mut settings = RenderSettings::default();
//! (settings.mode, settings.iso_hu) = (Mode::Iso, -480.0);
//! let prepared = Arc::new(Renderer::new(volume)).prepare(&settings).unwrap();
//! let camera = Camera::look_at(centre_mm, centre_mm + DVec3::Z, DVec3::Y, 90.0, [32, 32]).unwrap();
//! let generation = AtomicU64::new(0);
//! let mut stages = Vec::new();
//! let options = ProgressiveOptions { still_frames: 3, ..ProgressiveOptions::default() };
//! progressive(&prepared, &camera, &generation, 0, &options, |stage, frame| {
//!     assert_eq!([frame.width, frame.height], [32, 32]);
//!     stages.push(stage);
//! })
//! .unwrap();
//! assert_eq!(stages.last(), Some(&Stage::Still(3)));
//! ```

use super::frame::{Frame, Layers};
use super::options::{Cancelled, Filter, Progress, Quality, RenderOptions};
use super::still::Still;
use super::{Camera, Prepared};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;

/// A finished level the driver delivers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// A reduced-quality frame, upsampled to the full size.
    Preview(Quality),
    /// The full-quality frame, as [`Prepared::render`] makes it.
    Full,
    /// The average of this many jittered full-quality frames: with the trilinear filter 2 or
    /// more, the first being the full frame; with B-splines 1 or more, all the spline's.
    Still(usize),
}

/// What the driver renders.
#[derive(Debug, Clone, PartialEq)]
pub struct ProgressiveOptions {
    /// The reduced levels before the full frame, in order (default quarter, then half).
    pub previews: Vec<Quality>,
    /// Frames averaged into the last still, the full frame included (default 8; 1 or 0: no
    /// still after the full frame).
    pub still_frames: usize,
    /// Optional layers of every frame (default none; a still's are its first frame's).
    pub layers: Layers,
    /// How the still's frames reconstruct the volume (default trilinear; the
    /// previews and the full frame are always trilinear).
    pub still_filter: Filter,
}

impl Default for ProgressiveOptions {
    fn default() -> Self {
        Self {
            previews: vec![Quality::Quarter, Quality::Half],
            still_frames: 8,
            layers: Layers::NONE,
            still_filter: Filter::Trilinear,
        }
    }
}

/// Renders `camera`'s view with `prepared` level by level — the previews, the full frame, then
/// stills of 2, 3, … `still_frames` frames (B-spline stills start again: 1, 2, …
/// `still_frames` frames of the spline) — handing each finished one to `deliver`, as long as
/// `generation` still holds `seen` (the value read with the view). Returns [`Cancelled`] as soon
/// as it changes: before a level starts, or through the cancel flag of the level in flight.
pub fn progressive(
    prepared: &Prepared,
    camera: &Camera,
    generation: &AtomicU64,
    seen: u64,
    options: &ProgressiveOptions,
    mut deliver: impl FnMut(Stage, &Frame),
) -> Result<(), Cancelled> {
    let cancel = AtomicBool::new(false);
    let changed = || generation.load(Ordering::Acquire) != seen;
    let watch = |_: Progress| {
        if changed() {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let base = RenderOptions::new()
        .layers(options.layers)
        .cancel(&cancel)
        .progress(&watch);
    let check = || if changed() { Err(Cancelled) } else { Ok(()) };
    let mut frame = Frame::default();
    for &quality in &options.previews {
        check()?;
        prepared.render_with(camera, &base.quality(quality), &mut frame)?;
        deliver(Stage::Preview(quality), &frame);
    }
    check()?;
    prepared.render_with(camera, &base, &mut frame)?;
    deliver(Stage::Full, &frame);
    let mut still = Still::new();
    if options.still_filter == Filter::Trilinear {
        still.add(&frame);
    }
    let still_options = base.filter(options.still_filter);
    while options.still_frames > 1 && still.frames() < options.still_frames {
        check()?;
        still.render_next(prepared, camera, &still_options)?;
        deliver(Stage::Still(still.frames()), still.frame());
    }
    Ok(())
}

/// Picks the previews of a moving view from what the last frames cost, so that the first
/// picture after an input arrives within a time budget whatever the mode: a cheap opaque wall
/// starts at a quarter of the resolution, an expensive translucent view at an eighth.
#[derive(Debug, Clone, Copy, Default)]
pub struct PreviewPlanner {
    /// Wall seconds per cast pixel of the last frame observed (none before the first).
    seconds_per_pixel: Option<f64>,
}

impl PreviewPlanner {
    /// Learns the cost of a delivered frame rendered at `quality` (its time over the pixels
    /// cast at that level). Stills say nothing new and are ignored.
    pub fn observe(&mut self, stage: Stage, frame: &Frame) {
        let quality = match stage {
            Stage::Preview(quality) => quality,
            Stage::Full => Quality::Full,
            Stage::Still(_) => return,
        };
        let [w, h] = quality.reduced_size([frame.width, frame.height]);
        let seconds = frame.stats.time.as_secs_f64();
        if w * h > 0 && seconds.is_finite() && seconds > 0.0 {
            self.seconds_per_pixel = Some(seconds / (w * h) as f64);
        }
    }

    /// The predicted wall time of a frame of `size` at `quality` (none before the first
    /// observation).
    pub fn predict(&self, quality: Quality, size: [usize; 2]) -> Option<Duration> {
        let [w, h] = quality.reduced_size(size);
        let seconds = self.seconds_per_pixel? * (w * h) as f64;
        Duration::try_from_secs_f64(seconds).ok()
    }

    /// The previews before the full frame of a moving view of `size`: quarter then half, led
    /// by an eighth when a quarter is predicted to take longer than `budget`.
    pub fn previews(&self, size: [usize; 2], budget: Duration) -> Vec<Quality> {
        let slow = self
            .predict(Quality::Quarter, size)
            .is_some_and(|t| t > budget);
        let mut previews = vec![Quality::Quarter, Quality::Half];
        if slow {
            previews.insert(0, Quality::Eighth);
        }
        previews
    }
}
