//! Small DICOM overlays written by tests: a segmentation (SEG, binary) and a dose grid
//! (RTDOSE, 32-bit), on axis-aligned grids.
//!
//! # Panics
//!
//! Every function panics when the file cannot be written (a test's failure).

#![allow(clippy::unwrap_used)] // a failed write is a failed test

use dicom_core::value::DataSetSequence;
use dicom_core::{DataElement, PrimitiveValue, VR};
use dicom_dictionary_std::{tags, uids};
use dicom_object::{FileMetaTableBuilder, InMemDicomObject};
use std::path::Path;

type Element = DataElement<InMemDicomObject>;

/// One frame of a segmentation: its segment, the `z` of its plane (mm) and its set pixels
/// (row, column).
pub struct SegFrame {
    /// ReferencedSegmentNumber.
    pub segment: u16,
    /// The plane's z, mm (its x and y are the grid's origin).
    pub z: f64,
    /// The pixels in the segment, (row, column).
    pub pixels: Vec<(usize, usize)>,
}

/// An axis-aligned grid: its first pixel's centre, the spacing between columns (x) and rows
/// (y), and its columns and rows.
pub struct Grid {
    /// The first pixel's centre, LPS mm.
    pub origin: [f64; 3],
    /// Spacing between columns (along x) and between rows (along y), mm.
    pub spacing: [f64; 2],
    /// Columns and rows.
    pub size: [usize; 2],
}

fn text(tag: dicom_core::Tag, vr: VR, value: &str) -> Element {
    Element::new(tag, vr, PrimitiveValue::from(value))
}

fn short(tag: dicom_core::Tag, value: u16) -> Element {
    Element::new(tag, VR::US, PrimitiveValue::from(value))
}

fn sequence(tag: dicom_core::Tag, items: Vec<InMemDicomObject>) -> Element {
    Element::new(tag, VR::SQ, DataSetSequence::from(items))
}

fn item(elements: Vec<Element>) -> InMemDicomObject {
    InMemDicomObject::from_element_iter(elements)
}

/// The elements every overlay has: UIDs, modality, grid size, pixel spacing (DICOM: rows' then
/// columns' spacing).
fn common(grid: &Grid, modality: &str, sop_class: &str, frames: usize) -> Vec<Element> {
    vec![
        text(tags::SOP_CLASS_UID, VR::UI, sop_class),
        text(
            tags::SOP_INSTANCE_UID,
            VR::UI,
            "1.2.826.0.1.3680043.2.1125.77.1",
        ),
        text(
            tags::SERIES_INSTANCE_UID,
            VR::UI,
            "1.2.826.0.1.3680043.2.1125.77.2",
        ),
        text(tags::MODALITY, VR::CS, modality),
        short(tags::SAMPLES_PER_PIXEL, 1),
        text(tags::PHOTOMETRIC_INTERPRETATION, VR::CS, "MONOCHROME2"),
        text(tags::NUMBER_OF_FRAMES, VR::IS, &frames.to_string()),
        short(tags::ROWS, grid.size[1] as u16),
        short(tags::COLUMNS, grid.size[0] as u16),
        short(tags::PIXEL_REPRESENTATION, 0),
    ]
}

fn spacing(grid: &Grid) -> String {
    format!("{}\\{}", grid.spacing[1], grid.spacing[0])
}

fn write(path: &Path, elements: Vec<Element>) {
    item(elements)
        .with_meta(FileMetaTableBuilder::new().transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN))
        .unwrap()
        .write_to_file(path)
        .unwrap();
}

