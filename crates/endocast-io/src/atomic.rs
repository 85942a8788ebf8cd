//! Writing files so that a crash or a full disk never leaves a half-written file in place of a
//! good one: write a temporary file beside the target, flush it to disk, then rename it over.
//! A folder of frames is written the same way, whole: a temporary folder beside it swapped in
//! at the end ([`TemporaryFolder`]), so that it holds either the old frames or all the new.
//!
//! Temporary files and folders are created exclusively (`O_EXCL`: never through a symbolic
//! link planted at their name, never over another's) under unpredictable names
//! `.NAME.PID.RANDOM.tmp`. An output that exists as anything but a regular file (a folder, a
//! FIFO, a device) is refused rather than replaced.
//!
//! Every temporary file being written is listed ([`Pending`]) so that a program interrupted by a
//! signal, which ends without unwinding (no destructor removes anything), can remove them first
//! ([`remove_temporary_files`]). What a killed process (SIGKILL) leaves is removed by the next
//! write of the same target: the pid in the name says whose it was, and those of processes no
//! longer running go.

use crate::error::{ReadError, Result};
use std::ffi::OsStr;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard, PoisonError};
use tempfile::{Builder, TempDir};

/// The temporary files and folders this process is writing now.
static PENDING: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

fn pending() -> MutexGuard<'static, Vec<PathBuf>> {
    PENDING.lock().unwrap_or_else(PoisonError::into_inner)
}

/// A temporary file listed for [`remove_temporary_files`] until this guard is dropped
/// (dropping only unlists it; its owner removes or renames the file itself).
#[derive(Debug)]
pub(crate) struct Pending(PathBuf);

impl Pending {
    /// Lists `path`.
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

/// Removes every temporary file and folder this process is writing (atomic writes, GIF and
/// MP4 films and folders of frames in progress) and returns how many it removed: for a
/// SIGINT/SIGTERM handler that then ends the process, so that an interrupted command leaves no
/// temporary file behind.
pub fn remove_temporary_files() -> usize {
    pending().iter().filter(|path| remove(path).is_ok()).count()
}

/// Removes a file, or a folder with everything in it (a symbolic link itself, never what it
/// points to).
fn remove(path: &Path) -> std::io::Result<()> {
    if std::fs::symlink_metadata(path)?.is_dir() {
        std::fs::remove_dir_all(path)
    } else {
        std::fs::remove_file(path)
    }
}

/// Writes `path` atomically: `fill` writes the content into a temporary file in the same
/// directory, which replaces `path` only once it is complete and synced.
pub fn write_file(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let (mut temporary, file) = Temporary::create(path)?;
    write_synced(file, fill).map_err(|e| ReadError::io(path, e))?;
    temporary.commit()
}

/// Writes a new file at `path` in a folder only this process writes (a [`TemporaryFolder`]):
/// created exclusively, so it is never a file already there nor through a symbolic link.
pub(crate) fn write_new(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let created = File::create_new(path);
    created
        .and_then(|file| write_synced(file, fill))
        .map_err(|e| ReadError::io(path, e))
}

/// Buffers `fill`'s writes into `file` and syncs it to disk.
fn write_synced(
    file: File,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let mut writer = BufWriter::with_capacity(1 << 20, file);
    fill(&mut writer)?;
    writer.into_inner().map_err(|e| e.into_error())?.sync_all()
}

/// A file written under a temporary name beside its target and renamed over it on
/// [`commit`](Self::commit); dropped uncommitted, the temporary file is removed.
#[derive(Debug)]
pub(crate) struct Temporary {
    target: PathBuf,
    path: PathBuf,
    committed: bool,
    /// Lists the temporary file for a signal handler (see [`remove_temporary_files`]).
    _listed: Pending,
}

impl Temporary {
    /// Creates the temporary file for `target`, with the file open for writing; refuses a
    /// `target` that exists as anything but a regular file. Temporary files dead processes
    /// left for the same target are removed first.
    pub(crate) fn create(target: &Path) -> Result<(Self, File)> {
        let (dir, prefix) = beside(target, Expected::File)?;
        let created = builder(&prefix)
            .tempfile_in(dir)
            .map_err(|e| ReadError::io(target, e))?;
        let (file, path) = created.into_parts();
        let path = path.keep().map_err(|e| ReadError::io(target, e.error))?;
        let temporary = Self {
            target: target.to_path_buf(),
            _listed: Pending::new(&path),
            path,
            committed: false,
        };
        Ok((temporary, file))
    }

    /// The temporary file's path.
    pub(crate) fn path(&self) -> &Path {
        &self.path
    }

    /// The target's path.
    pub(crate) fn target(&self) -> &Path {
        &self.target
    }

