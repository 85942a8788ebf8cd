//! Hostile and corrupt input (issue 32, "Trust every byte"): small files made here, each
//! with one lie in it, must give a clean error that names the file and the problem (or load
//! with a loud warning where the data are still usable) — never a panic, a hang, a huge
//! allocation, or voxels silently filled with zeros.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use crate::dicom_bytes::*;
use endocast_io::{
    mesh, metaimage, nifti, nrrd, route_file, Limits, Loaded, OpenOptions, ReadError,
};
use std::path::Path;
use std::time::{Duration, Instant};

const IMPLICIT_LE: &str = "1.2.840.10008.1.2";
const RLE: &str = "1.2.840.10008.1.2.5";
const JPEG_BASELINE: &str = "1.2.840.10008.1.2.4.50";

/// Runs `read` on another thread and fails the test when it takes longer than `limit` (a hang
/// would otherwise stall the suite).
fn within<T: Send + 'static>(limit: Duration, read: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || send.send(read()));
    receive
        .recv_timeout(limit)
        .unwrap_or_else(|_| panic!("the read did not return within {limit:?}"))
}

#[test]
fn an_image_of_zero_rows_or_columns_is_refused() {
    for (rows, columns) in [(0, 4), (4, 0)] {
        let mut image = Image::ct(rows, columns);
        image.set((0x7FE0, 0x10), element((0x7FE0, 0x10), b"OW", &[]));
        let (_dir, path) = file_with("empty.dcm", &image.bytes(EXPLICIT_LE));
        refused(read_dicom(&path), &path, &["Rows", "Columns"]);
    }
}

/// ReferencedImageSequence items nested `depth` deep, each of undefined length.
fn nested_sequences(depth: usize) -> Vec<u8> {
    let mut nested = Vec::new();
    for _ in 0..depth {
        nested.extend(header((0x0008, 0x1140), b"SQ", u32::MAX));
        nested.extend(item(0xE000, u32::MAX));
    }
    nested.extend(element((0x0008, 0x1150), b"UI", b"1.2.3"));
    for _ in 0..depth {
        nested.extend(item(0xE00D, 0));
        nested.extend(item(0xE0DD, 0));
    }
    nested
}

#[test]
fn sequences_nested_twenty_thousand_deep_are_refused() {
    let mut image = Image::ct(2, 2);
    image.set((0x0008, 0x1140), nested_sequences(20_000));
    let (_dir, path) = file_with("nested.dcm", &image.bytes(EXPLICIT_LE));
    let start = Instant::now();
    refused(read_dicom(&path), &path, &["nested more than 32 levels"]);
    assert!(start.elapsed() < Duration::from_secs(1));
    // 32 levels, far more than real files have, still read.
    image.set((0x0008, 0x1140), nested_sequences(32));
    let (_dir, path) = file_with("deep.dcm", &image.bytes(EXPLICIT_LE));
    read_dicom(&path).unwrap();
}

/// The meta group's length ends it before an element of group 0002, which dicom-rs then reads
/// in the data set's implicit VR: its "VR" and reserved bytes become a 4 294 918 735-byte
/// length, reserved before the file is found short.
#[test]
fn an_element_longer_than_the_file_is_refused_before_any_allocation() {
    let mut bytes = meta(IMPLICIT_LE);
    // Explicit VR "OB", reserved bytes FF FF, length 0; as implicit VR: length 0xFFFF424F.
    bytes.extend_from_slice(&[0x02, 0x00, 0x16, 0x00, b'O', b'B', 0xFF, 0xFF, 0, 0, 0, 0]);
    let (_dir, path) = file_with("long.dcm", &bytes);
    let start = Instant::now();
    refused(
        read_dicom(&path),
        &path,
        &["(0002,0016)", "4294918735 bytes"],
    );
    assert!(start.elapsed() < Duration::from_secs(1));
}

