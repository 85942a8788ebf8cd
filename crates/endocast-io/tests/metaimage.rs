//! MetaImage reader and writer: the knee scans (raw and zlib), round trips, detached data
//! files, and bad headers that must fail cleanly.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use crate::test_volumes::{assert_same_volume, oblique_ct, scaled_volume, sheared_ct};
use endocast_io::{metaimage, open, Format, Limits, Loaded, OpenOptions, ReadError};
use glam::{DMat3, DVec3};
use std::io::Read;
use std::path::{Path, PathBuf};
use tempfile::TempDir;

fn read(path: &Path) -> Result<Loaded, ReadError> {
    metaimage::read(path, &OpenOptions::default())
}

/// The bytes after the `ElementDataFile = LOCAL` line.
fn local_data(bytes: &[u8]) -> &[u8] {
    let marker = b"ElementDataFile = LOCAL\n";
    let at = bytes
        .windows(marker.len())
        .position(|w| w == marker)
        .unwrap();
    &bytes[at + marker.len()..]
}

fn assert_knee(loaded: &Loaded, expected_voxels: &[u8]) {
    let v = &loaded.volume;
    let g = v.geometry();
    assert_eq!(v.dims(), [128, 64, 128]);
    assert_eq!(g.spacing_mm(), DVec3::new(1.0, 0.96875, 1.0));
    assert_eq!(g.direction(), DMat3::IDENTITY);
    assert_eq!(g.origin_mm(), DVec3::ZERO);
    let (lo, hi) = v.physical_range();
    assert!(
        lo >= 0.0 && (150.0..=210.0).contains(&hi),
        "range {lo}..{hi}"
    );
    assert_eq!(v.value_map().scale(), 1.0);
    // AnatomicalOrientation = RAI is ITK's name for the identity direction: no warning.
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(loaded.source.format, Format::MetaImage);
    // uint8 is stored exactly: every voxel equals the file's byte, in file order.
    let physical: Vec<u8> = v
        .voxels()
        .iter()
        .map(|&s| v.value_map().physical(s) as u8)
        .collect();
    assert!(
        physical == expected_voxels,
        "voxels differ from the file's bytes"
    );
}

#[test]
fn knee_raw_and_zlib() {
    let Some(dir) = endocast_testdata::shared_data("knee-mri") else {
        return;
    };
    let raw_path = dir.join("knee3D_dataT.mha");
    let loaded = read(&raw_path).unwrap();
    let bytes = std::fs::read(&raw_path).unwrap();
    assert_knee(&loaded, local_data(&bytes));
    assert_eq!(loaded.source.stored_type, "uint8 (MetaImage)");

    let zlib_path = dir.join("knee3D_dataR.mha");
    let loaded = open(&zlib_path, &OpenOptions::default()).unwrap();
    let bytes = std::fs::read(&zlib_path).unwrap();
    let mut inflated = Vec::new();
    flate2::read::ZlibDecoder::new(local_data(&bytes))
        .read_to_end(&mut inflated)
        .unwrap();
    assert_knee(&loaded, &inflated);
    assert_eq!(loaded.source.stored_type, "uint8 (MetaImage, zlib)");
}

fn round_trip(volume: &endocast_core::Volume) -> (Loaded, String) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v.mha");
    metaimage::write(&path, volume).unwrap();
    let loaded = open(&path, &OpenOptions::default()).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let header_len = bytes.len() - local_data(&bytes).len();
    let text = String::from_utf8(bytes[..header_len].to_vec()).unwrap();
    (loaded, text)
}

#[test]
fn oblique_ct_round_trips_exactly_as_met_short() {
    let volume = oblique_ct();
    let (loaded, text) = round_trip(&volume);
    assert_same_volume(&loaded.volume, &volume, 0.0);
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    assert_eq!(
        loaded.volume.geometry(),
        volume.geometry(),
        "geometry is written exactly"
    );
    assert!(text.contains("ElementType = MET_SHORT\n"), "{text}");
    assert!(text.ends_with("ElementDataFile = LOCAL\n"));
    let code = volume.geometry().orientation_code();
    let itk: String = code
        .chars()
        .map(|c| match c {
            'L' => 'R',
            'R' => 'L',
            'P' => 'A',
            'A' => 'P',
            'S' => 'I',
            'I' => 'S',
            other => panic!("orientation letter {other}"),
        })
        .collect();
    assert!(
        text.contains(&format!("AnatomicalOrientation = {itk}\n")),
        "{text}"
    );
}

