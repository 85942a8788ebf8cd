//! `endocast film`: the frames of a flight flown in parts (`fly --frames`, a folder of PNGs a
//! part) joined in order into one film, through the sinks `fly` writes with: the film is the
//! one the whole flight makes.

use crate::progress::Progress;
use anyhow::{Context, Result};
use clap::Args;
use endocast_io::video::{frame_files, open_sink, read_frame, VideoOptions};
use std::path::PathBuf;

/// Arguments of `endocast film`.
#[derive(Args, Debug)]
pub struct FilmArgs {
    /// The folders of frames (frame_NNNNN.png), in any order: together they must hold frames
    /// 0, 1, 2, … each once.
    #[arg(required = true)]
    folders: Vec<PathBuf>,
    /// Output: a .gif, an .mp4 (H.264, yuv420p) or a folder of PNG frames, as `fly -o`.
    #[arg(short, long)]
    output: PathBuf,
    /// Frames per second of the video (as the whole flight's `fly --fps`).
    #[arg(long, default_value_t = 25.0)]
    fps: f64,
    /// Encode the MP4 with this ffmpeg program (libx264) instead of the built-in OpenH264
    /// encoder (as `fly --ffmpeg`).
    #[arg(long, value_name = "PROGRAM")]
    ffmpeg: Option<PathBuf>,
}

/// Runs `endocast film`.
pub fn run(args: &FilmArgs) -> Result<()> {
    let files = frame_files(&args.folders)?;
    let mut options = VideoOptions::default();
    options.fps = args.fps;
    options.ffmpeg.clone_from(&args.ffmpeg);
    let mut sink = open_sink(&args.output, &options).context("cannot write the video")?;
    let mut progress = Progress::new("joining", files.len());
    for file in &files {
        let (width, height, rgb) = read_frame(file)?;
        sink.push(&rgb, width, height)?;
        progress.step();
    }
    progress.finish();
    let written = sink.finish()?;
    println!("{}: {} frames", written.display(), files.len());
    Ok(())
}
