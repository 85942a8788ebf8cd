//! DICOM series and files: transfer syntaxes, ordering, geometry (gantry tilt, uneven gaps),
//! values (rescale, padding), series choice, junk and broken input.

#![allow(clippy::unwrap_used)] // helpers of tests: a failed unwrap is a failed test

use dicom_dictionary_std::tags;
use dicom_object::OpenFileOptions;
use endocast_core::Modality;
use endocast_io::{dicom, Format, OpenOptions, Progress, ReadError, ReadProgress, ReadStep};
use endocast_testdata::shared_data;
use glam::DVec3;
use std::path::{Path, PathBuf};

fn read(path: &Path) -> endocast_io::Loaded {
    dicom::read(path, &OpenOptions::default()).unwrap()
}

fn has_warning(loaded: &endocast_io::Loaded, words: &str) -> bool {
    loaded.warnings.iter().any(|w| w.contains(words))
}

/// ImagePositionPatient, ImageOrientationPatient (row, column) and PixelSpacing of one file.
fn placement(path: &Path) -> (DVec3, [DVec3; 2], [f64; 2]) {
    let object = OpenFileOptions::new()
        .read_until(tags::PIXEL_DATA)
        .open_file(path)
        .unwrap();
    let floats = |tag| object.element(tag).unwrap().to_multi_float64().unwrap();
    let p = floats(tags::IMAGE_POSITION_PATIENT);
    let o = floats(tags::IMAGE_ORIENTATION_PATIENT);
    let s = floats(tags::PIXEL_SPACING);
    (
        DVec3::new(p[0], p[1], p[2]),
        [DVec3::new(o[0], o[1], o[2]), DVec3::new(o[3], o[4], o[5])],
        [s[0], s[1]],
    )
}

#[test]
fn all_nine_transfer_syntaxes_decode_to_identical_pixels() {
    let Some(dir) = shared_data("dicom-transfer-syntaxes") else {
        return;
    };
    let reference = read(&dir.join("1.dcm"));
    // Siemens mosaics: 35 slices of 64 × 64 tiled 6 × 6 in a 384 × 384 image.
    assert_eq!(reference.volume.dims(), [64, 64, 35]);
    assert_eq!(reference.volume.physical_range(), (0.0, 2362.0));
    // The geometry nibabel 5.3.2's MosaicWrapper gives (its affine, axes i and j swapped).
    let geometry = reference.volume.geometry();
    let near = |a: DVec3, b: DVec3| a.abs_diff_eq(b, 1e-4);
    assert!(near(
        geometry.origin_mm(),
        DVec3::new(-104.0, -144.868_087_29, -62.685_166_13)
    ));
    assert!(near(geometry.spacing_mm(), DVec3::new(3.25, 3.25, 3.6)));
    assert!(near(
        geometry.direction().z_axis,
        DVec3::new(0.0, 0.107_999_35, 0.994_150_96)
    ));
    assert_eq!(
        reference.source.stored_type,
        "uint16, 12 bits stored, Explicit VR Little Endian"
    );
    for n in 2..=9 {
        let loaded = read(&dir.join(format!("{n}.dcm")));
        assert_eq!(loaded.source.format, Format::Dicom);
        assert_eq!(
            loaded.volume.value_map(),
            reference.volume.value_map(),
            "{n}.dcm"
        );
        assert!(
            loaded.volume.voxels() == reference.volume.voxels(),
            "{n}.dcm ({}) decodes to different pixels",
            loaded.source.stored_type
        );
    }
    let implicit = read(&dir.join("2.dcm"));
    assert!(implicit
        .source
        .stored_type
        .ends_with("Implicit VR Little Endian"));
}

/// FNV-1a over the voxels' little-endian bytes.
fn voxel_checksum(voxels: &[u16]) -> u64 {
    voxels
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .fold(0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        })
}

/// The JPEG-LS files decode to the pixels CharLS gave before the switch to a pure-Rust decoder
/// (recorded with CharLS 2.4.5 through dicom-rs 0.10), which are also the pixels of the
/// uncompressed file. The checksum is of the unpacked mosaic: the 35 tiles of pydicom 3.0.1's
/// pixel array of 1.dcm, slice by slice, row by row (the tiled image's was
/// 0x3f7b_7f11_0b8d_2dd2).
#[test]
fn jpeg_ls_files_decode_to_the_pixels_charls_gave() {
    const CHARLS_CHECKSUM: u64 = 0x79ea_28bd_e534_5efa;
    let Some(dir) = shared_data("dicom-transfer-syntaxes") else {
        return;
    };
    let reference = read(&dir.join("1.dcm"));
    for name in ["7.dcm", "8.dcm"] {
        let loaded = read(&dir.join(name));
        assert!(loaded.source.stored_type.contains("JPEG-LS"), "{name}");
        let sum = voxel_checksum(loaded.volume.voxels());
        assert_eq!(sum, CHARLS_CHECKSUM, "{name}");
        assert!(
            loaded.volume.voxels() == reference.volume.voxels(),
            "{name}"
        );
    }
}

