//! The DICOM reader: a series from a directory (searched recursively), or one single- or
//! multi-frame file, becomes one [`Volume`].
//!
//! # How a series is read
//!
//! 1. `scan`: every file under the directory is listed (sorted) and its header, everything
//!    before PixelData, is parsed in parallel (a data set in implicit VR under a meta group
//!    that says explicit VR is read as implicit VR, warned, as pydicom does: `open`). Files
//!    without the DICOM magic, DICOM objects without an image and unreadable headers are
//!    skipped and reported in one warning.
//! 2. `series`: images are grouped by SeriesInstanceUID; the largest series is loaded unless
//!    [`OpenOptions::series`] names another.
//! 3. `stack`: frames (a file is one frame, an enhanced multi-frame file many) are ordered by
//!    the projection of ImagePositionPatient on the slice normal (row × column cosine), never
//!    by file name or InstanceNumber, which scanners number in either direction.
//! 4. `pixels`: each file is decoded (uncompressed little/big endian, deflate, JPEG, JPEG 2000
//!    through dicom-rs; RLE, JPEG-LS and 12-bit JPEG through our own `rle`, `jpegls` and
//!    `jpeg12`) straight into its
//!    slice of the final voxel buffer, files in parallel. Peak memory is that buffer plus one
//!    file per thread (a multi-frame file is held whole while its frames are decoded).
//! 5. `values`: one value map for the series (exact when all slices share their rescale).
//!
//! # Geometry decisions
//!
//! - Direction columns are the row cosine (`i`), the column cosine (`j`) and the unit vector
//!   from the first to the last slice position (`k`). With gantry tilt that last vector is not
//!   the slice normal: the stack is sheared, and we keep the shear in the affine rather than
//!   resample every slice in-plane (which would blur them and move the pixels the scanner
//!   measured). The renderer works in the volume's affine, so a sheared grid costs nothing;
//!   a warning names the tilt angle.
//! - Spacing is PixelSpacing (DICOM lists the spacing between rows first, so `i` takes its
//!   second value and `j` its first) and the mean step between slice positions, never
//!   SliceThickness (which may overlap or leave gaps). A single slice, with no neighbour to
//!   measure, takes its SliceThickness (or 1 mm, warned). PixelSpacing outside 0.001–1000 mm
//!   is refused; `0\0` means unknown, like a missing one (1 mm, warned).
//! - A multi-frame file whose frames carry no position of their own (or all the same one) is
//!   stacked in file order along the slice normal at SpacingBetweenSlices, else
//!   SliceThickness, else 1 mm, with a warning that says which (pydicom and nibabel keep such
//!   frames in file order too). A Siemens mosaic (ImageType MOSAIC) is unpacked
//!   (`mosaic`, as dcm2niix and nibabel do): NumberOfImagesInMosaic slices (from (0019,100A),
//!   else the CSA image header (0029,1010), else refused), tiled row by row in
//!   `ceil(sqrt(N))` tiles a side; the first slice lies half the difference between the
//!   image and a tile from the stored ImagePositionPatient, the others along the CSA
//!   SliceNormalVector (else row × column cosine) at SpacingBetweenSlices, else
//!   SliceThickness; a warning says which.
//! - Only the main stack is read: the largest group of images sharing an orientation and a
//!   size (`planes`). Images in another plane or of another size (a localiser) are set aside,
//!   named in a warning.
//! - Slices must lie on one line (else [`ReadError::Inconsistent`]). When the gaps between
//!   them differ by more than 1 % (`grid`), every real slice is still kept exactly: the stack
//!   goes onto a finer grid (the smallest gap, or a half, third or quarter of it when that puts
//!   every slice on a plane; at most 4× the slice count), each real slice copied onto its
//!   nearest plane (the move warned) and only the planes between them interpolated linearly.
//!   One or two gaps of a whole number of steps in an otherwise even stack are missing slices:
//!   refused, naming the gap, unless [`OpenOptions::fill_missing_slices`] asks to fill them
//!   (warned). The limits are checked before the resampled buffer is allocated; while it is
//!   filled, the decoded stack is held too (freed before returning).
//!
//! # Values
//!
//! RescaleSlope/Intercept apply per slice (per frame through PixelValueTransformationSequence);
//! a Modality LUT (ModalityLUTSequence) replaces them: stored samples are mapped through it
//! into the voxels, exactly (its outputs are unsigned 16-bit at most).
//! When every slice shares them, voxels hold raw samples exactly (signed samples offset by
//! 2^(BitsAllocated−1)) and the value map carries the rescale. Otherwise the physical range is
//! requantised onto 16 bits (warned). BitsStored masks unused high bits and sign-extends;
//! PixelPaddingValue voxels take the lowest real value of the series (warned). MONOCHROME1 is
//! inverted so that bright means high, except for CT, whose Hounsfield units are kept.

