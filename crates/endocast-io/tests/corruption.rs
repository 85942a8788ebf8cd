//! Corrupt compressed data is refused: every compressed stream the readers take (gzip NIfTI,
//! gzip NRRD, zlib MetaImage, deflated DICOM) is damaged — 16 bytes flipped at several offsets
//! of the stream, the stream cut short, garbage appended that inflates to extra bytes — and
//! every damaged file must give an error that names it (never a volume with wrong voxels).
//!
//! Raw deflate (DICOM's deflated transfer syntax) has no checksum: damage that still inflates
//! to a well-formed stream of exactly the original length, ending exactly at the end of the
//! file, cannot be told from valid data by any reader. Every other damage to it is refused,
//! and the test counts the undetectable cases.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use endocast_core::{Geometry, Modality, ValueMap, Volume};
use endocast_io::{open, OpenOptions};
use flate2::Compression;
use glam::{DMat3, DVec3};
use std::io::Write;
use std::ops::Range;
use std::path::Path;

/// A CT-like volume whose voxels compress with dynamic Huffman codes (smooth shapes and noise).
fn scan() -> Volume {
    let dims = [40, 36, 30];
    let geometry = Geometry::new(dims, DVec3::splat(0.8), DVec3::ZERO, DMat3::IDENTITY).unwrap();
    let voxels = (0..dims.iter().product::<usize>())
        .map(|n| {
            let (i, j, k) = (n % 40, n / 40 % 36, n / 1440);
            let r = ((i as f64 - 20.0).powi(2) + (j as f64 - 18.0).powi(2)).sqrt();
            let wall = if (8.0..11.0).contains(&r) { 1100 } else { 20 };
            (wall + (n * 7919 + k * 31) % 57) as u16
        })
        .collect();
    let map = ValueMap::new(1.0, -1024.0).unwrap();
    Volume::new(geometry, voxels, map, Modality::Ct).unwrap()
}

fn gzip(data: &[u8]) -> Vec<u8> {
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), Compression::default());
    gz.write_all(data).unwrap();
    gz.finish().unwrap()
}

fn zlib(data: &[u8]) -> Vec<u8> {
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), Compression::default());
    z.write_all(data).unwrap();
    z.finish().unwrap()
}

fn deflate(data: &[u8]) -> Vec<u8> {
    let mut d = flate2::write::DeflateEncoder::new(Vec::new(), Compression::default());
    d.write_all(data).unwrap();
    d.finish().unwrap()
}

/// The voxels as little-endian int16 (physical values).
fn int16_bytes(volume: &Volume) -> Vec<u8> {
    let map = volume.value_map();
    volume
        .voxels()
        .iter()
        .flat_map(|&s| (map.physical(s) as i16).to_le_bytes())
        .collect()
}

/// One valid file and where its compressed stream lies.
struct Sample {
    name: &'static str,
    bytes: Vec<u8>,
    stream: Range<usize>,
    /// Appended bytes that a lenient reader would inflate as more data.
    garbage: Vec<u8>,
    /// Whether the header bounds the stream, so that bytes appended after it are outside the
    /// data (ignored with a warning) rather than part of a corrupt stream.
    bounded: bool,
    /// Whether the stream carries a checksum (gzip, zlib); raw deflate (DICOM) has none.
    checksummed: bool,
}

/// A MetaImage with a zlib stream; `sized` writes CompressedDataSize.
fn metaimage(volume: &Volume, name: &'static str, sized: bool) -> Sample {
    let stream = zlib(&int16_bytes(volume));
    let [x, y, z] = volume.dims();
    let size = if sized {
        format!("CompressedDataSize = {}\n", stream.len())
    } else {
        String::new()
    };
    let header = format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n\
         CompressedData = True\n{size}ElementSpacing = 0.8 0.8 0.8\nDimSize = {x} {y} {z}\n\
         ElementType = MET_SHORT\nElementDataFile = LOCAL\n"
    );
    let mut bytes = header.into_bytes();
    let start = bytes.len();
    bytes.extend_from_slice(&stream);
    Sample {
        name,
        stream: start..bytes.len(),
        bytes,
        garbage: zlib(&[7u8; 300]),
        bounded: sized,
        checksummed: true,
    }
}

fn written(volume: &Volume, dir: &Path, name: &'static str, header_end: &[u8]) -> Sample {
    let path = dir.join(name);
    endocast_io::write(&path, volume).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let start = match header_end {
        [] => 0,
        marker => {
            bytes
                .windows(marker.len())
                .position(|w| w == marker)
                .unwrap()
                + marker.len()
        }
    };
    Sample {
        name,
        stream: start..bytes.len(),
        bytes,
        garbage: gzip(&[7u8; 300]),
        bounded: false,
        checksummed: true,
    }
}