#[test]
fn abdomen_series_is_ordered_by_position_with_hounsfield_units() {
    let Some(dir) = shared_data("abdomen-ct-pancreas-dicom") else {
        return;
    };
    let loaded = read(&dir);
    let volume = &loaded.volume;
    let g = volume.geometry();
    assert_eq!(volume.dims(), [512, 512, 134]);
    assert!(
        (g.spacing_mm() - DVec3::new(1.0742, 1.0742, 3.0))
            .abs()
            .max_element()
            < 1e-3
    );
    assert_eq!(volume.physical_range(), (-1000.0, 1988.0));
    assert_eq!(*volume.modality(), Modality::Ct);
    assert_eq!(
        loaded.source.stored_type,
        "uint16, 12 bits stored, Implicit VR Little Endian"
    );
    // Stacked along +z (the slice normal): k = 0 is the most inferior file, 1-134.dcm.
    let z = |k: usize| g.world_of(DVec3::new(0.0, 0.0, k as f64)).z;
    assert!((z(0) - 85.91).abs() < 1e-3 && (z(133) - 484.91).abs() < 1e-3);
    let (first_file_position, _, _) = placement(&dir.join("1-001.dcm"));
    assert!((g.world_of(DVec3::new(0.0, 0.0, 133.0)) - first_file_position).length() < 1e-3);
    // README slice index 67 (file 1-068.dcm, z = 283.91) is k = 133 − 67 = 66.
    assert!((z(66) - 283.91).abs() < 1e-3);
    let mut sum = 0.0;
    for j in 253..=257 {
        for i in 277..=281 {
            sum += volume.physical(i, j, 66).unwrap();
        }
    }
    let aorta_hu = sum / 25.0;
    assert!((aorta_hu - 188.0).abs() < 20.0, "aorta ROI {aorta_hu} HU");
    assert_eq!(loaded.source.series_found.len(), 1);
    assert_eq!(loaded.source.series_found[0].images, 134);
    assert_eq!(
        loaded.source.series_uid.as_deref(),
        Some(loaded.source.series_found[0].uid.as_str())
    );
}

#[test]
fn chest_series_has_its_own_intercept() {
    let Some(dir) = shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let loaded = read(&dir);
    let volume = &loaded.volume;
    let g = volume.geometry();
    assert_eq!(volume.dims(), [512, 512, 72]);
    assert!(
        (g.spacing_mm() - DVec3::new(0.9766, 0.9766, 2.0))
            .abs()
            .max_element()
            < 1e-3
    );
    assert_eq!(volume.value_map().offset(), -1024.0);
    assert_eq!(volume.physical_range().0, -1024.0);
    let z = |k: usize| g.world_of(DVec3::new(0.0, 0.0, k as f64)).z;
    assert!((z(0) - -66.5).abs() < 1e-3 && (z(71) - 75.5).abs() < 1e-3);
    assert!(!has_warning(&loaded, "uneven"));
}

