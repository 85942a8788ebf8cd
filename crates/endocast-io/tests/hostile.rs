//! Hostile and corrupt input (issue 32, "Trust every byte"): small files made here, each
//! with one lie in it, must give a clean error that names the file and the problem (or load
//! with a loud warning where the data are still usable) — never a panic, a hang, a huge
//! allocation, or voxels silently filled with zeros.

// Helpers panic on failure like the tests that call them.
#![allow(clippy::unwrap_used)]

use endocast_io::{
    dicom, mesh, metaimage, nifti, nrrd, route_file, Limits, Loaded, OpenOptions, ReadError,
};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub(crate) const EXPLICIT_LE: &str = "1.2.840.10008.1.2.1";
const IMPLICIT_LE: &str = "1.2.840.10008.1.2";
const RLE: &str = "1.2.840.10008.1.2.5";
const JPEG_BASELINE: &str = "1.2.840.10008.1.2.4.50";

/// Writes `bytes` as `name` in a fresh folder.
fn file_with(name: &str, bytes: &[u8]) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    (dir, path)
}

/// The error of a read that must fail, checked to name the file and to contain each of `words`.
fn refused(result: Result<Loaded, ReadError>, path: &Path, words: &[&str]) -> String {
    let error = match result {
        Ok(_) => panic!("{} was read", path.display()),
        Err(e) => e.to_string(),
    };
    let name = path.file_name().unwrap().to_str().unwrap();
    assert!(error.contains(name), "{error}");
    for word in words {
        assert!(error.contains(word), "{error:?} does not say {word:?}");
    }
    error
}

fn has_warning(loaded: &Loaded, words: &str) -> bool {
    loaded.warnings.iter().any(|w| w.contains(words))
}

/// Runs `read` on another thread and fails the test when it takes longer than `limit` (a hang
/// would otherwise stall the suite).
fn within<T: Send + 'static>(limit: Duration, read: impl FnOnce() -> T + Send + 'static) -> T {
    let (send, receive) = std::sync::mpsc::channel();
    std::thread::spawn(move || send.send(read()));
    receive
        .recv_timeout(limit)
        .unwrap_or_else(|_| panic!("the read did not return within {limit:?}"))
}

// ---------------------------------------------------------------------------------------------
// DICOM files byte by byte (explicit VR little endian unless said otherwise).

/// Value representations with a 2-byte reserved field and a 4-byte length.
fn is_long(vr: &[u8; 2]) -> bool {
    [b"OB", b"OW", b"SQ", b"UN", b"UT"].contains(&vr)
}

/// One explicit-VR little-endian element; an odd value is padded (NUL for UIDs and bytes).
pub(crate) fn element(tag: (u16, u16), vr: &[u8; 2], value: &[u8]) -> Vec<u8> {
    let mut value = value.to_vec();
    if value.len() % 2 == 1 {
        value.push(if matches!(vr, b"UI" | b"OB" | b"UN") {
            0
        } else {
            b' '
        });
    }
    let mut out = header(tag, vr, value.len() as u32);
    out.extend_from_slice(&value);
    out
}

/// An explicit-VR element header declaring `length` bytes.
fn header(tag: (u16, u16), vr: &[u8; 2], length: u32) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&tag.0.to_le_bytes());
    out.extend_from_slice(&tag.1.to_le_bytes());
    out.extend_from_slice(vr);
    if is_long(vr) {
        out.extend_from_slice(&[0, 0]);
        out.extend_from_slice(&length.to_le_bytes());
    } else {
        out.extend_from_slice(&(length as u16).to_le_bytes());
    }
    out
}

/// An item or delimiter tag (group FFFE) with its 4-byte length.
fn item(element: u16, length: u32) -> Vec<u8> {
    let mut out = vec![0xFE, 0xFF];
    out.extend_from_slice(&element.to_le_bytes());
    out.extend_from_slice(&length.to_le_bytes());
    out
}

/// Preamble, magic and a meta group naming `transfer_syntax`.
fn meta(transfer_syntax: &str) -> Vec<u8> {
    let mut group = element((2, 1), b"OB", &[0, 1]);
    group.extend(element((2, 2), b"UI", b"1.2.840.10008.5.1.4.1.1.2"));
    group.extend(element((2, 3), b"UI", b"1.2.3.4.1"));
    group.extend(element((2, 0x10), b"UI", transfer_syntax.as_bytes()));
    let mut out = vec![0u8; 128];
    out.extend_from_slice(b"DICM");
    out.extend(element((2, 0), b"UL", &(group.len() as u32).to_le_bytes()));
    out.extend(group);
    out
}