/// A data set in implicit VR under a meta group that says explicit VR (found by the fuzzer):
/// dicom-rs's explicit decoder would take the first element's VR bytes "S\x01" as UN, and a
/// later element's bytes as a 3 758 161 918-byte length, and reserve it. Such a file is read
/// by the adaptive decoder only, which finds the sequence's first item corrupt.
#[test]
fn an_implicit_data_set_under_an_explicit_meta_group_is_never_read_as_explicit() {
    let mut bytes = meta(EXPLICIT_LE);
    // (0008,1140) SQ, implicit length 339; as explicit VR: "S\x01" (UN), length 0, then
    // (5104,0000) with VR FF FF and length 0xE000FFFE.
    bytes.extend_from_slice(&[0x08, 0x00, 0x40, 0x11, 0x53, 0x01, 0x00, 0x00]);
    bytes.extend_from_slice(&[0, 0, 0, 0, 0x04, 0x51, 0, 0, 0xFF, 0xFF, 0xFF, 0xFF]);
    bytes.extend_from_slice(&[0xFE, 0xFF, 0x00, 0xE0]);
    bytes.resize(bytes.len() + 339 - 16, 0);
    let (_dir, path) = file_with("implicit-under-explicit.dcm", &bytes);
    let start = Instant::now();
    refused(
        read_dicom(&path),
        &path,
        &["read as implicit VR", "item header"],
    );
    assert!(start.elapsed() < Duration::from_secs(1));
}

/// An RLE header of `segments` segments for fragments of 2-byte samples.
fn rle_fragment(segments: &[Vec<u8>]) -> Vec<u8> {
    let mut data = vec![0u8; 64];
    data[..4].copy_from_slice(&(segments.len() as u32).to_le_bytes());
    let mut offset = 64u32;
    for (i, segment) in segments.iter().enumerate() {
        data[4 + 4 * i..8 + 4 * i].copy_from_slice(&offset.to_le_bytes());
        offset += segment.len() as u32;
    }
    segments.iter().for_each(|s| data.extend_from_slice(s));
    data
}

#[test]
fn rle_frames_are_checked_against_their_header_and_the_image_size() {
    // 2 × 2 samples of 16 bits: high bytes 0, low bytes 1, 2, 3, 4 (literal runs).
    let valid = rle_fragment(&[vec![253, 0], vec![3, 1, 2, 3, 4]]);
    let mut image = Image::ct(2, 2);
    image.fragments(std::slice::from_ref(&valid));
    let (_dir, path) = file_with("rle.dcm", &image.bytes(RLE));
    let loaded = read_dicom(&path).unwrap();
    assert_eq!(loaded.volume.physical(1, 1, 0), Some(4.0 - 1024.0));

    // A JPEG stream relabelled as RLE: its first word claims 3 774 863 615 segments.
    let jpeg = [0xFF, 0xD8, 0xFF, 0xE0, 0, 16, b'J', b'F', b'I', b'F'].repeat(10);
    image.fragments(&[jpeg]);
    let (_dir, path) = file_with("jpeg-as-rle.dcm", &image.bytes(RLE));
    refused(
        read_dicom(&path),
        &path,
        &["RLE header declares 3774863615 segments"],
    );

    // Three frames declared (sharing the top-level position), one stored.
    image
        .text((0x28, 8), b"IS", "3")
        .fragments(std::slice::from_ref(&valid));
    let (_dir, path) = file_with("missing-rle-frames.dcm", &image.bytes(RLE));
    refused(
        read_dicom(&path),
        &path,
        &["declares 3 frames", "1 fragment"],
    );
    image.0.remove(&(0x28, 8));

    // Segments that decode to fewer bytes than Rows × Columns are not zero-filled.
    let short = rle_fragment(&[vec![253, 0], vec![1, 1, 2]]);
    image.fragments(&[short]);
    let (_dir, path) = file_with("short-rle.dcm", &image.bytes(RLE));
    refused(read_dicom(&path), &path, &["decodes to 2 bytes", "need 4"]);
}