#[test]
fn gantry_tilt_keeps_the_shear_and_places_every_corner() {
    let Some(root) = shared_data("head-ct-ge-gantry-tilt") else {
        return;
    };
    let dir = root.join("GE");
    let loaded = read(&dir);
    let volume = &loaded.volume;
    let g = volume.geometry();
    assert!(
        has_warning(&loaded, "gantry tilt of 18.5°"),
        "{:?}",
        loaded.warnings
    );
    assert!(has_warning(&loaded, "uneven gaps"), "{:?}", loaded.warnings);
    assert!(
        has_warning(&loaded, "padding voxels"),
        "{:?}",
        loaded.warnings
    );
    assert!(!g.is_orthogonal());

    // The first and last slices by position along the normal stay exactly in place.
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let placements: Vec<_> = files.iter().map(|f| placement(f)).collect();
    let [row, column] = placements[0].1;
    let normal = row.cross(column);
    let along = |p: &(DVec3, [DVec3; 2], [f64; 2])| p.0.dot(normal);
    let first = placements
        .iter()
        .min_by(|a, b| along(a).total_cmp(&along(b)))
        .unwrap();
    let last = placements
        .iter()
        .max_by(|a, b| along(a).total_cmp(&along(b)))
        .unwrap();
    let [nx, ny, nz] = volume.dims();
    for (placement, k) in [(first, 0), (last, nz - 1)] {
        let (position, _, [between_rows, between_columns]) = *placement;
        for (i, j) in [(0, 0), (nx - 1, 0), (0, ny - 1), (nx - 1, ny - 1)] {
            let expected =
                position + row * (i as f64 * between_columns) + column * (j as f64 * between_rows);
            let actual = g.world_of(DVec3::new(i as f64, j as f64, k as f64));
            assert!(
                (actual - expected).length() < 0.01,
                "corner ({i},{j},{k}): {actual} vs {expected}"
            );
        }
    }

    // Values: −1500 padding replaced by the lowest real value; the brightest bone as stored.
    let (lo, hi) = volume.physical_range();
    assert!((-1024.0..-900.0).contains(&lo), "lowest {lo}");
    assert!((2000.0..=2121.0).contains(&hi), "highest {hi}");
    assert_eq!(*volume.modality(), Modality::Ct);
    assert!(loaded
        .source
        .stored_type
        .starts_with("int16, 16 bits stored"));
}

/// A temporary series folder: 5 abdomen slices, 3 chest slices in a subfolder, and junk.
fn mixed_folder() -> Option<tempfile::TempDir> {
    let abdomen = shared_data("abdomen-ct-pancreas-dicom")?;
    let chest = shared_data("chest-ct-airways-dicom")?;
    let dir = tempfile::tempdir().unwrap();
    for n in 1..=5 {
        let name = format!("1-{n:03}.dcm");
        std::fs::copy(abdomen.join(&name), dir.path().join(name)).unwrap();
    }
    std::fs::create_dir(dir.path().join("chest")).unwrap();
    for n in 20..23 {
        let name = format!("00-slice{n:03}.dcm");
        std::fs::copy(chest.join(&name), dir.path().join("chest").join(name)).unwrap();
    }
    std::fs::write(dir.path().join("notes.txt"), "not a scan").unwrap();
    Some(dir)
}

#[test]
fn mixed_folder_picks_the_largest_series_and_honours_a_choice() {
    let Some(dir) = mixed_folder() else {
        return;
    };
    let loaded = read(dir.path());
    assert_eq!(loaded.volume.dims(), [512, 512, 5]);
    let found = &loaded.source.series_found;
    assert_eq!(
        found.iter().map(|s| s.images).collect::<Vec<_>>(),
        vec![5, 3]
    );
    assert_eq!(
        loaded.source.series_uid.as_deref(),
        Some(found[0].uid.as_str())
    );
    assert!(
        has_warning(&loaded, "skipped 1 file"),
        "{:?}",
        loaded.warnings
    );
    assert!(has_warning(&loaded, "notes.txt"));

    let mut options = OpenOptions::default();
    options.series = Some(found[1].uid.clone());
    let chest = dicom::read(dir.path(), &options).unwrap();
    assert_eq!(chest.volume.dims(), [512, 512, 3]);
    assert_eq!(chest.volume.value_map().offset(), -1024.0);
    assert_eq!(chest.source.series_uid, options.series);

    let mut unknown = OpenOptions::default();
    unknown.series = Some("1.2.3.4".into());
    let error = dicom::read(dir.path(), &unknown).unwrap_err().to_string();
    assert!(
        error.contains("1.2.3.4") && error.contains(&found[0].uid) && error.contains(&found[1].uid)
    );
}

#[test]
fn empty_folder_and_junk_only_folder_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        dicom::read(dir.path(), &OpenOptions::default()),
        Err(ReadError::Format { .. })
    ));
    std::fs::write(dir.path().join("a.txt"), "hello").unwrap();
    let error = dicom::read(dir.path(), &OpenOptions::default()).unwrap_err();
    assert!(error.to_string().contains("not DICOM"), "{error}");
}