mod csa;
mod frame;
mod grid;
mod jpeg12;
mod jpegls;
mod lengths;
mod lut;
mod mosaic;
mod open;
mod overlay;
mod pixels;
mod planes;
mod rle;
mod scan;
mod series;
mod stack;
mod stream_size;
mod values;

pub use overlay::{read_overlay, Overlay, OverlayKind, Segment};

use crate::error::{ReadError, Result};
use crate::loaded::{Format, Loaded, OpenOptions, SourceInfo};
use crate::progress::{Progress, ReadStep};
use endocast_core::{Modality, Volume};
use mosaic::Mosaic;
use pixels::{FrameStats, SampleMap};
use rayon::prelude::*;
use scan::ImageFile;
use stack::Stack;
use std::path::Path;

/// Reads the DICOM series in directory `path` (or the single DICOM file `path`).
///
/// Errors: no image found, an unknown [`OpenOptions::series`] (the message lists the series
/// found), images of one series that disagree (size, orientation, spacing, or positions off
/// one line: [`ReadError::Inconsistent`]), a transfer syntax or sample format that cannot be
/// decoded ([`ReadError::Unsupported`]), a truncated or malformed file, or a volume beyond
/// [`OpenOptions::limits`].
pub fn read(path: &Path, options: &OpenOptions) -> Result<Loaded> {
    if path.is_file() {
        overlay::refuse_as_scan(path, &options.limits)?;
    }
    let mut warnings = Vec::new();
    let files = scan::list_files(path, &options.limits)?;
    options.progress.begin(ReadStep::Headers, files.len());
    let scanned = scan::scan_all(&files, &options.limits, &options.progress);
    let images = series::images(path, &files, scanned, &mut warnings)?;
    let (chosen, series_found) = series::choose(path, images, options.series.as_deref())?;
    warnings.extend(chosen.iter().flat_map(|file| file.notes.iter().cloned()));
    let chosen = planes::main_stack(path, chosen, &mut warnings);
    let stack = Stack::build(path, &chosen, &mut warnings)?;
    let grid = grid::plan(
        path,
        &stack,
        &chosen,
        options.fill_missing_slices,
        &mut warnings,
    )?;
    let first = &chosen[0];
    let ts_names = chosen
        .iter()
        .map(|file| pixels::transfer_syntax_name(&file.path, &file.transfer_syntax))
        .collect::<Result<Vec<_>>>()?;
    let modality = Modality::from_code(&first.modality);
    let invert = first.layout.modality_lut.is_none()
        && monochrome1_inversion(first, &modality, &mut warnings);
    let map = SampleMap::new(&first.path, &first.layout, first.padding, invert)?;
    pixels::check_high_bit(first, &mut warnings)?;

    let dims = [
        usize::from(first.layout.columns),
        usize::from(first.layout.rows),
    ];
    let slice_len = dims[0] * dims[1];
    let count = stack.slices.len();
    options.limits.check_slices(path, count as u64)?;
    let total = options
        .limits
        .check_dims(path, &[dims[0] as u64, dims[1] as u64, count as u64])?;
    let mut voxels = vec![0u16; total];
    let progress = &options.progress;
    let (stats, padded) = decode_all(
        &chosen,
        &ts_names,
        &stack,
        &mut voxels,
        slice_len,
        &map,
        progress,
    )?;
    warnings.extend(padded);
    let rescales: Vec<_> = stack.slices.iter().map(|s| s.rescale).collect();
    let value_map = values::unify(
        path,
        &mut voxels,
        slice_len,
        &rescales,
        &stats,
        &map,
        &mut warnings,
    )?;

    let voxels = match &grid.planes {
        Some(planes) => {
            let total = options
                .limits
                .check_dims(path, &[dims[0] as u64, dims[1] as u64, grid.count as u64])?;
            let mut resampled = vec![0u16; total];
            grid::resample(&voxels, slice_len, planes, &mut resampled);
            resampled
        }
        None => voxels,
    };
    let geometry = stack.geometry(path, dims, grid.count, grid.step_mm)?;
    let volume = Volume::new(geometry, voxels, value_map, modality)
        .map_err(|e| ReadError::format(path, e.to_string()))?;
    let mut source = SourceInfo::new(Format::Dicom, stored_type(first, ts_names[0]));
    source.series_uid = Some(first.series_uid.clone());
    source.series_found = series_found;
    Ok(Loaded {
        volume,
        source,
        warnings,
    })
}