#[test]
fn sheared_grid_round_trips() {
    let volume = sheared_ct();
    let (loaded, _) = round_trip(&volume);
    assert_same_volume(&loaded.volume, &volume, 0.0);
}

#[test]
fn scaled_values_round_trip_as_float_within_a_quantisation_step() {
    let volume = scaled_volume();
    let (loaded, text) = round_trip(&volume);
    assert!(text.contains("ElementType = MET_FLOAT\n"), "{text}");
    // float32 holds these values exactly; reading floats back spreads their range over 16 bits.
    let step = loaded.volume.value_map().scale();
    assert!(step < 0.5, "step {step}");
    assert_same_volume(&loaded.volume, &volume, step / 2.0 + 1e-9);
}

#[test]
fn writing_mhd_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let e = metaimage::write(&dir.path().join("v.mhd"), &oblique_ct()).unwrap_err();
    assert!(matches!(e, ReadError::Unsupported { .. }), "{e}");
}

/// A scratch directory for the files one test writes.
fn scratch() -> TempDir {
    tempfile::tempdir().unwrap()
}

fn write_temp(dir: &TempDir, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// Six int16 samples −3…2 in the given byte order.
fn samples(big: bool) -> Vec<u8> {
    (-3i16..3)
        .flat_map(|v| {
            if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            }
        })
        .collect()
}

const HEAD: &str = "ObjectType = Image\nNDims = 3\nDimSize = 3 2 1\nElementType = MET_SHORT\n";

fn assert_samples(loaded: &Loaded) {
    let v = &loaded.volume;
    assert_eq!(v.dims(), [3, 2, 1]);
    assert_eq!(v.physical(0, 0, 0), Some(-3.0));
    assert_eq!(v.physical(2, 1, 0), Some(2.0));
}

#[test]
fn detached_big_endian_data_with_a_skipped_preamble() {
    let dir = scratch();
    std::fs::create_dir(dir.path().join("data")).unwrap();
    let mut raw = b"PREAMBLE".to_vec();
    raw.extend(samples(true));
    write_temp(&dir, "data/v.raw", &raw);
    let text = format!(
        "{HEAD}ElementSpacing = 0.5 0.5 2\nOrigin = 1 2 3\nElementByteOrderMSB = True\n\
         HeaderSize = 8\nElementDataFile = data/v.raw\n"
    );
    let loaded = read(&write_temp(&dir, "v.mhd", text.as_bytes())).unwrap();
    assert_samples(&loaded);
    assert_eq!(
        loaded.volume.geometry().origin_mm(),
        DVec3::new(1.0, 2.0, 3.0)
    );
    assert_eq!(loaded.source.stored_type, "int16 (MetaImage, big-endian)");
}

#[test]
fn header_size_minus_one_reads_the_last_bytes() {
    let dir = scratch();
    let mut bytes = format!("{HEAD}HeaderSize = -1\nElementDataFile = LOCAL\n").into_bytes();
    bytes.extend_from_slice(b"junk before the voxels");
    bytes.extend(samples(false));
    assert_samples(&read(&write_temp(&dir, "v.mha", &bytes)).unwrap());
}

#[test]
fn two_d_image_with_rotation_is_one_slice() {
    let dir = scratch();
    let mut bytes = "NDims = 2\nDimSize = 3 2\nElementType = MET_SHORT\n\
                     TransformMatrix = 0 1 -1 0\nElementDataFile = LOCAL\n"
        .as_bytes()
        .to_vec();
    bytes.extend(samples(false));
    let loaded = read(&write_temp(&dir, "v.mha", &bytes)).unwrap();
    assert_samples(&loaded);
    // i runs along +y (posterior), j along −x (right).
    assert_eq!(loaded.volume.geometry().orientation_code(), "PRS");
}

