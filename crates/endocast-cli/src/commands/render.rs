//! `endocast render`: one view of a scan, from inside (endoscopic) or framing it from outside.

use crate::case_args::{draw_marks, CaseArgs};
use crate::input::InputArgs;
use crate::look::{in_pool, LookArgs};
use crate::lumen::LumenArgs;
use crate::optics::{beside, LensArgs, StereoArgs};
use crate::parse::{parse_pixel, parse_size};
use crate::pose_args::PoseArgs;
use crate::scene_args::SceneArgs;
use crate::structure;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::camera::default_up;
use endocast_core::look::{self, RayPass};
use endocast_core::navigate::{default_view, DefaultView, FramingReason};
use endocast_core::presets::{Preset, DEFAULT_FOV_DEG};
use endocast_core::render::{
    Camera, Frame, Prepared, RenderOptions, RenderSettings, Renderer, Still,
};
use endocast_core::tissue::{self, ScanValues};
use endocast_core::views::stereo::{self, StereoOutput};
use endocast_core::views::Image;
use endocast_core::Volume;
use endocast_io::ImageFormat;
use glam::DVec3;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Arguments of `endocast render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output image: .png (8-bit sRGB) or .jpg.
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    #[command(flatten)]
    lens: LensArgs,
    #[command(flatten)]
    stereo: StereoArgs,
    #[command(flatten)]
    scene: SceneArgs,
    #[command(flatten)]
    case: CaseArgs,
    #[command(flatten)]
    pose: PoseArgs,
    /// Vertical field of view in degrees: 10–170 for a pinhole, up to 360 for a fisheye
    /// (default: the preset's, else 90; fisheye 170); view height in mm for orthographic.
    #[arg(long, value_name = "DEG")]
    fov: Option<f64>,
    /// Distance from the eye to the near plane, mm (may lie inside tissue).
    #[arg(long, default_value_t = 0.0)]
    near: f64,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: [usize; 2],
    /// Also write the depth image: float32 .npy, mm from the eye to the first hit, NaN where none.
    #[arg(long, value_name = "FILE.npy")]
    depth_out: Option<PathBuf>,
    /// Average this many jittered frames (sub-pixel offsets, shifted sample grids): a
    /// converged still without sampling bands or stair-stepped edges.
    #[arg(long, value_name = "FRAMES", default_value_t = 1)]
    still: usize,
    /// Print the frame's statistics and the camera pose it used as JSON.
    #[arg(long)]
    json: bool,
    /// Also write the structure the preset found (its lumen tinted green on the axial, coronal
    /// and sagittal slices through the camera) as a PNG; needs --preset and no --eye.
    #[arg(long, value_name = "FILE.png")]
    show_structure: Option<PathBuf>,
    /// Trace one pixel and print every sample along its ray.
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    debug_pixel: Option<[usize; 2]>,
}

/// Runs `endocast render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    ImageFormat::for_path(&args.output).context("cannot write the image")?;
    let eyes = if args.stereo.stereo.is_some() { 2 } else { 1 };
    args.input.check_frames(&args.output, args.size, eyes)?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let look = args.look.on_scan(&loaded.volume)?;
    eprintln!("{}", look.summary);
    if !(1..=MAX_STILL_FRAMES).contains(&args.still) {
        bail!(
            "--still must be between 1 and {MAX_STILL_FRAMES} frames, not {}",
            args.still
        );
    }
    let (settings, preset) = (look.settings, look.preset.as_ref());
    let (camera, view) = camera(args, preset, &loaded.volume, &settings)?;
    if let Some(path) = &args.show_structure {
        structure::write(path, &loaded.volume, view.as_ref(), preset)?;
    }
    let marks = args.case.annotations(&loaded.volume)?;
    if marks.is_some() && args.stereo.stereo.is_some() {
        bail!("--case draws on one view: leave out --stereo");
    }
    let renderer = Arc::new(Renderer::new(loaded.volume));
    let mut prepared = renderer
        .prepare(&settings)
        .context("invalid render settings")?;
    let scene = args.scene.scene()?;
    if look.look.is_some() && (scene.is_some() || args.stereo.stereo.is_some()) {
        bail!("--look clinical and realistic draw no geometry and no stereo pair yet; use --look plain");
    }
    prepared.set_scene(scene);
    if let Some([x, y]) = args.debug_pixel {
        print_trace(&prepared, &camera, x, y)?;
    }
    let stereo = args.stereo.rig(|| prepared.nearest_surface_mm(&camera))?;
    let frame = match stereo {
        Some((rig, output)) => {
            let frames = in_pool(args.look.threads, || prepared.render_stereo(&camera, &rig))?
                .context("invalid stereo rig")?;
            write_stereo(&args.output, &frames, output, settings.background)?;
            eprintln!(
                "stereo: eye separation {:.2} mm, focus {:.1} mm",
                rig.eye_separation_mm, rig.focus_mm
            );
            let [left, right] = frames;
            let mut both = left;
            both.stats.add(&right.stats);
            both
        }
        None => {
            let frame = match &look.look {
                Some(l) => {
                    let pass =
                        RayPass::new(&renderer, &settings, &l.ray).context("invalid look")?;
                    in_pool(args.look.threads, || {
                        look::still(&pass, &camera, &l.shading, args.still)
                    })?
                    .context("invalid look")?
                }
                None => in_pool(args.look.threads, || still(&prepared, &camera, args.still))??,
            };
            let [w, h] = [frame.width as u32, frame.height as u32];
            let mut image = Image::from_frame(&frame, settings.background)?;
            if let Some(marks) = &marks {
                let spacing = renderer.volume().geometry().spacing_mm();
                draw_marks(&mut image, marks, &camera, &frame.depth_mm, spacing);
            }
            endocast_io::write_image_rgb8(&args.output, w, h, image.rgb())
                .context("cannot write the image")?;
            frame
        }
    };
    warn_if_empty(&frame, &settings, &look.scan);
    let [w, h] = [frame.width as u32, frame.height as u32];
    if let Some(depth) = &args.depth_out {
        endocast_io::image_out::write_npy_f32(depth, w, h, &frame.depth_mm)
            .context("cannot write the depth image")?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&stats_json(&frame, &settings, &camera))?
        );
    } else {
        println!(
            "{}: {}×{} {} in {:.1} ms",
            args.output.display(),
            frame.width,
            frame.height,
            settings.mode.name(),
            frame.stats.time.as_secs_f64() * 1e3
        );
    }
    Ok(())
}

