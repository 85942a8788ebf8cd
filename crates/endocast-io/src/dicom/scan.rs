//! Finding DICOM files and reading their headers (everything before the pixel data), in
//! parallel, into plain structs the later stages can reason about without the DICOM object.

use super::csa;
use super::lengths;
use super::lut::ModalityLut;
use super::mosaic::Mosaic;
use super::open::{self, Body};
use crate::error::{ReadError, Result};
use crate::limits::Limits;
use crate::progress::Progress;
use crate::samples::Rescale;
use dicom_core::header::HasLength;
use dicom_core::{Tag, VR};
use dicom_dictionary_std::tags;
use dicom_object::InMemDicomObject;
use glam::DVec3;
use rayon::prelude::*;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Directory levels followed below the given folder; deeper trees are almost certainly a
/// mistake (or a link loop) rather than a series.
const MAX_DEPTH: usize = 16;

/// Every regular file under `root` (recursively, sorted by path), or `root` itself when it is a
/// file. Refuses more files than [`Limits::max_slices`] before reading any of them.
pub(super) fn list_files(root: &Path, limits: &Limits) -> Result<Vec<PathBuf>> {
    if !root.is_dir() {
        return Ok(vec![root.to_path_buf()]);
    }
    let mut files = Vec::new();
    collect_files(root, root, 0, limits, &mut files)?;
    files.sort();
    Ok(files)
}

fn collect_files(
    root: &Path,
    dir: &Path,
    depth: usize,
    limits: &Limits,
    files: &mut Vec<PathBuf>,
) -> Result<()> {
    let entries = std::fs::read_dir(dir).map_err(|e| ReadError::io(dir, e))?;
    let mut paths = entries
        .map(|entry| entry.map(|e| e.path()))
        .collect::<std::io::Result<Vec<_>>>()
        .map_err(|e| ReadError::io(dir, e))?;
    paths.sort();
    for path in paths {
        // `symlink_metadata` so that a link to a parent folder cannot make us loop.
        let meta = std::fs::symlink_metadata(&path).map_err(|e| ReadError::io(&path, e))?;
        if meta.is_dir() {
            if depth < MAX_DEPTH {
                collect_files(root, &path, depth + 1, limits, files)?;
            }
        } else if path.is_file() {
            files.push(path);
            limits.check_slices(root, files.len() as u64)?;
        }
    }
    Ok(())
}

/// One image file (single- or multi-frame) as its header describes it.
#[derive(Debug, Clone)]
pub(super) struct ImageFile {
    /// The file.
    pub path: PathBuf,
    /// SeriesInstanceUID (empty when absent).
    pub series_uid: String,
    /// SeriesDescription (empty when absent).
    pub description: String,
    /// Modality code (empty when absent).
    pub modality: String,
    /// Transfer syntax UID from the file meta group.
    pub transfer_syntax: String,
    /// The pixel layout, as stored.
    pub layout: PixelLayout,
    /// PixelPaddingValue, as a raw sample value (sign already resolved).
    pub padding: Option<i32>,
    /// One entry per frame (one for a classic single-frame image).
    pub frames: Vec<FrameHeader>,
    /// Warnings about what the header left unsaid and the reader assumed.
    pub notes: Vec<String>,
    /// For a Siemens mosaic, how its slices are tiled in the stored image (`layout` and
    /// `frames` then describe the slices, one frame per tile).
    pub mosaic: Option<Mosaic>,
    /// How its data set is encoded (the pre-flight walk's finding, for reading it whole).
    pub body: Body,
}

