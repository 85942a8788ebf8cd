//! NRRD: the real scans in ../shared/data (skipped when absent), generated files for every
//! header form, round trips through the writer, and bad files that must fail cleanly.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use endocast_core::{Geometry, Modality, ValueMap, Volume};
use endocast_io::{nrrd, Limits, Loaded, OpenOptions, ReadError};
use endocast_testdata::shared_data;
use glam::{DMat3, DVec3};
use std::path::{Path, PathBuf};

fn read(path: &Path) -> Loaded {
    nrrd::read(path, &OpenOptions::default())
        .unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

fn assert_close(a: DVec3, b: DVec3, tolerance: f64) {
    assert!((a - b).abs().max_element() <= tolerance, "{a} vs {b}");
}

/// Big-endian int16 samples of one raw slice file.
fn be_i16_file(path: &Path) -> Vec<i16> {
    std::fs::read(path)
        .unwrap()
        .chunks_exact(2)
        .map(|b| i16::from_be_bytes([b[0], b[1]]))
        .collect()
}

fn slice_physical(loaded: &Loaded, k: usize) -> Vec<f64> {
    let [nx, ny, _] = loaded.volume.dims();
    (0..ny)
        .flat_map(|j| (0..nx).map(move |i| (i, j)))
        .map(|(i, j)| loaded.volume.physical(i, j, k).unwrap())
        .collect()
}

#[test]
fn stanford_cthead_slices_follow_the_pattern() {
    let Some(dir) = shared_data("head-ct-stanford-cthead") else {
        return;
    };
    let loaded = read(&dir.join("CThead.nhdr"));
    let volume = &loaded.volume;
    assert_eq!(volume.dims(), [256, 256, 113]);
    assert_close(
        volume.geometry().spacing_mm(),
        DVec3::new(1.0, 1.0, 2.0),
        1e-12,
    );
    assert_eq!(volume.physical_range(), (0.0, 3272.0));
    assert_eq!(
        loaded.source.stored_type,
        "int16 big-endian, raw, 113 data files"
    );
    // Slice files land at k = file number − 1, byte-swapped correctly.
    for (k, file) in [(0, "CThead.1"), (56, "CThead.57"), (112, "CThead.113")] {
        let expected: Vec<f64> = be_i16_file(&dir.join(file))
            .into_iter()
            .map(f64::from)
            .collect();
        assert_eq!(slice_physical(&loaded, k), expected, "{file}");
    }
    // The header declares no space, only `spacings`, so the grid is read axis-aligned with k
    // running towards +z: CThead.1 (the top of the head, says the README) gets the SMALLEST
    // world z, i.e. it ends up inferior. The header, not the reader, lacks the orientation;
    // `cthead_with_an_assumed_orientation_puts_the_vertex_on_top` shows the option that fixes it.
    let g = volume.geometry();
    let z_first = g.world_of(DVec3::new(128.0, 128.0, 0.0)).z;
    let z_last = g.world_of(DVec3::new(128.0, 128.0, 112.0)).z;
    assert!(z_first < z_last);
}

#[test]
fn cthead_with_an_assumed_orientation_puts_the_vertex_on_top() {
    let Some(dir) = shared_data("head-ct-stanford-cthead") else {
        return;
    };
    let path = dir.join("CThead.nhdr");
    assert!(read(&path)
        .warnings
        .iter()
        .any(|w| w.contains("declares no patient orientation")));
    let mut options = OpenOptions::default();
    options.orientation = Some("LPI".into());
    let loaded = endocast_io::open(&path, &options).unwrap();
    let volume = &loaded.volume;
    // The README's landmark, seen in the voxels: CThead.1 (k = 0) is the vertex, a small cap of
    // skull and scalp, while a slice through the middle of the head is full of tissue.
    let tissue = |k: usize| {
        let [nx, ny, _] = volume.dims();
        (0..ny)
            .flat_map(|j| (0..nx).map(move |i| (i, j)))
            .filter(|&(i, j)| volume.physical(i, j, k).unwrap() > 550.0)
            .count()
    };
    assert!(
        tissue(0) * 4 < tissue(56),
        "{} vs {}",
        tissue(0),
        tissue(56)
    );
    // With the orientation given, that slice is the most superior one in LPS.
    let g = volume.geometry();
    assert_eq!(g.orientation_code(), "LPI");
    let z_of_k = |k: f64| g.world_of(DVec3::new(128.0, 128.0, k)).z;
    assert!(z_of_k(0.0) > z_of_k(112.0));
    // A file that declares its orientation refuses an assumed one.
    if let Some(flair) = shared_data("brain-mri-flair-nrrd") {
        assert!(endocast_io::open(&flair.join("FLAIR.nrrd"), &options).is_err());
    }
}

#[test]
fn vtk_headsq_with_and_without_the_forbidden_space_line() {
    let Some(dir) = shared_data("classic-vtk-headsq") else {
        return;
    };
    let original = read(&dir.join("quarter.nhdr"));
    let clean = read(&dir.join("quarter_nospace.nhdr"));
    for loaded in [&original, &clean] {
        assert_eq!(loaded.volume.dims(), [64, 64, 93]);
        assert_close(
            loaded.volume.geometry().spacing_mm(),
            DVec3::new(3.2, 3.2, 1.5),
            1e-12,
        );
        assert_eq!(loaded.volume.physical_range(), (0.0, 3926.0));
        assert_eq!(loaded.volume.geometry().direction(), DMat3::IDENTITY);
    }
    assert_eq!(original.volume.voxels(), clean.volume.voxels());
    assert_eq!(original.volume.value_map(), clean.volume.value_map());
    assert_eq!(original.warnings.len(), 1, "{:?}", original.warnings);
    assert!(original.warnings[0].contains("spacings"));
    assert_eq!(clean.warnings.len(), 1, "{:?}", clean.warnings);
    assert!(clean.warnings[0].contains("no patient orientation"));
    // Little-endian slice files: voxel (32, 32) of quarter.1.
    let bytes = std::fs::read(dir.join("quarter.1")).unwrap();
    let at = 2 * (32 * 64 + 32);
    let expected = i16::from_le_bytes([bytes[at], bytes[at + 1]]);
    assert_eq!(clean.volume.physical(32, 32, 0), Some(f64::from(expected)));
}

#[test]
fn flair_is_oblique_gzip_uint8() {
    let Some(dir) = shared_data("brain-mri-flair-nrrd") else {
        return;
    };
    let loaded = read(&dir.join("FLAIR.nrrd"));
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let volume = &loaded.volume;
    let g = volume.geometry();
    assert_eq!(volume.dims(), [124, 160, 140]);
    assert_close(g.spacing_mm(), DVec3::ONE, 1e-4);
    assert_eq!(volume.physical_range(), (0.0, 255.0));
    assert_eq!(loaded.source.stored_type, "uint8, gzip");
    // Orthonormal ...
    let d = g.direction();
    assert!(g.is_orthogonal());
    assert!((d.determinant().abs() - 1.0).abs() < 1e-4);
    // ... but about 18° off the nearest axis for the slice axis (LPS, taken as written).
    for column in [d.x_axis, d.y_axis, d.z_axis] {
        assert!(column.abs().max_element() < 0.999, "{column}");
    }
    let tilt_deg = d.z_axis.z.abs().acos().to_degrees();
    assert!((15.0..25.0).contains(&tilt_deg), "{tilt_deg}");
    assert_close(
        d.x_axis,
        DVec3::new(-0.993_592_009, 0.049_704_927, -0.101_510_292),
        1e-4,
    );
    assert_close(
        g.origin_mm(),
        DVec3::new(
            64.898_239_135_742_2,
            110.431_144_714_355_5,
            -27.925_539_016_723_64,
        ),
        1e-9,
    );
}

#[test]
fn stent_is_gzip_int16() {
    let Some(dir) = shared_data("aorta-stent-cta") else {
        return;
    };
    let loaded = read(&dir.join("stent.nrrd"));
    assert_eq!(loaded.volume.dims(), [128, 128, 256]);
    assert_eq!(loaded.volume.physical_range(), (0.0, 2000.0));
    assert_close(loaded.volume.geometry().spacing_mm(), DVec3::ONE, 1e-12);
    assert_eq!(loaded.source.stored_type, "int16 little-endian, gzip");
    // `space dimension: 3` without a `space`: a frame with no anatomical meaning.
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
}

fn oblique_geometry(dims: [usize; 3]) -> Geometry {
    let direction = DMat3::from_rotation_z(0.4) * DMat3::from_rotation_x(-0.25);
    Geometry::new(
        dims,
        DVec3::new(0.7, 0.85, 1.25),
        DVec3::new(-120.5, 33.25, 1e-3),
        direction,
    )
    .unwrap()
}

fn assert_same_geometry(a: &Geometry, b: &Geometry) {
    assert_eq!(a.dims(), b.dims());
    assert_close(a.spacing_mm(), b.spacing_mm(), 1e-5);
    assert_close(a.origin_mm(), b.origin_mm(), 1e-5);
    for (x, y) in a
        .direction()
        .to_cols_array()
        .iter()
        .zip(b.direction().to_cols_array())
    {
        assert!(
            (x - y).abs() < 1e-5,
            "{:?} vs {:?}",
            a.direction(),
            b.direction()
        );
    }
}

#[test]
fn hounsfield_volume_round_trips_as_short() {
    let dims = [7, 5, 4];
    let voxels: Vec<u16> = (0..140u16).map(|n| n * 29 % 4096).collect();
    let hu = ValueMap::new(1.0, -1024.0).unwrap();
    let volume = Volume::new(oblique_geometry(dims), voxels, hu, Modality::Ct).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("hu.nrrd");
    nrrd::write(&path, &volume).unwrap();
    let back = read(&path);
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    assert_eq!(back.source.stored_type, "int16 little-endian, gzip");
    assert_same_geometry(volume.geometry(), back.volume.geometry());
    for (a, b) in volume.voxels().iter().zip(back.volume.voxels()) {
        assert_eq!(hu.physical(*a), back.volume.value_map().physical(*b));
    }
    // Through the dispatching entry points too.
    let again = tmp.path().join("again.nrrd");
    endocast_io::write(&again, &back.volume).unwrap();
    let reread = endocast_io::open(&again, &OpenOptions::default()).unwrap();
    assert_eq!(reread.volume.voxels(), back.volume.voxels());
}

#[test]
fn fractional_value_map_round_trips_as_float() {
    let dims = [6, 4, 3];
    let voxels: Vec<u16> = (0..72u16).map(|n| n.wrapping_mul(977)).collect();
    let map = ValueMap::new(0.037, -12.5).unwrap();
    let volume = Volume::new(oblique_geometry(dims), voxels, map, Modality::Mr).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join("float.nrrd");
    nrrd::write(&path, &volume).unwrap();
    let back = read(&path);
    assert!(back.source.stored_type.starts_with("float32"));
    assert_same_geometry(volume.geometry(), back.volume.geometry());
    let back_map = back.volume.value_map();
    for (a, b) in volume.voxels().iter().zip(back.volume.voxels()) {
        let (want, got) = (map.physical(*a), back_map.physical(*b));
        // f32 rounding, then the reader's 16-bit quantisation of the float range.
        let tolerance = want.abs() * f64::from(f32::EPSILON) + back_map.scale() / 2.0 + 1e-9;
        assert!((want - got).abs() <= tolerance, "{want} vs {got}");
    }
}

/// Writes `header` followed by `data` as `name` in `dir`.
fn write_file(dir: &Path, name: &str, header: &str, data: &[u8]) -> PathBuf {
    let path = dir.join(name);
    let mut bytes = header.as_bytes().to_vec();
    bytes.extend_from_slice(data);
    std::fs::write(&path, bytes).unwrap();
    path
}

fn options_with_max_voxels(max: u64) -> OpenOptions {
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(max);
    options
}

#[test]
fn ras_directions_become_lps_and_skips_apply() {
    let tmp = tempfile::tempdir().unwrap();
    let samples: Vec<u8> = (1..=8).collect();
    // Attached, with a line skip and a byte skip after the blank line.
    let mut data = b"junk line\nXY".to_vec();
    data.extend_from_slice(&samples);
    let path = write_file(
        tmp.path(),
        "ras.nrrd",
        "NRRD0005\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nspace: RAS\n\
         space directions: (2,0,0) (0,3,0) (0,0,4)\nspace origin: (10,20,30)\n\
         line skip: 1\nbyte skip: 2\n\n",
        &data,
    );
    let loaded = read(&path);
    let g = loaded.volume.geometry();
    assert_eq!(g.orientation_code(), "RAS");
    assert_close(g.origin_mm(), DVec3::new(-10.0, -20.0, 30.0), 1e-12);
    assert_close(g.spacing_mm(), DVec3::new(2.0, 3.0, 4.0), 1e-12);
    assert_eq!(loaded.volume.physical(1, 1, 1), Some(8.0));
    assert_eq!(loaded.volume.physical(1, 0, 0), Some(2.0));
}

#[test]
fn list_of_files_with_data_at_their_end_and_a_4d_header() {
    let tmp = tempfile::tempdir().unwrap();
    for (name, value) in [("b.raw", 7u16), ("a.raw", 9)] {
        let mut bytes = b"some preamble".to_vec();
        for _ in 0..6 {
            bytes.extend_from_slice(&value.to_be_bytes());
        }
        std::fs::write(tmp.path().join(name), bytes).unwrap();
    }
    let path = write_file(
        tmp.path(),
        "list.nhdr",
        "NRRD0004\ntype: ushort\ndimension: 4\nsizes: 1 3 2 2\nendian: big\n\
         space: left-anterior-superior\nspace directions: none (1,0,0) (0,1,0) (0,0,1)\n\
         byte skip: -1\ndata file: LIST 3\nb.raw\na.raw\n",
        &[],
    );
    let loaded = read(&path);
    assert_eq!(loaded.volume.dims(), [3, 2, 2]);
    assert_eq!(loaded.volume.geometry().orientation_code(), "LAS");
    assert_eq!(loaded.volume.physical(2, 1, 0), Some(7.0));
    assert_eq!(loaded.volume.physical(0, 0, 1), Some(9.0));
}

#[test]
fn two_dimensional_image_is_one_slice() {
    let tmp = tempfile::tempdir().unwrap();
    let path = write_file(
        tmp.path(),
        "flat.nrrd",
        "NRRD0001\ntype: float\ndimension: 2\nsizes: 2 1\nspacings: 0.5 0.25\nendian: little\n\n",
        &[1.5f32.to_le_bytes(), (-2.0f32).to_le_bytes()].concat(),
    );
    let loaded = read(&path);
    assert_eq!(loaded.volume.dims(), [2, 1, 1]);
    assert_close(
        loaded.volume.geometry().spacing_mm(),
        DVec3::new(0.5, 0.25, 1.0),
        1e-12,
    );
    assert_eq!(loaded.volume.physical(0, 0, 0), Some(1.5));
}

#[test]
fn text_encodings() {
    let tmp = tempfile::tempdir().unwrap();
    let ascii = write_file(
        tmp.path(),
        "ascii.nrrd",
        "NRRD0004\ntype: short\ndimension: 3\nsizes: 3 1 1\nencoding: ascii\nendian: big\n\n",
        b"-1024 7,\n 3071\n",
    );
    let loaded = read(&ascii);
    assert_eq!(loaded.source.stored_type, "int16, ascii");
    let values: Vec<f64> = (0..3)
        .map(|i| loaded.volume.physical(i, 0, 0).unwrap())
        .collect();
    assert_eq!(values, vec![-1024.0, 7.0, 3071.0]);
    let hex = write_file(
        tmp.path(),
        "hex.nrrd",
        "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 2 1 1\nencoding: hex\nendian: big\n\n",
        b"01 02\nFF\n00\n",
    );
    let loaded = read(&hex);
    assert_eq!(loaded.volume.physical(0, 0, 0), Some(258.0));
    assert_eq!(loaded.volume.physical(1, 0, 0), Some(65280.0));
    for (name, data) in [
        ("short.nrrd", &b"1 2"[..]),
        ("word.nrrd", b"1 x 3"),
        ("odd.nrrd", b"010"),
    ] {
        let encoding = if name == "odd.nrrd" { "hex" } else { "ascii" };
        let path = write_file(
            tmp.path(),
            name,
            &format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 3 1 1\nencoding: {encoding}\n\n"),
            data,
        );
        assert_fails(&path, &OpenOptions::default());
    }
}

fn assert_fails(path: &Path, options: &OpenOptions) -> ReadError {
    match nrrd::read(path, options) {
        Ok(_) => panic!("{} was read but should fail", path.display()),
        Err(e) => {
            assert!(!e.to_string().is_empty());
            eprintln!("{e}");
            e
        }
    }
}

#[test]
fn bad_headers_fail_cleanly() {
    let tmp = tempfile::tempdir().unwrap();
    let base = "NRRD0004\ntype: short\nendian: little\n";
    let cases = [
        ("truncated", "NRRD0004\ntype: short\ndimension: 3\nsiz"),
        ("zero", "dimension: 3\nsizes: 0 2 2\n\n"),
        ("negative", "dimension: 3\nsizes: 2 -2 2\n\n"),
        ("nan", "dimension: 3\nsizes: 1 1 1\nspace: LPS\nspace directions: (1,0,0) (0,NaN,0) (0,0,1)\n\n"),
        ("parallel", "dimension: 3\nsizes: 1 1 1\nspace: LPS\nspace directions: (1,0,0) (2,0,0) (0,0,1)\n\n"),
        ("type", "NRRD0004\ntype: quaternion\ndimension: 3\nsizes: 1 1 1\n\n"),
        ("encoding", "dimension: 3\nsizes: 1 1 1\nencoding: lzma\n\n"),
        ("bzip2", "dimension: 3\nsizes: 1 1 1\nencoding: bzip2\n\n"),
        ("dimension", "dimension: 7\nsizes: 1 1 1 1 1 1 1\n\n"),
        ("4d", "dimension: 4\nsizes: 3 1 1 1\n\n"),
        ("short data", "dimension: 3\nsizes: 2 2 2\n\n\x01\x02"),
    ];
    for (name, text) in cases {
        let text = if text.starts_with("NRRD") {
            text.to_owned()
        } else {
            format!("{base}{text}")
        };
        let path = write_file(tmp.path(), &format!("{name}.nrrd"), &text, &[]);
        assert_fails(&path, &OpenOptions::default());
    }
    let huge = write_file(
        tmp.path(),
        "huge.nrrd",
        &format!("{base}dimension: 3\nsizes: 1000 1000 1000\n\n"),
        &[],
    );
    assert!(matches!(
        assert_fails(&huge, &options_with_max_voxels(1_000_000)),
        ReadError::Limit { .. }
    ));
    let pattern = write_file(
        tmp.path(),
        "pattern.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 1 1 4000000000\n\
         data file: s%d.raw 1 4000000000 1\n",
        &[],
    );
    assert!(matches!(
        assert_fails(&pattern, &OpenOptions::default()),
        ReadError::Limit { .. }
    ));
    let overflow = write_file(
        tmp.path(),
        "overflow.nrrd",
        &format!("{base}dimension: 3\nsizes: 18446744073709551615 2 2\n\n"),
        &[],
    );
    assert!(matches!(
        assert_fails(&overflow, &OpenOptions::default()),
        ReadError::Limit { .. }
    ));
}

#[test]
fn missing_and_truncated_data_fail_naming_the_file() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = write_file(
        tmp.path(),
        "missing.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\ndata file: nowhere.raw\n",
        &[],
    );
    let e = assert_fails(&missing, &OpenOptions::default());
    assert!(e.path().ends_with("nowhere.raw"), "{e}");

    for n in 1..=2 {
        std::fs::write(tmp.path().join(format!("s{n}.raw")), [0u8; 4]).unwrap();
    }
    let pattern = write_file(
        tmp.path(),
        "pattern.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 3\ndata file: s%d.raw 1 3 1\n",
        &[],
    );
    let e = assert_fails(&pattern, &OpenOptions::default());
    assert!(e.path().ends_with("s3.raw"), "{e}");

    let too_few = write_file(
        tmp.path(),
        "few.nhdr",
        "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 3\ndata file: s%d.raw 1 2 1\n",
        &[],
    );
    assert!(matches!(
        assert_fails(&too_few, &OpenOptions::default()),
        ReadError::Inconsistent { .. }
    ));

    let short_slice = write_file(
        tmp.path(),
        "short.nhdr",
        "NRRD0004\ntype: ushort\nendian: big\ndimension: 3\nsizes: 2 2 2\n\
         data file: s%d.raw 1 2 1\n",
        &[],
    );
    let e = assert_fails(&short_slice, &OpenOptions::default());
    assert!(e.path().ends_with("s1.raw"), "{e}");

    // A good gzip file cut in half.
    let volume = Volume::new(
        oblique_geometry([16, 16, 16]),
        (0..4096u16).map(|n| n.wrapping_mul(2654)).collect(),
        ValueMap::IDENTITY,
        Modality::Unknown,
    )
    .unwrap();
    let whole = tmp.path().join("whole.nrrd");
    nrrd::write(&whole, &volume).unwrap();
    let bytes = std::fs::read(&whole).unwrap();
    let cut = tmp.path().join("cut.nrrd");
    std::fs::write(&cut, &bytes[..bytes.len() / 2]).unwrap();
    assert_fails(&cut, &OpenOptions::default());
    // ... and with its compressed bytes corrupted.
    let mut corrupt = bytes.clone();
    let end = corrupt.len();
    corrupt[end - 300..end - 200].fill(0x55);
    let corrupt_path = tmp.path().join("corrupt.nrrd");
    std::fs::write(&corrupt_path, corrupt).unwrap();
    assert_fails(&corrupt_path, &OpenOptions::default());
}