/// The most frames `--still` averages.
const MAX_STILL_FRAMES: usize = 256;

/// The average of `frames` jittered frames of `camera` (one: the plain frame).
fn still(prepared: &Prepared, camera: &Camera, frames: usize) -> Result<Frame> {
    let mut still = Still::new();
    for _ in 0..frames {
        // Nothing cancels it.
        let _ = still.render_next(prepared, camera, &RenderOptions::new());
    }
    Ok(still.frame().clone())
}

/// The camera the options describe; without one, for an endoscopic preset, a view from inside
/// the structure it means along its axis, else one framing the whole volume from the front
/// (with the default view it came from).
fn camera(
    args: &RenderArgs,
    preset: Option<&Preset>,
    volume: &Volume,
    settings: &RenderSettings,
) -> Result<(Camera, Option<DefaultView>)> {
    let fov_deg = args
        .fov
        .unwrap_or_else(|| preset.map_or(DEFAULT_FOV_DEG, |p| p.fov_deg));
    let (eye, look_at, up, view) = match (args.pose.eye, args.pose.look_at) {
        (Some(eye), Some(look_at)) => (DVec3::from(eye), DVec3::from(look_at), None, None),
        (None, None) => {
            let view = default_pose(args, preset, volume, settings, fov_deg);
            let pose = view.pose();
            (pose.eye_mm, pose.look_at_mm, Some(pose.up), Some(view))
        }
        _ => bail!("--eye and --look-at go together"),
    };
    let up = args
        .pose
        .up
        .map(DVec3::from)
        .or(up)
        .unwrap_or_else(|| default_up(look_at - eye));
    let (lo, hi) = volume.geometry().world_bounds();
    let height_mm = (hi - lo).length();
    let optics = args.lens.optics(preset, args.fov, args.near, height_mm)?;
    let camera = optics
        .camera(eye, look_at, up, args.size)
        .context("invalid camera")?;
    Ok((camera, view))
}

/// Writes a stereo pair as `output` asks: one combined image at `path`, or for a pair
/// `NAME-left.png` and `NAME-right.png` beside it.
fn write_stereo(
    path: &Path,
    frames: &[Frame; 2],
    output: StereoOutput,
    background: [f32; 3],
) -> Result<()> {
    let [left, right] = [&frames[0], &frames[1]].map(|f| Image::from_frame(f, background));
    let (left, right) = (left?, right?);
    let write = |path: &Path, image: &Image| {
        let [w, h] = [image.width() as u32, image.height() as u32];
        endocast_io::write_image_rgb8(path, w, h, image.rgb())
            .with_context(|| format!("cannot write {}", path.display()))
    };
    if output == StereoOutput::Pair {
        write(&beside(path, "left"), &left)?;
        return write(&beside(path, "right"), &right);
    }
    write(path, &stereo::combine(&left, &right, output)?)
}