#[test]
fn contradicting_anatomical_orientation_warns() {
    let dir = scratch();
    let mut bytes =
        format!("{HEAD}AnatomicalOrientation = LPS\nElementDataFile = LOCAL\n").into_bytes();
    bytes.extend(samples(false));
    let loaded = read(&write_temp(&dir, "v.mha", &bytes)).unwrap();
    assert_eq!(loaded.warnings.len(), 1, "{:?}", loaded.warnings);
    assert!(loaded.warnings[0].contains("RAI"), "{}", loaded.warnings[0]);
}

fn assert_fails(path: &Path) -> ReadError {
    let e = read(path)
        .err()
        .unwrap_or_else(|| panic!("{} should not read", path.display()));
    eprintln!("{e}");
    e
}

#[test]
fn bad_files_are_errors() {
    let dir = scratch();
    let local = |name: &str, header: &str, data: &[u8]| {
        let mut bytes = header.as_bytes().to_vec();
        bytes.extend_from_slice(data);
        write_temp(&dir, name, &bytes)
    };
    let good = samples(false);
    assert_fails(&local("no-data-file.mha", HEAD, &good));
    assert_fails(&local("empty.mha", "", &[]));
    let e = assert_fails(&local(
        "missing.mhd",
        &format!("{HEAD}ElementDataFile = gone.raw\n"),
        &[],
    ));
    assert!(
        matches!(e, ReadError::Io { .. }) && e.path().ends_with("gone.raw"),
        "{e}"
    );
    let letters = "NDims = 3\nDimSize = 3 2 a\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
    assert_fails(&local("letters.mha", letters, &good));
    let with = |extra: &str| format!("{HEAD}{extra}ElementDataFile = LOCAL\n");
    assert_fails(&local("short.mha", &with(""), &good[..11]));
    assert_fails(&local(
        "garbage.mha",
        &with("CompressedData = True\n"),
        &[0x78, 0x9c, 1, 2, 3, 4, 5],
    ));
    assert_fails(&local(
        "not-zlib.mha",
        &with("CompressedData = True\n"),
        &good,
    ));
    let e = assert_fails(&local(
        "big-size.mha",
        &with("CompressedData = True\nCompressedDataSize = 999999\n"),
        &good,
    ));
    assert!(matches!(e, ReadError::Format { .. }), "{e}");
    assert_fails(&local(
        "vector.mha",
        &with("ElementNumberOfChannels = 3\n"),
        &good,
    ));
    assert_fails(&local("text.mha", &with("BinaryData = False\n"), &good));
    assert_fails(&local(
        "list.mha",
        &format!("{HEAD}ElementDataFile = LIST\na.raw\n"),
        &[],
    ));
    assert_fails(&local(
        "nan.mha",
        &with("ElementSpacing = 1 NaN 1\n"),
        &good,
    ));
    assert_fails(&local(
        "flat.mha",
        &with("TransformMatrix = 1 0 0 1 0 0 0 0 1\n"),
        &good,
    ));
    let no_newline = vec![b'a'; (1 << 20) + 10];
    assert_fails(&local("endless.mha", "", &no_newline));
    let many_lines = "Comment = x\n".repeat(100_000);
    assert_fails(&local("long.mha", &many_lines, &[]));

    let huge = "NDims = 3\nDimSize = 100000 100000 100000\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
    let path = local("huge.mha", huge, &good);
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(1_000_000);
    let e = metaimage::read(&path, &options).unwrap_err();
    assert!(matches!(e, ReadError::Limit { .. }), "{e}");
    let overflow = "NDims = 3\nDimSize = 18446744073709551615 4 4\nElementType = MET_SHORT\nElementDataFile = LOCAL\n";
    let e = metaimage::read(&local("overflow.mha", overflow, &good), &options).unwrap_err();
    assert!(matches!(e, ReadError::Limit { .. }), "{e}");
}

#[test]
fn mha_is_the_header_then_the_raw_voxels() {
    let volume = oblique_ct();
    let dir = scratch();
    let path = dir.path().join("v.mha");
    metaimage::write(&path, &volume).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let data = local_data(&bytes);
    assert_eq!(data.len(), 2 * volume.voxels().len());
    let first = i16::from_le_bytes([data[0], data[1]]);
    assert_eq!(f64::from(first), volume.physical(0, 0, 0).unwrap());
}
