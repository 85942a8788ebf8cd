//! Resource limits checked before any allocation a header (or an image size) asks for.

use crate::error::{ReadError, Result};
use endocast_core::look::{GBuffer, Look};
use endocast_core::render::{BSplineCoefficients, Filter, Frame, Layers, StereoFrames};
use endocast_core::views::Image;
use std::path::Path;

/// Caps on what a header or an option may make us allocate. A file that claims more is refused
/// with [`ReadError::Limit`] before anything is allocated.
///
/// "Memory" below is the machine's physical memory, or less where the process may use less: a
/// container's (cgroup's) memory limit or an address-space limit (`ulimit -v`, `prlimit --as`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Limits {
    /// Largest number of voxels a volume may have. Default: what fits in half of the
    /// memory at 2 bytes a voxel (1 GiB of voxels where memory is unknown).
    pub max_voxels: u64,
    /// Largest number of files or slices a series may have. Default: 100 000.
    pub max_slices: u64,
    /// Largest memory the rendered frames of one view may take, bytes (see
    /// [`Limits::check_frames`]). Default: a quarter of the memory (1 GiB where memory is
    /// unknown).
    pub max_frame_bytes: u64,
    /// Largest number of frames a flight or a benchmark run may have (see
    /// [`Limits::check_frame_count`]). Default: 100 000, over an hour at 25 frames a second.
    pub max_frames: u64,
    /// Most worker threads a command may start (see [`Limits::check_threads`]). Default:
    /// [`THREADS_PER_CORE`] per core.
    pub max_threads: usize,
}

/// Worker threads allowed per core: more only share the cores and cost memory.
pub const THREADS_PER_CORE: usize = 8;

impl Default for Limits {
    fn default() -> Self {
        Self::for_memory(memory_bytes().unwrap_or(1 << 32))
    }
}

impl Limits {
    /// The default limits for a process that may use `memory` bytes (see [`Limits`]).
    pub fn for_memory(memory: u64) -> Self {
        let cores = std::thread::available_parallelism().map_or(1, usize::from);
        Self {
            max_voxels: memory / 4,
            max_slices: 100_000,
            max_frame_bytes: memory / 4,
            max_frames: 100_000,
            max_threads: cores * THREADS_PER_CORE,
        }
    }
}

impl Limits {
    /// The memory the defaults are computed from (see [`Limits`]), bytes; `None` where it
    /// cannot be read (the defaults then assume 4 GiB).
    pub fn memory_counted() -> Option<u64> {
        memory_bytes()
    }

    /// The most pixels a single plain still may have under [`Limits::max_frame_bytes`] (what
    /// [`Limits::check_frames`] allows for one frame without extra layers).
    pub fn max_image_pixels(&self) -> u64 {
        self.max_frame_bytes / RenderKind::Plain(Layers::NONE).bytes_per_pixel()
    }

    /// Limits allowing at most `max_voxels` voxels (and the default slice count).
    pub fn with_max_voxels(max_voxels: u64) -> Self {
        Self {
            max_voxels,
            ..Self::default()
        }
    }

    /// The voxel count of `dims`, or an error naming `path` when it overflows or exceeds the limit.
    pub fn check_dims(&self, path: &Path, dims: &[u64]) -> Result<usize> {
        let over = |requested| ReadError::Limit {
            path: path.to_path_buf(),
            what: format!("a {} volume ({requested} voxels)", join_dims(dims)),
            requested,
            limit: self.max_voxels,
        };
        let count = dims
            .iter()
            .try_fold(1u64, |acc, &d| acc.checked_mul(d))
            .ok_or_else(|| over(u64::MAX))?;
        if count > self.max_voxels {
            return Err(over(count));
        }
        usize::try_from(count).map_err(|_| over(count))
    }

