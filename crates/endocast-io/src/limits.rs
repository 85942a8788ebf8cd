//! Resource limits checked before any allocation a header (or an image size) asks for.

use crate::error::{ReadError, Result};
use endocast_core::render::{Frame, Layers};
use std::path::Path;

/// Caps on what a header may make us allocate. A file that claims more is refused with
/// [`ReadError::Limit`] before anything is allocated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub struct Limits {
    /// Largest number of voxels a volume may have. Default: what fits in half of the
    /// machine's physical memory at 2 bytes a voxel (1 GiB of voxels where memory is unknown).
    pub max_voxels: u64,
    /// Largest number of files or slices a series may have. Default: 100 000.
    pub max_slices: u64,
    /// Largest memory the rendered frames of one view may take, bytes (see
    /// [`Limits::check_frames`]). Default: a quarter of the machine's physical memory (1 GiB
    /// where memory is unknown).
    pub max_frame_bytes: u64,
}

impl Default for Limits {
    fn default() -> Self {
        let memory = physical_memory_bytes().unwrap_or(1 << 32);
        Self {
            max_voxels: memory / 4,
            max_slices: 100_000,
            max_frame_bytes: memory / 4,
        }
    }
}

impl Limits {
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
    /// for a stereo pair) when their float buffers ([`Frame::bytes_for`]) and their 8-bit
    /// images (4 bytes a pixel) would take more than [`Limits::max_frame_bytes`]; `path` is the
    /// output they are for. Returns the bytes.
    pub fn check_frames(
        &self,
        path: &Path,
        [width, height]: [usize; 2],
        layers: Layers,
        frames: u64,
    ) -> Result<u64> {
        let bytes = Frame::bytes_for([width, height], layers)
            .and_then(|b| b.checked_add((width as u64).checked_mul(height as u64)?.checked_mul(4)?))
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

fn join_dims(dims: &[u64]) -> String {
    dims.iter()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join("×")
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
        // 28 bytes a pixel: colour, depth, value and the 8-bit image.
        assert_eq!(
            limits.check_frames(p, [512, 512], Layers::NONE, 2).unwrap(),
            2 * 28 * 512 * 512
        );
        let err = limits
            .check_frames(p, [100_000, 100_000], Layers::NONE, 1)
            .unwrap_err();
        assert!(matches!(
            err,
            ReadError::Limit {
                requested: 280_000_000_000,
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
