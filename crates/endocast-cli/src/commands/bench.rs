//! `endocast bench`: frames per second along a fixed fly path. Without a scan it runs the
//! protocol of Scharsach et al.'s Tables 1 and 2 on the colon phantom (512×512×478 at the default
//! size): iso-only, then the hybrid mode at isosurface opacity 100 / 80 / 50 / 0 % with a simple
//! ramp and a complex transfer function; with a scan and `--path` it measures one setting.

use crate::look::{in_pool, LookArgs};
use crate::parse::parse_size;
use crate::route::read_route;
use anyhow::{bail, Context, Result};
use clap::Args;
use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::{fly_through, Pose};
use endocast_core::render::{
    Camera, Frame, Mode, Quality, RenderOptions, RenderSettings, Renderer, TransferFunction,
};
use endocast_io::OpenOptions;
use glam::DVec3;
use serde_json::json;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Arc;

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
    /// Size of the colon phantom (512 gives the paper's 512×512×478).
    #[arg(long, default_value_t = 512)]
    size: usize,
    /// Frames of the colon phantom's fly path (or along a --path file of points).
    #[arg(long, default_value_t = 60)]
    frames: usize,
    /// Image size in pixels.
    #[arg(long, value_name = "WxH", default_value = "512x512", value_parser = parse_size)]
    image: [usize; 2],
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 90.0)]
    fov: f64,
    /// Cast rays at full, half or quarter resolution (upsampled to --image, edge-aware).
    #[arg(long, default_value = "full", value_parser = parse_quality)]
    quality: Quality,
    #[command(flatten)]
    look: LookArgs,
    /// Also append one JSON line per measured setting to this file.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
}

/// One measured setting: what it was and how fast it ran.
struct Cell {
    name: String,
    settings: RenderSettings,
}

/// Timings of one setting over the whole path.
struct Measured {
    ms: Vec<f64>,
    samples: u64,
}

/// Runs `endocast bench`.
pub fn run(args: &BenchArgs) -> Result<()> {
    let (renderer, poses, cells) = match &args.volume {
        None => paper_protocol(args)?,
        Some(volume) => one_setting(args, volume)?,
    };
    let renderer = Arc::new(renderer);
    let options = RenderOptions::new().quality(args.quality);
    let cameras: Vec<Camera> = poses
        .iter()
        .map(|p| Camera::look_at(p.eye_mm, p.look_at_mm, p.up, args.fov, args.image))
        .collect::<Result<_, _>>()
        .context("invalid camera on the path")?;
    println!(
        "{} frames of {}×{} ({} quality), {}° vertical field of view, {} threads",
        cameras.len(),
        args.image[0],
        args.image[1],
        args.quality.name(),
        args.fov,
        args.look.threads.unwrap_or_else(rayon::current_num_threads)
    );
    println!("| setting | min fps | avg fps | max fps | median ms | Msamples/s |");
    println!("|---|---|---|---|---|---|");
    for cell in &cells {
        let prepared = renderer
            .prepare(&cell.settings)
            .context("invalid settings")?;
        let measured = in_pool(args.look.threads, || {
            let mut m = Measured {
                ms: Vec::with_capacity(cameras.len()),
                samples: 0,
            };
            let mut frame = Frame::default();
            for camera in &cameras {
                // Nothing cancels it.
                let _ = prepared.render_with(camera, &options, &mut frame);
                m.ms.push(frame.stats.time.as_secs_f64() * 1e3);
                m.samples += frame.stats.samples;
            }
            m
        })?;
        report(args, cell, &measured)?;
    }
    Ok(())
}

/// A `--quality` level by name.
fn parse_quality(name: &str) -> Result<Quality, String> {
    Quality::from_name(name).ok_or_else(|| format!("{name:?}: expected full, half or quarter"))
}

/// The colon phantom, its fly path, and the paper's table cells.
fn paper_protocol(args: &BenchArgs) -> Result<(Renderer, Vec<Pose>, Vec<Cell>)> {
    if !(32..=1024).contains(&args.size) {
        bail!("--size must be between 32 and 1024, not {}", args.size);
    }
    let (volume, colon) = phantom::colon(&PhantomOptions {
        size: args.size,
        ..PhantomOptions::default()
    });
    let line = &colon.centreline;
    let poses = fly_through(
        volume.geometry(),
        |s| line.point_at(s),
        line.length_vox(),
        args.frames,
        10.0,
    )
    .with_context(|| format!("no fly path of {} frames fits the colon", args.frames))?;
    let base = args.look.settings()?;
    let with = |change: &dyn Fn(&mut RenderSettings)| {
        let mut s = base.clone();
        change(&mut s);
        s
    };
    let mut cells = vec![Cell {
        name: "iso only".into(),
        settings: with(&|s| s.mode = Mode::Iso),
    }];
    for tf in ["ramp", "complex"] {
        let tf_fn = TransferFunction::preset(tf).context("benchmark transfer function")?;
        for opacity in [1.0, 0.8, 0.5, 0.0] {
            cells.push(Cell {
                name: format!("hybrid {:.0} %, {tf} TF", opacity * 100.0),
                settings: with(&|s| {
                    s.mode = Mode::Hybrid;
                    s.iso_opacity = opacity;
                    s.tf = tf_fn.clone();
                }),
            });
        }
    }
    Ok((Renderer::for_many_frames(volume), poses, cells))
}

