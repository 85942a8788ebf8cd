//! The one entry point: pick the reader (or writer) from the path, return the volume, what the
//! source said about itself, and the warnings gathered on the way.

use crate::error::{ReadError, Result};
use crate::escape::escape;
use crate::loaded::{Format, Loaded, OpenOptions};
use crate::{dicom, metaimage, nifti, nrrd, raw};
use endocast_core::navigate::guess_head_orientation;
use endocast_core::{Geometry, Volume};
use std::io::Read;
use std::path::Path;

/// Reads the scan at `path`, choosing the reader from the path: a directory is a DICOM series;
/// otherwise the extension; otherwise the file's magic bytes. Raw files are read only when
/// `options.raw` describes them. The warnings come with control characters escaped
/// ([`escape`]), as error messages do.
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
        Format::Nifti | Format::Analyze => nifti::read(path, options),
        Format::Nrrd => nrrd::read(path, options),
        Format::MetaImage => metaimage::read(path, options),
        Format::Raw => raw::read(path, options),
    }?;
    let mut loaded = apply_orientation(path, loaded, options.orientation.as_deref())?;
    // Warnings quote headers and file names: no control characters reach the terminal.
    for warning in &mut loaded.warnings {
        *warning = escape(warning);
    }
    Ok(loaded)
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