/// A baseline JPEG of `rows` × `columns` 8-bit grey pixels.
fn jpeg(rows: u16, columns: u16) -> Vec<u8> {
    let pixels: Vec<u8> = (0..rows * columns).map(|i| (i * 13) as u8).collect();
    let mut out = Vec::new();
    jpeg_encoder::Encoder::new(&mut out, 90)
        .encode(&pixels, columns, rows, jpeg_encoder::ColorType::Luma)
        .unwrap();
    out
}

/// An 8-bit image of `rows` × `columns` whose pixel data is `stream` (a JPEG of any size).
fn jpeg_image(rows: u16, columns: u16, stream: Vec<u8>) -> Image {
    let mut image = Image::ct(rows, columns);
    image
        .short((0x28, 0x100), 8)
        .short((0x28, 0x101), 8)
        .short((0x28, 0x102), 7)
        .fragments(&[stream]);
    image
}

#[test]
fn a_compressed_stream_smaller_than_rows_and_columns_is_refused() {
    let fits = jpeg_image(8, 8, jpeg(8, 8));
    let (_dir, path) = file_with("jpeg.dcm", &fits.bytes(JPEG_BASELINE));
    read_dicom(&path).unwrap();
    // The header claims 16 rows; the stream holds 8: dicom-rs would zero the other 8.
    let lying = jpeg_image(16, 8, jpeg(8, 8));
    let (_dir, path) = file_with("jpeg-16-rows.dcm", &lying.bytes(JPEG_BASELINE));
    refused(read_dicom(&path), &path, &["8 rows × 8 columns", "16 × 8"]);
}

#[test]
fn uncompressed_pixel_data_must_be_the_declared_size() {
    let mut image = Image::ct(2, 2);
    image.set((0x7FE0, 0x10), element((0x7FE0, 0x10), b"OW", &[1; 12]));
    let (_dir, path) = file_with("long-pixels.dcm", &image.bytes(EXPLICIT_LE));
    refused(read_dicom(&path), &path, &["PixelData", "12 bytes", "= 8"]);

    // Three frames declared, one stored (the frames share the top-level position).
    let mut image = Image::ct(2, 2);
    image.text((0x28, 8), b"IS", "3");
    let (_dir, path) = file_with("missing-frames.dcm", &image.bytes(EXPLICIT_LE));
    refused(
        read_dicom(&path),
        &path,
        &["NumberOfFrames", "8 bytes", "= 24"],
    );
}

