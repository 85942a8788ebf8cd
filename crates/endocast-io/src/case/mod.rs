//! Case files: one scan and what was done to it — the scan's reference and fingerprint, the
//! viewer's controls and camera, key frames, and the annotations drawn and measured on the
//! tissue — as JSON, written atomically (a temporary file renamed over the old one, so a crash
//! or a kill during a save leaves the previous case whole). The viewer (`endocast view`) and
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
pub use scan::{IdentityRecord, ScanSource};

use endocast_core::annotate::{Annotations, ScanIdentity};
use serde::{Deserialize, Serialize};
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
        let size = std::fs::metadata(path)
            .map_err(|e| CaseError::new(path, e))?
            .len();
        if size > MAX_BYTES {
            return Err(CaseError::new(path, format!("{size} bytes is too large")));
        }
        let text = std::fs::read_to_string(path).map_err(|e| CaseError::new(path, e))?;
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

    /// Writes the case to `path` atomically, as the current [`VERSION`].
    pub fn write(&self, path: &Path) -> Result<(), CaseError> {
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
        Ok(Annotations::from_items(items))
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
