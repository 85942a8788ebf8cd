//! Frame sinks for fly-throughs: a folder of numbered PNGs, an animated GIF, or an MP4 (H.264
//! by the bundled OpenH264 encoder and our own muxer, or by the `ffmpeg` command-line tool when
//! asked). [`open_sink`] picks one from the output path.
//!
//! Every sink streams: a frame is encoded (or handed to `ffmpeg`) when it is pushed and nothing
//! keeps the frames, so a flight of any length runs in bounded memory. No sink leaves a half
//! output behind: the GIF and MP4 are written under a temporary name beside the target and
//! renamed only when [`FrameSink::finish`] succeeds, and a folder of PNGs is written as a
//! temporary folder beside it and swapped in whole then, so that the folder holds the old frames
//! or all the new ones, never a mix (a sink dropped unfinished removes its temporary file or
//! folder; see [`crate::atomic`]).
//!
//! ```no_run
//! use endocast_io::video::{open_sink, VideoOptions};
//!
//! let mut sink = open_sink("flight.gif".as_ref(), &VideoOptions::default())?;
//! for n in 0..10u8 {
//!     sink.push(&vec![n * 20; 64 * 48 * 3], 64, 48)?;
//! }
//! sink.finish()?;
//! # Ok::<(), endocast_io::ReadError>(())
//! ```

use crate::atomic::{Temporary, TemporaryFolder};
use crate::error::{ReadError, Result};
use crate::image_out::write_frame_png;
use endocast_core::views::Image;
use std::ffi::OsString;
use std::fs::File;
use std::io::{BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, Command, Stdio};
use std::thread::JoinHandle;

mod h264;
mod join;
mod mp4;

pub use join::{frame_files, read_frame};

/// Where the frames of a fly-through go.
pub trait FrameSink {
    /// Adds a frame of `width × height` pixels, `rgb` holding `width · height · 3` bytes, row 0
    /// at the top. Every frame must have the first frame's size.
    fn push(&mut self, rgb: &[u8], width: usize, height: usize) -> Result<()>;

    /// Adds an [`Image`] as the next frame.
    fn push_image(&mut self, image: &Image) -> Result<()> {
        self.push(image.rgb(), image.width(), image.height())
    }

    /// Number of frames pushed so far.
    fn frames(&self) -> usize;

    /// Completes the output (at least one frame must have been pushed) and returns its path.
    fn finish(self: Box<Self>) -> Result<PathBuf>;
}

/// The kinds of output, chosen by the path's ending.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SinkKind {
    /// Any path without one of the endings below: a folder of `frame_00000.png`, ...
    PngFolder,
    /// `.gif`: an animated GIF that loops.
    Gif,
    /// `.mp4`: H.264 video (yuv420p), by the built-in encoder or by `ffmpeg`.
    Mp4,
}

/// Endings that look like a single file of another kind, refused rather than made a folder.
const REFUSED_ENDINGS: [&str; 7] = ["png", "jpg", "jpeg", "avi", "mov", "mkv", "webm"];

impl SinkKind {
    /// The kind `path` asks for (case-insensitive ending); endings of images or other video
    /// containers are refused instead of becoming a folder by that name.
    pub fn for_path(path: &Path) -> Result<Self> {
        let ending = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ending.as_deref() {
            Some("gif") => Ok(Self::Gif),
            Some("mp4") => Ok(Self::Mp4),
            Some(e) if REFUSED_ENDINGS.contains(&e) => Err(ReadError::unsupported(
                path,
                format!("video output .{e}: write .gif, .mp4, or a folder of PNGs (no ending)"),
            )),
            _ => Ok(Self::PngFolder),
        }
    }
}

/// How to write a video.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct VideoOptions {
    /// Frames per second, 0.1–240. Default 25. (GIF stores delays in hundredths of a second, so
    /// its rate is rounded to the nearest such delay.)
    pub fps: f64,
    /// MP4 through this `ffmpeg` program (libx264; a name looked up on `PATH` or a path)
    /// instead of the built-in OpenH264 encoder. Default `None`: built in, nothing to install.
    pub ffmpeg: Option<PathBuf>,
    /// GIF colour quantisation speed, 1 (best) to 30 (fastest), NeuQuant's sampling factor.
    /// Default 10.
    pub gif_speed: i32,
    /// The number of the first frame in a folder of PNGs: a part of a flight (`fly --frames`)
    /// numbers its frames as the whole flight does, so that parts join by name. Default 0.
    pub first_number: usize,
}

