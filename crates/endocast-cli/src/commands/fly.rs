//! `endocast fly`: a fly-through along a path (or key frames) exported as a folder of PNGs, an
//! animated GIF or an MP4, as the endoscopic view alone or as a dashboard; optionally measuring
//! how much of the lumen wall the flight showed.

use crate::case_args::CaseArgs;
use crate::commands::fly_coverage;
use crate::commands::fly_dataset::{self, DatasetSink};
use crate::commands::fly_frames::{self, parse_frames, FrameRange};
use crate::input::InputArgs;
use crate::look::{set_threads, transfer_function, LookArgs, ScanLook};
use crate::lumen::LumenArgs;
use crate::optics::{beside, LensArgs, StereoArgs};
use crate::parse::parse_size;
use crate::progress::Progress;
use crate::scene_args::SceneArgs;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::{Args, ValueEnum};
use endocast_core::coverage::Coverage;
use endocast_core::flight::{
    lumen_overview, wall_coverage_near, BackwardPass, Flight, FlightOptions, FlightStereo, Layout,
    Route, Shot, ShotSettings, WallSeen,
};
use endocast_core::navigate::Lumen;
use endocast_core::render::{RenderSettings, Renderer};
use endocast_core::study::{Study, LOOK_AHEAD_MM};
use endocast_core::views::slices::Window;
use endocast_core::views::stereo::StereoOutput;
use endocast_core::views::Image;
use endocast_core::Volume;
use endocast_io::route_file::read_route;
use endocast_io::video::{open_sink, FrameSink, VideoOptions};
use endocast_io::{Limits, RenderKind};
use glam::DVec3;
use std::path::{Path, PathBuf};
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
    /// Output: a .gif, an .mp4 (H.264, yuv420p) or a folder of PNG frames.
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
    #[arg(long, value_name = "MM", default_value_t = LOOK_AHEAD_MM)]
    pub(crate) look_ahead: f64,
    /// Vertical field of view, degrees (default: the preset's, else 90; fisheye 170; key frames
    /// carry their own); view height in mm for an orthographic lens; 90 (fixed) for the cube;
    /// the latitudes spanned (default 180) for the panorama, which key frames leave as it is.
    #[arg(long = "fov", value_name = "DEG")]
    fov_deg: Option<f64>,
    #[command(flatten)]
    lens: LensArgs,
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    case: CaseArgs,
    #[command(flatten)]
    stereo: StereoArgs,
    /// Endoscope image size, pixels.
    #[arg(long, value_name = "WxH", default_value = "384x384", value_parser = parse_size)]
    pub(crate) size: [usize; 2],
    /// Frames per second of the video.
    #[arg(long, default_value_t = 25.0)]
    fps: f64,
    /// Encode the MP4 with this ffmpeg program (libx264) instead of the built-in OpenH264
    /// encoder.
    #[arg(long, value_name = "PROGRAM")]
    ffmpeg: Option<PathBuf>,
    /// Slice window centre and width, physical units (HU), for the dashboard (default: the
    /// preset's, e.g. -600,1500 for bronchoscopy; else -300,1400).
    #[arg(long, value_name = "LEVEL,WIDTH", allow_hyphen_values = true)]
    window: Option<String>,
    /// Measure the wall seen (forward, then forward + backward), print it and write
    /// OUT.coverage.json, OUT.coverage.png (wall never seen in red, seen only flying back in
    /// orange) and OUT.coverage.nii.gz (1 seen flying forward, 2 seen only flying back, 3 never
    /// seen).
    #[arg(long)]
    coverage: bool,
    /// Print the result (output, frames, length, speed, coverage) as JSON on stdout.
    #[arg(long)]
    json: bool,
    /// Also write training data into FOLDER (new or empty; one with files is refused): per
    /// frame images/NNNNN.png (the frame: plain, or the look's), depth/ and depth_z/ (16-bit
    /// PNG, mm = code × depth_scale_mm, along the ray and the view axis), normals/ (camera
    /// frame, (n+1)/2), masks/ (the wall seen); the cameras as nerfstudio's transforms.json
    /// and COLMAP's text model in colmap/ (docs/dataset-format.md). A pinhole or equidistant
    /// fisheye camera, without --stereo, with --layout endoscope.
    #[arg(long, value_name = "FOLDER")]
    dataset: Option<PathBuf>,
    /// Fly only these frames, START:END (frame START to before END, from 0) or K/N (part K of
    /// N equal parts), into a folder of PNGs numbered as in the whole flight, with the same
    /// pixels; `endocast film` joins the parts' folders into the whole flight's film.
    #[arg(long, value_name = "START:END|K/N", value_parser = parse_frames)]
    frames: Option<FrameRange>,
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
    if !(args.frame_step.is_finite() && args.frame_step > 0.0) {
        bail!(
            "--frame-step must be a positive number of mm, not {}",
            args.frame_step
        );
    }
    let stereo = flight_stereo(args)?;
    if args.dataset.is_some() {
        fly_dataset::check(stereo.is_some(), args.layout == LayoutArg::Dashboard)?;
    }
    if args.frames.is_some() {
        fly_frames::check(&args.output, args.coverage, args.dataset.is_some())?;
    }
    // Per frame: the view (both eyes of a pair) and, for a dashboard, its composite image
    // (counted as one more view); checked again once the look is known.
    let views = 1 + u64::from(args.layout == LayoutArg::Dashboard);
    let check = |look| {
        let kind = RenderKind::of(look, stereo.is_some());
        args.input
            .check_frames(&args.output, args.size, kind, views)
    };
    check(None)?;
    let route = read_route(&args.route).context("cannot read the path")?;
    let shots = shots(&route, args)?;
    let frames = match args.frames {
        Some(range) => range.of(shots.len())?,
        None => 0..shots.len(),
    };
    let mut video = video_options(args);
    video.first_number = frames.start;
    let mut sinks = Sinks::open(&args.output, &video, stereo.map(|s| s.output))?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let needs_lumen = args.coverage || args.layout == LayoutArg::Dashboard;
    let first = shots.first().context("the route has no frames")?.pose;
    // The structure is searched only when the lumen is needed; else the route's first camera
    // is the start.
    let pose = (!needs_lumen).then_some(first);
    let ScanLook {
        settings,
        study,
        look,
    } = args
        .look
        .on_scan(&loaded.volume, &args.lumen, pose, args.fov_deg)?;
    study_report::say(&study);
    check(look.as_ref())?;
    let window = slice_window(args.window.as_deref(), study.window())?;
    let lumen = if needs_lumen {
        Some(lumen_at_start(&study, &loaded.volume, first.eye_mm)?)
    } else {
        None
    };
    let preset = study.preset();
    let (lo, hi) = loaded.volume.geometry().world_bounds();
    let optics = args
        .lens
        .optics(preset, look.as_ref(), args.fov_deg, 0.0, (hi - lo).length())?;
    let marks = args.case.annotations(&loaded.volume)?;
    let renderer = Arc::new(Renderer::for_many_frames(loaded.volume));
    let options = FlightOptions {
        size: args.size,
        optics,
        stereo,
        layout: match args.layout {
            LayoutArg::Endoscope => Layout::Endoscope,
            LayoutArg::Dashboard => Layout::Dashboard,
        },
        window,
    };
    let mut dataset = match &args.dataset {
        Some(folder) => Some(DatasetSink::create(folder, &renderer, &options.optics)?),
        None => None,
    };
    let mut flight = Flight::new(Arc::clone(&renderer), options.clone());
    let scene = args.scene.scene()?;
    flight.set_scene(scene);
    flight.set_look(look);
    flight.set_annotations(marks);
    flight.set_target(args.case.target(Some(&args.route))?);
    if let Some(lumen) = &lumen {
        let geometry = renderer.volume().geometry();
        if args.layout == LayoutArg::Dashboard {
            let overview = lumen_overview(lumen, geometry, flight.overview_size()?)?;
            flight = flight.with_overview(overview, route.points_mm(2.0)?)?;
        }
        if args.coverage {
            let (wall, reach) = wall_coverage_near(lumen, geometry, &route.points_mm(1.0)?)
                .context("no wall around the lumen near the path")?;
            if !args.json {
                println!("coverage measured on the wall within {reach:.1} mm of the path");
            }
            flight = flight.with_coverage(wall);
        }
    }
    let mut progress = Progress::new("flying", frames.len());
    let mut looks = ShotSettings::new(settings.clone(), transfer_function);
    for (n, shot) in shots.iter().enumerate().take(frames.end).skip(frames.start) {
        let shot_settings = looks.for_shot(shot)?;
        let image = sinks.push(&mut flight, n, shot, &shot_settings)?;
        if let (Some(dataset), Some(image)) = (&mut dataset, image) {
            dataset.push(&flight, &image)?;
        }
        progress.step();
    }
    progress.finish();
    let written = sinks.finish()?;
    let dataset = dataset.map(DatasetSink::finish).transpose()?;
    if !args.json {
        println!(
            "{}: {} frames along {:.1} mm ({:.1} frames/s)",
            written.display(),
            frames.len(),
            route.len_mm(),
            progress.rate()
        );
    }
    let mut coverage = None;
    if let Some(forward) = flight.into_coverage() {
        let lumen = lumen.as_ref().context("coverage needs the lumen")?;
        let seen = fly_back(args, &renderer, &route, &options, &settings, forward)?;
        let geometry = renderer.volume().geometry();
        coverage = Some(fly_coverage::report(
            &args.output,
            geometry,
            lumen,
            &seen,
            args.json,
        )?);
    }
    if args.json {
        let summary = serde_json::json!({
            "output": written,
            "frames": frames.len(),
            "first_frame": frames.start,
            "length_mm": route.len_mm(),
            "frames_per_s": progress.rate(),
            "first_camera": study_report::pose_json(&first),
            "coverage": coverage,
            "dataset": dataset,
        });
        println!("{}", serde_json::to_string_pretty(&summary)?);
    }
    Ok(())
}

