//! Valid files that pydicom and nibabel read (issue 32, item 5; the whole corpus of their test
//! files is compared in crates/endocast-py/tests/test_peers_corpus.py): read, not refused —
//! Modality LUTs, frames without positions, sequences stored as UN, Siemens mosaics, padding
//! after the pixel data.

#![allow(clippy::unwrap_used)]

use crate::dicom_bytes::*;

#[test]
fn a_modality_lut_sequence_maps_the_stored_values() {
    let mut image = Image::ct(1, 4);
    image.0.remove(&(0x28, 0x1052));
    image.0.remove(&(0x28, 0x1053));
    // Three entries from stored value 1: 0 clamps to the first, 3 is the last (63 488).
    let mut lut = element((0x28, 0x3002), b"US", &words(&[3, 1, 16]));
    lut.extend(element(
        (0x28, 0x3006),
        b"OW",
        &words(&[100, 40_000, 63_488]),
    ));
    image
        .set((0x28, 0x3000), sequence((0x28, 0x3000), b"SQ", &lut))
        .set(
            (0x7FE0, 0x10),
            element((0x7FE0, 0x10), b"OW", &words(&[0, 1, 2, 3])),
        );
    let (_dir, path) = file_with("lut.dcm", &image.bytes(EXPLICIT_LE));
    let volume = read_dicom(&path).unwrap().volume;
    let values: Vec<_> = (0..4).map(|i| volume.physical(i, 0, 0).unwrap()).collect();
    assert_eq!(values, vec![100.0, 100.0, 40_000.0, 63_488.0]);
}