impl Default for VideoOptions {
    fn default() -> Self {
        Self {
            fps: 25.0,
            ffmpeg: None,
            gif_speed: 10,
            first_number: 0,
        }
    }
}

/// Opens the sink `path` asks for (see [`SinkKind::for_path`]). MP4 through `ffmpeg` checks here
/// that it runs, so a missing tool is reported before any frame is rendered.
pub fn open_sink(path: &Path, options: &VideoOptions) -> Result<Box<dyn FrameSink>> {
    if !(options.fps.is_finite() && (0.1..=240.0).contains(&options.fps)) {
        let message = format!("{} frames per second is outside 0.1–240", options.fps);
        return Err(ReadError::format(path, message));
    }
    if !(1..=30).contains(&options.gif_speed) {
        let message = format!("GIF speed {} is outside 1–30", options.gif_speed);
        return Err(ReadError::format(path, message));
    }
    Ok(match SinkKind::for_path(path)? {
        SinkKind::PngFolder => Box::new(PngFolder::create(path, options.first_number)?),
        SinkKind::Gif => Box::new(GifSink::create(path, options)?),
        SinkKind::Mp4 => match &options.ffmpeg {
            None => Box::new(H264Sink::create(path, options)?),
            Some(program) => Box::new(FfmpegSink::create(path, program, options)?),
        },
    })
}

/// The size every frame must have, fixed by the first one.
#[derive(Debug, Default)]
struct FrameSize(Option<(usize, usize)>);

impl FrameSize {
    /// Checks a frame against its buffer, `max_edge` and the first frame's size.
    fn check(
        &mut self,
        path: &Path,
        rgb: &[u8],
        (width, height): (usize, usize),
        max_edge: usize,
    ) -> Result<()> {
        if !(1..=max_edge).contains(&width) || !(1..=max_edge).contains(&height) {
            let message = format!("a {width}×{height} frame: edges must be 1 to {max_edge} pixels");
            return Err(ReadError::format(path, message));
        }
        if Some(rgb.len()) != width.checked_mul(height).and_then(|n| n.checked_mul(3)) {
            let message = format!(
                "a {width}×{height} RGB frame needs {} bytes, the buffer holds {}",
                width * height * 3,
                rgb.len()
            );
            return Err(ReadError::inconsistent(path, message));
        }
        match self.0 {
            Some(first) if first != (width, height) => Err(ReadError::inconsistent(
                path,
                format!(
                    "frame of {width}×{height} after frames of {}×{}",
                    first.0, first.1
                ),
            )),
            _ => {
                self.0 = Some((width, height));
                Ok(())
            }
        }
    }
}

fn no_frames(path: &Path) -> ReadError {
    ReadError::format(path, "no frames were pushed, nothing to write")
}

/// A folder of `frame_00000.png`, `frame_00001.png`, ... (five digits, more past 99 999),
/// written into a temporary folder that replaces the folder on [`FrameSink::finish`]. The
/// other files of a folder flown into before stay (linked into the new one); the old frames go.
#[derive(Debug)]
struct PngFolder {
    dir: PathBuf,
    folder: TemporaryFolder,
    size: FrameSize,
    frames: usize,
    first_number: usize,
}

impl PngFolder {
    fn create(dir: &Path, first_number: usize) -> Result<Self> {
        other_files(dir)?;
        Ok(Self {
            dir: dir.to_path_buf(),
            folder: TemporaryFolder::create(dir)?,
            size: FrameSize::default(),
            frames: 0,
            first_number,
        })
    }

    /// Links the files of the old folder that are not frames into the new one.
    fn keep_other_files(&self) -> Result<()> {
        for name in other_files(&self.dir)? {
            let (from, to) = (self.dir.join(&name), self.folder.path().join(&name));
            std::fs::hard_link(&from, &to).map_err(|e| ReadError::io(&from, e))?;
        }
        Ok(())
    }
}