#[test]
fn truncated_files_are_errors() {
    let Some(abdomen) = shared_data("abdomen-ct-pancreas-dicom") else {
        return;
    };
    let bytes = std::fs::read(abdomen.join("1-001.dcm")).unwrap();
    let dir = tempfile::tempdir().unwrap();
    for keep in [100, 140, 600, bytes.len() / 2, bytes.len() - 1] {
        let path = dir.path().join(format!("cut-{keep}.dcm"));
        std::fs::write(&path, &bytes[..keep]).unwrap();
        let result = dicom::read(&path, &OpenOptions::default());
        assert!(result.is_err(), "a file cut at {keep} bytes was read");
    }
    // In a folder, a file whose pixels are cut is an error too (its header looked fine).
    let folder = tempfile::tempdir().unwrap();
    std::fs::write(folder.path().join("cut.dcm"), &bytes[..bytes.len() / 2]).unwrap();
    assert!(dicom::read(folder.path(), &OpenOptions::default()).is_err());
}

#[test]
fn an_unknown_transfer_syntax_is_unsupported_and_named() {
    let Some(dir) = shared_data("dicom-transfer-syntaxes") else {
        return;
    };
    let mut bytes = std::fs::read(dir.join("1.dcm")).unwrap();
    // (0002,0010) UI, length 20: "1.2.840.10008.1.2.1\0" becomes an unknown UID of the same size.
    let header = [0x02, 0x00, 0x10, 0x00, b'U', b'I', 20, 0];
    let at = bytes.windows(8).position(|w| w == header).unwrap() + 8;
    bytes[at..at + 20].copy_from_slice(b"1.2.3.4.5.6.7.8.9.10");
    let temp = tempfile::tempdir().unwrap();
    let path = temp.path().join("unknown-ts.dcm");
    std::fs::write(&path, bytes).unwrap();
    match dicom::read(&path, &OpenOptions::default()) {
        Err(ReadError::Unsupported { what, .. }) => {
            assert!(what.contains("1.2.3.4.5.6.7.8.9.10"), "{what}")
        }
        other => panic!("expected Unsupported, got {other:?}"),
    }
}

/// An enhanced (multi-frame) CT of 3 frames of 3×2 pixels, stored from the top down, with
/// per-frame positions and rescale intercepts and shared pixel measures and orientation.
fn write_enhanced_ct(path: &Path) {
    use dicom_core::value::DataSetSequence;
    use dicom_core::{DataElement, PrimitiveValue, VR};
    use dicom_dictionary_std::uids;
    use dicom_object::{FileMetaTableBuilder, InMemDicomObject};

    type Element = DataElement<InMemDicomObject>;
    let text = |tag, vr, value: &str| Element::new(tag, vr, PrimitiveValue::from(value));
    let short = |tag, value: u16| Element::new(tag, VR::US, PrimitiveValue::from(value));
    let sequence = |tag, item: Vec<Element>| {
        let items = vec![InMemDicomObject::from_element_iter(item)];
        Element::new(tag, VR::SQ, DataSetSequence::from(items))
    };
    let intercepts = ["-1000", "-1000", "-1024"];
    let per_frame: Vec<InMemDicomObject> = (0..3)
        .map(|f| {
            let z = format!("0\\0\\{}", 10 * (2 - f));
            InMemDicomObject::from_element_iter([
                sequence(
                    tags::PLANE_POSITION_SEQUENCE,
                    vec![text(tags::IMAGE_POSITION_PATIENT, VR::DS, &z)],
                ),
                sequence(
                    tags::PIXEL_VALUE_TRANSFORMATION_SEQUENCE,
                    vec![
                        text(tags::RESCALE_INTERCEPT, VR::DS, intercepts[f]),
                        text(tags::RESCALE_SLOPE, VR::DS, "1"),
                    ],
                ),
            ])
        })
        .collect();
    let shared = InMemDicomObject::from_element_iter([
        sequence(
            tags::PIXEL_MEASURES_SEQUENCE,
            vec![text(tags::PIXEL_SPACING, VR::DS, "0.5\\0.25")],
        ),
        sequence(
            tags::PLANE_ORIENTATION_SEQUENCE,
            vec![text(
                tags::IMAGE_ORIENTATION_PATIENT,
                VR::DS,
                "1\\0\\0\\0\\1\\0",
            )],
        ),
    ]);
    // Frame f holds 10·f + pixel index.
    let words: Vec<u16> = (0..3)
        .flat_map(|f| (0..6).map(move |p| 10 * f + p))
        .collect();
    let object = InMemDicomObject::from_element_iter([
        text(tags::SOP_CLASS_UID, VR::UI, uids::ENHANCED_CT_IMAGE_STORAGE),
        text(
            tags::SOP_INSTANCE_UID,
            VR::UI,
            "1.2.826.0.1.3680043.2.1125.9.1",
        ),
        text(tags::MODALITY, VR::CS, "CT"),
        text(
            tags::SERIES_INSTANCE_UID,
            VR::UI,
            "1.2.826.0.1.3680043.2.1125.9.2",
        ),
        short(tags::SAMPLES_PER_PIXEL, 1),
        text(tags::PHOTOMETRIC_INTERPRETATION, VR::CS, "MONOCHROME2"),
        text(tags::NUMBER_OF_FRAMES, VR::IS, "3"),
        short(tags::ROWS, 2),
        short(tags::COLUMNS, 3),
        short(tags::BITS_ALLOCATED, 16),
        short(tags::BITS_STORED, 12),
        short(tags::HIGH_BIT, 11),
        short(tags::PIXEL_REPRESENTATION, 0),
        Element::new(
            tags::SHARED_FUNCTIONAL_GROUPS_SEQUENCE,
            VR::SQ,
            DataSetSequence::from(vec![shared]),
        ),
        Element::new(
            tags::PER_FRAME_FUNCTIONAL_GROUPS_SEQUENCE,
            VR::SQ,
            DataSetSequence::from(per_frame),
        ),
        Element::new(tags::PIXEL_DATA, VR::OW, PrimitiveValue::U16(words.into())),
    ]);
    object
        .with_meta(FileMetaTableBuilder::new().transfer_syntax(uids::EXPLICIT_VR_LITTLE_ENDIAN))
        .unwrap()
        .write_to_file(path)
        .unwrap();
}

