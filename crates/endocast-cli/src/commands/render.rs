//! `endocast render`: one view of a scan, from inside (endoscopic) or framing it from outside.

use crate::case_args::{draw_marks, draw_target_mark, CaseArgs};
use crate::input::InputArgs;
use crate::look::{in_pool, LookArgs};
use crate::lumen::LumenArgs;
use crate::optics::{beside, LensArgs, StereoArgs};
use crate::parse::{parse_filter, parse_pixel, parse_size};
use crate::pose_args::PoseArgs;
use crate::scene_args::SceneArgs;
use crate::structure;
use crate::study_report;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::look::{self, Look, MAX_STILL_FRAMES};
use endocast_core::presets::Preset;
use endocast_core::render::{Camera, Filter, Frame, Prepared, RenderSettings, Renderer};
use endocast_core::study::Study;
use endocast_core::tissue::short;
use endocast_core::views::stereo::{self, StereoOutput};
use endocast_core::views::{lens_marks, Image};
use endocast_core::Volume;
use endocast_io::{ImageFormat, RenderKind};
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
    /// (default: the preset's, else 90; fisheye 170); view height in mm for orthographic;
    /// 90 (fixed) for the cube; the latitudes spanned, 10–180 (default 180), for the panorama.
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
    /// converged still without sampling bands or stair-stepped edges (with --stereo, each eye).
    #[arg(long, value_name = "FRAMES", default_value_t = 1)]
    still: usize,
    /// How the still's frames reconstruct the volume: `bspline` (tricubic B-splines: surfaces
    /// exact at the voxels, smooth normals without voxel facets; about ten times slower a frame,
    /// and 4 bytes a voxel more memory; best with --still 4 or more) or `trilinear`.
    #[arg(long, value_name = "trilinear|bspline", value_parser = parse_filter, default_value = "trilinear")]
    still_filter: Filter,
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
    // Refused before the scan is read where even the plain look's frames would not fit.
    let check = |look| {
        let kind = RenderKind::of(look, args.stereo.stereo.is_some());
        args.input.check_frames(&args.output, args.size, kind, 1)
    };
    check(None)?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let look = args
        .look
        .on_scan(&loaded.volume, &args.lumen, args.pose.pose()?, args.fov)?;
    study_report::say(&look.study);
    check(look.look.as_ref())?;
    if !(1..=MAX_STILL_FRAMES).contains(&args.still) {
        bail!(
            "--still must be between 1 and {MAX_STILL_FRAMES} frames, not {}",
            args.still
        );
    }
    let settings = &look.settings;
    let preset = look.study.preset();
    let camera = camera(
        args,
        preset,
        look.look.as_ref(),
        &loaded.volume,
        &look.study,
    )?;
    if let Some(path) = &args.show_structure {
        structure::write(path, &loaded.volume, &look.study)?;
    }
    let marks = args.case.annotations(&loaded.volume)?;
    let target = args.case.target(None)?;
    if (marks.is_some() || target.is_some()) && args.stereo.stereo.is_some() {
        bail!("--case and --target draw on one view: leave out --stereo");
    }
    let voxels = loaded.volume.voxels().len();
    let (filter, warning) = args.input.limits().still_filter(args.still_filter, voxels);
    if let Some(warning) = warning {
        eprintln!("warning: {warning}");
    }
    let renderer = Arc::new(Renderer::new(loaded.volume));
    let mut prepared = renderer
        .prepare(settings)
        .context("invalid render settings")?;
    let scene = args.scene.scene()?;
    prepared.set_scene(scene);
    if let Some([x, y]) = args.debug_pixel {
        print_trace(&prepared, &camera, x, y)?;
    }
    let stereo = args.stereo.rig(|| prepared.nearest_surface_mm(&camera))?;
    let frame = match stereo {
        Some((rig, output)) => {
            let frames = in_pool(args.look.threads, || {
                look::stereo_view(
                    &prepared,
                    look.look.as_ref(),
                    (&camera, &rig),
                    (args.still, filter),
                )
            })?
            .context("invalid stereo rig or look")?;
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
            let frame = in_pool(args.look.threads, || {
                look::still_view(&prepared, look.look.as_ref(), &camera, args.still, filter)
            })?
            .context("invalid look")?;
            let [w, h] = [frame.width as u32, frame.height as u32];
            let mut image = Image::from_frame(&frame, settings.background)?;
            let spacing = renderer.volume().geometry().spacing_mm();
            if let Some(marks) = &marks {
                draw_marks(&mut image, marks, &camera, &frame.depth_mm, spacing);
            }
            if let Some(target) = target {
                draw_target_mark(&mut image, target, &camera, &frame.depth_mm, spacing);
            }
            lens_marks::draw(&mut image, &camera);
            endocast_io::write_image_rgb8(&args.output, w, h, image.rgb())
                .context("cannot write the image")?;
            frame
        }
    };
    warn_if_empty(&frame, settings, &look.study, renderer.volume().dims());
    let [w, h] = [frame.width as u32, frame.height as u32];
    if let Some(depth) = &args.depth_out {
        endocast_io::image_out::write_npy_f32(depth, w, h, &frame.depth_mm)
            .context("cannot write the depth image")?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&stats_json(&frame, settings, &camera, &look.study))?
        );
    } else {
        println!(
            "{}: {}×{} {} in {:.1} ms",
            args.output.display(),
            frame.width,
            frame.height,
            look.look
                .as_ref()
                .map_or(settings.mode.name(), |l| l.kind.name()),
            frame.stats.time.as_secs_f64() * 1e3
        );
    }
    Ok(())
}