/// How samples are stored; must be the same for every file of a series.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct PixelLayout {
    /// Rows (the `j` extent).
    pub rows: u16,
    /// Columns (the `i` extent).
    pub columns: u16,
    /// SamplesPerPixel.
    pub samples_per_pixel: u16,
    /// BitsAllocated.
    pub bits_allocated: u16,
    /// BitsStored.
    pub bits_stored: u16,
    /// HighBit.
    pub high_bit: u16,
    /// PixelRepresentation 1: two's complement samples.
    pub signed: bool,
    /// PhotometricInterpretation, trimmed (e.g. `MONOCHROME2`).
    pub photometric: String,
    /// The Modality LUT, which replaces RescaleSlope/Intercept when present.
    pub modality_lut: Option<ModalityLut>,
}

/// Where one frame lies and how its values map to physical units.
#[derive(Debug, Clone, Copy)]
pub(super) struct FrameHeader {
    /// Frame number inside its file (0 for single-frame files).
    pub frame: u32,
    /// ImagePositionPatient: world position (mm) of the centre of the first pixel.
    pub position: Option<DVec3>,
    /// ImageOrientationPatient: row cosine (direction of increasing column index), then
    /// column cosine (direction of increasing row index).
    pub orientation: Option<[DVec3; 2]>,
    /// PixelSpacing in DICOM order: between rows (mm), then between columns (mm).
    pub pixel_spacing: Option<[f64; 2]>,
    /// SliceThickness (mm); used only for a volume of a single slice.
    pub thickness: Option<f64>,
    /// RescaleSlope / RescaleIntercept (identity when absent).
    pub rescale: Rescale,
}

/// What a file turned out to be.
#[derive(Debug)]
pub(super) enum Scanned {
    /// An image we can place and decode.
    Image(ImageFile),
    /// No DICOM magic: not a DICOM file at all.
    NotDicom,
    /// A DICOM object without an image (report, DICOMDIR, presentation state, ...).
    NoImage,
    /// A DICOM file whose header could not be parsed; the error says why.
    Unreadable(ReadError),
}

/// Reads the headers of all `files` in parallel, in the order given.
pub(super) fn scan_all(files: &[PathBuf], limits: &Limits, progress: &Progress) -> Vec<Scanned> {
    files
        .par_iter()
        .map(|path| {
            let scanned = scan(path, limits);
            progress.advance();
            scanned
        })
        .collect()
}

/// Reads the header of one file, stopping before the pixel data.
pub(super) fn scan(path: &Path, limits: &Limits) -> Scanned {
    match has_dicom_magic(path) {
        Ok(true) => {}
        Ok(false) => return Scanned::NotDicom,
        Err(e) => return Scanned::Unreadable(e),
    }
    // A deflated data set holds at most the largest volume's 16-bit samples and its header.
    let max_inflated = limits.max_voxels.saturating_mul(2).saturating_add(1 << 26);
    let body = match lengths::check_element_lengths(path, max_inflated) {
        Ok(body) => body,
        Err(e) => return Scanned::Unreadable(e),
    };
    let object = match open::open(path, true, body) {
        Ok(opened) => opened,
        Err(e) => return Scanned::Unreadable(e),
    };
    match image_file(path, &object, &object.meta().transfer_syntax, limits) {
        Ok(Some(mut image)) => {
            image.body = body;
            if let Body::Implicit = body {
                image.notes.push(format!(
                    "{}: the meta group says explicit VR, but the data set is implicit VR; \
                     it was read as implicit VR (as pydicom does)",
                    path.display()
                ));
            }
            Scanned::Image(image)
        }
        Ok(None) => Scanned::NoImage,
        Err(e) => Scanned::Unreadable(e),
    }
}

/// `DICM` at byte 128 (after the preamble) or at byte 0 (a file without preamble).
fn has_dicom_magic(path: &Path) -> Result<bool> {
    let mut head = Vec::with_capacity(132);
    std::fs::File::open(path)
        .and_then(|f| f.take(132).read_to_end(&mut head))
        .map_err(|e| ReadError::io(path, e))?;
    Ok(head.get(128..132) == Some(b"DICM") || head.starts_with(b"DICM"))
}

