//! Case files: one scan and what was done to it — the scan's reference and fingerprint, the
//! viewer's controls and camera, key frames, and the annotations drawn and measured on the
//! tissue — as JSON, written atomically (a temporary file renamed over the old one, so a crash
//! or a kill during a save leaves the previous case whole) and under a lock, so that programs
//! changing one case at once ([`Case::update`]) lose none of each other's changes. The viewer (`endocast view`) and
//! the CLI (`endocast annotate`, `render --case`, `fly --case`) read and write the same files.
//!
//! ```json
//! {"format": "endocast-case", "version": 3,
//!  "scan": {"kind": "file", "path": "head.nrrd"},
//!  "identity": {"dims": [256, 256, 99], "spacing_mm": [1, 1, 2], "origin_mm": [0, 0, 0],
//!               "voxel_hash": "3f0c9a61d2b7e845"},
//!  "controls": {"preset": "sinus", "mode": "iso", "iso_hu": -400, ...,
//!               "tf": {"opacity": [[-1024, 0], ..], "color": [[-1024, 0, 0, 0], ..]},
//!               "peel": {"layer": "2", "falling": false, "keep": 0, "context": true},
//!               "geometry": {"grid": true, "endoscope": false, "markers": true, "meshes": true,
//!                            "mesh_files": ["/data/head/septum.stl"]}},
//!  "camera": {"eye": [0, 0, 0], "forward": [0, 0, 1], "up": [0, -1, 0]},
//!  "key_frames": [],
//!  "annotations": [{"id": 1, "kind": "measure", "points": [[..], [..]], "distance_mm": 7.9}]}
//! ```
//!
//! `controls` and `camera` are the viewer's and absent from a case the CLI made. Older versions
//! are still read: version 2 has no transfer function, peel settings or geometry in its
//! controls (the preset's apply), version 1 (the viewer's first cases) no identity either and
//! labelled points only.

mod records;
mod scan;

pub use records::{
    peel_layer, AnnotationRecord, CaseCamera, CaseControls, CaseGeometry, CaseKeyFrame, CasePeel,
    CaseTransfer,
};
pub use scan::{IdentityRecord, ScanFacts, ScanSource};

use endocast_core::annotate::{Annotations, ScanIdentity};
use serde::{Deserialize, Serialize};
use std::fs::File;
use std::path::{Path, PathBuf};

/// The `"format"` value of case files.
pub const FORMAT: &str = "endocast-case";
/// The version this code writes (it reads 1 and 2 too).
pub const VERSION: u32 = 3;
/// A case file larger than this is refused unread.
const MAX_BYTES: u64 = 64 << 20;

/// A case as the file holds it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// Always [`FORMAT`].
    pub format: String,
    /// [`VERSION`] (1 when read from an old file).
    pub version: u32,
    /// The scan.
    pub scan: ScanSource,
    /// The scan's fingerprint, when known: a case is only applied to that scan.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub identity: Option<IdentityRecord>,
    /// The viewer's control panel.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controls: Option<CaseControls>,
    /// The viewer's camera.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub camera: Option<CaseCamera>,
    /// The key frames, in playback order.
    #[serde(default)]
    pub key_frames: Vec<CaseKeyFrame>,
    /// The annotations, oldest first.
    #[serde(default)]
    pub annotations: Vec<AnnotationRecord>,
    /// A number that grows with every save of a session.
    #[serde(default)]
    pub revision: u64,
}

/// Why a case cannot be read, written or applied.
#[derive(Debug, thiserror::Error)]
#[error("case file {path}: {problem}")]
pub struct CaseError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong, one line.
    pub problem: String,
}

impl CaseError {
    /// The error `problem` (any error or text) about the case at `path`.
    pub fn new(path: &Path, problem: impl std::fmt::Display) -> Self {
        Self {
            path: path.to_owned(),
            problem: crate::escape(&problem.to_string()),
        }
    }
}

impl Case {
    /// An empty case on `scan` with its fingerprint.
    pub fn new(scan: ScanSource, identity: Option<&ScanIdentity>) -> Self {
        Self {
            format: FORMAT.into(),
            version: VERSION,
            scan,
            identity: identity.map(IdentityRecord::from),
            controls: None,
            camera: None,
            key_frames: Vec::new(),
            annotations: Vec::new(),
            revision: 0,
        }
    }

    /// Reads `path`; the error names the file and the problem.
    pub fn read(path: &Path) -> Result<Self, CaseError> {
        let bytes = Self::read_bytes(path)?;
        let text = String::from_utf8(bytes).map_err(|e| CaseError::new(path, e))?;
        let case: Self = serde_json::from_str(&text).map_err(|e| CaseError::new(path, e))?;
        if case.format != FORMAT || !(1..=VERSION).contains(&case.version) {
            return Err(CaseError::new(
                path,
                format!(
                    "format {:?} version {} is not {FORMAT:?} version 1 to {VERSION}",
                    case.format, case.version
                ),
            ));
        }
        case.annotations(path)?;
        Ok(case)
    }

    /// The file's bytes, refused beyond [`MAX_BYTES`] (read no further).
    fn read_bytes(path: &Path) -> Result<Vec<u8>, CaseError> {
        crate::text::read_capped(path, MAX_BYTES)
            .map_err(|e| CaseError::new(path, e))?
            .ok_or_else(|| {
                CaseError::new(path, format!("more than {MAX_BYTES} bytes is too large"))
            })
    }

