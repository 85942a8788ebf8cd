//! Resource limits checked before any allocation a header asks for.

use crate::error::{ReadError, Result};
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
}

impl Default for Limits {
    fn default() -> Self {
        let half_memory = physical_memory_bytes().map_or(1 << 31, |bytes| bytes / 2);
        Self {
            max_voxels: half_memory / 2,
            max_slices: 100_000,
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
}