/// The header of an image, or `None` for an object without Rows/Columns (no image).
fn image_file(
    path: &Path,
    object: &InMemDicomObject,
    transfer_syntax: &str,
    limits: &Limits,
) -> Result<Option<ImageFile>> {
    let (Some(rows), Some(columns)) = (
        integer::<u16>(object, tags::ROWS),
        integer::<u16>(object, tags::COLUMNS),
    ) else {
        return Ok(None);
    };
    if rows == 0 || columns == 0 {
        return Err(ReadError::format(
            path,
            format!(
                "Rows {rows} / Columns {columns}: an image needs at least one row and one \
                 column; the header is corrupt"
            ),
        ));
    }
    let bits_stored = integer(object, tags::BITS_STORED).unwrap_or(0u16);
    let signed = integer::<u16>(object, tags::PIXEL_REPRESENTATION) == Some(1);
    let mut layout = PixelLayout {
        rows,
        columns,
        samples_per_pixel: integer(object, tags::SAMPLES_PER_PIXEL).unwrap_or(1),
        bits_allocated: integer(object, tags::BITS_ALLOCATED).unwrap_or(0),
        bits_stored,
        high_bit: integer(object, tags::HIGH_BIT).unwrap_or(bits_stored.saturating_sub(1)),
        signed,
        photometric: text(object, tags::PHOTOMETRIC_INTERPRETATION).to_ascii_uppercase(),
        modality_lut: ModalityLut::read(path, object, signed)?,
    };
    let frame_count = integer::<u32>(object, tags::NUMBER_OF_FRAMES)
        .unwrap_or(1)
        .max(1);
    limits.check_slices(path, u64::from(frame_count))?;
    let mut frames = (0..frame_count)
        .map(|frame| frame_header(path, object, frame))
        .collect::<Result<Vec<_>>>()?;
    let mut notes: Vec<String> = stack_unplaced_frames(path, object, &mut frames)?
        .into_iter()
        .collect();
    let mosaic = unpack_mosaic(path, object, &mut layout, &mut frames)?.map(|(mosaic, note)| {
        notes.push(note);
        mosaic
    });
    limits.check_slices(path, frames.len() as u64)?;
    if layout.modality_lut.is_some() {
        // The LUT's outputs are the values (PS3.3 C.11.1: a LUT or a rescale, never both).
        for frame in &mut frames {
            frame.rescale = Rescale::IDENTITY;
        }
    }
    Ok(Some(ImageFile {
        path: path.to_path_buf(),
        series_uid: text(object, tags::SERIES_INSTANCE_UID),
        description: text(object, tags::SERIES_DESCRIPTION),
        modality: text(object, tags::MODALITY).to_ascii_uppercase(),
        transfer_syntax: transfer_syntax.trim_end_matches(['\0', ' ']).to_string(),
        padding: padding_value(object, layout.signed),
        layout,
        frames,
        notes,
        mosaic,
        body: Body::AsDeclared,
    }))
}

/// A multi-frame image whose frames share one position or have none (older multi-frame MR
/// and NM files): its frames are stacked in file order along the slice normal (row × column
/// cosine; axial when the orientation is missing too) from that position (or the origin), at
/// SpacingBetweenSlices, else SliceThickness, else 1 mm. Returns the warning that says so;
/// `None` when the frames are placed by the header.
fn stack_unplaced_frames(
    path: &Path,
    object: &InMemDicomObject,
    frames: &mut [FrameHeader],
) -> Result<Option<String>> {
    let first = frames[0];
    let shared = |f: &FrameHeader| f.position == first.position;
    if frames.len() < 2 || !frames.iter().all(shared) {
        return Ok(None);
    }
    let orientation = first.orientation.unwrap_or([DVec3::X, DVec3::Y]);
    let normal = orientation[0].cross(orientation[1]);
    let (step, source) = stated_step(path, object, first.thickness)?;
    let origin = first.position.unwrap_or(DVec3::ZERO);
    for (k, frame) in frames.iter_mut().enumerate() {
        frame.position = Some(origin + normal * (step * k as f64));
        frame.orientation = Some(orientation);
    }
    let placed = match (first.position, first.orientation) {
        (Some(_), Some(_)) => "one ImagePositionPatient for all frames",
        (None, Some(_)) => "no ImagePositionPatient (placed at the origin)",
        (Some(_), None) => "one ImagePositionPatient and no ImageOrientationPatient (axial)",
        (None, None) => "no ImagePositionPatient/ImageOrientationPatient (at the origin, axial)",
    };
    Ok(Some(format!(
        "{}: {} frames with {placed}: stacked in file order along the slice normal, {step} mm          apart (from {source}); the slice positions are assumed, not read",
        path.display(),
        frames.len()
    )))
}