#[test]
fn frames_without_positions_are_stacked_at_their_spacing_with_a_warning() {
    let mut image = Image::ct(2, 2);
    image.0.remove(&(0x20, 0x32));
    image.0.remove(&(0x20, 0x37));
    let pixels: Vec<u16> = (0..12).collect();
    image
        .text((0x28, 8), b"IS", "3")
        .text((0x18, 0x88), b"DS", "2.5")
        .set(
            (0x7FE0, 0x10),
            element((0x7FE0, 0x10), b"OW", &words(&pixels)),
        );
    let (_dir, path) = file_with("frames.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    let volume = &loaded.volume;
    assert_eq!(volume.dims(), [2, 2, 3]);
    assert_eq!(volume.geometry().spacing_mm().z, 2.5);
    for k in 0..3 {
        assert_eq!(
            volume.physical(1, 1, k),
            Some(4.0 * k as f64 + 3.0 - 1024.0)
        );
    }
    assert!(
        has_warning(&loaded, "SpacingBetweenSlices"),
        "{:?}",
        loaded.warnings
    );
    assert!(has_warning(&loaded, "assumed"), "{:?}", loaded.warnings);
}

#[test]
fn a_sequence_stored_as_un_is_read_as_the_implicit_vr_sequence_it_is() {
    // (0018,9346) as UN of a defined length, holding one implicit-VR item (PS3.5 6.2.2). (One
    // of undefined length is walked too, but dicom-rs 0.10 then parses its items as explicit
    // VR and refuses the file.)
    let code = implicit((8, 0x100), b"113691");
    let mut image = Image::ct(2, 2);
    image.set((0x18, 0x9346), sequence((0x18, 0x9346), b"UN", &code));
    let (_dir, path) = file_with("un-sequence.dcm", &image.bytes(EXPLICIT_LE));
    read_dicom(&path).unwrap();
}

/// A Siemens mosaic of 4 rows × 6 columns (2 × 2 tiles of 2 rows × 3 columns), placed at
/// (10, 20, 30), 0.5 mm between rows and 2 mm between columns, 2.5 mm between slices.
fn mosaic() -> Image {
    let mut image = Image::ct(4, 6);
    image
        .text((8, 8), b"CS", "ORIGINAL\\PRIMARY\\M\\ND\\MOSAIC")
        .text((0x18, 0x88), b"DS", "2.5")
        .text((0x20, 0x32), b"DS", "10\\20\\30")
        .text((0x28, 0x30), b"DS", "0.5\\2");
    image
}

/// A CSA2 image header (0029,1010) of `(name, items)` fields, with its private creator.
fn csa_header(image: &mut Image, fields: &[(&str, &[&str])]) {
    let mut csa = b"SV10\x04\x03\x02\x01".to_vec();
    csa.extend((fields.len() as u32).to_le_bytes());
    csa.extend(77u32.to_le_bytes());
    for (name, items) in fields {
        let mut tag = name.as_bytes().to_vec();
        tag.resize(64, 0);
        csa.extend(tag);
        csa.extend([3, 0, 0, 0, b'F', b'D', 0, 0, 4, 0, 0, 0]);
        csa.extend((items.len() as u32).to_le_bytes());
        csa.extend(77u32.to_le_bytes());
        for item in *items {
            let length = item.len() as u32 + 1;
            for word in [length, length, 77, length] {
                csa.extend(word.to_le_bytes());
            }
            csa.extend(item.as_bytes());
            csa.resize(csa.len() + 1 + (4 - length as usize % 4) % 4, 0);
        }
    }
    image
        .text((0x29, 0x10), b"LO", "SIEMENS CSA HEADER")
        .set((0x29, 0x1010), element((0x29, 0x1010), b"OB", &csa));
}

/// The stored sample of row `row`, column `column` of `Image::ct`'s 6-column image, in HU.
fn mosaic_hu(row: usize, column: usize) -> f64 {
    f64::from((row * 6 + column) as u16 * 37 % 4000) - 1024.0
}

#[test]
fn a_siemens_mosaic_is_unpacked_into_its_slices_and_placed_as_dcm2niix_does() {
    let mut image = mosaic();
    image
        .text((0x19, 0x10), b"LO", "SIEMENS MR HEADER")
        .short((0x19, 0x100A), 3);
    let (_dir, path) = file_with("mosaic.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    let volume = &loaded.volume;
    assert_eq!(volume.dims(), [3, 2, 3]);
    // Tiles row by row from the top left: slice k's pixel (i, j) is the image's pixel at row
    // 2 (k / 2) + j, column 3 (k % 2) + i.
    for k in 0..3 {
        for j in 0..2 {
            for i in 0..3 {
                let expected = mosaic_hu(2 * (k / 2) + j, 3 * (k % 2) + i);
                assert_eq!(volume.physical(i, j, k), Some(expected), "({i}, {j}, {k})");
            }
        }
    }
    let geometry = volume.geometry();
    // Moved by half of (6 − 3) columns × 2 mm along x and (4 − 2) rows × 0.5 mm along y.
    assert!(geometry
        .origin_mm()
        .abs_diff_eq(glam::DVec3::new(13.0, 20.5, 30.0), 1e-9));
    assert!(geometry
        .spacing_mm()
        .abs_diff_eq(glam::DVec3::new(2.0, 0.5, 2.5), 1e-9));
    assert!(geometry
        .direction()
        .z_axis
        .abs_diff_eq(glam::DVec3::Z, 1e-9));
    assert!(
        has_warning(&loaded, "unpacked into 3 slices of 2 rows × 3 columns")
            && has_warning(&loaded, "(0019,100A)")
            && has_warning(&loaded, "row × column cosine"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_mosaic_takes_its_count_and_normal_from_the_csa_header() {
    let mut image = mosaic();
    csa_header(
        &mut image,
        &[
            ("SliceNormalVector", &["0", "0", "-1"]),
            ("NumberOfImagesInMosaic", &["4"]),
        ],
    );
    let (_dir, path) = file_with("mosaic.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    let volume = &loaded.volume;
    assert_eq!(volume.dims(), [3, 2, 4]);
    // The slices run towards −z: the stack, ordered along +z, starts with the last tile.
    assert_eq!(volume.physical(0, 0, 0), Some(mosaic_hu(2, 3)));
    assert_eq!(volume.physical(0, 0, 3), Some(mosaic_hu(0, 0)));
    let origin = volume.geometry().origin_mm();
    assert!(
        origin.abs_diff_eq(glam::DVec3::new(13.0, 20.5, 22.5), 1e-9),
        "{origin}"
    );
    assert!(
        has_warning(&loaded, "the CSA image header (0029,1010)")
            && has_warning(&loaded, "SliceNormalVector"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_mosaic_without_a_count_or_whose_count_does_not_tile_it_is_refused() {
    let (_dir, path) = file_with("mosaic.dcm", &mosaic().bytes(EXPLICIT_LE));
    refused(
        read_dicom(&path),
        &path,
        &["NumberOfImagesInMosaic", "(0029,1010)"],
    );
    let mut image = mosaic();
    image
        .text((0x19, 0x10), b"LO", "SIEMENS MR HEADER")
        .short((0x19, 0x100A), 9);
    let (_dir, path) = file_with("mosaic.dcm", &image.bytes(EXPLICIT_LE));
    refused(
        read_dicom(&path),
        &path,
        &["NumberOfImagesInMosaic", "4 rows × 6 columns"],
    );
}

#[test]
fn zero_padding_after_the_pixel_data_is_ignored_with_a_warning() {
    let mut image = Image::ct(2, 2);
    image.set(
        (0x7FE0, 0x10),
        element((0x7FE0, 0x10), b"OW", &words(&[1, 2, 3, 4, 0, 0, 0, 0])),
    );
    let (_dir, path) = file_with("padded.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    assert_eq!(loaded.volume.physical(1, 1, 0), Some(4.0 - 1024.0));
    assert!(
        has_warning(&loaded, "8 bytes of zeros"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn an_implicit_vr_data_set_under_an_explicit_vr_meta_group_is_read_with_a_warning() {
    let image = Image::ct(2, 2);
    // Every element re-encoded without its VR: tag, 4-byte length, value.
    let mut bytes = meta(EXPLICIT_LE);
    for encoded in image.0.values() {
        let vr: [u8; 2] = [encoded[4], encoded[5]];
        let value_at = if is_long(&vr) { 12 } else { 8 };
        bytes.extend(implicit(
            (
                u16::from_le_bytes([encoded[0], encoded[1]]),
                u16::from_le_bytes([encoded[2], encoded[3]]),
            ),
            &encoded[value_at..],
        ));
    }
    let (_dir, path) = file_with("implicit-body.dcm", &bytes);
    let loaded = read_dicom(&path).unwrap();
    let (_dir, explicit) = file_with("explicit.dcm", &image.bytes(EXPLICIT_LE));
    assert_eq!(
        loaded.volume.voxels(),
        read_dicom(&explicit).unwrap().volume.voxels()
    );
    assert!(has_warning(&loaded, "implicit VR"), "{:?}", loaded.warnings);
}
