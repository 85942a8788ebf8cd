//! Overlays that belong to a scan and are drawn with it: DICOM segmentations (SEG, binary or
//! fractional: each segment a labelled region) and radiotherapy dose grids (RTDOSE, 16- or
//! 32-bit with their DoseGridScaling), each read in its own geometry (LPS mm), so that the
//! see-through views can show exactly what a planner segmented or irradiated behind the wall.
//!
//! Both are multi-frame images whose frames lie on one regular stack: a SEG lists a position
//! per frame (frames of several segments may share a position, and positions without any
//! segment may be missing), a dose grid one position and the frames' offsets along the normal
//! (GridFrameOffsetVector). Only native (uncompressed) transfer syntaxes are read; an overlay
//! is read whole, its bytes checked against what its header declares before anything is
//! allocated for them.

use super::lengths::check_element_lengths;
use super::open::open;
use crate::error::{ReadError, Result};
use crate::Limits;
use dicom_core::Tag;
use dicom_dictionary_std::{tags, uids};
use dicom_object::InMemDicomObject;
use endocast_core::{Geometry, Modality, ValueMap, Volume};
use glam::{DMat3, DVec3};
use std::path::Path;

/// What an overlay holds.
#[derive(Debug, Clone, PartialEq)]
pub enum OverlayKind {
    /// A segmentation: the volume's values are segment numbers (0: none).
    Segmentation(Vec<Segment>),
    /// A dose grid: the volume's values are doses, in `units` (GY or RELATIVE).
    Dose {
        /// DoseUnits as the file gives them.
        units: String,
    },
}

/// One segment of a segmentation.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// SegmentNumber: its value in the label volume.
    pub number: u16,
    /// SegmentLabel.
    pub label: String,
    /// The recommended display colour (from CIELab), 0–1 sRGB; a palette colour when none.
    pub colour: [f32; 3],
}

/// A segmentation or a dose grid, in its own geometry.
#[derive(Debug, Clone)]
pub struct Overlay {
    /// Segment numbers or doses, on the overlay's own grid.
    pub volume: Volume,
    /// What the values mean.
    pub kind: OverlayKind,
}

/// Colours for segments that recommend none.
const PALETTE: [[f32; 3]; 6] = [
    [0.9, 0.3, 0.3],
    [0.3, 0.8, 0.3],
    [0.3, 0.5, 0.95],
    [0.95, 0.8, 0.2],
    [0.8, 0.4, 0.9],
    [0.2, 0.85, 0.85],
];

/// Reads the segmentation or dose grid at `path`. Errors name the file and what is wrong: not
/// a SEG or RTDOSE, a compressed transfer syntax, frames off one regular stack, pixel data
/// shorter than the frames declared, a grid beyond `limits`.
pub fn read_overlay(path: &Path, limits: &Limits) -> Result<Overlay> {
    let body = check_element_lengths(path, limits.max_voxels.saturating_mul(4))?;
    let object = open(path, false, body)?;
    let syntax = object.meta().transfer_syntax.trim_end_matches('\0');
    if ![
        uids::EXPLICIT_VR_LITTLE_ENDIAN,
        uids::IMPLICIT_VR_LITTLE_ENDIAN,
    ]
    .contains(&syntax)
    {
        return Err(ReadError::unsupported(
            path,
            format!("an overlay in transfer syntax {syntax}: only uncompressed overlays are read"),
        ));
    }
    let file = File {
        path,
        object: &object,
    };
    match file.text(tags::MODALITY).as_str() {
        "SEG" => segmentation(&file, limits),
        "RTDOSE" => dose(&file, limits),
        other => Err(ReadError::format(
            path,
            format!(
                "modality {other:?}: an overlay is a segmentation (SEG) or a dose grid (RTDOSE)"
            ),
        )),
    }
}

/// Refuses a segmentation or dose grid given as a scan, saying how to use it; any other file
/// (readable or not) passes, for the scan reader to judge.
pub(super) fn refuse_as_scan(path: &Path, limits: &Limits) -> Result<()> {
    let Ok(body) = check_element_lengths(path, limits.max_voxels.saturating_mul(4)) else {
        return Ok(());
    };
    let Ok(object) = open(path, true, body) else {
        return Ok(());
    };
    let what = match text(&object, tags::MODALITY).as_str() {
        "SEG" => "a segmentation (SEG)",
        "RTDOSE" => "a dose grid (RTDOSE)",
        _ => return Ok(()),
    };
    Err(ReadError::unsupported(
        path,
        format!("{what} as a scan: it is an overlay; draw it over its scan with --overlay FILE"),
    ))
}