#[test]
fn high_bit_must_match_bits_stored_in_compressed_data_and_is_warned_in_native_data() {
    let mut image = Image::ct(2, 2);
    image.short((0x28, 0x102), 13);
    let (_dir, path) = file_with("high-bit.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    assert!(has_warning(&loaded, "HighBit 13"), "{:?}", loaded.warnings);

    let mut image = jpeg_image(8, 8, jpeg(8, 8));
    image.short((0x28, 0x101), 6);
    let (_dir, path) = file_with("jpeg-high-bit.dcm", &image.bytes(JPEG_BASELINE));
    refused(read_dicom(&path), &path, &["HighBit 7", "BitsStored 6"]);
}

#[test]
fn a_rescale_intercept_that_is_not_a_number_is_refused() {
    let mut image = Image::ct(2, 2);
    image.text((0x28, 0x1052), b"DS", "-1O24");
    let (_dir, path) = file_with("intercept.dcm", &image.bytes(EXPLICIT_LE));
    refused(read_dicom(&path), &path, &["RescaleIntercept", "-1O24"]);
}

#[test]
fn a_single_slice_without_a_usable_thickness_is_warned() {
    for thickness in ["NaN", "0", "-2"] {
        let mut image = Image::ct(2, 2);
        image.text((0x18, 0x50), b"DS", thickness);
        let (_dir, path) = file_with("thickness.dcm", &image.bytes(EXPLICIT_LE));
        let loaded = read_dicom(&path).unwrap();
        let words = format!("slicethickness {}", thickness.to_lowercase());
        let said = loaded
            .warnings
            .iter()
            .any(|w| w.to_lowercase().contains(&words) && w.contains("1 mm"));
        assert!(said, "{thickness}: {:?}", loaded.warnings);
    }
}

#[test]
fn pixel_spacing_out_of_range_is_refused_and_zero_is_unknown() {
    let mut image = Image::ct(2, 2);
    image.text((0x28, 0x30), b"DS", "1e-300\\0.5");
    let (_dir, path) = file_with("tiny-spacing.dcm", &image.bytes(EXPLICIT_LE));
    refused(read_dicom(&path), &path, &["PixelSpacing", "1e-300"]);

    image.text((0x28, 0x30), b"DS", "0\\0");
    let (_dir, path) = file_with("zero-spacing.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    assert!(
        has_warning(&loaded, "assuming 1 mm pixels"),
        "{:?}",
        loaded.warnings
    );
}

#[test]
fn an_image_position_stored_as_un_is_read_from_its_text() {
    let mut image = Image::ct(2, 2);
    image.set(
        (0x20, 0x32),
        element((0x20, 0x32), b"UN", b"10\\-20.5\\30 "),
    );
    let (_dir, path) = file_with("un-position.dcm", &image.bytes(EXPLICIT_LE));
    let loaded = read_dicom(&path).unwrap();
    let origin = loaded.volume.geometry().origin_mm();
    assert_eq!(origin.to_array(), [10.0, -20.5, 30.0]);
}

#[test]
fn a_deflated_file_padded_after_its_stream_is_read() {
    let image = Image::ct(2, 2);
    let mut deflate = flate2::write::DeflateEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut deflate, &image.data_set()).unwrap();
    let mut bytes = meta("1.2.840.10008.1.2.1.99");
    bytes.extend(deflate.finish().unwrap());
    bytes.extend_from_slice(&[0; 8]);
    let (_dir, path) = file_with("padded.dcm", &bytes);
    let loaded = read_dicom(&path).unwrap();
    assert_eq!(loaded.volume.dims(), [2, 2, 1]);
    bytes.extend_from_slice(&[0; 2]);
    let (_dir, path) = file_with("junk.dcm", &bytes);
    refused(
        read_dicom(&path),
        &path,
        &["10 bytes follow the end of the stream"],
    );
}

// ---------------------------------------------------------------------------------------------
// NRRD and MetaImage headers that lie about their data.

/// An NRRD header of `sizes` int16 samples; `data` is its `data file` line or attached bytes.
fn nrrd_header(sizes: &str, encoding: &str, data_file: Option<&str>) -> String {
    let mut text = format!(
        "NRRD0004\ntype: short\ndimension: 3\nsizes: {sizes}\nencoding: {encoding}\n\
         endian: little\nspacings: 1 1 1\n"
    );
    match data_file {
        Some(name) => text.push_str(&format!("data file: {name}\n")),
        None => text.push('\n'),
    }
    text
}

fn read_nrrd(path: &Path) -> Result<Loaded, ReadError> {
    nrrd::read(path, &OpenOptions::default())
}

/// Options whose voxel limit lets a lying header through to the check of its data (the
/// default limit depends on the machine's memory).
fn unlimited() -> OpenOptions {
    let mut options = OpenOptions::default();
    options.limits = Limits::with_max_voxels(1 << 40);
    options
}

#[test]
#[cfg(unix)]
fn a_data_file_that_never_ends_is_refused_at_once() {
    let header = nrrd_header("2 2 2", "raw", Some("/dev/zero"));
    let (_dir, path) = file_with("zero.nhdr", header.as_bytes());
    let result = within(Duration::from_secs(5), {
        let path = path.clone();
        move || read_nrrd(&path)
    });
    refused(result, &path, &["/dev/zero", "not a regular file"]);
}

