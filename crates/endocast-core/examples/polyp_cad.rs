//! Times the polyp detection (CAD) pass on the colon phantom with drawn polyps: the wall
//! voxels' curvatures, the hysteresis regions and their measures, without the phantom's
//! generation and the lumen's fill.
//!
//! `cargo run --release -p endocast-core --example polyp_cad [SIZE] [ROUNDS]` (default 512,
//! the 512 × 512 × 478 paper size, and 5 rounds; prints each round and the median).

use endocast_core::navigate::{Lumen, LumenSide};
use endocast_core::phantom::{colon_polyps, PhantomOptions};
use endocast_core::polyps::{find_candidates, PolypOptions};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let size: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(512);
    let rounds: usize = args.next().map(|s| s.parse()).transpose()?.unwrap_or(5);
    let options = PhantomOptions {
        size,
        ..PhantomOptions::default()
    };
    let (volume, truth) = colon_polyps(&options, 9);
    let line = &truth.colon.centreline;
    let seed = line
        .point_at(line.length_vox() / 2.0)
        .round()
        .to_array()
        .map(|c| c as usize);
    let lumen = Lumen::from_seed(&volume, seed, -480.0, LumenSide::Below)?;
    println!(
        "colon {:?} with {} polyps, {} rayon threads",
        volume.dims(),
        truth.polyps.len(),
        rayon::current_num_threads()
    );
    let mut seconds = Vec::with_capacity(rounds);
    for round in 1..=rounds {
        let start = Instant::now();
        let found = find_candidates(&volume, &lumen, &PolypOptions::default())?;
        seconds.push(start.elapsed().as_secs_f64());
        println!(
            "round {round}: {:.3} s, {} candidates",
            seconds[round - 1],
            found.len()
        );
    }
    seconds.sort_by(f64::total_cmp);
    println!("median {:.3} s", seconds[seconds.len() / 2]);
    Ok(())
}
