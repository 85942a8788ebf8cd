//! Time per frame of MP4 encoding at 512×512: the built-in encoder (OpenH264 + our muxer)
//! against the ffmpeg pipe (libx264), on smooth moving frames like a fly-through's.
//!
//! cargo run -p endocast-io --example mp4_encode_time -- [FRAMES] [RUNS]

use endocast_io::video::{open_sink, VideoOptions};
use std::time::Instant;

const EDGE: usize = 512;

/// A smooth shaded ring pattern drifting with `n`, as an endoscopic view's gradients.
fn frame(n: usize) -> Vec<u8> {
    let shift = n as f64 * 3.0;
    (0..EDGE * EDGE)
        .flat_map(|p| {
            let (x, y) = ((p % EDGE) as f64 - 256.0 + shift, (p / EDGE) as f64 - 256.0);
            let r = (x * x + y * y).sqrt();
            let shade = 0.5 + 0.5 * (r / 23.0).cos();
            [
                (200.0 * shade) as u8 + 30,
                (120.0 * shade) as u8 + 20,
                (90.0 * shade) as u8,
            ]
        })
        .collect()
}

/// Milliseconds per frame of one encoding of `frames` frames.
fn run(options: &VideoOptions, frames: &[Vec<u8>]) -> f64 {
    let dir = std::env::temp_dir().join(format!("endocast-mp4-time-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("a temporary folder");
    let path = dir.join("t.mp4");
    let start = Instant::now();
    let mut sink = open_sink(&path, options).expect("the sink opens");
    for rgb in frames {
        sink.push(rgb, EDGE, EDGE).expect("the frame is encoded");
    }
    sink.finish().expect("the file is written");
    let ms = start.elapsed().as_secs_f64() * 1e3 / frames.len() as f64;
    let bytes = std::fs::metadata(&path).map_or(0, |m| m.len());
    println!(
        "  {ms:.2} ms/frame, {:.1} KiB/frame",
        bytes as f64 / 1024.0 / frames.len() as f64
    );
    let _ = std::fs::remove_dir_all(&dir);
    ms
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args()
        .skip(1)
        .map(|a| a.parse().expect("a count"));
    let (count, runs): (usize, usize) = (args.next().unwrap_or(100), args.next().unwrap_or(5));
    let frames: Vec<Vec<u8>> = (0..count).map(frame).collect();
    let builtin = VideoOptions::default();
    let mut ffmpeg = VideoOptions::default();
    ffmpeg.ffmpeg = Some("ffmpeg".into());
    for (name, options) in [
        ("built-in (OpenH264)", builtin),
        ("ffmpeg pipe (libx264)", ffmpeg),
    ] {
        println!("{name}: {count} frames of {EDGE}×{EDGE}");
        let times: Vec<f64> = (0..runs).map(|_| run(&options, &frames)).collect();
        println!(
            "{name}: median {:.2} ms/frame over {runs} runs",
            median(times)
        );
    }
}