/// An explicit-VR little-endian element.
fn element(out: &mut Vec<u8>, group: u16, element: u16, vr: &[u8; 2], value: &[u8]) {
    let mut value = value.to_vec();
    if value.len() % 2 == 1 {
        value.push(if vr == b"UI" { 0 } else { b' ' });
    }
    out.extend_from_slice(&group.to_le_bytes());
    out.extend_from_slice(&element.to_le_bytes());
    out.extend_from_slice(vr);
    if matches!(vr, b"OB" | b"OW") {
        out.extend_from_slice(&[0, 0]);
        out.extend_from_slice(&(value.len() as u32).to_le_bytes());
    } else {
        out.extend_from_slice(&(value.len() as u16).to_le_bytes());
    }
    out.extend_from_slice(&value);
}

/// One slice of the volume as a CT image in the Deflated Explicit VR Little Endian syntax.
fn deflated_dicom(volume: &Volume) -> Sample {
    const SOP_CLASS: &[u8] = b"1.2.840.10008.5.1.4.1.1.2";
    const INSTANCE: &[u8] = b"1.2.826.0.1.3680043.2.1125.77.1";
    let [columns, rows, _] = volume.dims();
    let us = |v: usize| (v as u16).to_le_bytes();
    let mut meta = Vec::new();
    element(&mut meta, 2, 0x0001, b"OB", &[0, 1]);
    element(&mut meta, 2, 0x0002, b"UI", SOP_CLASS);
    element(&mut meta, 2, 0x0003, b"UI", INSTANCE);
    element(&mut meta, 2, 0x0010, b"UI", b"1.2.840.10008.1.2.1.99");
    let mut set = Vec::new();
    element(&mut set, 8, 0x0016, b"UI", SOP_CLASS);
    element(&mut set, 8, 0x0018, b"UI", INSTANCE);
    element(&mut set, 8, 0x0060, b"CS", b"CT");
    element(
        &mut set,
        0x20,
        0x000E,
        b"UI",
        b"1.2.826.0.1.3680043.2.1125.77.2",
    );
    element(&mut set, 0x20, 0x0032, b"DS", b"0\\0\\0");
    element(&mut set, 0x20, 0x0037, b"DS", b"1\\0\\0\\0\\1\\0");
    element(&mut set, 0x28, 0x0002, b"US", &us(1));
    element(&mut set, 0x28, 0x0004, b"CS", b"MONOCHROME2");
    element(&mut set, 0x28, 0x0010, b"US", &us(rows));
    element(&mut set, 0x28, 0x0011, b"US", &us(columns));
    element(&mut set, 0x28, 0x0030, b"DS", b"0.8\\0.8");
    element(&mut set, 0x28, 0x0100, b"US", &us(16));
    element(&mut set, 0x28, 0x0101, b"US", &us(16));
    element(&mut set, 0x28, 0x0102, b"US", &us(15));
    element(&mut set, 0x28, 0x0103, b"US", &us(1));
    element(&mut set, 0x28, 0x1052, b"DS", b"0");
    element(&mut set, 0x28, 0x1053, b"DS", b"1");
    let slice = &int16_bytes(volume)[..2 * columns * rows];
    element(&mut set, 0x7FE0, 0x0010, b"OW", slice);

    let mut bytes = vec![0u8; 128];
    bytes.extend_from_slice(b"DICM");
    element(&mut bytes, 2, 0, b"UL", &(meta.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&meta);
    let start = bytes.len();
    bytes.extend_from_slice(&deflate(&set));
    Sample {
        name: "slice.dcm",
        stream: start..bytes.len(),
        bytes,
        garbage: deflate(&[0u8; 300]),
        bounded: false,
        checksummed: false,
    }
}

fn samples(dir: &Path) -> Vec<Sample> {
    let volume = scan();
    vec![
        written(&volume, dir, "scan.nii.gz", &[]),
        written(&volume, dir, "scan.nrrd", b"\n\n"),
        metaimage(&volume, "sized.mha", true),
        metaimage(&volume, "unsized.mha", false),
        deflated_dicom(&volume),
    ]
}

/// Every way one sample is damaged, each with a description.
fn damaged(sample: &Sample) -> Vec<(String, Vec<u8>)> {
    let Range { start, end } = sample.stream.clone();
    let len = end - start;
    let mut out = Vec::new();
    for percent in [2, 10, 25, 40, 50, 60, 75, 90, 97] {
        let at = (start + len * percent / 100).min(end - 16);
        for pattern in [0xFFu8, 0x01, 0x55] {
            let mut bytes = sample.bytes.clone();
            bytes[at..at + 16].iter_mut().for_each(|b| *b ^= pattern);
            out.push((format!("16 bytes ^{pattern:#04x} at {percent} %"), bytes));
        }
    }
    for cut in [len / 2, len * 9 / 10, len - 8, len - 4, len - 1] {
        let bytes = sample.bytes[..start + cut].to_vec();
        out.push((format!("cut after {cut} of {len} stream bytes"), bytes));
    }
    if !sample.bounded {
        let mut appended = sample.bytes.clone();
        appended.extend_from_slice(&sample.garbage);
        out.push(("a second stream appended".into(), appended));
        let mut junk = sample.bytes.clone();
        junk.extend_from_slice(b"\x00\x01junk after the stream");
        out.push(("junk appended".into(), junk));
    }
    out
}

#[test]
fn valid_samples_load_with_the_right_voxels() {
    let dir = tempfile::tempdir().unwrap();
    let volume = scan();
    for sample in samples(dir.path()) {
        let path = dir.path().join(sample.name);
        std::fs::write(&path, &sample.bytes).unwrap();
        let loaded =
            open(&path, &OpenOptions::default()).unwrap_or_else(|e| panic!("{}: {e}", sample.name));
        let [x, y, z] = loaded.volume.dims();
        for (n, (i, j, k)) in [(0, 0, 0), (17, 3, 0), (x - 1, y - 1, z - 1)]
            .into_iter()
            .enumerate()
        {
            assert_eq!(
                loaded.volume.physical(i, j, k),
                volume.physical(i, j, k),
                "{} voxel {n}",
                sample.name
            );
        }
    }
}

/// Whether `stream` inflates (raw deflate) to exactly `len` bytes and ends with its last byte.
fn inflates_whole_to(stream: &[u8], len: usize) -> bool {
    let mut decoder = flate2::bufread::DeflateDecoder::new(stream);
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut decoder, &mut out).is_ok()
        && out.len() == len
        && decoder.total_in() == stream.len() as u64
}

