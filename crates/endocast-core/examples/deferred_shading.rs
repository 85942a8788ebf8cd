//! The deferred stage alone on a fixed G-buffer: the sinus phantom (size 96) seen from inside
//! its right cell through a 90° pinhole at 512×512, traced once with the realistic look's ray
//! pass, then smoothed and shaded FRAMES times with the realistic look of the CT preset (its
//! detail texture, or the one named). Median wall-clock ms per frame; with one thread, a
//! repeatable workload for `valgrind --tool=callgrind`.
//!
//! ```text
//! cargo run --release -p endocast-core --example deferred_shading -- [FRAMES] [THREADS] [TEXTURE]
//! ```

use endocast_core::look::{self, Look, LookKind, PresetLook, RayPass, Texture};
use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::render::{Camera, Quality, RenderSettings, Renderer};
use glam::DVec3;
use std::sync::Arc;
use std::time::Instant;

/// Any error of this example.
type Error = Box<dyn std::error::Error + Send + Sync>;

fn main() -> Result<(), Error> {
    let mut args = std::env::args().skip(1);
    let frames: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(20);
    let threads: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(1);
    let texture = args.next();
    let (volume, _) = phantom::sinus(&PhantomOptions {
        size: 96,
        ..Default::default()
    });
    let eye = volume.geometry().world_of(DVec3::new(28.8, 38.0, 43.2));
    let camera = Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, 90.0, [512, 512])?;
    let mut look = Look::of_kind(LookKind::Realistic, &PresetLook::CT).ok_or("no look")?;
    if let Some(name) = texture {
        look.shading.texture = Texture::built_in(&name).map(Arc::new);
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()?;
    let renderer = Arc::new(Renderer::new(volume));
    let pass = RayPass::new(&renderer, &RenderSettings::default(), &look.ray)?;
    let gbuffer = pool.install(|| pass.trace(&camera, Quality::Full));
    let hits = gbuffer.depth_mm.iter().filter(|d| !d.is_nan()).count();
    let mut ms = Vec::with_capacity(frames);
    for _ in 0..frames {
        let start = Instant::now();
        pool.install(|| look::shade(&gbuffer, &camera, &look.shading))?;
        ms.push(start.elapsed().as_secs_f64() * 1e3);
    }
    ms.sort_by(f64::total_cmp);
    println!(
        "deferred stage, {frames} frames of 512×512 ({hits} hits), {threads} threads: \
         median {:.2} ms",
        ms[ms.len() / 2]
    );
    Ok(())
}
