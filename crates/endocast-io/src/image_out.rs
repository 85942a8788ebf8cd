//! Writers for rendered images: 8-bit PNG (RGB or RGBA, tagged sRGB) or JPEG (RGB, chosen by
//! the file's ending, see [`ImageFormat`]) and single-channel float images as NumPy `.npy`
//! files (e.g. a depth image in millimetres with NaN where no ray hit).
//!
//! Both take pixels row by row, row 0 at the top of the image, left to right within a row, and
//! write through [`write_file`] so a failed write never leaves a half file behind.

use crate::atomic::{write_file, write_new};
use crate::error::{ReadError, Result};
use std::io::Write;
use std::path::Path;

/// The formats a rendered view is written in, by the output's ending.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// `.png`: lossless.
    Png,
    /// `.jpg` or `.jpeg`: baseline JPEG, quality [`JPEG_QUALITY`], no chroma subsampling.
    Jpeg,
}

/// The quality of JPEG output (1–100).
pub const JPEG_QUALITY: u8 = 92;

impl ImageFormat {
    /// The format `path`'s ending names (case-insensitive); any other ending, or none, is
    /// refused with a message naming the ones written.
    pub fn for_path(path: &Path) -> Result<Self> {
        let ending = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase());
        match ending.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("jpg" | "jpeg") => Ok(Self::Jpeg),
            Some(other) => Err(ReadError::unsupported(
                path,
                format!("image output .{other}: write .png or .jpg"),
            )),
            None => Err(ReadError::unsupported(
                path,
                "image output without an ending: write .png or .jpg",
            )),
        }
    }
}

/// Writes an 8-bit RGB image in the format `path`'s ending names ([`ImageFormat::for_path`]):
/// `pixels` holds `width·height·3` bytes, row 0 at the top.
pub fn write_image_rgb8(path: &Path, width: u32, height: u32, pixels: &[u8]) -> Result<()> {
    match ImageFormat::for_path(path)? {
        ImageFormat::Png => write_png_rgb8(path, width, height, pixels),
        ImageFormat::Jpeg => write_jpeg_rgb8(path, width, height, pixels),
    }
}

/// Writes an 8-bit RGB JPEG (quality [`JPEG_QUALITY`], 4:4:4): `pixels` holds
/// `width·height·3` bytes, row 0 at the top. Edges are at most 65 535 pixels.
pub fn write_jpeg_rgb8(path: &Path, width: u32, height: u32, pixels: &[u8]) -> Result<()> {
    let edges = u16::try_from(width)
        .ok()
        .zip(u16::try_from(height).ok())
        .filter(|&(w, h)| w > 0 && h > 0);
    let Some((w, h)) = edges else {
        return Err(ReadError::format(
            path,
            format!("a JPEG has 1 to 65535 pixels per edge, the image is {width}×{height}"),
        ));
    };
    check_len(path, width, height, 3, pixels.len())?;
    write_file(path, |out| {
        let mut encoder = jpeg_encoder::Encoder::new(out, JPEG_QUALITY);
        encoder.set_sampling_factor(jpeg_encoder::SamplingFactor::F_1_1);
        encoder
            .encode(pixels, w, h, jpeg_encoder::ColorType::Rgb)
            .map_err(|e| match e {
                jpeg_encoder::EncodingError::IoError(io) => io,
                other => std::io::Error::other(other.to_string()),
            })
    })
}

/// Writes an 8-bit RGB PNG: `pixels` holds `width·height·3` bytes, row 0 at the top.
pub fn write_png_rgb8(path: &Path, width: u32, height: u32, pixels: &[u8]) -> Result<()> {
    write_png(path, width, height, png::ColorType::Rgb, pixels)
}

/// Writes an 8-bit RGBA PNG (straight, not premultiplied, alpha): `pixels` holds
/// `width·height·4` bytes, row 0 at the top.
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, pixels: &[u8]) -> Result<()> {
    write_png(path, width, height, png::ColorType::Rgba, pixels)
}

/// Writes a `height × width` float32 image as a NumPy `.npy` file (format 1.0, little-endian,
/// C order, so `numpy.load(path)[row, column]` with row 0 at the top). `values` holds
/// `width·height` samples; NaN and infinities are stored as they are.
pub fn write_npy_f32(path: &Path, width: u32, height: u32, values: &[f32]) -> Result<()> {
    check_len(path, width, height, 1, values.len())?;
    write_npy(path, &format!("({height}, {width})"), values)
}

