//! `endocast bench`: frames per second along a fixed fly path. Without a scan it runs the
//! protocol of Scharsach et al.'s Tables 1 and 2 on the colon phantom (512×512×478 at the default
//! size): iso-only, then the hybrid mode at isosurface opacity 100 / 80 / 50 / 0 % with a simple
//! ramp and a complex transfer function, then depth peeling; with a scan and `--path` it measures
//! one setting.

use crate::cleanse_args::CleanseArgs;
use crate::look::{find_preset, in_pool, LookArgs, ScanLook};
use crate::lumen::LumenArgs;
use crate::optics::{LensArgs, StereoArgs};
use crate::parse::parse_size;
use crate::scene_args::SceneArgs;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::camera::StereoRig;
use endocast_core::look::{self, Look, RayPass, RayPassSettings, Shading};
use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::{fly_through, Pose};
use endocast_core::render::quality::reduced_camera;
use endocast_core::render::{
    Camera, Filter, Frame, FrameReuse, Layers, Mode, PeelLayer, Prepared, Quality, RenderOptions,
    RenderSettings, Renderer, StereoFrames,
};
use endocast_core::scene::Scene;
use endocast_core::Volume;
use endocast_io::route_file::{read_camera_path, CameraPath};
use endocast_io::{Limits, OpenOptions, RenderKind};
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// Arguments of `endocast bench`.
#[derive(Args, Debug)]
pub struct BenchArgs {
    /// A scan to fly through along `--path`; without it, the colon phantom and its centreline.
    volume: Option<PathBuf>,
    /// Camera path: a JSON list of {"eye": [x,y,z], "look_at": [..], "up": [..]} in world mm,
    /// or a path file as `endocast fly` reads it (then --frames cameras along it).
    #[arg(long)]
    path: Option<PathBuf>,
    /// For files that declare no patient orientation: where their index axes point (e.g. LPI).
    #[arg(long, value_name = "CODE")]
    orientation: Option<String>,
    /// DICOM: fill missing slices by interpolation (warned) instead of refusing the series.
    #[arg(long)]
    fill_missing_slices: bool,
    #[command(flatten)]
    cleanse: CleanseArgs,
    /// Size of the colon phantom (512 gives the paper's 512×512×478).
    #[arg(long, value_name = "N", default_value_t = 512)]
    phantom_size: usize,
    /// Frames of the colon phantom's fly path (or along a --path file of points).
    #[arg(long, default_value_t = 60)]
    frames: usize,
    /// Image size in pixels (`--image` is an old name).
    #[arg(long, alias = "image", value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: [usize; 2],
    /// Vertical field of view in degrees (default: the preset's, else 90).
    #[arg(long, value_name = "DEG")]
    fov: Option<f64>,
    /// Cast rays at full, half, quarter or eighth resolution (upsampled to --image, edge-aware).
    #[arg(long, default_value = "full", value_parser = parse_quality)]
    quality: Quality,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lens: LensArgs,
    /// Also time each camera as a stereo pair (the output named is not written) and report
    /// the pair's cost against one eye's.
    #[command(flatten)]
    stereo: StereoArgs,
    /// Also render each camera with frame-to-frame reuse (its searches bounded by the previous
    /// camera's depths: the same images), interleaved with the plain frames, and report the
    /// reused frame's time over the plain one's.
    #[arg(long)]
    reuse: bool,
    /// Print one JSON line per measured setting instead of the table.
    #[arg(long)]
    json: bool,
    /// Measure only the settings (table rows) whose name contains this text, e.g. "iso only"
    /// or "complex TF". Repeatable: a row named by any of them is measured.
    #[arg(long, value_name = "TEXT")]
    rows: Vec<String>,
    /// Geometry drawn in every frame (the cost of meshes, a grid, the endoscope): each camera
    /// is also rendered without it, and each setting reports the per-frame ratio; a look's
    /// deferred stage is also timed with the geometry composited (at full quality).
    #[command(flatten)]
    scene: SceneArgs,
    /// Also append one JSON line per measured setting to this file.
    #[arg(long, value_name = "FILE")]
    json_file: Option<PathBuf>,
}