/// The step between slices the header states, with the field it comes from:
/// SpacingBetweenSlices, else SliceThickness (`thickness`), else 1 mm.
fn stated_step(
    path: &Path,
    object: &InMemDicomObject,
    thickness: Option<f64>,
) -> Result<(f64, &'static str)> {
    let between = floats(
        path,
        "SpacingBetweenSlices",
        object,
        tags::SPACING_BETWEEN_SLICES,
    )?
    .and_then(|v| v.first().map(|s| s.abs()));
    let positive = |v: &f64| v.is_finite() && *v > 0.0;
    Ok(
        match (between.filter(positive), thickness.filter(positive)) {
            (Some(step), _) => (step, "SpacingBetweenSlices"),
            (None, Some(step)) => (step, "SliceThickness"),
            (None, None) => (
                1.0,
                "nothing (no SpacingBetweenSlices or SliceThickness): 1 mm assumed",
            ),
        },
    )
}

/// A Siemens mosaic (ImageType MOSAIC) is unpacked: `layout` becomes that of one tile and
/// `frames` one frame per slice (frame `k` is tile `k`), placed as dcm2niix places them
/// ([`Mosaic::first_position`], then along the slice normal at [`stated_step`]). Returns the
/// tiling and the warning that says how; `None` for any other image. Refuses a mosaic whose
/// slice count, position or orientation is missing, of several frames, or whose tiles do not
/// fit the image.
fn unpack_mosaic(
    path: &Path,
    object: &InMemDicomObject,
    layout: &mut PixelLayout,
    frames: &mut Vec<FrameHeader>,
) -> Result<Option<(Mosaic, String)>> {
    let image_type = text(object, tags::IMAGE_TYPE).to_ascii_uppercase();
    if !image_type.split('\\').any(|value| value.trim() == "MOSAIC") {
        return Ok(None);
    }
    let refuse = |what: &str| {
        ReadError::format(
            path,
            format!(
                "a Siemens mosaic (ImageType {image_type}) without {what}: its slices cannot \
                 be unpacked; convert it with the scanner's software or dcm2niix"
            ),
        )
    };
    let (count, count_source) = mosaic_count(object).ok_or_else(|| {
        refuse(
            "NumberOfImagesInMosaic (neither (0019,100A) of the SIEMENS MR HEADER block nor \
             the CSA image header (0029,1010) gives it)",
        )
    })?;
    let first = frames[0];
    let (Some(position), Some(orientation)) = (first.position, first.orientation) else {
        return Err(refuse("ImagePositionPatient and ImageOrientationPatient"));
    };
    if frames.len() > 1 {
        return Err(refuse("a single frame (it has several: NumberOfFrames)"));
    }
    let mosaic = Mosaic::new(path, [layout.rows, layout.columns], count, count_source)?;
    let spacing = first.pixel_spacing.unwrap_or([1.0, 1.0]);
    let start = mosaic.first_position(position, orientation, spacing);
    let (normal, normal_source) = mosaic_normal(object, orientation);
    let (step, step_source) = stated_step(path, object, first.thickness)?;
    *frames = (0..count)
        .map(|k| FrameHeader {
            frame: u32::from(k),
            position: Some(start + normal * (step * f64::from(k))),
            ..first
        })
        .collect();
    [layout.rows, layout.columns] = mosaic.tile;
    let [rows, columns] = mosaic.tile;
    let note = format!(
        "{}: a Siemens mosaic (ImageType {image_type}) unpacked into {count} slices of {rows} \
         rows × {columns} columns ({side} × {side} tiles; the count from {count_source}): the \
         first slice placed at the centre of the tiled image (as dcm2niix does), the others \
         {step} mm apart (from {step_source}) along {normal_source}",
        path.display(),
        side = mosaic.per_side,
    );
    Ok(Some((mosaic, note)))
}

