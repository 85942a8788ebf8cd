//! Times the navigation field on the colon phantom and reports peak memory (Linux).
//!
//! `cargo run --release -p endocast-core --example navigate_colon [SIZE]` (default 512, the
//! 512 × 512 × 478 paper size).

use endocast_core::navigate::{
    centreline, default_viewpoint, DistanceField, Lumen, LumenSide, PathEnd,
};
use endocast_core::phantom::{self, PhantomOptions};
use std::time::Instant;

/// Resident and peak resident memory of this process, MiB (zero where /proc is missing).
fn memory_mib() -> (f64, f64) {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    let field = |name: &str| {
        status
            .lines()
            .find(|l| l.starts_with(name))
            .and_then(|l| l.split_whitespace().nth(1))
            .and_then(|kb| kb.parse::<f64>().ok())
            .unwrap_or(0.0)
            / 1024.0
    };
    (field("VmRSS:"), field("VmHWM:"))
}

fn report(stage: &str, started: Instant) {
    let (rss, peak) = memory_mib();
    println!(
        "{stage:<24} {:>8.3} s   RSS {rss:>7.1} MiB   peak {peak:>7.1} MiB",
        started.elapsed().as_secs_f64()
    );
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let size = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(512);
    let t = Instant::now();
    let (volume, colon) = phantom::colon(&PhantomOptions {
        size,
        ..Default::default()
    });
    report("phantom", t);
    println!(
        "dims {:?}, threads {}",
        volume.dims(),
        rayon::current_num_threads()
    );
    let line = &colon.centreline;
    let seed = line.point_at(0.0).round();
    let t = Instant::now();
    let lumen = Lumen::from_seed(
        &volume,
        [seed.x as usize, seed.y as usize, seed.z as usize],
        -480.0,
        LumenSide::Below,
    )?;
    report("lumen (flood fill)", t);
    let (lo, hi) = lumen.bounds();
    println!("lumen {} voxels, box {lo:?}..{hi:?}", lumen.voxel_count());
    let t = Instant::now();
    let field = DistanceField::new(&lumen, volume.geometry());
    report("distance field", t);
    println!(
        "field {:.1} MiB, max {:.2} mm",
        field.bytes() as f64 / 1048576.0,
        field.max_mm()
    );
    let g = volume.geometry();
    let (start, end) = (
        g.world_of(line.point_at(0.0)),
        g.world_of(line.point_at(line.length_vox())),
    );
    let t = Instant::now();
    let path = centreline(&volume, &lumen, &field, start, PathEnd::Point(end))?;
    report("centreline end to end", t);
    println!(
        "path {} points, {:.1} mm (analytic {:.1}), distance min {:.2} mean {:.2} mm",
        path.points_mm.len(),
        path.length_mm,
        line.length_vox(),
        path.min_distance_mm,
        path.mean_distance_mm
    );
    let t = Instant::now();
    let far = centreline(&volume, &lumen, &field, start, PathEnd::Farthest)?;
    report("centreline to farthest", t);
    println!("farthest path {:.1} mm", far.length_mm);
    let t = Instant::now();
    let pose = default_viewpoint(&volume, -480.0, LumenSide::Below);
    report("default viewpoint", t);
    println!("{pose:?}");
    Ok(())
}
