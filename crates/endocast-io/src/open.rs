//! The one entry point: pick the reader (or writer) from the path, return the volume, what the
//! source said about itself, and the warnings gathered on the way.

use crate::error::{ReadError, Result};
use crate::escape::escape;
use crate::loaded::{Format, Loaded, OpenOptions};
use crate::{dicom, metaimage, nifti, nrrd, raw, zarr};
use endocast_core::navigate::guess_head_orientation;
use endocast_core::{Geometry, Volume};
use std::io::Read;
use std::path::{Path, PathBuf};

/// Entries of a folder looked at for a scan file when it holds no DICOM series.
const MAX_FOLDER_ENTRIES: usize = 100_000;

/// Reads the scan at `path`, choosing the reader from the path: a directory holding Zarr
/// metadata is an OME-Zarr image (or one of its levels); another directory is a DICOM series
/// (or, without one, the one scan file of another format it holds, with a warning); otherwise
/// the extension; otherwise the file's magic bytes. Raw files are read only when
/// `options.raw` describes them. The warnings come with control characters escaped
/// ([`escape`]), as error messages do.
pub fn open(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let meta = std::fs::metadata(path).map_err(|e| ReadError::io(path, e))?;
    if options.raw.is_some() {
        return raw::read(path, options);
    }
    let (path, loaded) = if meta.is_dir() && zarr::is_zarr(path) {
        (path.to_owned(), zarr::read(path, options)?)
    } else if meta.is_dir() {
        read_folder(path, options)?
    } else {
        (path.to_owned(), read_file(path, options)?)
    };
    let mut loaded = apply_orientation(&path, loaded, options.orientation.as_deref())?;
    // Warnings quote headers and file names: no control characters reach the terminal.
    for warning in &mut loaded.warnings {
        *warning = escape(warning);
    }
    Ok(loaded)
}

/// Reads one file by the reader its extension or magic bytes name.
fn read_file(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    let format = match Format::from_extension(path) {
        Some(f) => f,
        None => sniff(path)?,
    };
    match format {
        Format::Dicom => dicom::read(path, options),
        Format::Nifti | Format::Analyze => nifti::read(path, options),
        Format::Nrrd => nrrd::read(path, options),
        Format::MetaImage => metaimage::read(path, options),
        Format::Raw => raw::read(path, options),
        Format::OmeZarr => Err(ReadError::format(
            path,
            "an OME-Zarr image is a folder, and this is a file",
        )),
    }
}

/// A folder's DICOM series; where it has none, the one NIfTI, Analyze, NRRD or MetaImage file
/// it holds (the Stanford CThead's `.nhdr` beside its raw slices), with a warning that says
/// so. Returns the path read and the scan.
fn read_folder(path: &Path, options: &OpenOptions) -> Result<(PathBuf, Loaded)> {
    let no_dicom = match dicom::read(path, options) {
        Ok(loaded) => return Ok((path.to_owned(), loaded)),
        Err(e) => e,
    };
    let files = scan_files_in(path);
    match files.as_slice() {
        [] => Err(no_dicom),
        [one] => {
            let mut loaded = read_file(one, options)?;
            loaded.warnings.insert(
                0,
                format!(
                    "{}: no DICOM series; read {}, the one scan file in the folder",
                    path.display(),
                    one.display()
                ),
            );
            Ok((one.clone(), loaded))
        }
        several => {
            let names: Vec<String> = several.iter().map(|p| p.display().to_string()).collect();
            Err(ReadError::unsupported(
                path,
                format!(
                    "{no_dicom}; the folder holds {}: name one",
                    names.join(", ")
                ),
            ))
        }
    }
}

/// The NIfTI, Analyze, NRRD and MetaImage files directly in `folder` (by their names; at most
/// [`MAX_FOLDER_ENTRIES`] entries looked at), sorted.
fn scan_files_in(folder: &Path) -> Vec<PathBuf> {
    const SCAN_SUFFIXES: [&str; 7] = [".nii", ".nii.gz", ".hdr", ".nrrd", ".nhdr", ".mha", ".mhd"];
    let Ok(entries) = std::fs::read_dir(folder) else {
        return Vec::new();
    };
    let mut found: Vec<PathBuf> = entries
        .take(MAX_FOLDER_ENTRIES)
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.is_file())
        .filter(|p| {
            let name = p
                .file_name()
                .map(|n| n.to_string_lossy().to_ascii_lowercase());
            name.is_some_and(|n| SCAN_SUFFIXES.iter().any(|s| n.ends_with(s)))
        })
        .collect();
    found.sort();
    found
}

/// Gives an undeclared orientation the code the user named (see [`OpenOptions::orientation`]).
fn apply_orientation(path: &Path, loaded: Loaded, code: Option<&str>) -> Result<Loaded> {
    let Some(code) = code else {
        return guess_orientation(path, loaded);
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
    let mut loaded = oriented(path, loaded, code)?;
    loaded.warnings.push(format!(
        "{}: orientation {code} assumed, as asked",
        path.display()
    ));
    Ok(loaded)
}

/// A head CT that declares no orientation turned upright: its orientation guessed from the
/// anatomy ([`guess_head_orientation`]), with a warning that says so.
fn guess_orientation(path: &Path, loaded: Loaded) -> Result<Loaded> {
    if loaded.source.orientation_declared {
        return Ok(loaded);
    }
    let Some(guess) = guess_head_orientation(&loaded.volume) else {
        return Ok(loaded);
    };
    let mut loaded = oriented(path, loaded, &guess.code)?;
    loaded.warnings.push(format!(
        "{}: read as {} instead, guessed from the anatomy ({}); --orientation \
         overrides",
        path.display(),
        guess.code,
        guess.reason
    ));
    Ok(loaded)
}

/// `loaded` with its index axes pointing as `code` says.
fn oriented(path: &Path, mut loaded: Loaded, code: &str) -> Result<Loaded> {
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
    Ok(loaded)
}

/// Writes `volume` to `path` atomically, in the format its extension names
/// (`.nii`, `.nii.gz`, `.nrrd`, `.mha`, or `.zarr`: an OME-Zarr 0.5 folder).
pub fn write(path: &Path, volume: &Volume) -> Result<()> {
    match Format::from_extension(path) {
        Some(Format::Nifti) => nifti::write(path, volume),
        Some(Format::Nrrd) => nrrd::write(path, volume),
        Some(Format::MetaImage) => metaimage::write(path, volume),
        Some(Format::OmeZarr) => zarr::write(path, volume),
        _ => Err(ReadError::unsupported(
            path,
            "output format: name the file .nii, .nii.gz, .nrrd, .mha or .zarr",
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
        || (head.len() >= 348
            && (matches!(&head[344..348], b"n+1\0" | b"ni1\0")
                || matches!(&head[4..8], b"n+2\0" | b"ni2\0")))
    {
        // A gzip stream without a telling name is most likely a .nii.gz.
        Ok(Format::Nifti)
    } else if head.len() >= 348
        && [348i32.to_le_bytes(), 348i32.to_be_bytes()]
            .iter()
            .any(|sizeof_hdr| head.starts_with(sizeof_hdr))
    {
        // Analyze 7.5 has no magic: sizeof_hdr is all there is to go by.
        Ok(Format::Analyze)
    } else if head.starts_with(b"ObjectType") || head.starts_with(b"NDims") {
        Ok(Format::MetaImage)
    } else {
        Err(ReadError::unsupported(
            path,
            "file format: not DICOM, NIfTI, Analyze, NRRD or MetaImage by name or content \
             (for a headerless file give --raw-dims, --raw-type and --raw-spacing)",
        ))
    }
}