/// One measured setting: what it was and how fast it ran.
struct Cell {
    name: String,
    settings: RenderSettings,
    /// A clinical or realistic look: its ray pass and deferred stage are timed instead.
    look: Option<Look>,
}

/// Timings of one setting over the whole path.
#[derive(Default)]
struct Measured {
    ms: Vec<f64>,
    samples: u64,
}

/// Runs `endocast bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    check_size(args.size)?;
    let preset = args.look.preset()?;
    let (renderer, poses, mut cells) = match &args.volume {
        None => paper_protocol(args)?,
        Some(volume) => one_setting(args, volume)?,
    };
    if !args.rows.is_empty() {
        cells.retain(|c| args.rows.iter().any(|r| c.name.contains(r.as_str())));
        if cells.is_empty() {
            bail!(
                "--rows {:?}: no setting of the benchmark has such a name",
                args.rows
            );
        }
    }
    let (lo, hi) = renderer.volume().geometry().world_bounds();
    // Every row sees through the look's lens (the realistic look's endoscope), so the look
    // and the plain rows compare on the same cameras.
    let look = cells.iter().find_map(|c| c.look.as_ref());
    let optics = args
        .lens
        .optics(preset, look, args.fov, 0.0, (hi - lo).length())?;
    let renderer = Arc::new(renderer);
    let scene = args.scene.scene()?;
    let options = RenderOptions::new().quality(args.quality);
    let cameras: Vec<Camera> = poses
        .iter()
        .map(|p| optics.camera(p.eye_mm, p.look_at_mm, p.up, args.size))
        .collect::<Result<_, _>>()
        .context("invalid camera on the path")?;
    let table = !args.json;
    say(
        table,
        &format!(
            "{} frames of {}×{} ({} quality), {} lens, field {}, {} threads",
            cameras.len(),
            args.size[0],
            args.size[1],
            args.quality.name(),
            optics.projection.name(),
            optics.field,
            args.look.threads.unwrap_or_else(rayon::current_num_threads)
        ),
    );
    say(
        table,
        "| setting | min fps | avg fps | max fps | median ms | Msamples/s |\n|---|---|---|---|---|---|",
    );
    for cell in &cells {
        if let Some(look) = &cell.look {
            let pass =
                RayPass::new(&renderer, &cell.settings, &look.ray).context("invalid look")?;
            let stages = (&pass, &look.shading, scene.as_deref());
            let timed = in_pool(args.look.threads, || measure_look(stages, args, &cameras))??;
            report(args, optics.field, &cell.name, &timed.whole, None)?;
            let name = format!("{}: its deferred stage alone", cell.name);
            report(args, optics.field, &name, &timed.deferred, None)?;
            if let Some(geometry) = &timed.geometry {
                let name = format!("{}: its deferred stage with the geometry", cell.name);
                report(args, optics.field, &name, geometry, None)?;
            }
            let label = ("stereo pair", "pair ÷ one eye", "pair_over_one_eye");
            report_against(args, optics.field, &cell.name, timed.pair, label)?;
            let label = (
                "stereo pair, eyes traced apart",
                "apart ÷ one eye",
                "apart_over_one_eye",
            );
            report_against(args, optics.field, &cell.name, timed.apart, label)?;
            continue;
        }
        let mut prepared = renderer
            .prepare(&cell.settings)
            .context("invalid settings")?;
        // With geometry, the same frames without it too, for the geometry's cost.
        let plain = match scene {
            Some(_) => Some(
                renderer
                    .prepare(&cell.settings)
                    .context("invalid settings")?,
            ),
            None => None,
        };
        prepared.set_scene(scene.clone());
        let timed = in_pool(args.look.threads, || {
            measure(args, (&prepared, plain.as_ref()), &options, &cameras)
        })?;
        report(args, optics.field, &cell.name, &timed.mono?, None)?;
        let against = [
            (
                timed.pair,
                "stereo pair",
                "pair ÷ one eye",
                "pair_over_one_eye",
            ),
            (
                timed.plain,
                "without geometry",
                "with geometry ÷ without",
                "scene_over_without",
            ),
            (
                timed.reused,
                "with frame-to-frame reuse",
                "reused ÷ plain",
                "reused_over_plain",
            ),
        ];
        for (paired, suffix, label, key) in against {
            report_against(args, optics.field, &cell.name, paired, (suffix, label, key))?;
        }
    }
    Ok(())
}