#[test]
fn enhanced_multi_frame_file_stacks_its_frames_by_position() {
    let temp = tempfile::tempdir().unwrap();
    let path = temp.path().join("enhanced.dcm");
    write_enhanced_ct(&path);
    let loaded = read(&path);
    let volume = &loaded.volume;
    let g = volume.geometry();
    assert_eq!(volume.dims(), [3, 2, 3]);
    assert!(
        (g.spacing_mm() - DVec3::new(0.25, 0.5, 10.0))
            .abs()
            .max_element()
            < 1e-9
    );
    assert!((g.origin_mm() - DVec3::ZERO).length() < 1e-9);
    assert!((g.world_of(DVec3::new(2.0, 1.0, 2.0)) - DVec3::new(0.5, 0.5, 20.0)).length() < 1e-9);
    // k = 0 is the lowest frame (frame 2, intercept −1024); k = 2 the top one (frame 0).
    for (i, j) in [(0, 0), (2, 1)] {
        let p = (i + 3 * j) as f64;
        assert_eq!(volume.physical(i, j, 0), Some(20.0 + p - 1024.0));
        assert_eq!(volume.physical(i, j, 1), Some(10.0 + p - 1000.0));
        assert_eq!(volume.physical(i, j, 2), Some(p - 1000.0));
    }
    assert!(
        has_warning(&loaded, "differ between slices"),
        "{:?}",
        loaded.warnings
    );
    assert_eq!(loaded.source.series_found[0].images, 3);
}

#[test]
fn a_folder_read_counts_its_files_for_a_progress_bar() {
    let Some(chest) = shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    for n in 20..26 {
        let name = format!("00-slice{n:03}.dcm");
        std::fs::copy(chest.join(&name), dir.path().join(&name)).unwrap();
    }
    std::fs::write(dir.path().join("notes.txt"), "not DICOM").unwrap();
    let progress = Progress::default();
    let mut options = OpenOptions::default();
    options.progress = progress.clone();
    assert_eq!(progress.get(), None);
    // A thread looks at the counts while the folder is read, as the viewer's window does.
    let watcher = {
        let progress = progress.clone();
        std::thread::spawn(move || {
            let mut seen = Vec::new();
            let start = std::time::Instant::now();
            while start.elapsed().as_secs() < 60
                && seen
                    .last()
                    .is_none_or(|p: &ReadProgress| p.step != ReadStep::Pixels || p.done < p.total)
            {
                if let Some(p) = progress.get().filter(|p| seen.last() != Some(p)) {
                    assert!(p.done <= p.total, "{p:?}");
                    seen.push(p);
                }
                std::thread::yield_now();
            }
            seen
        })
    };
    let loaded = dicom::read(dir.path(), &options).unwrap();
    assert_eq!(loaded.volume.dims()[2], 6);
    let seen = watcher.join().unwrap();
    let done = ReadProgress {
        step: ReadStep::Pixels,
        done: 6,
        total: 6,
    };
    assert_eq!(seen.last(), Some(&done));
    assert!(seen
        .iter()
        .all(|p| p.step == ReadStep::Pixels || p.total == 7));
}
