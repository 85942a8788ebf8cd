//! `endocast render`: one view of a scan, from inside (endoscopic) or framing it from outside.

use crate::input::InputArgs;
use crate::look::{in_pool, LookArgs};
use crate::lumen::LumenArgs;
use crate::parse::{parse_pixel, parse_size, parse_vec3};
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::navigate::{default_viewpoint, preset_lumen};
use endocast_core::pose::Pose;
use endocast_core::render::{Camera, Frame, Prepared, RenderSettings, Renderer};
use endocast_core::{Geometry, Volume};
use glam::DVec3;
use serde_json::json;
use std::path::PathBuf;
use std::sync::Arc;

/// Arguments of `endocast render`.
#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    input: InputArgs,
    /// Output PNG (8-bit sRGB).
    #[arg(short, long)]
    output: PathBuf,
    #[command(flatten)]
    look: LookArgs,
    #[command(flatten)]
    lumen: LumenArgs,
    /// Eye position, world mm (LPS, as `endocast info` reports). Without it, an endoscopic
    /// preset looks along the largest lumen from its most central point; otherwise the view
    /// frames the whole volume from the front.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    eye: Option<[f64; 3]>,
    /// Point looked at, world mm (needed with --eye).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    look_at: Option<[f64; 3]>,
    /// Up direction (default: superior, +z; posterior when looking up or down).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true)]
    up: Option<[f64; 3]>,
    /// Vertical field of view in degrees (10–170).
    #[arg(long, default_value_t = 90.0)]
    fov: f64,
    /// Distance from the eye to the near plane, mm (may lie inside tissue).
    #[arg(long, default_value_t = 0.0)]
    near: f64,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    size: [usize; 2],
    /// Also write the depth image: float32 .npy, mm from the eye to the first hit, NaN where none.
    #[arg(long, value_name = "FILE.npy")]
    depth_out: Option<PathBuf>,
    /// Print the frame's statistics as JSON.
    #[arg(long)]
    json: bool,
    /// Trace one pixel and print every sample along its ray.
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    debug_pixel: Option<[usize; 2]>,
}

/// Runs `endocast render`.
pub fn run(args: &RenderArgs) -> Result<()> {
    let settings = args.look.settings()?;
    let loaded = args.input.open()?;
    for warning in &loaded.warnings {
        eprintln!("warning: {warning}");
    }
    let camera = camera(args, &loaded.volume, &settings)?;
    let renderer = Arc::new(Renderer::new(loaded.volume));
    let prepared = renderer
        .prepare(&settings)
        .context("invalid render settings")?;
    if let Some([x, y]) = args.debug_pixel {
        print_trace(&prepared, &camera, x, y)?;
    }
    let frame = in_pool(args.look.threads, || prepared.render(&camera))?;
    let [w, h] = [frame.width as u32, frame.height as u32];
    let rgb = frame.to_rgb8(settings.background);
    endocast_io::image_out::write_png_rgb8(&args.output, w, h, &rgb)
        .context("cannot write the image")?;
    if let Some(depth) = &args.depth_out {
        endocast_io::image_out::write_npy_f32(depth, w, h, &frame.depth_mm)
            .context("cannot write the depth image")?;
    }
    if args.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&stats_json(&frame, &settings))?
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

/// The camera the options describe; without one, for an endoscopic preset, a view from inside
/// the largest lumen along its axis, else one framing the whole volume from the front.
fn camera(args: &RenderArgs, volume: &Volume, settings: &RenderSettings) -> Result<Camera> {
    let (eye, look_at, up) = match (args.eye, args.look_at) {
        (Some(eye), Some(look_at)) => (DVec3::from(eye), DVec3::from(look_at), None),
        (None, None) => match inside_view(args, volume, settings) {
            Some(pose) => (pose.eye_mm, pose.look_at_mm, Some(pose.up)),
            None => {
                let (eye, look_at) = framing_eye(volume.geometry(), args.fov);
                (eye, look_at, None)
            }
        },
        _ => bail!("--eye and --look-at go together"),
    };
    let up = args
        .up
        .map(DVec3::from)
        .or(up)
        .unwrap_or_else(|| default_up(look_at - eye));
    Camera::look_at(eye, look_at, up, args.fov, args.size)
        .and_then(|c| c.with_near_mm(args.near))
        .context("invalid camera")
}

/// The default endoscopic view of `--preset` (see [`default_viewpoint`]), if it names a lumen
/// and the scan has one.
fn inside_view(args: &RenderArgs, volume: &Volume, settings: &RenderSettings) -> Option<Pose> {
    let name = args
        .look
        .preset()
        .filter(|name| preset_lumen(name).is_some())?;
    let (threshold, side) = match args.lumen.resolve(Some(name), Some(settings.iso_hu)) {
        Ok(lumen) => lumen,
        Err(error) => {
            eprintln!("warning: {error:#}; framing the whole volume instead");
            return None;
        }
    };
    let pose = default_viewpoint(volume, threshold, side);
    match &pose {
        Some(p) => eprintln!(
            "camera inside the largest lumen {side} {threshold}: --eye {} --look-at {} --up {}",
            triple(p.eye_mm),
            triple(p.look_at_mm),
            triple(p.up)
        ),
        None => eprintln!("warning: no lumen {side} {threshold}; framing the whole volume instead"),
    }
    pose
}

/// `x,y,z` with two decimals, as `--eye` takes it.
fn triple(v: DVec3) -> String {
    format!("{:.2},{:.2},{:.2}", v.x, v.y, v.z)
}

/// Superior (+z in LPS), or posterior when looking (nearly) straight up or down.
fn default_up(forward: DVec3) -> DVec3 {
    let forward = forward.normalize_or_zero();
    if forward.dot(DVec3::Z).abs() > 0.99 {
        DVec3::Y
    } else {
        DVec3::Z
    }
}

/// An eye in front of the patient (anterior, −y in LPS) from which the bounding sphere of the
/// volume fills the vertical field of view, looking at the volume's centre.
fn framing_eye(geometry: &Geometry, fov_deg: f64) -> (DVec3, DVec3) {
    let (lo, hi) = geometry.world_bounds();
    let centre = (lo + hi) / 2.0;
    let radius = ((hi - lo).length() / 2.0).max(1.0);
    let half_fov = (fov_deg.clamp(10.0, 170.0) / 2.0).to_radians();
    let distance = radius / half_fov.sin();
    (centre - DVec3::Y * distance, centre)
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

fn stats_json(frame: &Frame, settings: &RenderSettings) -> serde_json::Value {
    let s = &frame.stats;
    json!({
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