/// An open overlay file and the path its errors name.
struct File<'a> {
    path: &'a Path,
    object: &'a InMemDicomObject,
}

impl File<'_> {
    fn text(&self, tag: Tag) -> String {
        text(self.object, tag)
    }

    fn error(&self, message: impl Into<String>) -> ReadError {
        ReadError::format(self.path, message)
    }

    /// An unsigned number the file must hold.
    fn count(&self, tag: Tag, name: &str) -> Result<usize> {
        self.object
            .element(tag)
            .ok()
            .and_then(|e| e.to_int::<i64>().ok())
            .and_then(|v| usize::try_from(v).ok())
            .ok_or_else(|| self.error(format!("{name} is missing or not a number")))
    }

    /// The pixel data's bytes, at least `needed` of them.
    fn pixel_bytes(&self, needed: usize) -> Result<Vec<u8>> {
        let bytes = self
            .object
            .element(tags::PIXEL_DATA)
            .map_err(|_| self.error("no PixelData"))?
            .to_bytes()
            .map_err(|e| self.error(format!("PixelData: {e}")))?;
        if bytes.len() < needed {
            return Err(self.error(format!(
                "PixelData holds {} bytes, but the frames declared need {needed}",
                bytes.len()
            )));
        }
        Ok(bytes.into_owned())
    }
}

/// A DICOM SEG: every frame's set pixels take its segment's number.
fn segmentation(file: &File<'_>, limits: &Limits) -> Result<Overlay> {
    let (rows, columns) = (
        file.count(tags::ROWS, "Rows")?,
        file.count(tags::COLUMNS, "Columns")?,
    );
    let frames = file.count(tags::NUMBER_OF_FRAMES, "NumberOfFrames")?;
    let pixels = rows * columns;
    check_size(file, [columns, rows, frames], limits)?;
    let shared = first_item(file.object, tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE);
    let per_frame = items(file.object, tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE);
    if per_frame.len() != frames {
        return Err(file.error(format!(
            "{} per-frame functional groups for {frames} frames",
            per_frame.len()
        )));
    }
    let group = |f: usize, sequence: Tag, tag: Tag| {
        floats_in(&per_frame[f], sequence, tag)
            .or_else(|| shared.and_then(|s| floats_in(s, sequence, tag)))
    };
    let orientation = group(
        0,
        tags::PLANE_ORIENTATION_SEQUENCE,
        tags::IMAGE_ORIENTATION_PATIENT,
    )
    .ok_or_else(|| file.error("no ImageOrientationPatient in the functional groups"))?;
    let spacing = group(0, tags::PIXEL_MEASURES_SEQUENCE, tags::PIXEL_SPACING)
        .ok_or_else(|| file.error("no PixelSpacing in the functional groups"))?;
    let positions = (0..frames)
        .map(|f| {
            group(
                f,
                tags::PLANE_POSITION_SEQUENCE,
                tags::IMAGE_POSITION_PATIENT,
            )
            .and_then(|p| vector(&p))
            .ok_or_else(|| file.error(format!("frame {}: no ImagePositionPatient", f + 1)))
        })
        .collect::<Result<Vec<_>>>()?;
    let numbers = (0..frames)
        .map(|f| {
            floats_in(
                &per_frame[f],
                tags::SEGMENT_IDENTIFICATION_SEQUENCE,
                tags::REFERENCED_SEGMENT_NUMBER,
            )
            .and_then(|n| n.first().copied())
            .filter(|&n| (1.0..=65535.0).contains(&n))
            .map(|n| n as u16)
            .ok_or_else(|| file.error(format!("frame {}: no ReferencedSegmentNumber", f + 1)))
        })
        .collect::<Result<Vec<_>>>()?;
    let stack = Stack::new(
        file,
        [columns, rows],
        &orientation,
        &spacing,
        &positions,
        limits,
    )?;
    let fractional = file.text(tags::SEGMENTATION_TYPE) == "FRACTIONAL";
    let bytes = file.pixel_bytes(if fractional {
        pixels * frames
    } else {
        (pixels * frames).div_ceil(8)
    })?;
    let half = file
        .object
        .element(tags::MAXIMUM_FRACTIONAL_VALUE)
        .ok()
        .and_then(|e| e.to_int::<u16>().ok())
        .unwrap_or(255)
        / 2;
    let set = |n: usize| {
        if fractional {
            u16::from(bytes[n]) > half
        } else {
            bytes[n / 8] >> (n % 8) & 1 == 1
        }
    };
    let mut labels = vec![0u16; stack.voxels()];
    for (f, &number) in numbers.iter().enumerate() {
        let slice = stack.slice_of[f] * pixels;
        for p in (0..pixels).filter(|&p| set(f * pixels + p)) {
            labels[slice + p] = labels[slice + p].max(number);
        }
    }
    let volume = stack.volume(
        file,
        labels,
        ValueMap::IDENTITY,
        Modality::Other("SEG".into()),
    )?;
    Ok(Overlay {
        volume,
        kind: OverlayKind::Segmentation(segments(file.object)),
    })
}

