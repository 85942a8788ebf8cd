//! The one entry point: pick the reader (or writer) from the path, return the volume, what the
//! source said about itself, and the warnings gathered on the way.

use crate::error::{ReadError, Result};
use crate::limits::Limits;
use crate::{dicom, metaimage, nifti, nrrd, raw};
use endocast_core::{Geometry, Volume};
use std::io::Read;
use std::path::Path;

/// The file formats endocast reads.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// A DICOM series (a directory) or a single, possibly multi-frame, DICOM file.
    Dicom,
    /// NIfTI-1 or NIfTI-2, optionally gzip-compressed.
    Nifti,
    /// NRRD, attached (`.nrrd`) or detached (`.nhdr`).
    Nrrd,
    /// MetaImage (`.mha`, or `.mhd` with a separate data file).
    MetaImage,
    /// Headerless samples described on the command line.
    Raw,
}

impl Format {
    /// The format's usual name.
    pub fn name(self) -> &'static str {
        match self {
            Self::Dicom => "DICOM",
            Self::Nifti => "NIfTI",
            Self::Nrrd => "NRRD",
            Self::MetaImage => "MetaImage",
            Self::Raw => "raw",
        }
    }

    /// The format a path's name implies (`.nii`, `.nii.gz`, `.nrrd`, `.nhdr`, `.mha`, `.mhd`).
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
    pub raw: Option<raw::RawSpec>,
    /// For files that declare no patient orientation (raw, NRRD without an anatomical space):
    /// the orientation code of their index axes, e.g. `"LPI"` for slices stored from the top of
    /// the head down. Giving it for a file that declares its own orientation is an error.
    /// Default: none (such files are read as axis-aligned LPS, with a warning).
    pub orientation: Option<String>,
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

/// Reads the scan at `path`, choosing the reader from the path: a directory is a DICOM series;
/// otherwise the extension; otherwise the file's magic bytes. Raw files are read only when
/// `options.raw` describes them.
pub fn open(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let meta = std::fs::metadata(path).map_err(|e| ReadError::io(path, e))?;
    if options.raw.is_some() {
        return raw::read(path, options);
    }
    let format = if meta.is_dir() {
        Format::Dicom
    } else {
        match Format::from_extension(path) {
            Some(f) => f,
            None => sniff(path)?,
        }
    };
    let loaded = match format {
        Format::Dicom => dicom::read(path, options),
        Format::Nifti => nifti::read(path, options),
        Format::Nrrd => nrrd::read(path, options),
        Format::MetaImage => metaimage::read(path, options),
        Format::Raw => raw::read(path, options),
    }?;
    apply_orientation(path, loaded, options.orientation.as_deref())
}

/// Gives an undeclared orientation the code the user named (see [`OpenOptions::orientation`]).
fn apply_orientation(path: &Path, mut loaded: Loaded, code: Option<&str>) -> Result<Loaded> {
    let Some(code) = code else {
        return Ok(loaded);
    };
    if loaded.source.orientation_declared {
        return Err(ReadError::inconsistent(
            path,
            format!(
                "the file declares its own orientation ({}); an assumed orientation ({code}) \
                 applies only to files that declare none",
                loaded.volume.geometry().orientation_code()
            ),
        ));
    }
    let direction = Geometry::direction_from_code(code).ok_or_else(|| {
        ReadError::format(
            path,
            format!("orientation {code:?} is not three of L/R, P/A, S/I naming different axes"),
        )
    })?;
    let geometry = loaded
        .volume
        .geometry()
        .with_direction(direction)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    let volume = loaded.volume;
    let (map, modality) = (volume.value_map(), volume.modality().clone());
    loaded.volume = Volume::new(geometry, volume.into_voxels(), map, modality)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    loaded.warnings.push(format!(
        "{}: orientation {code} assumed, as asked",
        path.display()
    ));
    Ok(loaded)
}

/// Writes `volume` to `path` atomically, in the format its extension names
/// (`.nii`, `.nii.gz`, `.nrrd`, `.mha`).
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    match Format::from_extension(path) {
        Some(Format::Nifti) => nifti::write(path, volume),
        Some(Format::Nrrd) => nrrd::write(path, volume),
        Some(Format::MetaImage) => metaimage::write(path, volume),
        _ => Err(ReadError::unsupported(
            path,
            "output format: name the file .nii, .nii.gz, .nrrd or .mha",
        )),
    }
}

/// Recognises a file by its first bytes.
fn sniff(path: &Path) -> Result<Format> {
    let mut head = Vec::with_capacity(352);
    std::fs::File::open(path)
        .and_then(|f| f.take(352).read_to_end(&mut head))
        .map_err(|e| ReadError::io(path, e))?;
    if head.len() >= 132 && &head[128..132] == b"DICM" {
        Ok(Format::Dicom)
    } else if head.starts_with(b"NRRD000") {
        Ok(Format::Nrrd)
    } else if head.starts_with(&[0x1f, 0x8b])
        || (head.len() >= 348 && (&head[344..348] == b"n+1\0" || &head[4..8] == b"n+2\0"))
    {
        // A gzip stream without a telling name is most likely a .nii.gz.
        Ok(Format::Nifti)
    } else if head.starts_with(b"ObjectType") || head.starts_with(b"NDims") {
        Ok(Format::MetaImage)
    } else {
        Err(ReadError::unsupported(
            path,
            "file format: not DICOM, NIfTI, NRRD or MetaImage by name or content \
             (for a headerless file give --raw-dims, --raw-type and --raw-spacing)",
        ))
    }
}