#[test]
fn data_files_outside_the_header_folder_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let inner = dir.path().join("scan");
    std::fs::create_dir(&inner).unwrap();
    std::fs::write(dir.path().join("outside.raw"), [0u8; 16]).unwrap();
    for name in ["/etc/passwd", "../outside.raw"] {
        let path = inner.join("v.nhdr");
        std::fs::write(&path, nrrd_header("2 2 2", "raw", Some(name))).unwrap();
        refused(read_nrrd(&path), &path, &["outside the header's folder"]);
        let mhd = inner.join("v.mhd");
        std::fs::write(&mhd, metaimage_header("2 2 2", false, name)).unwrap();
        refused(
            metaimage::read(&mhd, &OpenOptions::default()),
            &mhd,
            &["outside the header's folder"],
        );
    }
    // A data file in a sub-folder is fine.
    std::fs::create_dir(inner.join("data")).unwrap();
    std::fs::write(inner.join("data/v.raw"), [0u8; 16]).unwrap();
    let path = inner.join("v.nhdr");
    std::fs::write(&path, nrrd_header("2 2 2", "raw", Some("data/v.raw"))).unwrap();
    read_nrrd(&path).unwrap();
}

#[test]
fn data_files_elsewhere_are_read_when_allowed_but_must_still_be_regular_files() {
    let dir = tempfile::tempdir().unwrap();
    let inner = dir.path().join("scan");
    std::fs::create_dir(&inner).unwrap();
    std::fs::write(dir.path().join("outside.raw"), [0u8; 16]).unwrap();
    let mut allowed = OpenOptions::default();
    allowed.allow_outside_data = true;
    let path = inner.join("v.nhdr");
    std::fs::write(&path, nrrd_header("2 2 2", "raw", Some("../outside.raw"))).unwrap();
    nrrd::read(&path, &allowed).unwrap();
    let mhd = inner.join("v.mhd");
    std::fs::write(&mhd, metaimage_header("2 2 2", false, "../outside.raw")).unwrap();
    metaimage::read(&mhd, &allowed).unwrap();
    if cfg!(unix) {
        std::fs::write(&path, nrrd_header("2 2 2", "raw", Some("/dev/zero"))).unwrap();
        refused(nrrd::read(&path, &allowed), &path, &["not a regular file"]);
    }
}

#[test]
fn huge_sizes_in_a_small_nrrd_are_refused_before_allocating() {
    for (encoding, words) in [
        ("raw", "holds only"),
        ("gzip", "inflate to at most"),
        ("ascii", "holds only"),
        ("hex", "holds only"),
    ] {
        let mut bytes = nrrd_header("4294967296 1 1", encoding, None).into_bytes();
        bytes.extend_from_slice(&[0x1f, 0x8b, 8, 0, 0, 0, 0, 0, 0, 3, 1, 0, 0]);
        let (_dir, path) = file_with("huge.nrrd", &bytes);
        let start = Instant::now();
        refused(nrrd::read(&path, &unlimited()), &path, &[words]);
        assert!(start.elapsed() < Duration::from_secs(1), "{encoding}");
    }
}

/// A MetaImage header of `dims` int16 voxels, zlib-compressed or not, whose data are `data`.
fn metaimage_header(dims: &str, compressed: bool, data: &str) -> String {
    let compressed = if compressed { "True" } else { "False" };
    format!(
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = False\n\
         CompressedData = {compressed}\nDimSize = {dims}\nElementType = MET_SHORT\n\
         ElementDataFile = {data}\n"
    )
}