/// The segments the SegmentSequence describes.
fn segments(object: &InMemDicomObject) -> Vec<Segment> {
    items(object, tags::SEGMENT_SEQUENCE)
        .iter()
        .enumerate()
        .filter_map(|(n, item)| {
            let number = item
                .element(tags::SEGMENT_NUMBER)
                .ok()?
                .to_int::<u16>()
                .ok()?;
            let lab = item
                .element(tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE)
                .ok()
                .and_then(|e| e.to_multi_int::<u16>().ok())
                .filter(|v| v.len() == 3);
            Some(Segment {
                number,
                label: text(item, tags::SEGMENT_LABEL),
                colour: lab.map_or(PALETTE[n % PALETTE.len()], |v| {
                    srgb_from_dicom_lab([v[0], v[1], v[2]])
                }),
            })
        })
        .collect()
}

/// An RTDOSE grid: doses (stored × DoseGridScaling) on frames at GridFrameOffsetVector.
fn dose(file: &File<'_>, limits: &Limits) -> Result<Overlay> {
    let (rows, columns) = (
        file.count(tags::ROWS, "Rows")?,
        file.count(tags::COLUMNS, "Columns")?,
    );
    let frames = file
        .count(tags::NUMBER_OF_FRAMES, "NumberOfFrames")
        .unwrap_or(1);
    check_size(file, [columns, rows, frames], limits)?;
    let bits = file.count(tags::BITS_ALLOCATED, "BitsAllocated")?;
    if !matches!(bits, 16 | 32)
        || file
            .count(tags::PIXEL_REPRESENTATION, "PixelRepresentation")
            .unwrap_or(0)
            != 0
    {
        return Err(ReadError::unsupported(
            file.path,
            format!(
                "a dose grid of {bits}-bit or signed samples: 16- and 32-bit unsigned are read"
            ),
        ));
    }
    let scaling = floats(file.object, tags::DOSE_GRID_SCALING)
        .and_then(|v| v.first().copied())
        .filter(|s| s.is_finite() && *s > 0.0)
        .ok_or_else(|| file.error("DoseGridScaling is missing or not a positive number"))?;
    let orientation = floats(file.object, tags::IMAGE_ORIENTATION_PATIENT)
        .ok_or_else(|| file.error("no ImageOrientationPatient"))?;
    let spacing =
        floats(file.object, tags::PIXEL_SPACING).ok_or_else(|| file.error("no PixelSpacing"))?;
    let origin = floats(file.object, tags::IMAGE_POSITION_PATIENT)
        .and_then(|p| vector(&p))
        .ok_or_else(|| file.error("no ImagePositionPatient"))?;
    let offsets = floats(file.object, tags::GRID_FRAME_OFFSET_VECTOR).unwrap_or_else(|| vec![0.0]);
    if offsets.len() != frames {
        return Err(file.error(format!(
            "GridFrameOffsetVector gives {} offsets for {frames} frames",
            offsets.len()
        )));
    }
    let [row, column] = cosines(file, &orientation)?;
    let normal = row.cross(column);
    let positions: Vec<DVec3> = offsets.iter().map(|&o| origin + o * normal).collect();
    let stack = Stack::new(
        file,
        [columns, rows],
        &orientation,
        &spacing,
        &positions,
        limits,
    )?;
    let samples = columns * rows * frames;
    let bytes = file.pixel_bytes(samples * bits / 8)?;
    let stored: Vec<u32> = match bits {
        16 => bytes
            .chunks_exact(2)
            .take(samples)
            .map(|b| u32::from(u16::from_le_bytes([b[0], b[1]])))
            .collect(),
        _ => bytes
            .chunks_exact(4)
            .take(samples)
            .map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
            .collect(),
    };
    let top = stored.iter().copied().max().unwrap_or(0).max(1);
    // Kept exactly when the samples fit 16 bits, else scaled to them (1/65535 of the maximum).
    let shrink = (f64::from(top) / 65535.0).max(1.0);
    let mut voxels = vec![0u16; stack.voxels()];
    let pixels = columns * rows;
    for (f, frame) in stored.chunks_exact(pixels).enumerate() {
        let slice = stack.slice_of[f] * pixels;
        for (v, &s) in voxels[slice..slice + pixels].iter_mut().zip(frame) {
            *v = (f64::from(s) / shrink).round() as u16;
        }
    }
    let map = ValueMap::new(scaling * shrink, 0.0).map_err(|e| file.error(e.to_string()))?;
    let volume = stack.volume(file, voxels, map, Modality::Other("RTDOSE".into()))?;
    let units = file.text(tags::DOSE_UNITS);
    Ok(Overlay {
        volume,
        kind: OverlayKind::Dose { units },
    })
}