/// NumberOfImagesInMosaic and where it was found: the SIEMENS MR HEADER's (0019,100A), else
/// the CSA image header's field.
fn mosaic_count(object: &InMemDicomObject) -> Option<(u16, &'static str)> {
    let siemens = text(object, Tag(0x0019, 0x0010)) == "SIEMENS MR HEADER";
    let tag = Tag(0x0019, 0x100A);
    let stored = object
        .get(tag)
        .filter(|_| siemens)
        .and_then(|element| match element.vr() {
            // Implicit VR: the two bytes of the US it is.
            VR::UN => Some(u16::from_le_bytes(
                element.to_bytes().ok()?.as_ref().try_into().ok()?,
            )),
            _ => integer(object, tag),
        });
    let csa = || {
        csa_field(object, "NumberOfImagesInMosaic")?
            .first()?
            .parse()
            .ok()
    };
    match stored {
        Some(count) => Some((count, "NumberOfImagesInMosaic (0019,100A)")),
        None => csa().map(|count| (count, "the CSA image header (0029,1010)")),
    }
}

/// The slice normal of a mosaic and where it came from: the CSA image header's
/// SliceNormalVector when it is a unit vector along ± the row × column cosine (it says which
/// way the slices run), else that cross product.
fn mosaic_normal(object: &InMemDicomObject, [row, column]: [DVec3; 2]) -> (DVec3, &'static str) {
    let cross = row.cross(column);
    let csa = csa_field(object, "SliceNormalVector").and_then(|values| {
        let numbers: Vec<f64> = values
            .iter()
            .map(|v| v.parse().ok())
            .collect::<Option<_>>()?;
        let [x, y, z] = numbers[..] else { return None };
        let normal = DVec3::new(x, y, z);
        let unit = normal.is_finite() && (normal.length() - 1.0).abs() < 1e-2;
        (unit && normal.dot(cross).abs() > 1.0 - 1e-3).then(|| normal.normalize())
    });
    match csa {
        Some(normal) => (normal, "the CSA image header's SliceNormalVector"),
        None => (
            cross,
            "the row × column cosine (no usable SliceNormalVector in a CSA image header)",
        ),
    }
}

/// The items of field `name` of the CSA image header (0029,1010), when the SIEMENS CSA HEADER
/// block holds one that parses.
fn csa_field(object: &InMemDicomObject, name: &str) -> Option<Vec<String>> {
    if text(object, Tag(0x0029, 0x0010)) != "SIEMENS CSA HEADER" {
        return None;
    }
    let bytes = object.get(Tag(0x0029, 0x1010))?.to_bytes().ok()?;
    csa::field(&bytes, name)
}

/// PixelPaddingValue as the raw sample it marks. Implicit VR files give no VR, so a signed
/// padding of −1500 may arrive as the unsigned 64036: reinterpret it for signed images.
fn padding_value(object: &InMemDicomObject, signed: bool) -> Option<i32> {
    let value = integer::<i32>(object, tags::PIXEL_PADDING_VALUE)?;
    Some(if signed && value > i32::from(i16::MAX) {
        value - 65536
    } else {
        value
    })
}

