//! The cost of `isosurface()` alone (no file reading or writing): a phantom built in memory,
//! meshed several times; prints the CPU seconds of the process per extraction (user + system,
//! from /proc/self/stat, so Linux only; its clock ticks are 10 ms, hence the mean over all
//! runs), the median wall seconds, and the mesh's size. Run with `RAYON_NUM_THREADS=1` to
//! compare with VTK's flying edges on one thread.
//!
//! ```text
//! RAYON_NUM_THREADS=1 cargo run --release -p endocast-core --example mesh_extraction -- \
//!     colon 256 -500 5
//! ```

use endocast_core::isosurface::isosurface;
use endocast_core::navigate::LumenSide;
use endocast_core::phantom::{Phantom, PhantomOptions};
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let arg = |n: usize, default: &str| args.get(n).cloned().unwrap_or(default.to_string());
    let name = arg(0, "colon");
    let size: usize = arg(1, "256").parse().expect("size: a whole number");
    let iso: f64 = arg(2, "-500").parse().expect("iso: a number");
    let runs: usize = arg(3, "5").parse().expect("runs: a whole number");
    let phantom = Phantom::from_name(&name).expect("a phantom's name (endocast phantom --help)");
    let volume = phantom.build(&PhantomOptions {
        size,
        ..Default::default()
    });
    let (mut wall, mut size_of) = (Vec::new(), (0, 0));
    let start_cpu = cpu_seconds();
    for _ in 0..runs {
        let start = Instant::now();
        let mesh = isosurface(&volume, iso, LumenSide::Below).expect("a surface");
        wall.push(start.elapsed().as_secs_f64());
        size_of = (mesh.triangles().len(), mesh.vertices().len());
    }
    let cpu = (cpu_seconds() - start_cpu) / runs.max(1) as f64;
    println!(
        "{name} {:?} iso {iso}: {} triangles, {} vertices; {runs} runs: CPU {cpu:.3} s each \
         (mean), wall {:.3} s (median)",
        volume.dims(),
        size_of.0,
        size_of.1,
        median(wall)
    );
}

/// User + system CPU seconds of this process so far (clock ticks of 1/100 s).
fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command's closing parenthesis: utime and stime are the 12th and 13th.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let field = |n: usize| {
        rest.split_whitespace()
            .nth(n)
            .and_then(|v| v.parse::<f64>().ok())
    };
    (field(11).unwrap_or(0.0) + field(12).unwrap_or(0.0)) / 100.0
}

/// The median of `values`.
fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}