    /// The filter a still of a volume of `voxels` voxels can use: `filter`, or trilinear and a
    /// warning saying why where the B-spline's coefficients (a second copy of the volume,
    /// [`BSplineCoefficients::BYTES_PER_VOXEL`] bytes a voxel) would take more than
    /// [`Limits::max_frame_bytes`], the share of memory a view's frames may take.
    pub fn still_filter(&self, filter: Filter, voxels: usize) -> (Filter, Option<String>) {
        let bytes = (voxels as u64).saturating_mul(BSplineCoefficients::BYTES_PER_VOXEL as u64);
        if filter != Filter::BSpline || bytes <= self.max_frame_bytes {
            return (filter, None);
        }
        let warning = format!(
            "the B-spline still of {voxels} voxels needs {} MiB for its coefficients, over the \
             {} MiB allowed: the still is trilinear",
            bytes >> 20,
            self.max_frame_bytes >> 20
        );
        (Filter::Trilinear, Some(warning))
    }

    /// Refuses a series of more than [`Limits::max_slices`] files or slices.
    pub fn check_slices(&self, path: &Path, slices: u64) -> Result<()> {
        if slices > self.max_slices {
            return Err(ReadError::Limit {
                path: path.to_path_buf(),
                what: "slices".into(),
                requested: slices,
                limit: self.max_slices,
            });
        }
        Ok(())
    }

    /// Refuses `frames` views of `[width, height]` pixels rendered as `kind` says (e.g. a view
    /// and a dashboard) when rendering and writing them would take more than
    /// [`Limits::max_frame_bytes`] ([`RenderKind::bytes_per_pixel`] each); `path` is the
    /// output they are for. Returns the bytes.
    pub fn check_frames(
        &self,
        path: &Path,
        [width, height]: [usize; 2],
        kind: RenderKind,
        frames: u64,
    ) -> Result<u64> {
        let bytes = (width as u64)
            .checked_mul(height as u64)
            .and_then(|pixels| pixels.checked_mul(kind.bytes_per_pixel()))
            .and_then(|b| b.checked_mul(frames));
        let requested = bytes.unwrap_or(u64::MAX);
        if requested > self.max_frame_bytes {
            let count = match frames {
                1 => "a frame".to_owned(),
                n => format!("{n} frames"),
            };
            return Err(ReadError::Limit {
                path: path.to_path_buf(),
                what: format!(
                    "rendering {count} of {width}×{height} pixels (bytes of memory; use a \
                     smaller --size)"
                ),
                requested,
                limit: self.max_frame_bytes,
            });
        }
        Ok(requested)
    }
}

impl Limits {
    /// Refuses more than [`Limits::max_frames`] frames, `option` naming where the count comes
    /// from (e.g. `--frames`).
    pub fn check_frame_count(&self, option: &str, frames: u64) -> Result<()> {
        if frames > self.max_frames {
            return Err(ReadError::Limit {
                path: option.into(),
                what: "the frame count".into(),
                requested: frames,
                limit: self.max_frames,
            });
        }
        Ok(())
    }

    /// Refuses more than [`Limits::max_threads`] worker threads, `option` naming where the
    /// count comes from (e.g. `--threads`).
    pub fn check_threads(&self, option: &str, threads: usize) -> Result<()> {
        if threads > self.max_threads {
            return Err(ReadError::Limit {
                path: option.into(),
                what: format!("the worker threads ({THREADS_PER_CORE} a core at most)"),
                requested: threads as u64,
                limit: self.max_threads as u64,
            });
        }
        Ok(())
    }
}

/// What a command renders, as far as its memory goes (see [`RenderKind::bytes_per_pixel`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RenderKind {
    /// The plain look, in any mode and with any `--still` count, its frames holding these
    /// optional layers.
    Plain(Layers),
    /// A two-stage look (clinical, realistic): its ray pass renders frames with these layers
    /// ([`RayPassSettings::traced_layers`]), which become a G-buffer shaded into a frame.
    ///
    /// [`RayPassSettings::traced_layers`]: endocast_core::look::RayPassSettings::traced_layers
    Look(Layers),
    /// A stereo pair of the plain look, written as one image or two.
    Stereo,
    /// A stereo pair of a two-stage look whose ray pass renders frames with these layers.
    LookStereo(Layers),
}