/// The names of the files in the folder `dir` (none when it does not exist) that are not
/// frames; an error for anything there but frames and plain files (a folder or a link in it
/// would be lost when the new frames replace it).
fn other_files(dir: &Path) -> Result<Vec<OsString>> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(Vec::new());
    };
    let mut names = Vec::new();
    for entry in entries {
        let entry = entry.map_err(|e| ReadError::io(dir, e))?;
        let name = entry.file_name();
        if name.to_str().is_some_and(is_frame_name) {
            continue;
        }
        if !entry.file_type().is_ok_and(|t| t.is_file()) {
            let message = format!(
                "holds {} besides frames and files, which writing frames into it would lose: \
                 write them into another folder",
                name.to_string_lossy()
            );
            return Err(ReadError::format(dir, crate::escape(&message)));
        }
        names.push(name);
    }
    Ok(names)
}

/// Whether `name` is a frame's, `frame_NNNNN.png` (five digits or more).
fn is_frame_name(name: &str) -> bool {
    frame_number(name).is_some()
}

/// The number of the frame named `name`, `frame_NNNNN.png` (five digits or more).
fn frame_number(name: &str) -> Option<usize> {
    name.strip_prefix("frame_")
        .and_then(|n| n.strip_suffix(".png"))
        .filter(|digits| digits.len() >= 5 && digits.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|digits| digits.parse().ok())
}

impl FrameSink for PngFolder {
    fn push(&mut self, rgb: &[u8], width: usize, height: usize) -> Result<()> {
        self.size
            .check(&self.dir, rgb, (width, height), u32::MAX as usize)?;
        let name = format!("frame_{:05}.png", self.first_number + self.frames);
        let path = self.folder.path().join(name);
        write_frame_png(&path, width as u32, height as u32, rgb)?;
        self.frames += 1;
        Ok(())
    }

    fn frames(&self) -> usize {
        self.frames
    }

    fn finish(self: Box<Self>) -> Result<PathBuf> {
        if self.frames == 0 {
            return Err(no_frames(&self.dir));
        }
        self.keep_other_files()?;
        self.folder.commit()?;
        Ok(self.dir)
    }
}

/// An animated GIF, each frame with its own 256-colour palette quantised by NeuQuant (the gif
/// crate's): smooth endoscopic shading keeps far more of its gradients than with one fixed
/// palette for the whole flight.
struct GifSink {
    target: Temporary,
    speed: i32,
    /// Delay between frames, hundredths of a second.
    delay_cs: u16,
    /// The open temporary file until the first frame creates the encoder.
    file: Option<BufWriter<File>>,
    encoder: Option<gif::Encoder<BufWriter<File>>>,
    size: FrameSize,
    frames: usize,
}

impl GifSink {
    fn create(path: &Path, options: &VideoOptions) -> Result<Self> {
        let (target, file) = Temporary::create(path)?;
        Ok(Self {
            delay_cs: (100.0 / options.fps).round().clamp(1.0, 65535.0) as u16,
            speed: options.gif_speed,
            file: Some(BufWriter::with_capacity(1 << 20, file)),
            encoder: None,
            target,
            size: FrameSize::default(),
            frames: 0,
        })
    }

    fn gif_error(&self, e: gif::EncodingError) -> ReadError {
        let io = match e {
            gif::EncodingError::Io(io) => io,
            other => std::io::Error::other(other),
        };
        ReadError::io(self.target.target(), io)
    }

    /// The encoder, created (with its header and a loop-forever extension) at the first frame.
    fn encoder(&mut self, width: u16, height: u16) -> Result<&mut gif::Encoder<BufWriter<File>>> {
        if let Some(file) = self.file.take() {
            let made = gif::Encoder::new(file, width, height, &[]).and_then(|mut encoder| {
                encoder.set_repeat(gif::Repeat::Infinite)?;
                Ok(encoder)
            });
            self.encoder = Some(made.map_err(|e| self.gif_error(e))?);
        }
        self.encoder
            .as_mut()
            .ok_or_else(|| ReadError::format(self.target.target(), "the GIF encoder failed before"))
    }
}

impl FrameSink for GifSink {
    fn push(&mut self, rgb: &[u8], width: usize, height: usize) -> Result<()> {
        let path = self.target.target().to_path_buf();
        self.size
            .check(&path, rgb, (width, height), usize::from(u16::MAX))?;
        // Both edges fit a u16: checked above.
        let (w, h) = (width as u16, height as u16);
        let mut frame = gif::Frame::from_rgb_speed(w, h, rgb, self.speed);
        frame.delay = self.delay_cs;
        let written = self.encoder(w, h)?.write_frame(&frame);
        written.map_err(|e| self.gif_error(e))?;
        self.frames += 1;
        Ok(())
    }