/// A one-slice CT image as a map of its encoded elements, so that tests can replace any.
pub(crate) struct Image(BTreeMap<(u16, u16), Vec<u8>>);

impl Image {
    /// Rows × columns of 16-bit samples (12 stored), placed, spaced, rescaled to HU.
    pub(crate) fn ct(rows: u16, columns: u16) -> Self {
        let pixels: Vec<u8> = (0..u32::from(rows) * u32::from(columns))
            .flat_map(|i| (i as u16 * 37 % 4000).to_le_bytes())
            .collect();
        let mut image = Self(BTreeMap::new());
        image
            .text((8, 0x16), b"UI", "1.2.840.10008.5.1.4.1.1.2")
            .text((8, 0x18), b"UI", "1.2.3.4.1")
            .text((8, 0x60), b"CS", "CT")
            .text((0x20, 0xE), b"UI", "1.2.3.4.5")
            .text((0x20, 0x32), b"DS", "0\\0\\0")
            .text((0x20, 0x37), b"DS", "1\\0\\0\\0\\1\\0")
            .short((0x28, 2), 1)
            .text((0x28, 4), b"CS", "MONOCHROME2")
            .short((0x28, 0x10), rows)
            .short((0x28, 0x11), columns)
            .text((0x28, 0x30), b"DS", "0.5\\0.5")
            .short((0x28, 0x100), 16)
            .short((0x28, 0x101), 12)
            .short((0x28, 0x102), 11)
            .short((0x28, 0x103), 0)
            .text((0x28, 0x1052), b"DS", "-1024")
            .text((0x28, 0x1053), b"DS", "1")
            .set((0x7FE0, 0x10), element((0x7FE0, 0x10), b"OW", &pixels));
        image
    }

    pub(crate) fn set(&mut self, tag: (u16, u16), encoded: Vec<u8>) -> &mut Self {
        self.0.insert(tag, encoded);
        self
    }

    pub(crate) fn text(&mut self, tag: (u16, u16), vr: &[u8; 2], value: &str) -> &mut Self {
        self.set(tag, element(tag, vr, value.as_bytes()))
    }

    fn short(&mut self, tag: (u16, u16), value: u16) -> &mut Self {
        self.set(tag, element(tag, b"US", &value.to_le_bytes()))
    }

    /// Encapsulated pixel data: an empty offset table, then one fragment per frame.
    fn fragments(&mut self, frames: &[Vec<u8>]) -> &mut Self {
        let mut encoded = header((0x7FE0, 0x10), b"OB", u32::MAX);
        encoded.extend(item(0xE000, 0));
        for frame in frames {
            let mut frame = frame.clone();
            frame.resize(frame.len().next_multiple_of(2), 0);
            encoded.extend(item(0xE000, frame.len() as u32));
            encoded.extend(frame);
        }
        encoded.extend(item(0xE0DD, 0));
        self.set((0x7FE0, 0x10), encoded)
    }

    /// The elements after the meta group.
    fn data_set(&self) -> Vec<u8> {
        self.0.values().flatten().copied().collect()
    }

    /// The file, in `transfer_syntax` (whose pixel data the test has set).
    pub(crate) fn bytes(&self, transfer_syntax: &str) -> Vec<u8> {
        let mut out = meta(transfer_syntax);
        out.extend(self.data_set());
        out
    }
}

fn read_dicom(path: &Path) -> Result<Loaded, ReadError> {
    dicom::read(path, &OpenOptions::default())
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

// ---------------------------------------------------------------------------------------------
// Valid files that pydicom and nibabel read (issue 32, item 5; the whole corpus of their test
// files is compared in crates/endocast-py/tests/test_peers_corpus.py): read, not refused.

/// 16-bit little-endian words as bytes.
fn words(values: &[u16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A sequence of one defined-length item holding the encoded `elements`, stored as `vr`.
fn sequence(tag: (u16, u16), vr: &[u8; 2], elements: &[u8]) -> Vec<u8> {
    let mut value = item(0xE000, elements.len() as u32);
    value.extend_from_slice(elements);
    let mut out = header(tag, vr, value.len() as u32);
    out.extend(value);
    out
}

/// One implicit-VR little-endian element (tag, 4-byte length, value).
fn implicit(tag: (u16, u16), value: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&tag.0.to_le_bytes());
    out.extend_from_slice(&tag.1.to_le_bytes());
    out.extend_from_slice(&(value.len() as u32).to_le_bytes());
    out.extend_from_slice(value);
    out
}

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