#[test]
fn a_folder_without_dicom_opens_its_one_scan_file_and_names_several() {
    let dims = [7, 5, 4];
    let voxels: Vec<u16> = (0..140u16).map(|n| n * 29 % 4096).collect();
    let hu = ValueMap::new(1.0, -1024.0).unwrap();
    let volume = Volume::new(oblique_geometry(dims), voxels, hu, Modality::Ct).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("README.md"), "not a scan").unwrap();
    let scan = tmp.path().join("head.nrrd");
    nrrd::write(&scan, &volume).unwrap();
    let loaded = endocast_io::open(tmp.path(), &OpenOptions::default()).unwrap();
    for (a, b) in volume.voxels().iter().zip(loaded.volume.voxels()) {
        assert_eq!(hu.physical(*a), loaded.volume.value_map().physical(*b));
    }
    assert!(
        loaded.warnings[0].contains("no DICOM series") && loaded.warnings[0].contains("head.nrrd"),
        "{:?}",
        loaded.warnings
    );
    // Two scan files: which one is meant is the user's to say.
    nrrd::write(&tmp.path().join("other.nrrd"), &volume).unwrap();
    let error = endocast_io::open(tmp.path(), &OpenOptions::default()).unwrap_err();
    let said = error.to_string();
    assert!(
        said.contains("head.nrrd") && said.contains("other.nrrd") && said.contains("name one"),
        "{said}"
    );
}