    fn frames(&self) -> usize {
        self.frames
    }

    fn finish(mut self: Box<Self>) -> Result<PathBuf> {
        let path = self.target.target().to_path_buf();
        let encoder = self.encoder.take().ok_or_else(|| no_frames(&path))?;
        let io = |e| ReadError::io(&path, e);
        // `into_inner` writes the trailer.
        let writer = encoder.into_inner().map_err(|e| self.gif_error(e))?;
        let file = writer.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        drop(file);
        self.target.commit()?;
        Ok(path)
    }
}

/// H.264 in MP4 by the built-in encoder ([`h264`]) and muxer ([`mp4`]), into a temporary file.
struct H264Sink {
    target: Temporary,
    /// The open temporary file until the first frame makes the muxer.
    file: Option<File>,
    fps: f64,
    coder: Option<(h264::H264Encoder, mp4::Mp4Muxer<BufWriter<File>>)>,
    size: FrameSize,
}

impl H264Sink {
    fn create(path: &Path, options: &VideoOptions) -> Result<Self> {
        let (target, file) = Temporary::create(path)?;
        Ok(Self {
            target,
            file: Some(file),
            fps: options.fps,
            coder: None,
            size: FrameSize::default(),
        })
    }

    /// The encoder and the muxer for frames of `width × height`, made at the first frame.
    fn start(
        &mut self,
        width: usize,
        height: usize,
    ) -> Result<(h264::H264Encoder, mp4::Mp4Muxer<BufWriter<File>>)> {
        let path = self.target.target();
        let encoder = h264::H264Encoder::new(width, height, self.fps)
            .map_err(|e| ReadError::io(path, std::io::Error::other(e)))?;
        let file = self
            .file
            .take()
            .ok_or_else(|| ReadError::format(path, "the H.264 encoder failed before"))?;
        let (w, h) = encoder.padded_size();
        // Both edges are at most MP4_MAX_EDGE (even), checked by the caller.
        let muxer = mp4::Mp4Muxer::new(BufWriter::new(file), w as u16, h as u16, self.fps)
            .map_err(|e| ReadError::io(path, e))?;
        Ok((encoder, muxer))
    }
}

/// The longest frame edge written to MP4 (the sample entry holds 16 bits). The built-in
/// encoder refuses more than 3840 × 2160 itself, with its own message.
const MP4_MAX_EDGE: usize = 16384;

impl FrameSink for H264Sink {
    fn push(&mut self, rgb: &[u8], width: usize, height: usize) -> Result<()> {
        let path = self.target.target().to_path_buf();
        self.size.check(&path, rgb, (width, height), MP4_MAX_EDGE)?;
        if self.coder.is_none() {
            self.coder = Some(self.start(width, height)?);
        }
        let Some((encoder, muxer)) = self.coder.as_mut() else {
            return Err(ReadError::format(&path, "the H.264 encoder failed before"));
        };
        let frame = encoder
            .encode(rgb)
            .map_err(|e| ReadError::io(&path, std::io::Error::other(e)))?;
        muxer.push(&frame).map_err(|e| ReadError::io(&path, e))
    }

    fn frames(&self) -> usize {
        self.coder.as_ref().map_or(0, |(_, muxer)| muxer.frames())
    }

    fn finish(mut self: Box<Self>) -> Result<PathBuf> {
        let path = self.target.target().to_path_buf();
        let (_, muxer) = self.coder.take().ok_or_else(|| no_frames(&path))?;
        let io = |e| ReadError::io(&path, e);
        let writer = muxer.finish().map_err(io)?;
        let file = writer.into_inner().map_err(|e| io(e.into_error()))?;
        file.sync_all().map_err(io)?;
        drop(file);
        self.target.commit()?;
        Ok(path)
    }
}

/// Most of `ffmpeg`'s error output kept for the error message, bytes.
const STDERR_KEPT: usize = 4000;

/// H.264 in MP4 by an `ffmpeg` child process reading raw RGB frames on its standard input.
struct FfmpegSink {
    target: Temporary,
    program: PathBuf,
    fps: f64,
    child: Option<Child>,
    stdin: Option<ChildStdin>,
    stderr: Option<JoinHandle<String>>,
    size: FrameSize,
    frames: usize,
}