/// The attributes of frame `frame`: from its PerFrameFunctionalGroupsSequence item, then the
/// SharedFunctionalGroupsSequence, then the top level (classic single-frame images).
fn frame_header(path: &Path, object: &InMemDicomObject, frame: u32) -> Result<FrameHeader> {
    let per_frame = first_items(object, tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|items| items.get(usize::try_from(frame).ok()?));
    let shared = first_items(object, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE)
        .and_then(|items| items.first());
    let scope = FrameScope {
        groups: [per_frame, shared],
        top: object,
    };
    let position = scope
        .floats(
            path,
            "ImagePositionPatient",
            tags::PLANE_POSITION_SEQUENCE,
            tags::IMAGE_POSITION_PATIENT,
        )?
        .map(|v| vector3(path, "ImagePositionPatient", &v))
        .transpose()?;
    let orientation = scope
        .floats(
            path,
            "ImageOrientationPatient",
            tags::PLANE_ORIENTATION_SEQUENCE,
            tags::IMAGE_ORIENTATION_PATIENT,
        )?
        .map(|v| orientation(path, &v))
        .transpose()?;
    let measures = tags::PIXEL_MEASURES_SEQUENCE;
    let pixel_spacing = scope
        .floats(path, "PixelSpacing", measures, tags::PIXEL_SPACING)?
        .map(|v| pixel_spacing(path, &v))
        .transpose()?
        .flatten();
    let thickness = scope
        .floats(path, "SliceThickness", measures, tags::SLICE_THICKNESS)?
        .and_then(|v| v.first().copied());
    let transform = tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE;
    let first = |name, tag| -> Result<Option<f64>> {
        Ok(scope
            .floats(path, name, transform, tag)?
            .and_then(|v| v.first().copied()))
    };
    let rescale = Rescale {
        slope: first("RescaleSlope", tags::RESCALE_SLOPE)?.unwrap_or(1.0),
        intercept: first("RescaleIntercept", tags::RESCALE_INTERCEPT)?.unwrap_or(0.0),
    };
    if !rescale.slope.is_finite() || rescale.slope == 0.0 || !rescale.intercept.is_finite() {
        return Err(ReadError::format(
            path,
            format!(
                "RescaleSlope {} / RescaleIntercept {} must be finite with a non-zero slope",
                rescale.slope, rescale.intercept
            ),
        ));
    }
    Ok(FrameHeader {
        frame,
        position,
        orientation,
        pixel_spacing,
        thickness,
        rescale,
    })
}

/// The places a frame attribute may live, most specific first.
struct FrameScope<'a> {
    groups: [Option<&'a InMemDicomObject>; 2],
    top: &'a InMemDicomObject,
}

impl FrameScope<'_> {
    /// The numbers of `tag` (called `name` in errors) inside the functional group `sequence`,
    /// or at the top level; `None` when absent or empty.
    fn floats(&self, path: &Path, name: &str, sequence: Tag, tag: Tag) -> Result<Option<Vec<f64>>> {
        for group in self.groups.iter().flatten() {
            let Some(item) = first_items(group, sequence).and_then(<[_]>::first) else {
                continue;
            };
            if let Some(values) = floats(path, name, item, tag)? {
                return Ok(Some(values));
            }
        }
        floats(path, name, self.top, tag)
    }
}

fn first_items(object: &InMemDicomObject, tag: Tag) -> Option<&[InMemDicomObject]> {
    object.get(tag)?.items()
}