/// Decodes every slice of `stack` into its slot of `voxels`, one file per task, counting the
/// files in `progress`, and returns the statistics of each slice in stack order and the
/// warnings of files whose pixel data carried padding.
fn decode_all(
    files: &[ImageFile],
    ts_names: &[&str],
    stack: &Stack,
    voxels: &mut [u16],
    slice_len: usize,
    map: &SampleMap,
    progress: &Progress,
) -> Result<(Vec<FrameStats>, Vec<String>)> {
    // Hand each file the slots of its frames, so that a multi-frame file is opened once.
    let mut per_file: Vec<Vec<(usize, u32, &mut [u16])>> =
        files.iter().map(|_| Vec::new()).collect();
    for (k, (slot, slice)) in voxels.chunks_mut(slice_len).zip(&stack.slices).enumerate() {
        per_file[slice.file].push((k, slice.frame, slot));
    }
    progress.begin(
        ReadStep::Pixels,
        per_file.iter().filter(|f| !f.is_empty()).count(),
    );
    let decoded = per_file
        .into_par_iter()
        .enumerate()
        .filter(|(_, frames)| !frames.is_empty())
        .map(|(file, frames)| {
            let (ks, slots): (Vec<usize>, Vec<(u32, &mut [u16])>) = frames
                .into_iter()
                .map(|(k, frame, slot)| (k, (frame, slot)))
                .unzip();
            let (stats, padded) = match &files[file].mosaic {
                Some(mosaic) => decode_mosaic(&files[file], mosaic, ts_names[file], slots, map)?,
                None => pixels::decode_file(&files[file], ts_names[file], slots, map)?,
            };
            progress.advance();
            Ok((ks.into_iter().zip(stats).collect::<Vec<_>>(), padded))
        })
        .collect::<Result<Vec<_>>>()?;
    let mut stats = vec![None; stack.slices.len()];
    let mut padded = Vec::new();
    for (frames, warning) in decoded {
        padded.extend(warning);
        for (k, frame_stats) in frames {
            stats[k] = Some(frame_stats);
        }
    }
    Ok((stats.into_iter().flatten().collect(), padded))
}

/// Decodes the one tiled image of a mosaic and copies each `(tile, slot)` into its slot, as
/// [`pixels::decode_file`] does for the frames of other files.
fn decode_mosaic(
    file: &ImageFile,
    mosaic: &Mosaic,
    ts_name: &str,
    tiles: Vec<(u32, &mut [u16])>,
    map: &SampleMap,
) -> Result<(Vec<FrameStats>, Option<String>)> {
    let mut stored = file.clone();
    [stored.layout.rows, stored.layout.columns] = mosaic.stored;
    stored.frames.truncate(1);
    let mut whole = vec![0u16; mosaic.stored_len()];
    let (_, padded) = pixels::decode_file(&stored, ts_name, vec![(0, &mut whole)], map)?;
    let stats = tiles
        .into_iter()
        .map(|(tile, slot)| {
            mosaic.copy_tile(&whole, tile, slot).ok_or_else(|| {
                ReadError::format(
                    &file.path,
                    format!("mosaic tile {tile} does not fit the tiled image"),
                )
            })?;
            Ok(map.measure(slot))
        })
        .collect::<Result<_>>()?;
    Ok((stats, padded))
}

/// Whether to invert MONOCHROME1 samples (minimum is white): yes, so that bright means high,
/// except for CT, whose values are Hounsfield units whatever the display convention.
fn monochrome1_inversion(
    first: &ImageFile,
    modality: &Modality,
    warnings: &mut Vec<String>,
) -> bool {
    if first.layout.photometric != "MONOCHROME1" {
        return false;
    }
    let invert = *modality != Modality::Ct;
    warnings.push(if invert {
        format!(
            "{}: MONOCHROME1 (minimum is white) samples were inverted so that bright is high",
            first.path.display()
        )
    } else {
        format!(
            "{}: CT marked MONOCHROME1; Hounsfield units are kept as stored (not inverted)",
            first.path.display()
        )
    });
    invert
}

/// E.g. `uint16, 12 bits stored, Implicit VR Little Endian`.
fn stored_type(first: &ImageFile, ts_name: &str) -> String {
    let layout = &first.layout;
    format!(
        "{}int{}, {} bits stored, {ts_name}",
        if layout.signed { "" } else { "u" },
        layout.bits_allocated,
        layout.bits_stored
    )
}