#[test]
fn every_damaged_stream_is_refused_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let (mut cases, mut undetectable) = (0, 0);
    for sample in samples(dir.path()) {
        let inflated_len = if sample.checksummed {
            0
        } else {
            let mut out = Vec::new();
            let stream = &sample.bytes[sample.stream.clone()];
            std::io::Read::read_to_end(&mut flate2::read::DeflateDecoder::new(stream), &mut out)
                .unwrap();
            out.len()
        };
        for (what, bytes) in damaged(&sample) {
            let path = dir.path().join(format!("damaged-{}", sample.name));
            std::fs::write(&path, &bytes).unwrap();
            cases += 1;
            match open(&path, &OpenOptions::default()) {
                Ok(_)
                    if !sample.checksummed
                        && inflates_whole_to(&bytes[sample.stream.start..], inflated_len) =>
                {
                    undetectable += 1;
                }
                Ok(_) => panic!("{} with {what}: loaded", sample.name),
                Err(e) => {
                    let message = e.to_string();
                    assert!(
                        message.contains(&format!("damaged-{}", sample.name)),
                        "{} with {what}: {message}",
                        sample.name
                    );
                }
            }
        }
    }
    eprintln!("{cases} damaged files, {undetectable} undetectable (raw deflate, same length)");
    assert!(cases >= 5 * 30, "{cases} cases");
    assert!(
        undetectable * 10 <= cases,
        "{undetectable} of {cases} undetected"
    );
}

#[test]
fn bytes_after_a_bounded_stream_are_ignored_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let sample = metaimage(&scan(), "sized.mha", true);
    let path = dir.path().join(sample.name);
    let mut bytes = sample.bytes.clone();
    bytes.extend_from_slice(&sample.garbage);
    std::fs::write(&path, &bytes).unwrap();
    let loaded = open(&path, &OpenOptions::default()).unwrap();
    let expected = format!(
        "{} bytes after the voxel data were ignored",
        sample.garbage.len()
    );
    assert!(
        loaded.warnings.iter().any(|w| w.contains(&expected)),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_nrrd_with_more_raw_data_than_its_sizes_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.nrrd");
    let mut bytes =
        b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n".to_vec();
    bytes.extend_from_slice(&[1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11]);
    std::fs::write(&path, &bytes).unwrap();
    let loaded = open(&path, &OpenOptions::default()).unwrap();
    assert_eq!(loaded.volume.physical(1, 1, 1), Some(8.0));
    assert!(
        loaded
            .warnings
            .iter()
            .any(|w| w.contains("long.nrrd: 3 bytes of data beyond the samples")),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn a_4d_gzip_nifti_is_checked_to_its_end() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("scan.nii.gz");
    endocast_io::write(&path, &scan()).unwrap();
    let mut raw = Vec::new();
    std::io::Read::read_to_end(
        &mut flate2::read::GzDecoder::new(&std::fs::read(&path).unwrap()[..]),
        &mut raw,
    )
    .unwrap();
    // dim[0] = 4, dim[4] = 2: a second volume follows the first.
    raw[40..42].copy_from_slice(&4i16.to_le_bytes());
    raw[48..50].copy_from_slice(&2i16.to_le_bytes());
    let one_volume = raw.len() - 352;
    let mut two = raw.clone();
    two.extend_from_slice(&raw[352..]);
    std::fs::write(&path, gzip(&two)).unwrap();
    let loaded = open(&path, &OpenOptions::default()).unwrap();
    assert_eq!(loaded.volume.dims(), [40, 36, 30]);
    // The second volume cut short, or followed by more data: corrupt.
    for bad in [
        &two[..two.len() - 2],
        &[&two[..], &[0u8; 2][..]].concat()[..],
    ] {
        std::fs::write(&path, gzip(bad)).unwrap();
        let err = open(&path, &OpenOptions::default()).unwrap_err();
        assert!(err.to_string().contains("scan.nii.gz"), "{err}");
    }
    assert!(one_volume > 0);
}