/// Frames placed on one regular stack of slices.
struct Stack {
    dims: [usize; 3],
    spacing: DVec3,
    origin: DVec3,
    direction: DMat3,
    /// The slice of each frame.
    slice_of: Vec<usize>,
}

impl Stack {
    /// The stack through `positions` (one per frame): its step is the smallest gap between
    /// distinct positions, and every position must lie on it and on the first frame's line.
    fn new(
        file: &File<'_>,
        [columns, rows]: [usize; 2],
        orientation: &[f64],
        spacing: &[f64],
        positions: &[DVec3],
        limits: &Limits,
    ) -> Result<Self> {
        let [row, column] = cosines(file, orientation)?;
        let normal = row.cross(column);
        let (dy, dx) = match spacing {
            [a, b, ..]
                if [a, b]
                    .iter()
                    .all(|s| s.is_finite() && **s > 1e-3 && **s < 1e3) =>
            {
                (*a, *b)
            }
            _ => {
                return Err(file.error(format!(
                    "PixelSpacing {spacing:?} is not two spacings of 0.001–1000 mm"
                )))
            }
        };
        let along: Vec<f64> = positions.iter().map(|p| p.dot(normal)).collect();
        let mut distinct = along.clone();
        distinct.sort_by(f64::total_cmp);
        distinct.dedup_by(|a, b| (*a - *b).abs() < 1e-3);
        let first = distinct[0];
        let step = distinct
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() { step } else { 1.0 };
        let slices = ((distinct[distinct.len() - 1] - first) / step).round() as usize + 1;
        check_size(file, [columns, rows, slices], limits)?;
        let base = positions[along
            .iter()
            .position(|&a| (a - first).abs() < 1e-3)
            .unwrap_or(0)];
        let mut slice_of = Vec::with_capacity(positions.len());
        for (f, (&a, p)) in along.iter().zip(positions).enumerate() {
            let index = (a - first) / step;
            let sideways = (*p - base) - (a - first) * normal;
            if (index - index.round()).abs() > 0.1 || sideways.length() > 0.01 * dx.min(dy).max(0.1)
            {
                return Err(file.error(format!(
                    "frame {}: its position {p} is off the regular stack of the others (step {step:.3} mm)",
                    f + 1
                )));
            }
            slice_of.push(index.round() as usize);
        }
        Ok(Self {
            dims: [columns, rows, slices],
            spacing: DVec3::new(dx, dy, step),
            origin: base,
            direction: DMat3::from_cols(row, column, normal),
            slice_of,
        })
    }

    fn voxels(&self) -> usize {
        self.dims.iter().product()
    }

    fn volume(
        &self,
        file: &File<'_>,
        voxels: Vec<u16>,
        map: ValueMap,
        modality: Modality,
    ) -> Result<Volume> {
        let geometry = Geometry::new(self.dims, self.spacing, self.origin, self.direction)
            .map_err(|e| file.error(e.to_string()))?;
        Volume::new(geometry, voxels, map, modality).map_err(|e| file.error(e.to_string()))
    }
}