/// Writes a binary segmentation of `frames` on `grid`, its segments named by `segments`
/// (number, label, CIELab colour scaled as DICOM stores it).
pub fn write_segmentation(
    path: &Path,
    grid: &Grid,
    segments: &[(u16, &str, [u16; 3])],
    frames: &[SegFrame],
) {
    let [columns, rows] = grid.size;
    let pixels = columns * rows;
    let mut bits = vec![0u8; (pixels * frames.len()).div_ceil(8)];
    for (f, frame) in frames.iter().enumerate() {
        for &(r, c) in &frame.pixels {
            let n = f * pixels + r * columns + c;
            bits[n / 8] |= 1 << (n % 8);
        }
    }
    let per_frame = frames
        .iter()
        .map(|frame| {
            let [x, y, _] = grid.origin;
            item(vec![
                sequence(
                    tags::PLANE_POSITION_SEQUENCE,
                    vec![item(vec![text(
                        tags::IMAGE_POSITION_PATIENT,
                        VR::DS,
                        &format!("{x}\\{y}\\{}", frame.z),
                    )])],
                ),
                sequence(
                    tags::SEGMENT_IDENTIFICATION_SEQUENCE,
                    vec![item(vec![short(
                        tags::REFERENCED_SEGMENT_NUMBER,
                        frame.segment,
                    )])],
                ),
            ])
        })
        .collect();
    let shared = item(vec![
        sequence(
            tags::PIXEL_MEASURES_SEQUENCE,
            vec![item(vec![text(
                tags::PIXEL_SPACING,
                VR::DS,
                &spacing(grid),
            )])],
        ),
        sequence(
            tags::PLANE_ORIENTATION_SEQUENCE,
            vec![item(vec![text(
                tags::IMAGE_ORIENTATION_PATIENT,
                VR::DS,
                "1\\0\\0\\0\\1\\0",
            )])],
        ),
    ]);
    let segment_items = segments
        .iter()
        .map(|(number, label, lab)| {
            item(vec![
                short(tags::SEGMENT_NUMBER, *number),
                text(tags::SEGMENT_LABEL, VR::LO, label),
                Element::new(
                    tags::RECOMMENDED_DISPLAY_CIE_LAB_VALUE,
                    VR::US,
                    PrimitiveValue::U16(lab.to_vec().into()),
                ),
            ])
        })
        .collect();
    let mut elements = common(grid, "SEG", "1.2.840.10008.5.1.4.1.1.66.4", frames.len());
    elements.extend([
        short(tags::BITS_ALLOCATED, 1),
        short(tags::BITS_STORED, 1),
        short(tags::HIGH_BIT, 0),
        text(tags::SEGMENTATION_TYPE, VR::CS, "BINARY"),
        sequence(tags::SEGMENT_SEQUENCE, segment_items),
        sequence(tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE, vec![shared]),
        sequence(tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE, per_frame),
        Element::new(tags::PIXEL_DATA, VR::OB, PrimitiveValue::U8(bits.into())),
    ]);
    write(path, elements);
}

/// Writes a 32-bit dose grid on `grid`: frame `f` at `offsets[f]` mm along z from the origin,
/// its stored samples `samples` (frames × rows × columns, columns fastest) times `scaling` Gy.
pub fn write_dose(path: &Path, grid: &Grid, offsets: &[f64], scaling: f64, samples: &[u32]) {
    let [x, y, z] = grid.origin;
    let offsets: Vec<String> = offsets.iter().map(f64::to_string).collect();
    let mut elements = common(
        grid,
        "RTDOSE",
        "1.2.840.10008.5.1.4.1.1.481.2",
        offsets.len(),
    );
    elements.extend([
        short(tags::BITS_ALLOCATED, 32),
        short(tags::BITS_STORED, 32),
        short(tags::HIGH_BIT, 31),
        text(
            tags::IMAGE_POSITION_PATIENT,
            VR::DS,
            &format!("{x}\\{y}\\{z}"),
        ),
        text(tags::IMAGE_ORIENTATION_PATIENT, VR::DS, "1\\0\\0\\0\\1\\0"),
        text(tags::PIXEL_SPACING, VR::DS, &spacing(grid)),
        text(tags::DOSE_UNITS, VR::CS, "GY"),
        text(tags::DOSE_GRID_SCALING, VR::DS, &scaling.to_string()),
        text(tags::GRID_FRAME_OFFSET_VECTOR, VR::DS, &offsets.join("\\")),
        Element::new(
            tags::PIXEL_DATA,
            VR::OW,
            PrimitiveValue::U32(samples.to_vec().into()),
        ),
    ]);
    write(path, elements);
}