/// The bytes the PNG or JPEG encoder holds a pixel of the image it writes: its filtered copy
/// and the compressed stream (at most the image's size).
pub const ENCODER_BYTES_PER_PIXEL: u64 = 2 * Image::BYTES_PER_PIXEL as u64;

/// What [`RenderKind::bytes_per_pixel`] adds for the buffers kept per thread or per row
/// (tiles' rows, the smoothing's bands): under a byte a pixel measured at 2000² and more.
pub const MARGIN_BYTES_PER_PIXEL: u64 = 4;

impl RenderKind {
    /// The kind of a view drawn with a two-stage `look` (a pair with `stereo`), or else a
    /// stereo pair (`stereo`), or else the plain look without optional layers.
    pub fn of(look: Option<&Look>, stereo: bool) -> Self {
        match (look, stereo) {
            (Some(look), false) => Self::Look(look.ray.traced_layers()),
            (Some(look), true) => Self::LookStereo(look.ray.traced_layers()),
            (None, true) => Self::Stereo,
            (None, false) => Self::Plain(Layers::NONE),
        }
    }

    /// The bytes a pixel of the view takes at the peak of rendering and writing it, from the
    /// buffers' sizes (a single still is rendered as a still of one frame, so its running mean
    /// is counted whatever the `--still` count), and [`MARGIN_BYTES_PER_PIXEL`]:
    /// - plain: a frame being rendered ([`Frame::rendering_bytes_per_pixel`]) beside the
    ///   still's mean, or the last frame, the mean and the copy handed out;
    /// - look: beside the still's mean, a pass's frame being rendered, or that frame with the
    ///   hit positions, normals and secretion the search beyond secretion adds, or the
    ///   G-buffer and its shaded frame (scene geometry is composited into that frame in place,
    ///   with a block of rays per thread);
    /// - stereo: the left eye's frame beside the right one being rendered and the start-up
    ///   the right eye reuses, or both frames, their 8-bit images and the combined image (side
    ///   by side: two) with the encoder's copies;
    /// - a look's stereo pair: a look's peak beside the other eye's still mean and frame,
    ///   its first-pass frame and the start-up, or the stereo pair's writing;
    ///
    /// and for every kind at least the frame, its 8-bit image and the encoder's copies. After
    /// a render with optional layers, the tiles' memory (two small blocks a tile) is counted as
    /// still held: the allocator was measured to keep most of it (a 4000² clinical view),
    /// which it does not after a render without layers.
    pub fn bytes_per_pixel(self) -> u64 {
        let frame = per_pixel(Frame::BYTES_PER_PIXEL);
        let rendering = |layers| per_pixel(Frame::rendering_bytes_per_pixel(layers));
        let image = per_pixel(Image::BYTES_PER_PIXEL);
        let written = image + ENCODER_BYTES_PER_PIXEL;
        let stereo_written = 2 * frame + 2 * image + 2 * written;
        let start_up = per_pixel(StereoFrames::SCRATCH_BYTES_PER_PIXEL);
        let peak = match self {
            Self::Plain(layers) => {
                let with_layers = per_pixel(Frame::bytes_per_pixel(layers));
                (rendering(layers) + with_layers).max(kept_tiles(layers) + 3 * with_layers)
            }
            Self::Look(traced) => {
                let found = Frame::bytes_per_pixel(Layers::HIT_POSITION | Layers::NORMAL);
                let found = per_pixel(found + size_of::<f32>());
                let shading = per_pixel(GBuffer::BYTES_PER_PIXEL) + frame;
                let after = kept_tiles(traced) + found.max(shading);
                frame + rendering(traced).max(after)
            }
            Self::Stereo => {
                let rendering = frame + rendering(Layers::NONE) + start_up;
                rendering.max(stereo_written)
            }
            Self::LookStereo(traced) => {
                let one_eye = Self::Look(traced).bytes_per_pixel();
                let first_pass = per_pixel(Frame::bytes_per_pixel(traced));
                (one_eye + 2 * frame + first_pass + start_up).max(stereo_written)
            }
        };
        peak.max(frame + written) + MARGIN_BYTES_PER_PIXEL
    }
}

