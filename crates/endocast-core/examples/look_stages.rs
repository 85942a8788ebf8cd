//! Where the realistic look's time goes, stage by stage, on the colon phantom's fly path (the
//! `endocast bench --look realistic` protocol): plain iso, the look's first-hit pass alone (the
//! renderer at the secretion threshold), the whole ray pass with secretion on and off, the
//! smoothing alone and the deferred stage (smoothing, shading and, below full quality, the
//! upsampling of the shaded frame). Median wall-clock ms per frame of 512×512.
//!
//! ```text
//! cargo run --release -p endocast-core --example look_stages -- [full|half] [FRAMES] [THREADS]
//! ```

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
    pool.install(|| stages(&renderer, &look, &cameras, quality))
}

/// Times every stage on every camera and prints the medians.
fn stages(
    renderer: &Arc<Renderer>,
    look: &Look,
    cameras: &[Camera],
    quality: Quality,
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
    let mut time = |stage: usize, run: &mut dyn FnMut()| {
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
        let gbuffer = gbuffer.ok_or("no G-buffer")?;
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
    println!("{} frames, {quality:?} quality, median ms:", cameras.len());
    for (name, mut v) in names.iter().zip(ms) {
        v.sort_by(f64::total_cmp);
        println!("  {name:<40} {:>7.1}", v[v.len() / 2]);
    }
    Ok(())
}
