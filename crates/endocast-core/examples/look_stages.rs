//! Where the realistic look's time goes, stage by stage, on the colon phantom's fly path (the
//! `endocast bench --look realistic` protocol): plain iso, the look's first-hit pass alone (the
//! renderer at the secretion threshold), the whole ray pass with secretion on and off, the
//! smoothing alone and the deferred stage (smoothing, shading and, below full quality, the
//! upsampling of the shaded frame). Median wall-clock ms per frame of 512×512.
//!
//! ```text
//! cargo run --release -p endocast-core --example look_stages -- [full|half] [FRAMES] [THREADS] [all|iso|look]
//! ```
//!
//! `iso` or `look` runs only plain iso or only the look's frame (its ray pass with secretion and
//! its deferred stage), for instruction counts: e.g. `valgrind --tool=callgrind
//! --toggle-collect=look_stages::stages` with one thread counts that stage alone.

use endocast_core::look::{self, Look, LookKind, PresetLook, RayPass, SecretionMode};
use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::fly_through;
use endocast_core::render::quality::reduced_camera;
use endocast_core::render::{
    Camera, Frame, Mode, Quality, RenderOptions, RenderSettings, Renderer,
};
use std::sync::Arc;
use std::time::Instant;

/// Any error of this example.
type Error = Box<dyn std::error::Error + Send + Sync>;

fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let quality = match args.next().as_deref() {
        Some("half") => Quality::Half,
        _ => Quality::Full,
    };
    let frames: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(20);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(2);
    let only = match args.next().as_deref() {
        None | Some("all") => Only::All,
        Some("iso") => Only::Iso,
        Some("look") => Only::Look,
        Some(other) => return Err(format!("{other:?}: expected all, iso or look").into()),
    };
    let (volume, colon) = phantom::colon(&PhantomOptions {
        size: 512,
        ..Default::default()
    });
    let line = &colon.centreline;
    let poses = fly_through(
        volume.geometry(),
        |s| line.point_at(s),
        line.length_vox(),
        frames,
        10.0,
    )
    .ok_or("no fly path")?;
    let renderer = Arc::new(Renderer::for_many_frames(volume));
    let cameras = poses
        .iter()
        .map(|p| Camera::look_at(p.eye_mm, p.look_at_mm, p.up, 90.0, [512, 512]))
        .collect::<Result<Vec<_>, _>>()?;
    let look = Look::of_kind(LookKind::Realistic, &PresetLook::CT).ok_or("no look")?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    pool.install(|| stages(&renderer, &look, &cameras, quality, only))
}

/// Which stages run.
#[derive(Clone, Copy, PartialEq)]
enum Only {
    All,
    /// Plain iso alone.
    Iso,
    /// The look's frame alone: the ray pass with secretion and the deferred stage.
    Look,
}

/// Times every stage (or those `only` names) on every camera and prints the medians.
fn stages(
    renderer: &Arc<Renderer>,
    look: &Look,
    cameras: &[Camera],
    quality: Quality,
    only: Only,
) -> Result<(), Error> {
    let base = RenderSettings::default();
    let pass = RayPass::new(renderer, &base, &look.ray)?;
    let mut dry = look.ray.clone();
    dry.secretion = SecretionMode::Off;
    let dry = RayPass::new(renderer, &base, &dry)?;
    let mut iso = base.clone();
    iso.mode = Mode::Iso;
    let iso = renderer.prepare(&iso)?;
    let options = RenderOptions::new().quality(quality);
    let mut frame = Frame::default();
    let mut ms: [Vec<f64>; 6] = Default::default();
    let runs = |stage: usize| match only {
        Only::All => true,
        Only::Iso => stage == 0,
        Only::Look => stage == 2 || stage == 5,
    };
    let mut time = |stage: usize, run: &mut dyn FnMut()| {
        if !runs(stage) {
            return;
        }
        let start = Instant::now();
        run();
        ms[stage].push(start.elapsed().as_secs_f64() * 1e3);
    };
    for camera in cameras {
        // Nothing cancels these renders.
        time(0, &mut || {
            let _ = iso.render_with(camera, &options, &mut frame);
        });
        let first = pass.prepared();
        time(1, &mut || {
            let _ = first.render_with(camera, &options, &mut frame);
        });
        // Below full quality both stages run at the reduced size (as `endocast bench` does).
        let small = reduced_camera(camera, quality.reduced_size(camera.size()));
        let mut gbuffer = None;
        time(2, &mut || gbuffer = Some(pass.trace(&small, Quality::Full)));
        time(3, &mut || drop(dry.trace(&small, Quality::Full)));
        let Some(gbuffer) = gbuffer else { continue };
        time(4, &mut || drop(look::smooth::smooth(&gbuffer, 2)));
        let mut shaded = Ok(Frame::default());
        time(5, &mut || {
            shaded = look::shade_reduced(&gbuffer, camera, &look.shading)
        });
        shaded?;
    }
    let names = [
        "plain iso",
        "first-hit pass (secretion threshold)",
        "ray pass, secretion on",
        "ray pass, secretion off",
        "smoothing alone",
        "deferred stage (smoothing, shading)",
    ];
    // The look's frame: its ray pass with secretion and its deferred stage, frame by frame.
    let frames: Vec<f64> = ms[2].iter().zip(&ms[5]).map(|(a, b)| a + b).collect();
    let whole = median(frames);
    println!("{} frames, {quality:?} quality, median ms:", cameras.len());
    for (name, v) in names.iter().zip(&ms) {
        if let Some(m) = median(v.clone()) {
            println!("  {name:<40} {m:>7.1}");
        }
    }
    if let Some(whole) = whole {
        println!(
            "  {:<40} {whole:>7.1}",
            "look frame (ray pass on + deferred)"
        );
    }
    if let (Some(whole), Some(iso)) = (whole, median(ms[0].clone())) {
        println!("  {:<40} {:>7.2}", "look frame ÷ plain iso", whole / iso);
    }
    Ok(())
}

/// The median of `v` (`None` when empty).
fn median(mut v: Vec<f64>) -> Option<f64> {
    v.sort_by(f64::total_cmp);
    v.get(v.len() / 2).copied()
}