/// The numbers of `tag` (called `name` in errors): `None` when absent or empty, an error when
/// present but not numbers (a value read as 0 would shift every voxel or slice). A value of VR
/// UN (an implicit-VR file converted by a tool that did not know the tag) is read from its
/// text.
fn floats(
    path: &Path,
    name: &str,
    object: &InMemDicomObject,
    tag: Tag,
) -> Result<Option<Vec<f64>>> {
    let Some(element) = object.get(tag) else {
        return Ok(None);
    };
    if element.is_empty() {
        return Ok(None);
    }
    let numbers = match element.vr() {
        VR::UN => element
            .to_bytes()
            .ok()
            .and_then(|bytes| decimal_strings(&bytes)),
        _ => element.to_multi_float64().ok(),
    };
    match numbers {
        Some(values) if !values.is_empty() => Ok(Some(values)),
        _ => {
            let found = element.to_str().map(|s| s.into_owned()).unwrap_or_default();
            Err(ReadError::format(
                path,
                format!(
                    "{name} ({:04X},{:04X}) must hold numbers, found {found:?}; correct or \
                     remove the attribute",
                    tag.group(),
                    tag.element()
                ),
            ))
        }
    }
}

/// Backslash-separated decimal numbers (DICOM's DS) from raw bytes, padding trimmed.
fn decimal_strings(bytes: &[u8]) -> Option<Vec<f64>> {
    let text = std::str::from_utf8(bytes).ok()?;
    text.trim_matches(['\0', ' '])
        .split('\\')
        .map(|n| n.trim().parse().ok())
        .collect()
}

/// An integer attribute that fits `T` (`None` when absent, malformed or out of range).
fn integer<T: TryFrom<i64>>(object: &InMemDicomObject, tag: Tag) -> Option<T> {
    let value = object.get(tag)?.to_int::<i64>().ok()?;
    T::try_from(value).ok()
}

/// A string attribute without DICOM padding (trailing spaces or NULs); empty when absent.
fn text(object: &InMemDicomObject, tag: Tag) -> String {
    object
        .get(tag)
        .and_then(|e| e.to_str().ok())
        .map(|s| s.trim_matches(['\0', ' ']).to_string())
        .unwrap_or_default()
}

fn vector3(path: &Path, name: &str, values: &[f64]) -> Result<DVec3> {
    match values {
        [x, y, z] if values.iter().all(|v| v.is_finite()) => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(ReadError::format(
            path,
            format!("{name} must be 3 finite numbers, found {values:?}"),
        )),
    }
}

fn orientation(path: &Path, values: &[f64]) -> Result<[DVec3; 2]> {
    let bad = || {
        ReadError::format(
            path,
            format!(
                "ImageOrientationPatient must be two orthogonal unit vectors (6 numbers), \
                 found {values:?}"
            ),
        )
    };
    let [a, b, c, d, e, f] = values else {
        return Err(bad());
    };
    let row = DVec3::new(*a, *b, *c);
    let column = DVec3::new(*d, *e, *f);
    // Headers round cosines to a few digits; accept that, refuse anything that is not a frame.
    let unit = |v: DVec3| v.is_finite() && (v.length() - 1.0).abs() < 1e-2;
    if !unit(row) || !unit(column) || row.dot(column).abs() > 1e-2 {
        return Err(bad());
    }
    Ok([row.normalize(), column.normalize()])
}

/// Pixel spacings (mm) outside this range are not a scan's: a corrupt or mistyped header.
const PIXEL_SPACING_MM: std::ops::RangeInclusive<f64> = 1e-3..=1e3;

/// PixelSpacing: two numbers within [`PIXEL_SPACING_MM`], or `None` for `0\0`, which some
/// tools write for "unknown" (the reader then warns and assumes 1 mm, as for a missing one).
fn pixel_spacing(path: &Path, values: &[f64]) -> Result<Option<[f64; 2]>> {
    match values {
        [between_rows, between_columns] if values.iter().all(|v| PIXEL_SPACING_MM.contains(v)) => {
            Ok(Some([*between_rows, *between_columns]))
        }
        [0.0, 0.0] => Ok(None),
        _ => Err(ReadError::format(
            path,
            format!(
                "PixelSpacing (0028,0030) must be 2 numbers from {} to {} mm, found {values:?}; \
                 correct the header's PixelSpacing",
                PIXEL_SPACING_MM.start(),
                PIXEL_SPACING_MM.end()
            ),
        )),
    }
}