/// The library's default view (see [`default_view`]) for `--preset` and the lumen options,
/// saying on stderr what it found, where it put the camera and why it fell back to framing the
/// volume.
fn default_pose(
    args: &RenderArgs,
    preset: Option<&Preset>,
    volume: &Volume,
    settings: &RenderSettings,
    fov_deg: f64,
) -> DefaultView {
    let mut choice = preset.map(|p| args.lumen.choice(Some(p), Some(settings.iso_hu)));
    if let Some(choice) = choice.as_mut() {
        choice.within =
            preset.and_then(|p| tissue::central_structure(p, volume, &ScanValues::measure(volume)));
    }
    let clock = std::time::Instant::now();
    let view = default_view(volume, choice.as_ref(), fov_deg);
    let found_ms = clock.elapsed().as_secs_f64() * 1e3;
    match &view {
        DefaultView::InsideLumen {
            pose,
            threshold,
            side,
            what,
            ..
        } => eprintln!(
            "found the {what}\ncamera inside the lumen {side} {threshold:.1} (found in \
             {found_ms:.0} ms): --eye {} --look-at {} --up {}",
            triple(pose.eye_mm),
            triple(pose.look_at_mm),
            triple(pose.up)
        ),
        DefaultView::Framing { reason, .. } => match reason {
            FramingReason::Choice(error) => {
                eprintln!("warning: {error}; framing the whole volume instead");
            }
            FramingReason::NoLumen { threshold, side } => {
                eprintln!("warning: no lumen {side} {threshold}; framing the whole volume instead");
            }
            _ => {}
        },
    }
    view
}

/// Warns, saying why and what to try, when nothing in the image was hit or drawn.
fn warn_if_empty(frame: &Frame, settings: &RenderSettings, scan: &ScanValues) {
    let drawn = frame.color.iter().any(|p| p.transmittance < 0.99);
    if frame.stats.iso_hits > 0 || drawn {
        return;
    }
    let (lo, hi) = scan.range;
    eprintln!(
        "warning: the image is empty: no ray met the wall at {:.1} or anything the transfer \
         function shows (values {lo:.1} to {hi:.1}, {scan}); try --iso {:.1} (background/object \
         boundary) without --eye, or another --preset",
        settings.iso_hu, scan.object_threshold
    );
}

/// `x,y,z` with two decimals, as `--eye` takes it.
fn triple(v: DVec3) -> String {
    format!("{:.2},{:.2},{:.2}", v.x, v.y, v.z)
}

fn print_trace(prepared: &Prepared, camera: &Camera, x: usize, y: usize) -> Result<()> {
    let [w, h] = camera.size();
    if x >= w || y >= h {
        bail!("--debug-pixel {x},{y} lies outside the {w}×{h} image");
    }
    let trace = prepared.trace_pixel(camera, x, y);
    eprintln!(
        "pixel {x},{y}: range {:?} mm, step {:.3} mm, {} samples, rgb {:?}, alpha {:.3}, depth {} mm",
        trace.range_mm,
        trace.step_mm,
        trace.samples.len(),
        trace.rgb,
        trace.alpha,
        trace.depth_mm
    );
    for s in &trace.samples {
        eprintln!(
            "  t {:9.3} mm  value {:9.2}  alpha {:.4}",
            s.t_mm, s.value, s.alpha
        );
    }
    Ok(())
}

/// The frame's statistics and the camera that took it (world mm, LPS; `field`: degrees across
/// the image height, or mm of view height for an orthographic lens).
fn stats_json(frame: &Frame, settings: &RenderSettings, camera: &Camera) -> serde_json::Value {
    let s = &frame.stats;
    let v = |v: DVec3| [v.x, v.y, v.z];
    json!({
        "camera": {
            "eye": v(camera.eye_mm()),
            "look_direction": v(camera.forward()),
            "up": v(camera.up()),
            "field": camera.field(),
            "projection": camera.projection().name(),
            "near_mm": camera.near_mm(),
            "distortion": camera.lens().distortion,
            "vignetting": camera.lens().vignetting,
        },
        "mode": settings.mode.name(),
        "width": frame.width,
        "height": frame.height,
        "time_ms": s.time.as_secs_f64() * 1e3,
        "rays": s.rays,
        "samples": s.samples,
        "bricks_visited": s.bricks_visited,
        "bricks_skipped": s.bricks_skipped,
        "rays_terminated_early": s.terminated_early,
        "iso_hits": s.iso_hits,
    })
}