/// Flies `route` back for coverage (with a progress line) and adds what it saw to `forward`;
/// key frames are not flown back.
fn fly_back(
    args: &FlyArgs,
    renderer: &Arc<Renderer>,
    route: &Route,
    options: &FlightOptions,
    settings: &RenderSettings,
    forward: Coverage,
) -> Result<WallSeen> {
    let (step, look_ahead) = (args.frame_step, args.look_ahead);
    let back = BackwardPass::new(
        Arc::clone(renderer),
        route,
        options,
        step,
        look_ahead,
        &forward,
    )
    .context("cannot reverse the path")?;
    let Some(back) = back else {
        return Ok(WallSeen::forward_only(forward));
    };
    let mut progress = Progress::new("backward", back.shots().len());
    let backward = back.fly(settings, || progress.step())?;
    progress.finish();
    Ok(WallSeen::with_backward(forward, &backward)?)
}

/// The route's shots every `--frame-step`, refused above the frame limit
/// ([`Limits::check_frame_count`]) before any is made.
fn shots(route: &Route, args: &FlyArgs) -> Result<Vec<Shot>> {
    let frames = (route.len_mm() / args.frame_step).ceil() + 1.0;
    // A float count converts saturating: no overflow.
    Limits::default().check_frame_count("--frame-step", frames as u64)?;
    route
        .shots(args.frame_step, args.look_ahead)
        .context("cannot sample the route")
}

