//! Writing files so that a crash or a full disk never leaves a half-written file in place of a
//! good one: write a temporary file beside the target, flush it to disk, then rename it over.
//!
//! Every temporary file being written is listed ([`Pending`]) so that a program interrupted by a
//! signal, which ends without unwinding (no destructor removes anything), can remove them first
//! ([`remove_temporary_files`]).

use crate::error::{ReadError, Result};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};

/// The temporary files this process is writing now.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A temporary file listed for [`remove_temporary_files`] from its creation until this guard
/// is dropped (dropping only unlists it; the writer removes or renames the file itself).
#[derive(Debug)]
pub(crate) struct Pending(PathBuf);

impl Pending {
    /// Lists `path`; make the guard before creating the file.
    pub(crate) fn new(path: &Path) -> Self {
        pending().push(path.to_path_buf());
        Self(path.to_path_buf())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        let mut list = pending();
        if let Some(at) = list.iter().position(|p| *p == self.0) {
            list.swap_remove(at);
        }
    }
}

/// Removes every temporary file this process is writing (atomic writes, GIF and MP4 films in
/// progress) and returns how many it removed: for a SIGINT/SIGTERM handler that then ends the
/// process, so that an interrupted command leaves no temporary file behind.
pub fn remove_temporary_files() -> usize {
    pending()
        .iter()
        .filter(|path| std::fs::remove_file(path).is_ok())
        .count()
}

/// Writes `path` atomically: `fill` writes the content into a temporary file in the same
/// directory, which replaces `path` only once it is complete and synced.
pub fn write_file(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| ReadError::format(path, "the output path names no file"))?;
    let tmp = dir.join(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let _listed = Pending::new(&tmp);
    let result = (|| {
        let file = File::create(&tmp)?;
        let mut writer = BufWriter::with_capacity(1 << 20, file);
        fill(&mut writer)?;
        let file = writer.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        // Best effort: the temporary file is ours and useless now.
        let _ = std::fs::remove_file(&tmp);
        ReadError::io(path, e)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn failed_fill_leaves_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        write_file(&p, |w| w.write_all(b"first")).unwrap();
        let err = write_file(&p, |w| {
            w.write_all(b"partial")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn temporary_files_are_listed_while_written() {
        // (Removal itself is tested end to end by signalling the CLI: calling it here would
        // remove the files of tests running beside this one.)
        let tmp = Path::new("/nonexistent/.film.gif.tmp");
        let listed = Pending::new(tmp);
        assert!(pending().iter().any(|p| p == tmp));
        drop(listed);
        assert!(!pending().iter().any(|p| p == tmp));
    }
}
