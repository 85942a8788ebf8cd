//! Loads a scan N times and prints the median wall time and the peak resident memory.
//!
//! ```text
//! cargo run --release -p endocast-io --example load_time -- ../shared/data/abdomen-ct-pancreas-dicom 5
//! ```

use endocast_io::{open, OpenOptions};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let path = args.next().ok_or("usage: load_time PATH [RUNS]")?;
    let runs: usize = args.next().map_or(Ok(5), |n| n.parse())?;
    let mut seconds = Vec::with_capacity(runs);
    for run in 0..runs.max(1) {
        let start = Instant::now();
        let loaded = open(path.as_ref(), &OpenOptions::default())?;
        seconds.push(start.elapsed().as_secs_f64());
        if run == 0 {
            let volume = &loaded.volume;
            let g = volume.geometry();
            println!(
                "{:?} spacing {:?} mm, origin {:?}, {} {}, values {:?}, {}",
                volume.dims(),
                g.spacing_mm().to_array(),
                g.origin_mm().to_array(),
                g.orientation_code(),
                volume.modality().name(),
                volume.physical_range(),
                loaded.source.stored_type
            );
            for warning in &loaded.warnings {
                println!("warning: {warning}");
            }
        }
    }
    seconds.sort_by(f64::total_cmp);
    println!(
        "median {:.3} s over {} runs (min {:.3}, max {:.3}); peak RSS {}",
        seconds[seconds.len() / 2],
        seconds.len(),
        seconds[0],
        seconds[seconds.len() - 1],
        peak_rss().unwrap_or_else(|| "unknown".into())
    );
    Ok(())
}

/// VmHWM (peak resident set) from /proc/self/status, Linux only.
fn peak_rss() -> Option<String> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    Some(line.trim_start_matches("VmHWM:").trim().to_string())
}