/// Refuses a grid of more voxels than `limits` allow, before anything is allocated for it.
fn check_size(file: &File<'_>, dims: [usize; 3], limits: &Limits) -> Result<()> {
    let voxels = dims.iter().try_fold(1u64, |n, &d| n.checked_mul(d as u64));
    match voxels {
        Some(n) if n > 0 && n <= limits.max_voxels => Ok(()),
        _ => Err(file.error(format!(
            "an overlay grid of {dims:?} voxels: empty, or more than the limit of {}",
            limits.max_voxels
        ))),
    }
}

/// The row and column cosines of ImageOrientationPatient, unit and orthogonal.
fn cosines(file: &File<'_>, values: &[f64]) -> Result<[DVec3; 2]> {
    let bad = || {
        file.error(format!(
            "ImageOrientationPatient {values:?} is not two orthogonal unit vectors"
        ))
    };
    let [a, b, c, d, e, f] = values else {
        return Err(bad());
    };
    let (row, column) = (DVec3::new(*a, *b, *c), DVec3::new(*d, *e, *f));
    let unit = |v: DVec3| (v.length() - 1.0).abs() < 1e-2;
    if !(row.is_finite()
        && column.is_finite()
        && unit(row)
        && unit(column)
        && row.dot(column).abs() < 1e-2)
    {
        return Err(bad());
    }
    Ok([row.normalize(), column.normalize()])
}

fn vector(values: &[f64]) -> Option<DVec3> {
    match values {
        [x, y, z] if [x, y, z].iter().all(|v| v.is_finite() && v.abs() < 1e6) => {
            Some(DVec3::new(*x, *y, *z))
        }
        _ => None,
    }
}

fn text(object: &InMemDicomObject, tag: Tag) -> String {
    object
        .element(tag)
        .ok()
        .and_then(|e| e.to_str().ok())
        .map(|s| s.trim().to_owned())
        .unwrap_or_default()
}

fn floats(object: &InMemDicomObject, tag: Tag) -> Option<Vec<f64>> {
    object.element(tag).ok()?.to_multi_float64().ok()
}

fn items(object: &InMemDicomObject, tag: Tag) -> &[InMemDicomObject] {
    object.get(tag).and_then(|e| e.items()).unwrap_or(&[])
}

fn first_item(object: &InMemDicomObject, tag: Tag) -> Option<&InMemDicomObject> {
    items(object, tag).first()
}

/// `tag` inside the first item of `sequence` of `object`.
fn floats_in(object: &InMemDicomObject, sequence: Tag, tag: Tag) -> Option<Vec<f64>> {
    floats(first_item(object, sequence)?, tag)
}

/// sRGB (0–1) of a DICOM CIELab triple (L*, a*, b* scaled to 0–65535; D65 white).
fn srgb_from_dicom_lab([l, a, b]: [u16; 3]) -> [f32; 3] {
    let l = f64::from(l) * 100.0 / 65535.0;
    let a = f64::from(a) * 255.0 / 65535.0 - 128.0;
    let b = f64::from(b) * 255.0 / 65535.0 - 128.0;
    let fy = (l + 16.0) / 116.0;
    let (fx, fz) = (fy + a / 500.0, fy - b / 200.0);
    let inverse = |t: f64| {
        if t > 6.0 / 29.0 {
            t * t * t
        } else {
            3.0 * (6.0f64 / 29.0).powi(2) * (t - 4.0 / 29.0)
        }
    };
    let (x, y, z) = (0.950_47 * inverse(fx), inverse(fy), 1.088_83 * inverse(fz));
    let linear = [
        3.240_6 * x - 1.537_2 * y - 0.498_6 * z,
        -0.968_9 * x + 1.875_8 * y + 0.041_5 * z,
        0.055_7 * x - 0.204_0 * y + 1.057_0 * z,
    ];
    linear.map(|c| {
        let c = c.clamp(0.0, 1.0);
        let g = if c <= 0.003_130_8 {
            12.92 * c
        } else {
            1.055 * c.powf(1.0 / 2.4) - 0.055
        };
        g as f32
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dicom_lab_white_and_red_become_srgb() {
        let white = srgb_from_dicom_lab([65535, 32896, 32896]);
        assert!(white.iter().all(|&c| c > 0.98), "{white:?}");
        // L* 53.2, a* 80.1, b* 67.2 is sRGB red.
        let red = srgb_from_dicom_lab([34865, 53485, 50171]);
        assert!(red[0] > 0.95 && red[1] < 0.1 && red[2] < 0.1, "{red:?}");
    }
}
