//! Resource limits checked before any allocation a header (or an image size) asks for.

use crate::error::{ReadError, Result};
use endocast_core::render::{Frame, Layers};
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
        let memory = memory_bytes().unwrap_or(1 << 32);
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
        let per_pixel = view_bytes([1, 1], Layers::NONE).unwrap_or(u64::MAX).max(1);
        self.max_frame_bytes / per_pixel
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

    /// Refuses `frames` rendered frames of `[width, height]` pixels with `layers` (e.g. two
    /// for a stereo pair) when rendering and writing them would take more than
    /// [`Limits::max_frame_bytes`] ([`view_bytes`] each); `path` is the output they are for.
    /// Returns the bytes.
    pub fn check_frames(
        &self,
        path: &Path,
        [width, height]: [usize; 2],
        layers: Layers,
        frames: u64,
    ) -> Result<u64> {
        let bytes = view_bytes([width, height], layers).and_then(|b| b.checked_mul(frames));
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

/// What one view takes, bytes a pixel, at the peak of rendering and writing it, besides the
/// float buffers of its frame ([`Frame::bytes_for`], counted three times: a still's frame being
/// rendered, its running mean and the copy handed out), whatever the look: the look's G-buffer,
/// its smoothed copy and the smoothing's planes (80), the 8-bit image and the encoder's copy
/// of it (8).
///
/// Measured (peak resident memory of `endocast render`, 1000² to 4000² pixels): 76 bytes a
/// pixel for the plain look, 81 for the realistic, 142 for the clinical; the estimate, with a
/// plain frame's 24 bytes, is 160.
const VIEW_BYTES_PER_PIXEL: u64 = 88;

/// The memory one view of `[width, height]` pixels with `layers` takes at its peak (see
/// [`VIEW_BYTES_PER_PIXEL`]); `None` when it overflows.
fn view_bytes([width, height]: [usize; 2], layers: Layers) -> Option<u64> {
    let pixels = (width as u64).checked_mul(height as u64)?;
    Frame::bytes_for([width, height], layers)?
        .checked_mul(3)?
        .checked_add(pixels.checked_mul(VIEW_BYTES_PER_PIXEL)?)
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
    fn refuses_frames_beyond_the_memory_limit() {
        let limits = Limits {
            max_frame_bytes: 1 << 30,
            ..Limits::default()
        };
        let p = Path::new("view.png");
        // 160 bytes a pixel: three frames of colour, depth and value, the look's buffers, the
        // image and the encoder's.
        assert_eq!(
            limits.check_frames(p, [512, 512], Layers::NONE, 2).unwrap(),
            2 * 160 * 512 * 512
        );
        // At least what renders were measured to take: 4.6 GB for 8000² (plain) and 2.17 GB
        // for 4000² (the clinical look).
        let at_least = |edge, bytes| view_bytes([edge, edge], Layers::NONE).unwrap() >= bytes;
        assert!(at_least(8000, 4_600_000_000) && at_least(4000, 2_170_000_000));
        let err = limits
            .check_frames(p, [100_000, 100_000], Layers::NONE, 1)
            .unwrap_err();
        assert!(matches!(
            err,
            ReadError::Limit {
                requested: 1_600_000_000_000,
                ..
            }
        ));
        let message = err.to_string();
        assert!(
            message.starts_with("view.png: rendering a frame of 100000×100000 pixels"),
            "{message}"
        );
        assert!(limits
            .check_frames(p, [usize::MAX, 2], Layers::ALL, 1)
            .is_err());
    }
}