/// The bytes a pixel of a render's tiles takes after the render with `layers`: all of them
/// with optional layers (see [`RenderKind::bytes_per_pixel`]), none without.
fn kept_tiles(layers: Layers) -> u64 {
    if layers.is_empty() {
        return 0;
    }
    per_pixel(Frame::rendering_bytes_per_pixel(layers) - Frame::bytes_per_pixel(layers))
}

fn per_pixel(bytes: usize) -> u64 {
    bytes as u64
}

fn join_dims(dims: &[u64]) -> String {
    dims.iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join("×")
}

/// The memory this process may use, bytes: the least of the physical memory, the cgroup's
/// limit and the address-space limit, of those that can be read (Linux).
fn memory_bytes() -> Option<u64> {
    [
        physical_memory_bytes(),
        cgroup_memory_bytes(),
        address_space_bytes(),
    ]
    .into_iter()
    .flatten()
    .min()
}

/// The memory limit of this process's cgroup (v2, else v1), if any.
fn cgroup_memory_bytes() -> Option<u64> {
    [
        "/sys/fs/cgroup/memory.max",
        "/sys/fs/cgroup/memory/memory.limit_in_bytes",
    ]
    .iter()
    .find_map(|file| std::fs::read_to_string(file).ok()?.trim().parse().ok())
}

/// The soft address-space limit (`RLIMIT_AS`) from `/proc/self/limits`, if any.
fn address_space_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = text.lines().find(|l| l.starts_with("Max address space"))?;
    line["Max address space".len()..]
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}

