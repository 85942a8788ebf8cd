//! Release-mode timing runs of the ray caster, ignored by default
//! (`cargo test --release -p endocast-core -- --ignored timing --nocapture`): they print, they
//! assert nothing about time.

use super::tests::colon_view;
use super::*;
use crate::phantom::{self, PhantomOptions};
use glam::Vec3;
use std::time::Instant;

fn options(size: usize) -> PhantomOptions {
    PhantomOptions {
        size,
        ..Default::default()
    }
}

#[test]
#[ignore = "timing: run with --release -- --ignored --nocapture"]
fn timing_reclassification_on_the_paper_size_colon() {
    let (renderer, _) = colon_view(512, 0.3, 8);
    let mut s = RenderSettings::preset("colonoscopy").unwrap();
    for iso in [-600.0, -500.0, -400.0] {
        s.iso_hu = iso;
        let start = Instant::now();
        let prepared = renderer.prepare(&s).unwrap();
        let ms = start.elapsed().as_secs_f64() * 1e3;
        println!(
            "prepare (TF table + activity) at iso {iso}: {ms:.2} ms, {} of {} bricks iso-active, {} TF-active",
            prepared.activity().iso.count(),
            renderer.grid().len(),
            prepared.activity().tf.count()
        );
        assert!(ms < 50.0);
    }
}

#[test]
#[ignore = "timing: run with --release -- --ignored --nocapture"]
fn timing_fly_through_the_paper_size_colon() {
    // ENDOCAST_TIMING_SIZE (default 512) and ENDOCAST_TIMING_MODES (a comma list of the labels'
    // first words, default all) shorten profiling runs.
    let size = std::env::var("ENDOCAST_TIMING_SIZE").map_or(512, |s| s.parse().unwrap_or(512));
    let only = std::env::var("ENDOCAST_TIMING_MODES").unwrap_or_default();
    let (volume, colon) = phantom::colon(&options(size));
    let start = Instant::now();
    let renderer = Arc::new(Renderer::new(volume));
    println!("brick grid: {:.1} ms", start.elapsed().as_secs_f64() * 1e3);
    let g = *renderer.volume().geometry();
    let line = &colon.centreline;
    let cameras: Vec<Camera> = (0..20)
        .map(|n| {
            let s = line.length_vox() * (0.1 + 0.8 * f64::from(n) / 20.0);
            let (eye, ahead) = (line.point_at(s), line.point_at(s + 10.0));
            let up = (ahead - eye).any_orthonormal_vector();
            Camera::look_at(g.world_of(eye), g.world_of(ahead), up, 90.0, [512, 512]).unwrap()
        })
        .collect();
    for (label, mode, tf, opacity) in [
        ("iso", Mode::Iso, "ramp", 1.0),
        ("hybrid 100% ramp", Mode::Hybrid, "ramp", 1.0),
        ("hybrid 50% ramp", Mode::Hybrid, "ramp", 0.5),
        ("hybrid 0% ramp", Mode::Hybrid, "ramp", 0.0),
        ("hybrid 50% complex", Mode::Hybrid, "complex", 0.5),
        ("hybrid 0% complex", Mode::Hybrid, "complex", 0.0),
        ("dvr colonoscopy", Mode::Dvr, "colonoscopy", 1.0),
    ] {
        let first_word = label.split(' ').next().unwrap_or_default();
        if !only.is_empty() && !only.split(',').any(|m| m == first_word) {
            continue;
        }
        let s = RenderSettings {
            mode,
            iso_opacity: opacity,
            tf: TransferFunction::preset(tf).unwrap(),
            ..Default::default()
        };
        let prepared = renderer.prepare(&s).unwrap();
        let mut total = RenderStats::default();
        let mut worst: f64 = 0.0;
        for camera in &cameras {
            let frame = prepared.render(camera);
            worst = worst.max(frame.stats.time.as_secs_f64());
            total.add(&frame.stats);
        }
        let n = cameras.len() as f64;
        let ms = total.time.as_secs_f64() * 1e3 / n;
        println!(
            "{label:>20}: {ms:6.1} ms/frame avg ({:5.1} fps), worst {:6.1} ms, {:.1} M samples/frame, \
             {:.0} M samples/s, {:.0}% rays terminated early, {:.0}% bricks skipped",
            1e3 / ms,
            worst * 1e3,
            total.samples as f64 / n / 1e6,
            total.samples as f64 / total.time.as_secs_f64() / 1e6,
            100.0 * total.terminated_early as f64 / total.rays.max(1) as f64,
            100.0 * total.bricks_skipped as f64
                / (total.bricks_skipped + total.bricks_visited).max(1) as f64,
        );
    }
}

#[test]
#[ignore = "timing: run with --release -- --ignored --nocapture"]
fn timing_trilinear_sample() {
    let (volume, _) = phantom::sphere_shell(&options(64));
    let sampler = Sampler::new(&volume);
    let mut p = Vec3::new(10.3, 20.7, 30.1);
    let step = Vec3::new(0.31, 0.17, 0.23);
    let start = Instant::now();
    let cpu_start = thread_cpu_ns();
    let mut sum = 0.0;
    let n = 20_000_000;
    for _ in 0..n {
        sum += sampler.value(p);
        p += step;
        if p.x > 60.0 || p.y > 60.0 || p.z > 60.0 {
            p -= Vec3::splat(50.0);
        }
    }
    let ns = start.elapsed().as_secs_f64() * 1e9 / f64::from(n);
    let cpu = (thread_cpu_ns() - cpu_start) / f64::from(n);
    println!("trilinear: {ns:.2} ns/sample wall, {cpu:.2} ns on the CPU (checksum {sum})");
}

/// CPU time of this thread, ns (Linux; 0 elsewhere): timings on a shared machine.
fn thread_cpu_ns() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(0.0)
}
