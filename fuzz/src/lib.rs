//! Shared by the fuzz targets: the readers take paths, so each input is written to a file in a
//! private temporary folder first, and read with limits small enough that a lying header is
//! refused rather than allocated (libFuzzer stops at 2 GiB).

use endocast_io::{Limits, OpenOptions};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// At most 16 Mi voxels per volume.
pub const MAX_VOXELS: u64 = 1 << 24;

/// The options every target reads with: the default ones but [`MAX_VOXELS`].
pub fn options() -> OpenOptions {
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(MAX_VOXELS);
    options
}

/// Writes `data` to the file `name` in this process's temporary folder and returns its path.
pub fn file_with(name: &str, data: &[u8]) -> PathBuf {
    let path = folder().join(name);
    std::fs::write(&path, data).expect("the fuzz folder is writable");
    path
}

fn folder() -> &'static Path {
    static FOLDER: OnceLock<PathBuf> = OnceLock::new();
    FOLDER.get_or_init(|| {
        let dir = std::env::temp_dir().join(format!("endocast-fuzz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a temporary folder can be made");
        dir
    })
}
