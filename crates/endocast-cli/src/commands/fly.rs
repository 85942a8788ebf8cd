//! `endocast fly`: a fly-through along a path (or key frames) exported as a folder of PNGs, an
//! animated GIF or an MP4, as the endoscopic view alone or as a dashboard; optionally measuring
//! how much of the lumen wall the flight showed.

use crate::input::InputArgs;
use crate::look::{set_threads, transfer_function, LookArgs};
use crate::lumen::LumenArgs;
use crate::parse::parse_size;
use crate::progress::Progress;
use crate::route::read_route;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use endocast_core::coverage::Coverage;
use endocast_core::flight::{lumen_overview, Flight, FlightOptions, Layout, Shot};
use endocast_core::navigate::{seed_voxel, Lumen};
use endocast_core::render::{RenderSettings, Renderer};
use endocast_core::views::slices::Window;
use endocast_io::video::{open_sink, VideoOptions};
use std::path::PathBuf;
use std::sync::Arc;

/// Arguments of `endocast fly`.
#[derive(Args, Debug)]
pub struct FlyArgs {
    #[command(flatten)]
    input: InputArgs,
    /// The route: a path JSON of points or key frames (docs/path-format.md, as `endocast path`
    /// writes it) or a 3D Slicer Markups curve/point list (.mrk.json).
    #[arg(long = "path", value_name = "FILE")]
    route: PathBuf,
    /// Output: a .gif, an .mp4 (needs the ffmpeg program) or a folder of PNG frames.
    #[arg(short, long)]
    pub(crate) output: PathBuf,
    /// What each frame shows.
    #[arg(long, value_enum, default_value_t = LayoutArg::Endoscope)]
    layout: LayoutArg,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    /// Distance between frames along the route, mm.
    #[arg(long, value_name = "MM", default_value_t = 1.0)]
    pub(crate) frame_step: f64,
    /// How far ahead on the path the camera looks, mm.
    #[arg(long, value_name = "MM", default_value_t = 10.0)]
    pub(crate) look_ahead: f64,
    /// Vertical field of view, degrees (key frames carry their own).
    #[arg(long, default_value_t = 90.0)]
    pub(crate) fov: f64,
    /// Endoscope image size, pixels.
    #[arg(long, value_name = "WxH", default_value = "384x384", value_parser = parse_size)]
    pub(crate) size: [usize; 2],
    /// Frames per second of the video.
    #[arg(long, default_value_t = 25.0)]
    fps: f64,
    /// Slice window centre and width, physical units (HU), for the dashboard.
    #[arg(
        long,
        value_name = "LEVEL,WIDTH",
        default_value = "-300,1400",
        allow_hyphen_values = true
    )]
    window: String,
    /// Measure the wall seen (forward, then forward + backward), print it and write
    /// OUT.coverage.json, OUT.coverage.png (unseen wall in red) and OUT.coverage.nii.gz
    /// (1 seen, 2 unseen wall voxels).
    #[arg(long)]
    coverage: bool,
}

/// The `--layout` choices.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum LayoutArg {
    /// The endoscopic view alone.
    Endoscope,
    /// The view beside the three slices and an overview of the lumen.
    Dashboard,
}