    /// Renames the temporary file over the target.
    pub(crate) fn commit(&mut self) -> Result<()> {
        std::fs::rename(&self.path, &self.target).map_err(|e| ReadError::io(&self.target, e))?;
        self.committed = true;
        Ok(())
    }
}

impl Drop for Temporary {
    fn drop(&mut self) {
        if !self.committed {
            // Best effort: the temporary file is ours and useless now.
            let _ = std::fs::remove_file(&self.path);
        }
    }
}

/// A folder written under a temporary name beside its target and swapped in whole on
/// [`commit`](Self::commit) (the old folder is kept until then); dropped uncommitted, the
/// temporary folder is removed with what it holds.
#[derive(Debug)]
pub(crate) struct TemporaryFolder {
    target: PathBuf,
    dir: TempDir,
    /// Lists the temporary folder for a signal handler (see [`remove_temporary_files`]).
    _listed: Pending,
}

impl TemporaryFolder {
    /// Creates the temporary folder for `target`; refuses a `target` that exists as anything
    /// but a folder. What dead processes left for the same target is removed first.
    pub(crate) fn create(target: &Path) -> Result<Self> {
        let (dir, prefix) = beside(target, Expected::Folder)?;
        let created = builder(&prefix)
            .tempdir_in(dir)
            .map_err(|e| ReadError::io(target, e))?;
        Ok(Self {
            target: target.to_path_buf(),
            _listed: Pending::new(created.path()),
            dir: created,
        })
    }

    /// The temporary folder's path.
    pub(crate) fn path(&self) -> &Path {
        self.dir.path()
    }

    /// Puts the temporary folder in the target's place; the old folder, if any, is removed.
    pub(crate) fn commit(self) -> Result<()> {
        let io = |e| ReadError::io(&self.target, e);
        if std::fs::symlink_metadata(&self.target).is_err() {
            return std::fs::rename(self.dir.path(), &self.target).map_err(io);
        }
        // Where the file system cannot exchange two names at once, the old folder is moved
        // aside first (for a moment there is none).
        if exchange(self.dir.path(), &self.target).is_err() {
            let (dir, prefix) = beside(&self.target, Expected::Folder)?;
            let aside = builder(&prefix).tempdir_in(dir).map_err(io)?;
            std::fs::rename(&self.target, aside.path()).map_err(io)?;
            if let Err(e) = std::fs::rename(self.dir.path(), &self.target) {
                // The old folder back in its place, not removed with `aside`.
                let _ = std::fs::rename(aside.path(), &self.target);
                return Err(io(e));
            }
        }
        // `self.dir` now names the old folder (or nothing): dropping it removes it.
        Ok(())
    }
}

/// Swaps the names `a` and `b` at once (Linux's `renameat2` with `RENAME_EXCHANGE`).
#[cfg(target_os = "linux")]
fn exchange(a: &Path, b: &Path) -> std::io::Result<()> {
    use rustix::fs::{renameat_with, RenameFlags, CWD};
    renameat_with(CWD, a, CWD, b, RenameFlags::EXCHANGE).map_err(std::io::Error::from)
}

/// Swapping two names at once is Linux's alone.
#[cfg(not(target_os = "linux"))]
fn exchange(_: &Path, _: &Path) -> std::io::Result<()> {
    Err(std::io::ErrorKind::Unsupported.into())
}

/// What an output must be where it already exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Expected {
    File,
    Folder,
}

/// The folder of `target` and the prefix `.NAME.PID.` of its temporary files, after checking
/// that `target` is not something else than `expected` and removing the temporary files dead
/// processes left for it.
fn beside(target: &Path, expected: Expected) -> Result<(&Path, String)> {
    let name = target
        .file_name()
        .ok_or_else(|| ReadError::format(target, "the output path names no file"))?;
    refuse_other_kinds(target, expected)?;
    let dir = match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let stem = format!(".{}.", name.to_string_lossy());
    remove_stale(dir, &stem);
    Ok((dir, format!("{stem}{}.", std::process::id())))
}

/// Refuses a `target` that exists as something else than `expected` (a FIFO or a device is
/// never replaced, nor a folder by a file).
fn refuse_other_kinds(target: &Path, expected: Expected) -> Result<()> {
    let Ok(meta) = std::fs::metadata(target) else {
        return Ok(());
    };
    let problem = match expected {
        Expected::File if meta.is_dir() => "is a folder, not a file: refusing to replace it",
        Expected::File if !meta.is_file() => {
            "exists and is not a regular file (a FIFO, device or socket): refusing to replace it"
        }
        Expected::Folder if !meta.is_dir() => {
            "exists and is not a folder: refusing to replace it with a folder"
        }
        _ => return Ok(()),
    };
    Err(ReadError::format(target, problem))
}

/// A builder of exclusive temporary files and folders named `{prefix}RANDOM.tmp`, files
/// readable as a plain `File::create` makes them (not only by their owner).
fn builder(prefix: &str) -> Builder<'_, 'static> {
    let mut builder = Builder::new();
    builder.prefix(prefix).suffix(".tmp").rand_bytes(8);
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    builder
}