/// The stereo options as the flight takes them; side-by-side and top-bottom frames are twice
/// the size, so they go with the endoscopic view alone.
fn flight_stereo(args: &FlyArgs) -> Result<Option<FlightStereo>> {
    let Some(output) = args.stereo.stereo else {
        return Ok(None);
    };
    let doubled = matches!(output, StereoOutput::SideBySide | StereoOutput::TopBottom);
    if doubled && args.layout == LayoutArg::Dashboard {
        bail!(
            "--stereo {} needs --layout endoscope (the dashboard takes anaglyphs)",
            output.name()
        );
    }
    Ok(Some(FlightStereo {
        output,
        eye_separation_mm: args.stereo.eye_separation,
        focus_mm: args.stereo.focus,
    }))
}

/// Where the frames go: one film, or for a stereo pair a left and a right one.
enum Sinks {
    One(Box<dyn FrameSink>),
    Pair([Box<dyn FrameSink>; 2]),
}

impl Sinks {
    /// The film(s) at `output`: `NAME-left` and `NAME-right` beside it for a pair.
    fn open(output: &Path, options: &VideoOptions, stereo: Option<StereoOutput>) -> Result<Self> {
        let open = |path: &Path| open_sink(path, options).context("cannot write the video");
        Ok(match stereo {
            Some(StereoOutput::Pair) => Self::Pair([
                open(&beside(output, "left"))?,
                open(&beside(output, "right"))?,
            ]),
            _ => Self::One(open(output)?),
        })
    }

    /// Renders and writes frame `n`; returns it unless it is a pair.
    fn push(
        &mut self,
        flight: &mut Flight,
        n: usize,
        shot: &Shot,
        settings: &RenderSettings,
    ) -> Result<Option<Image>> {
        match self {
            Self::One(sink) => {
                let image = flight.frame(n, shot, settings)?.0;
                sink.push_image(&image)?;
                Ok(Some(image))
            }
            Self::Pair([left, right]) => {
                let ([l, r], _) = flight.stereo_frame(shot, settings)?;
                left.push_image(&l)?;
                right.push_image(&r)?;
                Ok(None)
            }
        }
    }

    /// Finishes the film(s); returns where the (first) one is.
    fn finish(self) -> Result<PathBuf> {
        Ok(match self {
            Self::One(sink) => sink.finish()?,
            Self::Pair([left, right]) => {
                let written = left.finish()?;
                right.finish()?;
                written
            }
        })
    }
}

fn video_options(args: &FlyArgs) -> VideoOptions {
    let mut options = VideoOptions::default();
    options.fps = args.fps;
    options.ffmpeg.clone_from(&args.ffmpeg);
    options
}

/// The lumen around the route's start `start_mm` ([`Study::lumen_from`]), saying when it is the
/// structure the study found.
pub(crate) fn lumen_at_start(study: &Study, volume: &Volume, start_mm: DVec3) -> Result<Lumen> {
    let (lumen, what) = study
        .lumen_from(volume, start_mm)
        .context("the route's start is not in the lumen")?;
    if let Some(what) = what {
        eprintln!("the path starts in the {what}: coverage is measured on its wall");
    }
    Ok(lumen)
}

/// The dashboard's slice window: `--window` when given, else the study's (`default`).
fn slice_window(text: Option<&str>, default: Window) -> Result<Window> {
    match text {
        Some(text) => parse_window(text),
        None => Ok(default),
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_slice_window_is_the_options_else_the_studys() {
        let lung = Window::new(-600.0, 1500.0).unwrap();
        assert_eq!(slice_window(None, lung).unwrap(), lung);
        let given = slice_window(Some("40, 400"), lung).unwrap();
        assert_eq!(given, Window::SOFT_TISSUE);
        assert!(slice_window(Some("40"), lung).is_err());
        assert!(slice_window(Some("40,-1"), lung).is_err());
    }
}
