//! Electronic cleansing time on the colon phantom with tagged pools (the benchmark).
//!
//! `cargo run --release -p endocast-core --example cleanse_time -- [SIZE] [ROUNDS]`
//! (default 512, 5): builds the phantom once, then cleanses it ROUNDS times and prints each time
//! and the median.

use endocast_core::cleanse::cleanse;
use endocast_core::phantom::{Phantom, PhantomOptions};
use std::time::Instant;

fn main() {
    let mut args = std::env::args().skip(1);
    let size = args.next().and_then(|a| a.parse().ok()).unwrap_or(512);
    let rounds: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let options = PhantomOptions {
        size,
        tagged_fluid: true,
        ..Default::default()
    };
    let volume = Phantom::Colon.build(&options);
    println!("colon phantom {:?} with tagged pools", volume.dims());
    let mut seconds = Vec::new();
    for round in 0..rounds.max(1) {
        let start = Instant::now();
        let cleansed = cleanse(&volume).expect("the phantom is a CT");
        seconds.push(start.elapsed().as_secs_f64());
        if round == 0 {
            println!("{}", cleansed.summary());
        }
        println!("round {round}: {:.3} s", seconds[round]);
    }
    seconds.sort_by(f64::total_cmp);
    println!(
        "median {:.3} s over {} rounds",
        seconds[seconds.len() / 2],
        seconds.len()
    );
}