/// A scan, the path the user gave, and the one setting the options describe.
fn one_setting(args: &BenchArgs, volume: &Path) -> Result<(Renderer, Vec<Pose>, Vec<Cell>)> {
    let path = args.path.as_ref().context("a scan needs a camera --path")?;
    let poses = read_path(path, args.frames)?;
    let mut options = OpenOptions::default();
    options.orientation.clone_from(&args.orientation);
    let loaded = endocast_io::open(volume, &options).context("cannot read the scan")?;
    let settings = args.look.settings()?;
    let cell = Cell {
        name: format!("{} {}", volume.display(), settings.mode.name()),
        settings,
    };
    Ok((Renderer::for_many_frames(loaded.volume), poses, vec![cell]))
}

/// Reads a camera path file: a JSON list of {"eye", "look_at", "up"} (world mm, the format the
/// VTK peer script reads too), or a path as `endocast fly` takes it (then `frames` cameras
/// spread evenly along it, looking 10 mm ahead).
fn read_path(path: &Path, frames: usize) -> Result<Vec<Pose>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the path {}", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).with_context(|| format!("{}: not JSON", path.display()))?;
    let Some(list) = value.as_array() else {
        return route_poses(path, frames);
    };
    let vector = |item: &serde_json::Value, key: &str, n: usize| -> Result<DVec3> {
        let v: Option<Vec<f64>> = item[key]
            .as_array()
            .and_then(|a| a.iter().map(serde_json::Value::as_f64).collect());
        match v.as_deref() {
            Some(&[x, y, z]) => Ok(DVec3::new(x, y, z)),
            _ => bail!(
                "{}: camera {n} has no {key:?} of three numbers",
                path.display()
            ),
        }
    };
    let poses = list
        .iter()
        .enumerate()
        .map(|(n, item)| {
            Ok(Pose {
                eye_mm: vector(item, "eye", n)?,
                look_at_mm: vector(item, "look_at", n)?,
                up: vector(item, "up", n)?,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    if poses.is_empty() {
        bail!("{}: the path has no cameras", path.display());
    }
    Ok(poses)
}

/// `frames` cameras spread evenly along a route file (see [`read_route`]).
fn route_poses(path: &Path, frames: usize) -> Result<Vec<Pose>> {
    let route = read_route(path)?;
    let step = route.len_mm() / frames.saturating_sub(1).max(1) as f64;
    let shots = route.shots(step, 10.0).context("cannot sample the path")?;
    Ok(shots
        .into_iter()
        .take(frames)
        .map(|shot| shot.pose)
        .collect())
}

/// Prints one table row (and appends a JSON line when asked).
fn report(args: &BenchArgs, cell: &Cell, m: &Measured) -> Result<()> {
    let total_s: f64 = m.ms.iter().sum::<f64>() / 1e3;
    let fps: Vec<f64> = m.ms.iter().map(|ms| 1e3 / ms).collect();
    let min = fps.iter().copied().fold(f64::INFINITY, f64::min);
    let max = fps.iter().copied().fold(0.0, f64::max);
    let avg = m.ms.len() as f64 / total_s;
    let mut sorted = m.ms.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[sorted.len() / 2];
    let msamples = m.samples as f64 / total_s / 1e6;
    println!(
        "| {} | {min:.1} | {avg:.1} | {max:.1} | {median:.1} | {msamples:.0} |",
        cell.name
    );
    if let Some(file) = &args.json {
        let line = json!({
            "setting": cell.name,
            "frames": m.ms.len(),
            "image": args.image,
            "fov_deg": args.fov,
            "fps_min": min, "fps_avg": avg, "fps_max": max,
            "ms_median": median,
            "ms": m.ms,
            "samples_per_s": m.samples as f64 / total_s,
        });
        let mut f = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(file)
            .with_context(|| format!("cannot open {}", file.display()))?;
        writeln!(f, "{line}").with_context(|| format!("cannot write {}", file.display()))?;
    }
    Ok(())
}