/// The camera of the study's start (the user's pose, or inside the structure the preset
/// means looking along its path, or the whole object framed), with `--up` and the lens options
/// over `look`'s lens.
fn camera(
    args: &RenderArgs,
    preset: Option<&Preset>,
    look: Option<&Look>,
    volume: &Volume,
    study: &Study,
) -> Result<Camera> {
    let pose = args.pose.with_up(study.start_pose());
    let (lo, hi) = volume.geometry().world_bounds();
    let height_mm = (hi - lo).length();
    let optics = args
        .lens
        .optics(preset, look, args.fov, args.near, height_mm)?;
    optics
        .camera(pose.eye_mm, pose.look_at_mm, pose.up, args.size)
        .context("invalid camera")
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

/// Warns, saying why and what to try, when nothing in the image was hit or drawn.
fn warn_if_empty(frame: &Frame, settings: &RenderSettings, study: &Study, dims: [usize; 3]) {
    let drawn = frame.color.iter().any(|p| p.transmittance < 0.99);
    if frame.stats.iso_hits > 0 || drawn {
        return;
    }
    let scan = study.scan();
    let (lo, hi) = scan.range;
    let what = format!(
        "no ray met the wall at {} or anything the transfer function shows (values {} to {}, \
         {scan})",
        short(settings.iso_hu),
        short(lo),
        short(hi)
    );
    let advice = if dims.contains(&1) {
        format!(
            "the scan is a single slice ({}×{}×{} voxels), not a volume to see into: open the \
             whole series (its folder) instead",
            dims[0], dims[1], dims[2]
        )
    } else if (settings.iso_hu - scan.object_threshold).abs() > 0.5 {
        format!(
            "try --iso {} (the background/object boundary), or another --preset",
            short(scan.object_threshold)
        )
    } else if study.request().pose.is_some() {
        "the camera placed with --eye sees nothing: leave out --eye and --look-at to frame the \
         object"
            .to_owned()
    } else {
        "try --mode mip to see the brightest values along each ray".to_owned()
    };
    eprintln!("warning: the image is empty: {what}; {advice}");
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
fn stats_json(
    frame: &Frame,
    settings: &RenderSettings,
    camera: &Camera,
    study: &Study,
) -> serde_json::Value {
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
        "study": study_report::to_json(study),
    })
}
