//! Trilinear sampling throughput, one sample at a time against batches of eight (AVX2 where
//! the CPU has it): 100 000 rays of 64 samples through a sphere-shell phantom of the given
//! edge, random origins and directions (worst-case locality), several rounds.
//!
//! ```text
//! cargo run --release -p endocast-core --example sampler_throughput -- 32   # fits in L2
//! cargo run --release -p endocast-core --example sampler_throughput -- 512  # 256 MiB
//! ```

use endocast_core::phantom::{self, PhantomOptions};
use endocast_core::render::{SampleGrid, Sampler};
use glam::Vec3;
use std::time::Instant;

fn main() {
    let size: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(32);
    let (volume, _) = phantom::sphere_shell(&PhantomOptions {
        size,
        ..Default::default()
    });
    let rays = random_rays(size as f32 - 2.0, 100_000);
    for round in 0..3 {
        for (name, sampler) in [
            ("one by one", Sampler::new(&volume).scalar()),
            ("batches of 8", Sampler::new(&volume)),
        ] {
            let start = Instant::now();
            let mut sum = 0.0f32;
            for grid in &rays {
                for n in (0..64).step_by(8) {
                    sum += sampler.grid8(grid, n, 8).iter().sum::<f32>();
                }
            }
            let ns = start.elapsed().as_nanos() as f64 / (rays.len() * 64) as f64;
            println!("{size}³ round {round} {name}: {ns:.2} ns/sample (checksum {sum})");
        }
    }
}

/// `count` rays with origins uniform in `[0, extent]³`, unit directions, 0.5 mm steps.
fn random_rays(extent: f32, count: usize) -> Vec<SampleGrid> {
    let mut state = 1u64;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (state >> 40) as f32 / (1u64 << 24) as f32
    };
    (0..count)
        .map(|_| {
            let origin = Vec3::new(uniform(), uniform(), uniform()) * extent;
            let direction = Vec3::new(uniform(), uniform(), uniform()) - 0.5;
            SampleGrid {
                origin,
                direction: direction.normalize_or(Vec3::X),
                t_start: 0.0,
                offset: 0.5,
                step: 0.5,
            }
        })
        .collect()
}