impl FfmpegSink {
    fn create(path: &Path, program: &Path, options: &VideoOptions) -> Result<Self> {
        check_ffmpeg(path, program)?;
        Ok(Self {
            target: Temporary::create(path)?.0,
            program: program.to_path_buf(),
            fps: options.fps,
            child: None,
            stdin: None,
            stderr: None,
            size: FrameSize::default(),
            frames: 0,
        })
    }

    /// Starts `ffmpeg` for frames of `width × height`: odd sizes are padded by one black pixel
    /// (4:2:0 chroma needs even ones), output to the temporary file.
    fn spawn(&mut self, width: usize, height: usize) -> Result<()> {
        let mut child = Command::new(&self.program)
            .args(["-hide_banner", "-loglevel", "error", "-y"])
            .args(["-f", "rawvideo", "-pix_fmt", "rgb24"])
            .args([
                "-s",
                &format!("{width}x{height}"),
                "-r",
                &self.fps.to_string(),
            ])
            .args(["-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2"])
            .args(["-c:v", "libx264", "-pix_fmt", "yuv420p", "-f", "mp4"])
            .arg(self.target.path())
            .stdin(Stdio::piped())
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| ffmpeg_missing(self.target.target(), &self.program, &e))?;
        self.stdin = child.stdin.take();
        // Drained on a thread so that a chatty ffmpeg never blocks on a full pipe.
        self.stderr = child.stderr.take().map(|mut err| {
            std::thread::spawn(move || {
                let mut text = Vec::new();
                let _ = err.read_to_end(&mut text);
                let cut = text.len().saturating_sub(STDERR_KEPT);
                String::from_utf8_lossy(&text[cut..]).into_owned()
            })
        });
        self.child = Some(child);
        Ok(())
    }

    /// Waits for `ffmpeg` to exit; an error carries what it printed.
    fn wait(&mut self) -> Result<()> {
        drop(self.stdin.take());
        let path = self.target.target().to_path_buf();
        let Some(mut child) = self.child.take() else {
            return Err(no_frames(&path));
        };
        let status = child.wait().map_err(|e| ReadError::io(&path, e))?;
        let said = self
            .stderr
            .take()
            .and_then(|t| t.join().ok())
            .unwrap_or_default();
        if status.success() {
            Ok(())
        } else {
            let message = format!("ffmpeg failed ({status}): {}", said.trim());
            Err(ReadError::io(&path, std::io::Error::other(message)))
        }
    }
}

/// Runs `program -version` to see that ffmpeg is there.
fn check_ffmpeg(path: &Path, program: &Path) -> Result<()> {
    let status = Command::new(program)
        .arg("-version")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .map_err(|e| ffmpeg_missing(path, program, &e))?;
    if status.success() {
        Ok(())
    } else {
        let message = format!("`{} -version` failed ({status})", program.display());
        Err(ReadError::unsupported(path, message))
    }
}

fn ffmpeg_missing(path: &Path, program: &Path, e: &std::io::Error) -> ReadError {
    ReadError::unsupported(
        path,
        format!(
            "MP4 output: the ffmpeg command-line tool `{}` could not be run ({e}); install \
             ffmpeg or leave the built-in H.264 encoder to write the MP4",
            program.display()
        ),
    )
}

impl FrameSink for FfmpegSink {
    fn push(&mut self, rgb: &[u8], width: usize, height: usize) -> Result<()> {
        let path = self.target.target().to_path_buf();
        self.size.check(&path, rgb, (width, height), MP4_MAX_EDGE)?;
        if self.child.is_none() {
            self.spawn(width, height)?;
        }
        let written = match self.stdin.as_mut() {
            Some(stdin) => stdin.write_all(rgb),
            None => Err(std::io::Error::from(std::io::ErrorKind::BrokenPipe)),
        };
        if let Err(e) = written {
            // ffmpeg stopped reading: its own message says why.
            self.wait()?;
            return Err(ReadError::io(&path, e));
        }
        self.frames += 1;
        Ok(())
    }

    fn frames(&self) -> usize {
        self.frames
    }

    fn finish(mut self: Box<Self>) -> Result<PathBuf> {
        let path = self.target.target().to_path_buf();
        self.wait()?;
        self.target.commit()?;
        Ok(path)
    }
}

impl Drop for FfmpegSink {
    fn drop(&mut self) {
        drop(self.stdin.take());
        if let Some(mut child) = self.child.take() {
            // Unfinished: stop ffmpeg; the temporary file goes with `target`.
            let _ = child.kill();
            let _ = child.wait();
        }
    }
}