/// Reports `paired`, the timings of `cell`'s frames rendered another way (`suffix`), and the
/// median and range of their per-frame ratios (`label`, JSON `key`); nothing without them.
fn report_against(
    args: &BenchArgs,
    fov_deg: f64,
    cell: &str,
    paired: Option<(Measured, Vec<f64>)>,
    (suffix, label, key): (&str, &str, &str),
) -> Result<()> {
    let Some((measured, mut ratios)) = paired else {
        return Ok(());
    };
    ratios.sort_by(f64::total_cmp);
    let name = format!("{cell}, {suffix}");
    report(args, fov_deg, &name, &measured, Some((key, &ratios)))?;
    say(
        !args.json,
        &format!(
            "|   {label}, median of the frames (min–max) | {:.3} ({:.2}–{:.2}) | | | | |",
            ratios[ratios.len() / 2],
            ratios[0],
            ratios[ratios.len() - 1]
        ),
    );
    Ok(())
}

/// The timings of one setting along the path: one eye, and where asked for, each camera as a
/// stereo pair (with the per-frame ratio of a pair's time to one eye's), without the
/// geometry (with the per-frame ratio of one eye's time, geometry included, to that) and with
/// frame-to-frame reuse (with the per-frame ratio of its time to the plain frame's).
struct Timed {
    mono: Result<Measured>,
    pair: Option<(Measured, Vec<f64>)>,
    plain: Option<(Measured, Vec<f64>)>,
    reused: Option<(Measured, Vec<f64>)>,
}