/// Writes a `height × width × channels` float32 array as a NumPy `.npy` file, as
/// [`write_npy_f32`] does (e.g. a wall point in mm per pixel: `numpy.load(path)[row, column]`
/// is its `channels` values). `values` holds `width·height·channels` samples.
pub fn write_npy_f32_channels(
    path: &Path,
    width: u32,
    height: u32,
    channels: u32,
    values: &[f32],
) -> Result<()> {
    check_len(path, width, height, channels as usize, values.len())?;
    write_npy(path, &format!("({height}, {width}, {channels})"), values)
}

/// Writes `values` under the `.npy` header of an array of `shape` (a Python tuple literal).
fn write_npy(path: &Path, shape: &str, values: &[f32]) -> Result<()> {
    let header = npy_header(shape);
    write_file(path, |w| {
        w.write_all(&header)?;
        // Converted in rows so a large image does not need a second full-size byte buffer.
        let mut row = Vec::with_capacity(values.len().min(1 << 16) * 4);
        for chunk in values.chunks(1 << 16) {
            row.clear();
            row.extend(chunk.iter().flat_map(|v| v.to_le_bytes()));
            w.write_all(&row)?;
        }
        Ok(())
    })
}

/// The 8 bytes every `.npy` file starts with: the magic string and format version 1.0.
const NPY_MAGIC: &[u8; 8] = b"\x93NUMPY\x01\x00";

/// The `.npy` 1.0 preamble for a little-endian float32 array of `shape` (a tuple literal such
/// as `(480, 640)`): magic, header length (u16 LE), then the Python dict literal padded with
/// spaces and ended by a newline so that the data starts at a multiple of 64 bytes, as the
/// format asks for aligned reads.
fn npy_header(shape: &str) -> Vec<u8> {
    let dict = format!("{{'descr': '<f4', 'fortran_order': False, 'shape': {shape}, }}");
    // magic (8) + length field (2) + dict + at least the newline, rounded up to 64.
    let unpadded = NPY_MAGIC.len() + 2 + dict.len() + 1;
    let total = unpadded.div_ceil(64) * 64;
    let header_len = total - NPY_MAGIC.len() - 2;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(NPY_MAGIC);
    // Three u32 dimensions print in at most ~70 characters, so the length fits a u16 easily.
    out.extend_from_slice(&(header_len as u16).to_le_bytes());
    out.extend_from_slice(dict.as_bytes());
    out.resize(total - 1, b' ');
    out.push(b'\n');
    out
}

/// Encodes `pixels` as an 8-bit PNG of `color` (RGB or RGBA) tagged as sRGB.
fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    color: png::ColorType,
    pixels: &[u8],
) -> Result<()> {
    check_png(path, width, height, color.samples(), pixels.len())?;
    write_file(path, |w| {
        encode_png(w, (width, height), color, Depth::Srgb8, pixels)
    })
}

/// Writes an 8-bit greyscale PNG of data (no colour tag; e.g. a mask): `values` holds
/// `width·height` bytes, row 0 at the top.
pub fn write_png_gray8(path: &Path, width: u32, height: u32, values: &[u8]) -> Result<()> {
    let color = png::ColorType::Grayscale;
    check_png(path, width, height, 1, values.len())?;
    write_file(path, |w| {
        encode_png(w, (width, height), color, Depth::Data8, values)
    })
}

/// Writes an 8-bit RGB PNG of data (no colour tag; e.g. normals): `values` holds
/// `width·height·3` bytes, row 0 at the top.
pub fn write_png_rgb8_data(path: &Path, width: u32, height: u32, values: &[u8]) -> Result<()> {
    let color = png::ColorType::Rgb;
    check_png(path, width, height, 3, values.len())?;
    write_file(path, |w| {
        encode_png(w, (width, height), color, Depth::Data8, values)
    })
}

/// Writes a 16-bit greyscale PNG of data (no colour tag; e.g. depth codes): `values` holds
/// `width·height` samples, row 0 at the top.
pub fn write_png_gray16(path: &Path, width: u32, height: u32, values: &[u16]) -> Result<()> {
    let color = png::ColorType::Grayscale;
    check_png(path, width, height, 1, values.len())?;
    // PNG stores 16-bit samples big-endian.
    let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_be_bytes()).collect();
    write_file(path, |w| {
        encode_png(w, (width, height), color, Depth::Data16, &bytes)
    })
}

/// Writes a fly-through's frame, an 8-bit RGB PNG, as a new file in a folder only this
/// process writes (see [`crate::atomic::write_new`]).
pub(crate) fn write_frame_png(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<()> {
    let color = png::ColorType::Rgb;
    check_png(path, width, height, 3, rgb.len())?;
    write_new(path, |w| {
        encode_png(w, (width, height), color, Depth::Srgb8, rgb)
    })
}

/// Fails unless `len` samples make a PNG of `width × height` with `channels` per pixel.
fn check_png(path: &Path, width: u32, height: u32, channels: usize, len: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(ReadError::format(
            path,
            format!("a PNG needs at least one pixel, the image is {width}×{height}"),
        ));
    }
    check_len(path, width, height, channels, len)
}