#[test]
fn huge_dims_in_a_small_metaimage_or_nifti_are_refused_before_allocating() {
    for compressed in [false, true] {
        let mut bytes = metaimage_header("4294967296 1 1", compressed, "LOCAL").into_bytes();
        bytes.extend_from_slice(&[0x78, 0x9c, 3, 0, 0, 0, 0, 1]);
        let (_dir, path) = file_with("huge.mha", &bytes);
        let start = Instant::now();
        let error = refused(metaimage::read(&path, &unlimited()), &path, &[]);
        assert!(
            error.contains("inflate to at most") || error.contains("end early"),
            "{error}"
        );
        assert!(start.elapsed() < Duration::from_secs(1), "{error}");
    }
    // A gzip NIfTI header claiming 32767 × 32767 × 1000 int16 voxels (2 TB) in 50 bytes.
    let mut header = vec![0u8; 348];
    header[..4].copy_from_slice(&348i32.to_le_bytes());
    for (i, d) in [3i16, 32767, 32767, 1000, 1, 1, 1, 1].iter().enumerate() {
        header[40 + 2 * i..42 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    header[70..72].copy_from_slice(&4i16.to_le_bytes());
    header[72..74].copy_from_slice(&16i16.to_le_bytes());
    for i in 0..4 {
        header[76 + 4 * i..80 + 4 * i].copy_from_slice(&1f32.to_le_bytes());
    }
    header[108..112].copy_from_slice(&352f32.to_le_bytes());
    header[344..348].copy_from_slice(b"n+1\0");
    header.extend_from_slice(&[0; 4]);
    let mut gz = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::default());
    std::io::Write::write_all(&mut gz, &header).unwrap();
    let (_dir, path) = file_with("huge.nii.gz", &gz.finish().unwrap());
    let start = Instant::now();
    refused(
        nifti::read(&path, &unlimited()),
        &path,
        &["inflate to at most"],
    );
    assert!(start.elapsed() < Duration::from_secs(1));
}

// ---------------------------------------------------------------------------------------------
// Routes, markups and meshes.

#[test]
fn coordinates_beyond_a_kilometre_are_refused_naming_the_point() {
    let path_json = r#"{"format": "endocast-path", "version": 1, "units": "mm",
        "coordinate_system": "LPS", "points": [[0, 0, 0], [1e308, 0, 0], [5, 0, 0]]}"#;
    let (_dir, path) = file_with("far.json", path_json.as_bytes());
    let error = route_file::read_route(&path).unwrap_err().to_string();
    assert!(
        error.contains("far.json") && error.contains("points[1]"),
        "{error}"
    );
    assert!(error.contains("1e308"), "{error}");

    let markups = r#"{"markups": [{"type": "Curve", "coordinateSystem": "LPS",
        "controlPoints": [{"position": [0, 0, 0]}, {"position": [0, -1e308, 0]}]}]}"#;
    let (_dir, path) = file_with("far.mrk.json", markups.as_bytes());
    let error = route_file::read_route(&path).unwrap_err().to_string();
    assert!(error.contains("far.mrk.json"), "{error}");
    assert!(error.contains("controlPoints[1]"), "{error}");

    let cameras = r#"[{"eye": [0, 0, 1e300], "look_at": [0, 0, 0], "up": [0, 1, 0]}]"#;
    let (_dir, path) = file_with("cameras.json", cameras.as_bytes());
    let error = route_file::read_camera_path(&path).unwrap_err().to_string();
    assert!(
        error.contains("camera 0") && error.contains("eye"),
        "{error}"
    );
}

#[test]
#[cfg(unix)]
fn a_mesh_that_is_a_device_is_refused_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("zero.stl");
    std::os::unix::fs::symlink("/dev/zero", &path).unwrap();
    let error = within(Duration::from_secs(5), {
        let path = path.clone();
        move || mesh::read_mesh(&path).map(|_| ())
    })
    .unwrap_err()
    .to_string();
    assert!(
        error.contains("zero.stl") && error.contains("not a regular file"),
        "{error}"
    );
}

#[test]
fn a_truncated_ascii_stl_is_refused() {
    let facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n\
                 endloop\nendfacet\n";
    let whole = format!("solid t\n{facet}{facet}endsolid t\n");
    let (_dir, path) = file_with("whole.stl", whole.as_bytes());
    assert_eq!(mesh::read_mesh(&path).unwrap().triangles().len(), 2);
    // Cut before endsolid (after whole facets), and inside the second facet after its vertices.
    let cut_at_facet = whole.find("endsolid").unwrap();
    let inside = whole.rfind("endloop").unwrap();
    for end in [cut_at_facet, inside] {
        let (_dir, path) = file_with("cut.stl", &whole.as_bytes()[..end]);
        let error = mesh::read_mesh(&path).unwrap_err().to_string();
        assert!(
            error.contains("cut.stl") && error.contains("endsolid"),
            "{error}"
        );
    }
}
