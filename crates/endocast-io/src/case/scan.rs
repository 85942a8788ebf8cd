//! The scan a case is about: where it comes from, and its fingerprint.

use crate::{Progress, SeriesSummary};
use endocast_core::annotate::ScanIdentity;
use endocast_core::phantom::{Phantom, PhantomOptions};
use endocast_core::Volume;
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// Where a scan comes from, as a case file records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ScanSource {
    /// A file or DICOM folder, and the DICOM series when not the largest.
    File {
        /// The file or folder.
        path: PathBuf,
        /// SeriesInstanceUID, DICOM only.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        series: Option<String>,
        /// The patient orientation given for a file that declares none (e.g. `LPI`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        orientation: Option<String>,
    },
    /// A generated phantom (see `endocast phantom`).
    Phantom {
        /// Its name (`colon`, `straight-tube`, ...).
        name: String,
        /// Its largest dimension, voxels.
        size: usize,
    },
}

/// What a front end offers around a scan it read.
#[derive(Debug, Clone, Default)]
pub struct ScanFacts {
    /// The series of the DICOM folder it was read from (empty for other sources).
    pub series_found: Vec<SeriesSummary>,
    /// Whether the file declared its patient orientation (a phantom's is known); when it did
    /// not, the orientation was guessed from the anatomy or given, and may be flipped.
    pub orientation_declared: bool,
    /// The reader's warnings (a guessed orientation, slices moved onto a grid, …).
    pub warnings: Vec<String>,
}

impl ScanSource {
    /// Reads or generates the volume; the error is one line naming the file and the problem.
    pub fn load(&self) -> Result<Volume, String> {
        self.load_with_facts(&Progress::default())
            .map(|(volume, _)| volume)
    }

    /// Reads or generates the volume, with what the viewer offers around it (the series a
    /// DICOM folder holds, whether the file declared its orientation); the reader counts how
    /// far it is in `progress`.
    pub fn load_with_facts(&self, progress: &Progress) -> Result<(Volume, ScanFacts), String> {
        match self {
            Self::File {
                path,
                series,
                orientation,
            } => {
                let mut options = crate::OpenOptions::default();
                options.series.clone_from(series);
                options.orientation.clone_from(orientation);
                options.progress = progress.clone();
                let loaded = crate::open(path, &options)
                    .map_err(|e| format!("cannot read the scan: {e}"))?;
                let facts = ScanFacts {
                    series_found: loaded.source.series_found,
                    orientation_declared: loaded.source.orientation_declared,
                    warnings: loaded.warnings,
                };
                Ok((loaded.volume, facts))
            }
            Self::Phantom { name, size } => {
                let phantom = Phantom::from_name(name)
                    .ok_or_else(|| format!("no phantom called {name:?}"))?;
                let options = PhantomOptions {
                    size: *size,
                    ..PhantomOptions::default()
                };
                let facts = ScanFacts {
                    series_found: Vec::new(),
                    orientation_declared: true,
                    warnings: Vec::new(),
                };
                Ok((phantom.build(&options), facts))
            }
        }
    }

    /// A short name for titles and messages.
    pub fn label(&self) -> String {
        match self {
            Self::File { path, .. } => path.display().to_string(),
            Self::Phantom { name, size } => format!("{name} phantom ({size})"),
        }
    }
}

/// A [`ScanIdentity`] as case files hold it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IdentityRecord {
    /// Voxels per axis.
    pub dims: [usize; 3],
    /// Voxel spacing, mm.
    pub spacing_mm: [f64; 3],
    /// World position of the first voxel, mm (LPS).
    pub origin_mm: [f64; 3],
    /// The world directions of the index axes, column by column (absent in cases written
    /// before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axes: Option<[f64; 9]>,
    /// Hash of the voxel values (16 hex digits).
    pub voxel_hash: String,
}

impl From<&ScanIdentity> for IdentityRecord {
    fn from(id: &ScanIdentity) -> Self {
        Self {
            dims: id.dims,
            spacing_mm: id.spacing_mm,
            origin_mm: id.origin_mm,
            axes: id.axes,
            voxel_hash: id.voxel_hash.clone(),
        }
    }
}

impl From<&IdentityRecord> for ScanIdentity {
    fn from(r: &IdentityRecord) -> Self {
        Self {
            dims: r.dims,
            spacing_mm: r.spacing_mm,
            origin_mm: r.origin_mm,
            axes: r.axes,
            voxel_hash: r.voxel_hash.clone(),
        }
    }
}
