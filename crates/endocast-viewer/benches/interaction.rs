//! The interaction loop's latency (issue 21): from an input (a new camera pose) to the first
//! updated frame the UI can show, at moving quality, and to the full-quality frame, at 512×512
//! on the colon phantom, through the viewer's own session and render worker.
//!
//! `cargo bench -p endocast-viewer --bench interaction [-- SIZE [POSES [SCAN PRESET]]]`
//! (defaults 512, 40, the colon phantom of SIZE with colonoscopy); with a scan and a preset,
//! the poses follow the path the preset's study plans on it (as `endocast path`).
//!
//! On Linux it also reports the CPU time the process's threads ran, and waited runnable for a
//! CPU, from the input to the first frame (`/proc/self/task/*/schedstat`): on a shared machine
//! the waiting shows how much of the latency the load added.

use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::pose::Pose;
use endocast_core::presets::Preset;
use endocast_core::render::progressive::Stage;
use endocast_viewer::controller::FlyCamera;
use endocast_viewer::scene::{ScanSource, Scene};
use endocast_viewer::session::Session;
use std::sync::Arc;
use std::time::{Duration, Instant};

fn main() {
    let mut args = std::env::args().skip(1).filter(|a| !a.starts_with("--"));
    let size: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(512);
    let poses: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(40);
    let (mut session, flight, what) = match (args.next(), args.next()) {
        (Some(scan), Some(preset)) => on_scan(&scan, &preset),
        _ => on_colon(size),
    };
    session.set_view_size([512, 512]);
    let (mut first, mut full) = (Vec::new(), Vec::new());
    let (mut ran, mut waited) = (Vec::new(), Vec::new());
    let wait = Duration::from_secs(60);
    for k in 0..poses {
        let Some(camera) = FlyCamera::from_pose(&flight(k as f64 / poses as f64)) else {
            continue;
        };
        session.set_camera(camera);
        let cpu = cpu_times();
        let input = Instant::now();
        let generation = session.sync(true).expect("a new view");
        let preview = session
            .worker()
            .wait_for(generation, wait, |_| true)
            .expect("a frame");
        first.push((input.elapsed(), preview.stage));
        if let (Some((run0, wait0)), Some((run1, wait1))) = (cpu, cpu_times()) {
            ran.push(ms(run1.saturating_sub(run0)));
            waited.push(ms(wait1.saturating_sub(wait0)));
        }
        // The camera stops: the same view, refined.
        session.sync(false);
        let still = session.worker().generation();
        session
            .worker()
            .wait_for(still, wait, |f| f.stage == Stage::Full)
            .expect("the full frame");
        full.push(input.elapsed());
    }
    let mut first_ms: Vec<f64> = first.iter().map(|(d, _)| ms(*d)).collect();
    let mut full_ms: Vec<f64> = full.iter().map(|d| ms(*d)).collect();
    println!(
        "{what}, 512x512, {} poses along the path, first stages: {}",
        first.len(),
        stage_counts(first.iter().map(|f| f.1))
    );
    report("input -> first frame (moving quality)", &mut first_ms);
    report("input -> full-quality frame", &mut full_ms);
    if !ran.is_empty() {
        report("  CPU run by all threads, input -> first frame", &mut ran);
        report(
            "  waiting runnable for a CPU, input -> first frame",
            &mut waited,
        );
    }
}

/// Poses along a flight, by the share of it flown (0–1).
type Flight = Box<dyn Fn(f64) -> Pose>;

/// The colon phantom at `size` with the colonoscopy preset, flown along its centreline.
fn on_colon(size: usize) -> (Session, Flight, String) {
    let options = PhantomOptions {
        size,
        ..PhantomOptions::default()
    };
    let (volume, colon) = phantom::colon(&options);
    let geometry = *volume.geometry();
    let line = colon.centreline;
    let source = ScanSource::Phantom {
        name: "colon".into(),
        size,
    };
    let scene = Arc::new(Scene::new(source, volume));
    let length = line.length_vox();
    let at = move |s: f64| geometry.world_of(line.point_at(s));
    let pose = move |s: f64| {
        let (eye_mm, look_at_mm) = (at(s), at(s + 10.0));
        let forward = (look_at_mm - eye_mm).normalize_or_zero();
        let up = if forward.y.abs() < 0.9 {
            glam::DVec3::NEG_Y
        } else {
            glam::DVec3::Z
        };
        Pose {
            eye_mm,
            look_at_mm,
            up,
        }
    };
    let session = Session::new(scene, Preset::find("colonoscopy"), Some(pose(20.0)), || {});
    let flight = Box::new(move |share: f64| pose(20.0 + (length - 40.0) * share));
    (
        session,
        flight,
        format!("colon phantom {size}, colonoscopy"),
    )
}

/// A real scan with `preset`, flown along the path its study plans (`endocast path`'s).
fn on_scan(scan: &str, preset: &str) -> (Session, Flight, String) {
    let source = ScanSource::File {
        path: scan.into(),
        series: None,
        orientation: None,
    };
    let (volume, facts) = source
        .load_with_facts(&Default::default())
        .expect("the scan");
    let scene = Arc::new(Scene::new(source, volume).with_facts(facts));
    let session = Session::new(scene, Preset::find(preset), None, || {});
    let path = session
        .study()
        .path()
        .expect("a path the preset plans on this scan")
        .path
        .clone();
    let length = path.len_mm();
    let flight = Box::new(move |share: f64| {
        path.pose_at(length * share * 0.9, 10.0)
            .expect("a pose on the path")
    });
    (session, flight, format!("{scan}, {preset}"))
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// CPU time this process's threads have run, and waited runnable for a CPU, so far (Linux's
/// `/proc/self/task/*/schedstat`); `None` where that is not readable.
fn cpu_times() -> Option<(Duration, Duration)> {
    let (mut run, mut wait) = (0, 0);
    for task in std::fs::read_dir("/proc/self/task").ok()? {
        let text = std::fs::read_to_string(task.ok()?.path().join("schedstat")).ok()?;
        let mut fields = text.split_whitespace().map(str::parse::<u64>);
        run += fields.next()?.ok()?;
        wait += fields.next()?.ok()?;
    }
    Some((Duration::from_nanos(run), Duration::from_nanos(wait)))
}

fn report(what: &str, values: &mut [f64]) {
    values.sort_by(f64::total_cmp);
    let q = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
    println!(
        "{what}: median {:.1} ms, p10 {:.1} ms, p90 {:.1} ms, max {:.1} ms",
        q(0.5),
        q(0.1),
        q(0.9),
        q(1.0)
    );
}

/// "Preview(Eighth) ×29, Preview(Quarter) ×1": how often each stage came first.
fn stage_counts(stages: impl Iterator<Item = Stage>) -> String {
    let mut counts: Vec<(String, usize)> = Vec::new();
    for stage in stages.map(|s| format!("{s:?}")) {
        match counts.iter_mut().find(|(s, _)| *s == stage) {
            Some((_, n)) => *n += 1,
            None => counts.push((stage, 1)),
        }
    }
    let parts: Vec<String> = counts.iter().map(|(s, n)| format!("{s} ×{n}")).collect();
    parts.join(", ")
}
