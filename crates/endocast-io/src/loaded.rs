//! What a read returns and how to ask for it: the [`Format`]s, the [`OpenOptions`] (with the
//! [`RawSpec`] of a headerless file), and the [`Loaded`] volume with its [`SourceInfo`]. Every
//! reader and [`crate::open()`] share these types, so they live below all of them.

use crate::limits::Limits;
use crate::progress::Progress;
use crate::samples::{ElementType, Endian};
use endocast_core::Volume;
use std::path::Path;

/// The file formats endocast reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// A DICOM series (a directory) or a single, possibly multi-frame, DICOM file.
    Dicom,
    /// NIfTI-1 or NIfTI-2, optionally gzip-compressed.
    Nifti,
    /// An Analyze 7.5 header (`.hdr`) and its voxels (`.img`), each optionally gzip-compressed.
    Analyze,
    /// NRRD, attached (`.nrrd`) or detached (`.nhdr`).
    Nrrd,
    /// MetaImage (`.mha`, or `.mhd` with a separate data file).
    MetaImage,
    /// Headerless samples described on the command line.
    Raw,
    /// OME-Zarr 0.4 or 0.5 (a folder, `.zarr`).
    OmeZarr,
}

impl Format {
    /// The format's usual name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dicom => "DICOM",
            Self::Nifti => "NIfTI",
            Self::Analyze => "Analyze 7.5",
            Self::Nrrd => "NRRD",
            Self::MetaImage => "MetaImage",
            Self::Raw => "raw",
            Self::OmeZarr => "OME-Zarr",
        }
    }

    /// The format a path's name implies (`.nii`, `.nii.gz`, `.nrrd`, `.nhdr`, `.mha`, `.mhd`,
    /// `.zarr`).
    pub fn from_extension(path: &Path) -> Option<Self> {
        let name = path.file_name()?.to_string_lossy().to_ascii_lowercase();
        let ends = |suffixes: &[&str]| suffixes.iter().any(|s| name.ends_with(s));
        if ends(&[".nii", ".nii.gz"]) {
            Some(Self::Nifti)
        } else if ends(&[".nrrd", ".nhdr"]) {
            Some(Self::Nrrd)
        } else if ends(&[".mha", ".mhd"]) {
            Some(Self::MetaImage)
        } else if ends(&[".dcm", ".dicom"]) {
            Some(Self::Dicom)
        } else if ends(&[".zarr"]) {
            Some(Self::OmeZarr)
        } else {
            None
        }
    }
}

/// How to open a scan. Every field has a default that suits a clinical scan.
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct OpenOptions {
    /// Resource limits checked before allocating. Default: [`Limits::default`].
    pub limits: Limits,
    /// DICOM: the SeriesInstanceUID to load. Default: the series with the most slices.
    pub series: Option<String>,
    /// Raw: how to interpret a headerless file. Default: none (raw files are not guessed).
    pub raw: Option<RawSpec>,
    /// For files that declare no patient orientation (raw, NRRD without an anatomical space):
    /// the orientation code of their index axes, e.g. `"LPI"` for slices stored from the top of
    /// the head down. Giving it for a file that declares its own orientation is an error.
    /// Default: none (such files are read as axis-aligned LPS, with a warning).
    pub orientation: Option<String>,
    /// DICOM: fill missing slices (a gap of a whole number of steps in an otherwise evenly
    /// spaced series, e.g. a file lost or unreadable) by interpolating between their
    /// neighbours, with a warning naming them. Default: `false`, such a series is refused,
    /// the error naming the gap.
    pub fill_missing_slices: bool,
    /// NRRD and MetaImage: allow a detached data file outside the header's folder (it must
    /// still be a regular file). Default: `false`, such a file is refused.
    pub allow_outside_data: bool,
    /// Where the reader counts how far it is (DICOM folders: headers, then files decoded), for
    /// a progress bar on another thread. Default: counts nobody looks at.
    pub progress: Progress,
}

/// One DICOM series found in a directory.
#[derive(Debug, Clone, PartialEq)]
pub struct SeriesSummary {
    /// SeriesInstanceUID.
    pub uid: String,
    /// SeriesDescription, or empty.
    pub description: String,
    /// Modality code (CT, MR, ...), or empty.
    pub modality: String,
    /// Number of image files (or frames) in the series.
    pub images: usize,
}

/// What the source said about itself, beyond the volume.
#[derive(Debug, Clone, PartialEq)]
pub struct SourceInfo {
    /// The format the volume was read from.
    pub format: Format,
    /// How samples were stored in the file, e.g. `int16 big-endian` or
    /// `uint16, 12 bits stored, Implicit VR Little Endian`.
    pub stored_type: String,
    /// DICOM: the series loaded.
    pub series_uid: Option<String>,
    /// DICOM: every series found, largest first.
    pub series_found: Vec<SeriesSummary>,
    /// Whether the file states where its axes point in the patient. Raw files and NRRD files
    /// without an anatomical `space` do not; they are read as axis-aligned LPS unless
    /// [`OpenOptions::orientation`] says otherwise.
    pub orientation_declared: bool,
}

impl SourceInfo {
    /// Source information for a single-volume format.
    pub fn new(format: Format, stored_type: impl Into<String>) -> Self {
        Self {
            format,
            stored_type: stored_type.into(),
            series_uid: None,
            series_found: Vec::new(),
            orientation_declared: true,
        }
    }
}

/// A volume read from a file, with its provenance and the best-effort warnings on the way
/// (skipped files, uneven slice gaps, resampling, quantisation, ...).
#[derive(Debug, Clone)]
pub struct Loaded {
    /// The voxels, their geometry and physical values.
    pub volume: Volume,
    /// What the file said about itself.
    pub source: SourceInfo,
    /// Problems that did not stop the read, one sentence each.
    pub warnings: Vec<String>,
}

/// How to read a headerless file: an axis-aligned LPS grid starting at the origin.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawSpec {
    /// Samples along `i`, `j`, `k` (`i` fastest in the file).
    pub dims: [usize; 3],
    /// Voxel spacing in mm.
    pub spacing_mm: [f64; 3],
    /// Sample type.
    pub element: ElementType,
    /// Byte order of multi-byte samples.
    pub endian: Endian,
    /// Bytes to skip before the first sample.
    pub header_bytes: u64,
}