/// Renders every camera with `prepared` (one eye); with `plain` (the same settings without
/// the geometry) also without it, just before or after in turn (so that neither profits from
/// the caches the other warmed); with `--reuse` also with frame-to-frame reuse (whose state sees
/// only its own frames), before or after the plain frame in turn; with `--stereo` also as a
/// stereo pair right after it. The
/// pairs' timings are the whole [`Prepared::render_stereo_into`], from the pair's shared
/// start-up to its second eye.
fn measure(
    args: &BenchArgs,
    (prepared, plain): (&Prepared, Option<&Prepared>),
    options: &RenderOptions<'_>,
    cameras: &[Camera],
) -> Timed {
    let (mut mono, mut frame) = (Measured::default(), Frame::default());
    let paired = || (Measured::default(), Vec::new());
    let mut pair = args.stereo.stereo.map(|_| paired());
    let mut without = plain.map(|_| paired());
    let mut reused = args.reuse.then(paired);
    let mut reuse = (FrameReuse::new(), Frame::default());
    let mut pair_frames = StereoFrames::default();
    let mut render = |prepared: &Prepared, camera, measured: &mut Measured| {
        // Nothing cancels it.
        let _ = prepared.render_with(camera, options, &mut frame);
        let ms = frame.stats.time.as_secs_f64() * 1e3;
        measured.ms.push(ms);
        measured.samples += frame.stats.samples;
        ms
    };
    for (k, camera) in cameras.iter().enumerate() {
        let (mut one_ms, mut plain_ms, mut reused_ms) = (f64::NAN, f64::NAN, f64::NAN);
        // Every other camera with reuse first.
        let reuse_first = k % 2 == 1;
        if let (true, Some((measured, _))) = (reuse_first, &mut reused) {
            reused_ms = render_reusing(prepared, camera, options, &mut reuse, measured);
        }
        // Every other camera without the geometry first.
        for with_scene in [k % 2 == 0, k % 2 == 1] {
            if with_scene {
                one_ms = render(prepared, camera, &mut mono);
            } else if let (Some(plain), Some((measured, _))) = (plain, &mut without) {
                plain_ms = render(plain, camera, measured);
            }
        }
        if let Some((_, ratios)) = &mut without {
            ratios.push(one_ms / plain_ms);
        }
        if let Some((measured, ratios)) = &mut reused {
            if !reuse_first {
                reused_ms = render_reusing(prepared, camera, options, &mut reuse, measured);
            }
            ratios.push(reused_ms / one_ms);
        }
        let Some((pair, ratios)) = &mut pair else {
            continue;
        };
        let nearest = || prepared.nearest_surface_mm(camera);
        let failed = |error: anyhow::Error| Timed {
            mono: Err(error),
            pair: None,
            plain: None,
            reused: None,
        };
        let rig = match StereoRig::for_view(args.stereo.eye_separation, args.stereo.focus, nearest)
        {
            Ok(rig) => rig,
            Err(error) => {
                return failed(anyhow::Error::from(error).context("invalid --stereo options"))
            }
        };
        let start = Instant::now();
        if let Err(error) = prepared.render_stereo_into(camera, &rig, &mut pair_frames) {
            return failed(anyhow::Error::from(error).context("invalid stereo camera"));
        }
        let pair_ms = start.elapsed().as_secs_f64() * 1e3;
        pair.ms.push(pair_ms);
        let [left, right] = &pair_frames.eyes;
        pair.samples += left.stats.samples + right.stats.samples;
        ratios.push(pair_ms / one_ms);
    }
    Timed {
        mono: Ok(mono),
        pair,
        plain: without,
        reused,
    }
}

/// Renders `camera` with `prepared` and the reuse state and frame of `reuse`, adds its time
/// and samples to `measured` and returns its time (ms).
fn render_reusing(
    prepared: &Prepared,
    camera: &Camera,
    options: &RenderOptions<'_>,
    (reuse, frame): &mut (FrameReuse, Frame),
    measured: &mut Measured,
) -> f64 {
    // Nothing cancels it.
    let _ = prepared.render_reusing_with(camera, options, reuse, frame);
    let ms = frame.stats.time.as_secs_f64() * 1e3;
    measured.ms.push(ms);
    measured.samples += frame.stats.samples;
    ms
}

/// The timings of a look along the path: whole frames, their deferred stage alone, with
/// geometry that deferred stage with the geometry composited, and with `--stereo` the stereo
/// pairs (with the per-frame ratio of a pair's time to one eye's).
struct LookTimed {
    whole: Measured,
    deferred: Measured,
    geometry: Option<Measured>,
    pair: Option<(Measured, Vec<f64>)>,
    /// The same pairs with each eye traced and shaded alone (no search shared).
    apart: Option<(Measured, Vec<f64>)>,
}