/// What a PNG's samples are.
#[derive(Clone, Copy, PartialEq)]
enum Depth {
    /// 8-bit colour, tagged sRGB.
    Srgb8,
    /// 8-bit data, untagged.
    Data8,
    /// 16-bit data (big-endian bytes), untagged.
    Data16,
}

/// Encodes `pixels` (checked by [`check_png`]) into `w`.
fn encode_png(
    w: &mut dyn Write,
    (width, height): (u32, u32),
    color: png::ColorType,
    depth: Depth,
    pixels: &[u8],
) -> std::io::Result<()> {
    let mut encoder = png::Encoder::new(w, width, height);
    encoder.set_color(color);
    match depth {
        Depth::Srgb8 => encoder.set_source_srgb(png::SrgbRenderingIntent::Perceptual),
        Depth::Data8 => {}
        Depth::Data16 => encoder.set_depth(png::BitDepth::Sixteen),
    }
    let mut writer = encoder.write_header().map_err(png_to_io)?;
    writer.write_image_data(pixels).map_err(png_to_io)?;
    writer.finish().map_err(png_to_io)
}

/// Fails unless `len` equals `width·height·channels` (computed without overflow).
fn check_len(path: &Path, width: u32, height: u32, channels: usize, len: usize) -> Result<()> {
    let expected = usize::try_from(width)
        .ok()
        .zip(usize::try_from(height).ok())
        .and_then(|(w, h)| w.checked_mul(h)?.checked_mul(channels));
    if expected == Some(len) {
        return Ok(());
    }
    let wanted = expected.map_or_else(|| "more than memory holds".to_owned(), |n| n.to_string());
    Err(ReadError::inconsistent(
        path,
        format!(
            "a {width}×{height} image with {channels} value(s) per pixel needs {wanted} values, \
             the buffer holds {len}"
        ),
    ))
}

/// The PNG encoder's errors as I/O errors, so [`write_file`] reports them with the path.
fn png_to_io(e: png::EncodingError) -> std::io::Error {
    match e {
        png::EncodingError::IoError(io) => io,
        other => std::io::Error::other(other),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn npy_header_is_exact_and_aligned() {
        let h = npy_header("(480, 640)");
        let dict = b"{'descr': '<f4', 'fortran_order': False, 'shape': (480, 640), }";
        assert_eq!(h.len(), 128);
        assert_eq!(&h[..8], NPY_MAGIC);
        assert_eq!(u16::from_le_bytes([h[8], h[9]]), 118);
        assert_eq!(&h[10..10 + dict.len()], dict);
        assert!(h[10 + dict.len()..127].iter().all(|&b| b == b' '));
        assert_eq!(h[127], b'\n');
        // NumPy's own writer also pads the smallest shape to 128 bytes.
        assert_eq!(npy_header("(1, 1)").len(), 128);
        assert_eq!(npy_header("(4096, 4096, 3)").len() % 64, 0);
    }

    #[test]
    fn the_ending_picks_png_or_jpeg_and_refuses_others() {
        let dir = tempfile::tempdir().unwrap();
        let rgb: Vec<u8> = (0..16 * 8 * 3).map(|n| (n * 5 % 256) as u8).collect();
        for (name, magic) in [
            ("a.png", &b"\x89PNG"[..]),
            ("b.JPG", &[0xFF, 0xD8, 0xFF][..]),
        ] {
            let p = dir.path().join(name);
            write_image_rgb8(&p, 16, 8, &rgb).unwrap();
            assert!(std::fs::read(&p).unwrap().starts_with(magic), "{name}");
        }
        for name in ["c.bmp", "d"] {
            let p = dir.path().join(name);
            let err = write_image_rgb8(&p, 16, 8, &rgb).unwrap_err().to_string();
            assert!(err.contains(name) && err.contains(".png or .jpg"), "{err}");
            assert!(!p.exists());
        }
        let p = dir.path().join("wide.jpg");
        assert!(write_jpeg_rgb8(&p, 70_000, 1, &vec![0; 210_000]).is_err());
    }

    #[test]
    fn wrong_buffer_length_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("x.png");
        let err = write_png_rgb8(&p, 2, 2, &[0; 11]).unwrap_err().to_string();
        assert!(err.contains("x.png") && err.contains("needs 12"), "{err}");
        assert!(!p.exists());
        assert!(write_png_rgb8(&p, 0, 2, &[]).is_err());
        assert!(write_npy_f32(&dir.path().join("d.npy"), 3, 1, &[0.0; 2]).is_err());
    }
}