/// Removes, best effort, the temporary files and folders in `dir` named `{stem}PID.….tmp`
/// whose process is no longer running (where that can be told: Linux's `/proc`).
fn remove_stale(dir: &Path, stem: &str) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        if let Some(pid) = owner(&entry.file_name(), stem) {
            if !running(pid) {
                let _ = remove(&entry.path());
            }
        }
    }
}

/// The pid in a temporary name `{stem}PID.tmp` (as this module named them before) or
/// `{stem}PID.RANDOM.tmp` (eight random characters), not one of another target's whose name
/// goes on after `stem`.
fn owner(name: &OsStr, stem: &str) -> Option<u32> {
    let rest = name.to_str()?.strip_prefix(stem)?.strip_suffix(".tmp")?;
    let (pid, random) = rest.split_once('.').unwrap_or((rest, "RANDOMXX"));
    let random = random.len() == 8 && random.bytes().all(|b| b.is_ascii_alphanumeric());
    (random && pid.bytes().all(|b| b.is_ascii_digit()))
        .then(|| pid.parse().ok())
        .flatten()
}

/// Whether process `pid` is running; `true` where that cannot be told.
fn running(pid: u32) -> bool {
    let proc = Path::new("/proc");
    pid == std::process::id() || !proc.join("self").exists() || proc.join(pid.to_string()).exists()
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

    #[cfg(unix)]
    #[test]
    fn a_symlink_at_the_old_temporary_name_is_not_followed() {
        let dir = tempfile::tempdir().unwrap();
        let victim = dir.path().join("victim.txt");
        std::fs::write(&victim, b"precious").unwrap();
        let p = dir.path().join("a.txt");
        // The name this module used before: `.NAME.PID.tmp`.
        let planted = dir
            .path()
            .join(format!(".a.txt.{}.tmp", std::process::id()));
        std::os::unix::fs::symlink(&victim, &planted).unwrap();
        write_file(&p, |w| w.write_all(b"new")).unwrap();
        assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
        assert_eq!(std::fs::read(&p).unwrap(), b"new");
        assert!(planted.is_symlink());
    }

    #[cfg(unix)]
    #[test]
    fn outputs_that_are_not_regular_files_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("out.png");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        assert!(made.unwrap().success());
        let error = write_file(&fifo, |w| w.write_all(b"x")).unwrap_err();
        let message = error.to_string();
        assert!(
            message.contains("out.png") && message.contains("not a regular file"),
            "{message}"
        );
        let folder = dir.path().join("folder.png");
        std::fs::create_dir(&folder).unwrap();
        let message = write_file(&folder, |w| w.write_all(b"x"))
            .unwrap_err()
            .to_string();
        assert!(
            message.contains("folder.png") && message.contains("is a folder"),
            "{message}"
        );
        assert!(TemporaryFolder::create(&fifo).is_err());
        // Nothing was left beside them, and the FIFO is still one.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        assert!(!std::fs::metadata(&fifo).unwrap().is_file());
    }

    #[test]
    fn temporary_files_of_dead_processes_are_removed_by_the_next_write() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.txt");
        // No process has a pid this large (Linux caps them at 2²²).
        let dead = [".a.txt.4294967295.tmp", ".a.txt.4294967294.x1Yz0AbC.tmp"];
        let alive = format!(".a.txt.{}.kept0000.tmp", std::process::id());
        // Another target's, `a.txt.5`, is not taken for a file of process 5.
        let other = ".a.txt.5.4294967295.x1Yz0AbC.tmp";
        for name in dead.iter().chain([&"b.txt", &alive.as_str(), &other]) {
            std::fs::write(dir.path().join(name), b"left").unwrap();
        }
        write_file(&p, |w| w.write_all(b"new")).unwrap();
        let mut names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        let gone = Path::new("/proc/self").exists();
        assert_eq!(names.len(), if gone { 4 } else { 6 }, "{names:?}");
        assert!(names.contains(&alive) && names.contains(&other.to_owned()));
    }

    #[test]
    fn a_folder_is_swapped_in_whole() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("frames");
        for content in ["old", "new"] {
            let folder = TemporaryFolder::create(&target).unwrap();
            write_new(&folder.path().join("f"), |w| {
                w.write_all(content.as_bytes())
            })
            .unwrap();
            if content == "new" {
                // Until the commit the old folder stands.
                assert_eq!(std::fs::read(target.join("f")).unwrap(), b"old");
            }
            folder.commit().unwrap();
            assert_eq!(std::fs::read(target.join("f")).unwrap(), content.as_bytes());
        }
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        // Dropped uncommitted, nothing is left.
        let folder = TemporaryFolder::create(&target).unwrap();
        write_new(&folder.path().join("g"), |w| w.write_all(b"x")).unwrap();
        drop(folder);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        assert!(!target.join("g").exists());
    }
}