/// Runs `endocast fly`.
pub fn run(args: &FlyArgs) -> Result<()> {
    set_threads(args.look.threads)?;
    let settings = args.look.settings()?;
    if !(args.frame_step.is_finite() && args.frame_step > 0.0) {
        bail!(
            "--frame-step must be a positive number of mm, not {}",
            args.frame_step
        );
    }
    let route = read_route(&args.route)?;
    let shots = route
        .shots(args.frame_step, args.look_ahead)
        .context("cannot sample the route")?;
    let mut sink =
        open_sink(&args.output, &video_options(args.fps)).context("cannot write the video")?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let needs_lumen = args.coverage || args.layout == LayoutArg::Dashboard;
    let lumen = if needs_lumen {
        Some(lumen_at_start(args, &loaded.volume, &settings, &shots)?)
    } else {
        None
    };
    let renderer = Arc::new(Renderer::for_many_frames(loaded.volume));
    let options = FlightOptions {
        size: args.size,
        fov_deg: args.fov,
        layout: match args.layout {
            LayoutArg::Endoscope => Layout::Endoscope,
            LayoutArg::Dashboard => Layout::Dashboard,
        },
        window: parse_window(&args.window)?,
    };
    let mut flight = Flight::new(Arc::clone(&renderer), options);
    if let Some(lumen) = &lumen {
        let geometry = renderer.volume().geometry();
        if args.layout == LayoutArg::Dashboard {
            let overview = lumen_overview(lumen, geometry, flight.overview_size()?)?;
            flight = flight.with_overview(overview, route.points_mm(2.0)?)?;
        }
        if args.coverage {
            flight = flight.with_coverage(wall_coverage(lumen, geometry)?);
        }
    }
    let mut progress = Progress::new("flying", shots.len());
    let mut tfs = TfCache::default();
    for (n, shot) in shots.iter().enumerate() {
        let shot_settings = tfs.settings_for(&settings, shot)?;
        let (image, _) = flight.frame(n, shot, &shot_settings)?;
        sink.push_image(&image)?;
        progress.step();
    }
    progress.finish();
    let written = sink.finish()?;
    println!(
        "{}: {} frames along {:.1} mm ({:.1} frames/s)",
        written.display(),
        shots.len(),
        route.len_mm(),
        progress.rate()
    );
    if let Some(forward) = flight.into_coverage() {
        crate::commands::fly_coverage::report(
            args,
            &renderer,
            &route,
            &settings,
            lumen.as_ref(),
            &forward,
        )?;
    }
    Ok(())
}

fn video_options(fps: f64) -> VideoOptions {
    let mut options = VideoOptions::default();
    options.fps = fps;
    options
}

/// The lumen around the route's first camera position.
fn lumen_at_start(
    args: &FlyArgs,
    volume: &endocast_core::Volume,
    settings: &RenderSettings,
    shots: &[Shot],
) -> Result<Lumen> {
    let (threshold, side) = args
        .lumen
        .resolve(args.look.preset(), Some(settings.iso_hu))?;
    let start = shots
        .first()
        .context("the route has no frames")?
        .pose
        .eye_mm;
    let seed = seed_voxel(volume, start).context("the route starts outside the volume")?;
    Lumen::from_seed(volume, seed, threshold, side)
        .with_context(|| format!("the route's start is not in a lumen {side} {threshold}"))
}

/// Coverage of the wall voxels around `lumen` (its box grown by one voxel, where the wall is).
pub fn wall_coverage(lumen: &Lumen, geometry: &endocast_core::Geometry) -> Result<Coverage> {
    let (lo, hi) = lumen.bounds();
    let dims = geometry.dims();
    let bbox = [0, 1, 2].map(|a| lo[a].saturating_sub(1)..(hi[a] + 2).min(dims[a]));
    Coverage::new(geometry, |v| lumen.is_wall(v), &bbox).context("no wall around the lumen")
}

fn parse_window(text: &str) -> Result<Window> {
    let parts: Vec<f64> = text
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("--window expects LEVEL,WIDTH, found {text:?}"))?;
    let [level, width] = parts[..] else {
        bail!("--window expects LEVEL,WIDTH, found {text:?}");
    };
    Window::new(level, width).with_context(|| format!("--window {text:?}"))
}

/// Render settings per shot: the flight's, with a key frame's isovalue, opacity and transfer
/// function; each transfer function is read once.
#[derive(Default)]
struct TfCache {
    loaded: Vec<(String, endocast_core::render::TransferFunction)>,
}

impl TfCache {
    fn settings_for(&mut self, base: &RenderSettings, shot: &Shot) -> Result<RenderSettings> {
        let mut settings = base.clone();
        let Some(look) = &shot.look else {
            return Ok(settings);
        };
        settings.iso_hu = look.iso_hu;
        settings.iso_opacity = look.iso_opacity;
        if let Some(name) = &look.tf {
            if let Some((_, tf)) = self.loaded.iter().find(|(n, _)| n == name) {
                settings.tf = tf.clone();
            } else {
                let tf = transfer_function(name)?;
                settings.tf = tf.clone();
                self.loaded.push((name.clone(), tf));
            }
        }
        Ok(settings)
    }
}