    /// Writes the case to `path` atomically, as the current [`VERSION`], under the case's
    /// lock (so never in the middle of another program's [`Case::update`]).
    pub fn write(&self, path: &Path) -> Result<(), CaseError> {
        let _lock = CaseLock::acquire(path)?;
        self.write_locked(path)
    }

    /// Changes the case at `path` under its lock: reads it (or takes `new()` when there is
    /// none), lets `change` change it, and writes it back as the next revision. Programs
    /// changing one case at once take turns, each changing what the one before wrote, so that
    /// no change is lost. Returns what `change` returns; nothing is written when it fails.
    pub fn update<T, E: From<CaseError>>(
        path: &Path,
        new: impl FnOnce() -> Result<Self, E>,
        change: impl FnOnce(&mut Self) -> Result<T, E>,
    ) -> Result<T, E> {
        let _lock = CaseLock::acquire(path)?;
        let mut case = if path.exists() {
            Self::read(path)?
        } else {
            new()?
        };
        let changed = change(&mut case)?;
        case.revision += 1;
        case.write_locked(path)?;
        Ok(changed)
    }

    /// Writes the case over the file at `path` as it was read, at revision `base` (`None`:
    /// there was no file), as the next revision, under the case's lock. Refused, writing
    /// nothing, when another program saved the case since (the file's revision is not `base`),
    /// so that its changes are not overwritten unseen. Returns the revision written.
    pub fn write_over(&self, path: &Path, base: Option<u64>) -> Result<u64, CaseError> {
        let _lock = CaseLock::acquire(path)?;
        let now = Self::revision_at(path)?;
        if now != base {
            let said = |r: Option<u64>| r.map_or_else(|| "none".to_owned(), |r| r.to_string());
            return Err(CaseError::new(
                path,
                format!(
                    "saved by another program since it was opened (revision {}, opened at {}): \
                     not overwritten; save the case under another name",
                    said(now),
                    said(base)
                ),
            ));
        }
        let revision = base.map_or(1, |r| r + 1);
        Self {
            revision,
            ..self.clone()
        }
        .write_locked(path)?;
        Ok(revision)
    }

    /// The revision of the case at `path`, `None` when there is no file.
    pub fn revision_at(path: &Path) -> Result<Option<u64>, CaseError> {
        if !path.exists() {
            return Ok(None);
        }
        Self::read(path).map(|case| Some(case.revision))
    }

    /// Where a save keeps the version it replaces: `NAME.prev` beside the case.
    pub fn previous_path(path: &Path) -> PathBuf {
        let mut name = path.as_os_str().to_owned();
        name.push(".prev");
        PathBuf::from(name)
    }

    /// [`Case::write`] with the case's lock held by the caller; the version it replaces is kept
    /// at [`Case::previous_path`].
    fn write_locked(&self, path: &Path) -> Result<(), CaseError> {
        if std::fs::symlink_metadata(path).is_ok_and(|m| m.is_file()) {
            let old = Self::read_bytes(path)?;
            let previous = Self::previous_path(path);
            crate::atomic::write_file(&previous, |w| w.write_all(&old))
                .map_err(|e| CaseError::new(&previous, e))?;
        }
        let current = Self {
            version: VERSION,
            ..self.clone()
        };
        let json = serde_json::to_vec_pretty(&current).map_err(|e| CaseError::new(path, e))?;
        crate::atomic::write_file(path, |w| w.write_all(&json)).map_err(|e| CaseError::new(path, e))
    }

    /// The annotations; `path` names the file in errors.
    pub fn annotations(&self, path: &Path) -> Result<Annotations, CaseError> {
        let items = self
            .annotations
            .iter()
            .map(AnnotationRecord::annotation)
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| CaseError::new(path, e))?;
        Annotations::from_items(items).map_err(|e| CaseError::new(path, e))
    }

    /// Replaces the annotations.
    pub fn set_annotations(&mut self, annotations: &Annotations) {
        self.annotations = annotations
            .items()
            .iter()
            .map(AnnotationRecord::from)
            .collect();
    }

    /// Whether `scan` (the identity of the scan opened for this case) is the case's scan; a
    /// case without a fingerprint fits any. The error names the case file and what differs.
    pub fn check_scan(&self, scan: &ScanIdentity, path: &Path) -> Result<(), CaseError> {
        let Some(record) = &self.identity else {
            return Ok(());
        };
        ScanIdentity::from(record).check(scan).map_err(|e| {
            CaseError::new(
                path,
                format!("made on another scan than {}: {e}", self.scan.label()),
            )
        })
    }
}

/// A case file's lock, held while the case is written or changed: an advisory lock (`flock`)
/// on `.NAME.lock` beside it, released when dropped. The lock file stays, empty: removing it
/// would let two programs lock two different files of one name.
#[derive(Debug)]
struct CaseLock {
    _file: File,
}

impl CaseLock {
    /// Waits until the lock of the case at `path` is this process's alone.
    fn acquire(path: &Path) -> Result<Self, CaseError> {
        let name = path
            .file_name()
            .ok_or_else(|| CaseError::new(path, "the path names no file"))?;
        let lock = path.with_file_name(format!(".{}.lock", name.to_string_lossy()));
        // Made exclusively (never through a symbolic link), else opened to read only.
        let file = match File::create_new(&lock) {
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => File::open(&lock),
            opened => opened,
        };
        let cannot = |e| CaseError::new(path, format!("cannot lock {}: {e}", lock.display()));
        let file = file.map_err(cannot)?;
        file.lock().map_err(cannot)?;
        Ok(Self { _file: file })
    }
}