/// Total physical memory from `/proc/meminfo` (Linux), if readable.
fn physical_memory_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    kib.checked_mul(1024)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn refuses_huge_and_overflowing_headers() {
        let limits = Limits::with_max_voxels(1000);
        let p = Path::new("x.nii");
        assert_eq!(limits.check_dims(p, &[10, 10, 10]).unwrap(), 1000);
        assert!(matches!(
            limits.check_dims(p, &[10, 10, 11]),
            Err(ReadError::Limit {
                requested: 1100,
                ..
            })
        ));
        assert!(limits.check_dims(p, &[u64::MAX, 2, 2]).is_err());
        assert!(Limits::default().max_voxels > 1_000_000);
    }

    #[test]
    fn spline_stills_fall_back_to_trilinear_beyond_the_memory_limit() {
        let limits = Limits::for_memory(4 << 30);
        let fits = (limits.max_frame_bytes / 4) as usize;
        assert_eq!(
            limits.still_filter(Filter::BSpline, fits),
            (Filter::BSpline, None)
        );
        let (filter, warning) = limits.still_filter(Filter::BSpline, fits + 1);
        assert_eq!(filter, Filter::Trilinear);
        assert!(warning.unwrap().contains("trilinear"));
        assert_eq!(
            limits.still_filter(Filter::Trilinear, usize::MAX).0,
            Filter::Trilinear
        );
    }

    #[test]
    fn refuses_frames_beyond_the_memory_limit() {
        let limits = Limits {
            max_frame_bytes: 1 << 30,
            ..Limits::default()
        };
        let p = Path::new("view.png");
        let plain = RenderKind::Plain(Layers::NONE);
        // 76 bytes a pixel: three frames of colour, depth and value, and the margin.
        assert_eq!(
            limits.check_frames(p, [512, 512], plain, 2).unwrap(),
            2 * 76 * 512 * 512
        );
        let err = limits
            .check_frames(p, [100_000, 100_000], plain, 1)
            .unwrap_err();
        assert!(matches!(
            err,
            ReadError::Limit {
                requested: 760_000_000_000,
                ..
            }
        ));
        let message = err.to_string();
        assert!(
            message.starts_with("view.png: rendering a frame of 100000×100000 pixels"),
            "{message}"
        );
        assert!(limits
            .check_frames(p, [usize::MAX, 2], RenderKind::Plain(Layers::ALL), 1)
            .is_err());
    }

    #[test]
    fn each_kind_counts_the_buffers_it_holds_at_once() {
        let bytes = |b: usize| b as u64;
        let frame = bytes(Frame::BYTES_PER_PIXEL);
        let image = bytes(Image::BYTES_PER_PIXEL);
        let written = frame + image + ENCODER_BYTES_PER_PIXEL;
        let traced = [Layers::NONE, Layers::HIT_POSITION | Layers::NORMAL];
        for layers in traced.into_iter().chain([Layers::ALL]) {
            let with_layers = bytes(Frame::bytes_per_pixel(layers));
            let rendering = bytes(Frame::rendering_bytes_per_pixel(layers));
            let plain = RenderKind::Plain(layers).bytes_per_pixel();
            assert!(plain >= 3 * with_layers + kept_tiles(layers));
            assert!(plain >= rendering + with_layers && plain >= written);
        }
        // The tiles: a finished pixel and, with layers, its optional layers.
        assert_eq!(kept_tiles(Layers::NONE), 0);
        assert_eq!(kept_tiles(traced[1]), 24 + 40);
        let found = bytes(Frame::bytes_per_pixel(traced[1])) + bytes(size_of::<f32>());
        for layers in traced {
            let look = RenderKind::Look(layers).bytes_per_pixel();
            let rendering = bytes(Frame::rendering_bytes_per_pixel(layers));
            let shading = bytes(GBuffer::BYTES_PER_PIXEL) + 2 * frame;
            assert!(look >= shading + kept_tiles(layers));
            assert!(look >= rendering + frame && look >= found + frame && look >= written);
        }
        let stereo = RenderKind::Stereo.bytes_per_pixel();
        let start_up = bytes(StereoFrames::SCRATCH_BYTES_PER_PIXEL);
        let rendering = bytes(Frame::rendering_bytes_per_pixel(Layers::NONE));
        assert!(stereo >= frame + rendering + start_up);
        assert!(stereo >= 2 * frame + 4 * image + 2 * ENCODER_BYTES_PER_PIXEL);
        for layers in traced {
            let look = RenderKind::Look(layers).bytes_per_pixel();
            let pair = RenderKind::LookStereo(layers).bytes_per_pixel();
            assert!(pair >= look + 2 * frame + start_up && pair >= stereo);
        }
    }

    #[test]
    fn the_look_decides_what_memory_allows() {
        const GIB: u64 = 1 << 30;
        let p = Path::new("view.png");
        let plain = RenderKind::Plain(Layers::NONE);
        // A plain 8000² still fits a 24 GiB machine (a quarter of it for frames).
        let big = Limits::for_memory(24 * GIB);
        assert!(big.check_frames(p, [8000, 8000], plain, 1).is_ok());
        assert!(big.max_image_pixels() >= 8000 * 8000);
        // Where a plain 4000² still fits with little to spare, the looks and a stereo pair
        // are refused.
        let short = Limits::for_memory(4 * 80 * 4000 * 4000);
        assert!(short.check_frames(p, [4000, 4000], plain, 1).is_ok());
        let without_secretion = RenderKind::Look(Layers::HIT_POSITION | Layers::NORMAL);
        for kind in [
            RenderKind::Look(Layers::NONE),
            without_secretion,
            RenderKind::Stereo,
            RenderKind::LookStereo(Layers::NONE),
        ] {
            assert!(short.check_frames(p, [4000, 4000], kind, 1).is_err());
        }
    }
}