/// Renders every camera with a look's ray `pass` at `--quality` and shades it as `shading`
/// says (below full quality both stages at the reduced size, the shaded frame upsampled);
/// with a `scene` (full quality only) also shades each G-buffer again with the scene
/// composited; with `--stereo` (full quality only) also renders each camera as the look's
/// stereo pair right after it, without the scene as the whole frame is
/// ([`look::stereo_frame`], its eyes' searches shared).
fn measure_look(
    (pass, shading, scene): (&RayPass, &Shading, Option<&Scene>),
    args: &BenchArgs,
    cameras: &[Camera],
) -> Result<LookTimed> {
    let quality = args.quality;
    if (scene.is_some() || args.stereo.stereo.is_some()) && quality != Quality::Full {
        bail!("bench times a look's geometry and stereo pairs at --quality full only");
    }
    let (mut whole, mut deferred) = (Measured::default(), Measured::default());
    let mut geometry = scene.map(|_| Measured::default());
    let stereo = args.stereo.stereo.is_some();
    let mut pair = stereo.then(|| (Paired::default(), StereoFrames::default()));
    let mut apart = stereo.then(Paired::default);
    for camera in cameras {
        let start = Instant::now();
        let small = reduced_camera(camera, quality.reduced_size(camera.size()));
        let gbuffer = pass.trace(&small, Quality::Full);
        let shaded = Instant::now();
        look::shade_reduced(&gbuffer, camera, shading).context("invalid look")?;
        let end = Instant::now();
        whole.ms.push((end - start).as_secs_f64() * 1e3);
        whole.samples += gbuffer.stats.samples;
        deferred.ms.push((end - shaded).as_secs_f64() * 1e3);
        if let Some(measured) = &mut geometry {
            let start = Instant::now();
            look::shade_with_scene(&gbuffer, camera, shading, scene).context("invalid look")?;
            measured.ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        if let (Some((shared, frames)), Some(apart)) = (&mut pair, &mut apart) {
            let one_ms = whole.ms.last().copied().unwrap_or(f64::NAN);
            let nearest = || pass.prepared().nearest_surface_mm(camera);
            let rig = StereoRig::for_view(args.stereo.eye_separation, args.stereo.focus, nearest)
                .context("invalid --stereo options")?;
            let start = Instant::now();
            let eyes = look::stereo_frame(
                pass,
                (camera, &rig),
                shading,
                None,
                (0, Filter::Trilinear),
                frames,
            )
            .context("invalid stereo camera or look")?;
            let samples = eyes[0].stats.samples + eyes[1].stats.samples;
            shared.add(start.elapsed(), samples, one_ms);
            let start = Instant::now();
            let mut samples = 0;
            for eye in rig.eyes(camera).context("invalid stereo camera")? {
                let gbuffer = pass.trace(&eye, Quality::Full);
                look::shade(&gbuffer, &eye, shading).context("invalid look")?;
                samples += gbuffer.stats.samples;
            }
            apart.add(start.elapsed(), samples, one_ms);
        }
    }
    Ok(LookTimed {
        whole,
        deferred,
        geometry,
        pair: pair.map(|(shared, _)| shared.into_parts()),
        apart: apart.map(Paired::into_parts),
    })
}

/// Timings of frames rendered another way and their per-frame ratios to one eye's.
#[derive(Default)]
struct Paired {
    measured: Measured,
    ratios: Vec<f64>,
}

impl Paired {
    /// Adds a frame that took `time` and `samples`, against one eye's `one_ms`.
    fn add(&mut self, time: std::time::Duration, samples: u64, one_ms: f64) {
        let ms = time.as_secs_f64() * 1e3;
        self.measured.ms.push(ms);
        self.measured.samples += samples;
        self.ratios.push(ms / one_ms);
    }

    fn into_parts(self) -> (Measured, Vec<f64>) {
        (self.measured, self.ratios)
    }
}

/// A `--quality` level by name.
fn parse_quality(name: &str) -> Result<Quality, String> {
    Quality::from_name(name)
        .ok_or_else(|| format!("{name:?}: expected full, half, quarter or eighth"))
}

/// The study of `volume` for the options, started at the first of `poses` (no structure is
/// searched: the path is given), said on stderr.
fn on_path(args: &BenchArgs, volume: &Volume, poses: &[Pose]) -> Result<ScanLook> {
    let scan = args.look.on_scan(
        volume,
        &LumenArgs::default(),
        poses.first().copied(),
        args.fov,
    )?;
    if !args.json {
        study_report::say(&scan.study);
    }
    Ok(scan)
}

/// The colon phantom, its fly path, and the paper's table cells.
fn paper_protocol(args: &BenchArgs) -> Result<(Renderer, Vec<Pose>, Vec<Cell>)> {
    if !(32..=1024).contains(&args.phantom_size) {
        bail!(
            "--phantom-size must be between 32 and 1024, not {}",
            args.phantom_size
        );
    }
    let frames = frame_count(args.frames)?;
    let (volume, colon) = phantom::colon(&PhantomOptions {
        size: args.phantom_size,
        ..PhantomOptions::default()
    });
    let line = &colon.centreline;
    let poses = fly_through(
        volume.geometry(),
        |s| line.point_at(s),
        line.length_vox(),
        frames,
        10.0,
    )
    .with_context(|| format!("no fly path of {frames} frames fits the colon"))?;
    let ScanLook {
        settings: base,
        look,
        ..
    } = on_path(args, &volume, &poses)?;
    let with = |change: &dyn Fn(&mut RenderSettings)| {
        let mut s = base.clone();
        change(&mut s);
        s
    };
    let mut cells = vec![Cell {
        name: "iso only".into(),
        settings: with(&|s| s.mode = Mode::Iso),
        look: None,
    }];
    if let Some(look) = look {
        // The look against plain iso on the same path.
        cells.push(Cell {
            name: format!("{} look", args.look.look_name()),
            settings: base.clone(),
            look: Some(look),
        });
        return Ok((Renderer::for_many_frames(volume), poses, cells));
    }
    for tf in ["ramp", "complex"] {
        let tf_fn = find_preset(tf)?.transfer_function();
        for opacity in [1.0, 0.8, 0.5, 0.0] {
            cells.push(Cell {
                name: format!("hybrid {:.0} %, {tf} TF", opacity * 100.0),
                settings: with(&|s| {
                    s.mode = Mode::Hybrid;
                    s.iso_opacity = opacity;
                    s.tf = tf_fn.clone();
                }),
                look: None,
            });
        }
    }
    cells.extend(peel_cells(&base));
    Ok((Renderer::for_many_frames(volume), poses, cells))
}

/// Depth peeling on the colon (issue 19) at the wall's isovalue: the first peel is the wall the
/// iso-only cell shows; the second and the last are the next loops of the colon behind it, the
/// front discarded (a search alone) or kept at 30 % through the transfer function of the options
/// (the ramp by default).
fn peel_cells(base: &RenderSettings) -> Vec<Cell> {
    [
        ("peel 1", PeelLayer::Nth(1), 0.0),
        ("peel 2", PeelLayer::Nth(2), 0.0),
        ("peel last", PeelLayer::Last, 0.0),
        ("peel 2, 30 % of the front kept", PeelLayer::Nth(2), 0.3),
    ]
    .into_iter()
    .map(|(name, layer, keep)| {
        let mut s = base.clone();
        s.mode = Mode::Peel;
        s.peel.threshold_hu = None;
        (s.peel.layer, s.peel.keep) = (layer, keep);
        Cell {
            name: name.into(),
            settings: s,
            look: None,
        }
    })
    .collect()
}

/// A scan, the path the user gave, and the one setting the options describe.
fn one_setting(args: &BenchArgs, volume: &Path) -> Result<(Renderer, Vec<Pose>, Vec<Cell>)> {
    let path = args.path.as_ref().context("a scan needs a camera --path")?;
    let poses = read_path(path, args.frames)?;
    let mut options = OpenOptions::default();
    options.orientation.clone_from(&args.orientation);
    options.fill_missing_slices = args.fill_missing_slices;
    let mut loaded = endocast_io::open(volume, &options).context("cannot read the scan")?;
    loaded.volume = args.cleanse.apply(loaded.volume)?;
    let ScanLook { settings, look, .. } = on_path(args, &loaded.volume, &poses)?;
    let what = match look {
        Some(_) => format!("{} look", args.look.look_name()),
        None => settings.mode.name().to_owned(),
    };
    let cell = Cell {
        name: format!("{} {what}", volume.display()),
        settings,
        look,
    };
    Ok((Renderer::for_many_frames(loaded.volume), poses, vec![cell]))
}

/// How far ahead the cameras taken along a route file look, mm.
const LOOK_AHEAD_MM: f64 = 10.0;

/// The cameras of a camera path file: its list of {"eye", "look_at", "up"} (world mm, the format
/// the VTK peer script reads too), or `frames` cameras spread evenly along a route file as
/// `endocast fly` takes it, looking [`LOOK_AHEAD_MM`] ahead.
fn read_path(path: &Path, frames: usize) -> Result<Vec<Pose>> {
    match read_camera_path(path).context("cannot read the path")? {
        CameraPath::Cameras(poses) => Ok(poses),
        CameraPath::Route(route) => route
            .spread_poses(frame_count(frames)?, LOOK_AHEAD_MM)
            .context("cannot sample the path"),
    }
}

/// Refuses `--size` before anything is allocated where any of the benchmark's renders (a plain
/// frame, a look, a stereo pair) would take more memory than the limits allow
/// ([`Limits::check_frames`]).
fn check_size(size: [usize; 2]) -> Result<()> {
    let limits = Limits::default();
    // The look without secretion, whose ray pass renders the most layers.
    let look = RenderKind::Look(RayPassSettings::default().traced_layers());
    for kind in [RenderKind::Plain(Layers::NONE), look, RenderKind::Stereo] {
        limits
            .check_frames(Path::new("--size"), size, kind, 1)
            .context("the image is too large")?;
    }
    Ok(())
}

/// `--frames`, refused above the limit ([`Limits::check_frame_count`]) before a pose is made.
fn frame_count(frames: usize) -> Result<usize> {
    Limits::default().check_frame_count("--frames", frames as u64)?;
    Ok(frames)
}

/// Prints `text` when the table is printed (not under `--json`).
fn say(table: bool, text: &str) {
    if table {
        println!("{text}");
    }
}

/// Prints one table row or JSON line, and appends the JSON line to `--json-file`. `ratios`:
/// a stereo pair's time over one eye's, per frame, sorted.
fn report(
    args: &BenchArgs,
    fov_deg: f64,
    name: &str,
    m: &Measured,
    ratios: Option<(&str, &[f64])>,
) -> Result<()> {
    let total_s: f64 = m.ms.iter().sum::<f64>() / 1e3;
    let fps: Vec<f64> = m.ms.iter().map(|ms| 1e3 / ms).collect();
    let min = fps.iter().copied().fold(f64::INFINITY, f64::min);
    let max = fps.iter().copied().fold(0.0, f64::max);
    let avg = m.ms.len() as f64 / total_s;
    let mut sorted = m.ms.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let msamples = m.samples as f64 / total_s / 1e6;
    say(
        !args.json,
        &format!("| {name} | {min:.1} | {avg:.1} | {max:.1} | {median:.1} | {msamples:.0} |"),
    );
    let mut line = json!({
        "setting": name,
        "frames": m.ms.len(),
        "size": args.size,
        "fov_deg": fov_deg,
        "fps_min": min, "fps_avg": avg, "fps_max": max,
        "ms_median": median,
        "ms": m.ms,
        "samples_per_s": m.samples as f64 / total_s,
    });
    if let Some((key, ratios)) = ratios {
        line[key] = json!(ratios);
    }
    if args.json {
        println!("{line}");
    }
    if let Some(file) = &args.json_file {
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(file)
            .with_context(|| format!("cannot open {}", file.display()))?;
        writeln!(f, "{line}").with_context(|| format!("cannot write {}", file.display()))?;
    }
    Ok(())
}
