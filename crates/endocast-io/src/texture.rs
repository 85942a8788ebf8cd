//! Detail textures and specular maps for the realistic look from PNG files: any PNG (greyscale,
//! colour, palette, with or without alpha, 8 or 16 bits). A texture keeps the file's colour (a
//! grey file gives a grey texture); a specular map is the file's luminance.

use crate::error::{ReadError, Result};
use endocast_core::look::{Texture, BUILT_IN_TEXTURES, LUMA, MAX_TEXELS};
use std::io::BufReader;
use std::path::Path;

/// Reads the PNG at `path` as a [`Texture`] of its colours (alpha ignored). Errors name the
/// file: missing, not a PNG, or an image of 0 or more than 8192 pixels along an edge.
pub fn read_texture(path: &Path) -> Result<Texture> {
    let (width, height, rgb) = read_rgb(path)?;
    Texture::from_rgb(width, height, rgb).map_err(|e| ReadError::format(path, e.to_string()))
}

/// Reads the PNG at `path` as a specular map: a grey [`Texture`] of its luminance (Rec. 709
/// weights; alpha ignored). Errors as [`read_texture`]'s.
pub fn read_specular_map(path: &Path) -> Result<Texture> {
    let (width, height, rgb) = read_rgb(path)?;
    let luma = rgb
        .iter()
        .map(|c| (LUMA[0] * c[0] + LUMA[1] * c[1] + LUMA[2] * c[2]).clamp(0.0, 1.0))
        .collect();
    Texture::from_luma(width, height, luma).map_err(|e| ReadError::format(path, e.to_string()))
}

/// The PNG at `path`: width, height and its pixels' red, green and blue, 0–1 (grey repeated).
fn read_rgb(path: &Path) -> Result<(usize, usize, Vec<[f32; 3]>)> {
    let file = std::fs::File::open(path).map_err(|e| ReadError::io(path, e))?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let bad = |e: png::DecodingError| ReadError::format(path, format!("not a readable PNG: {e}"));
    let mut reader = decoder.read_info().map_err(bad)?;
    check_size(path, reader.info().size())?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| ReadError::format(path, "a PNG too large to decode"))?;
    let mut buffer = vec![0; size];
    let info = reader.next_frame(&mut buffer).map_err(bad)?;
    let channels = info.color_type.samples();
    let (width, height) = (info.width as usize, info.height as usize);
    let unit = |v: u8| f32::from(v) / 255.0;
    let rgb = buffer[..info.buffer_size()]
        .chunks_exact(info.line_size)
        .flat_map(|row| row[..width * channels].chunks_exact(channels))
        .map(|px| match px {
            [g] | [g, _] => [unit(*g); 3],
            [r, g, b, ..] => [unit(*r), unit(*g), unit(*b)],
            [] => [0.0; 3],
        })
        .collect();
    Ok((width, height, rgb))
}

/// A detail texture by built-in name (`none`: no texture) or from a PNG file, as `--texture`
/// and Python's `texture=` take it.
pub fn named_or_file(spec: &str) -> Result<Option<Texture>> {
    let name = spec.trim();
    if BUILT_IN_TEXTURES.contains(&name.to_ascii_lowercase().as_str()) {
        return Ok(Texture::built_in(name));
    }
    let path = Path::new(spec);
    let is_png = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("png"));
    if !is_png && !path.exists() {
        return Err(ReadError::format(
            path,
            format!(
                "unknown texture; choose {} or a .png file",
                BUILT_IN_TEXTURES.join(", ")
            ),
        ));
    }
    read_texture(path).map(Some)
}

/// Refuses a texture of more than [`MAX_TEXELS`] pixels along an edge, from its header, before
/// any pixel is decoded (a 20000² PNG of a few kilobytes would take gigabytes).
fn check_size(path: &Path, (width, height): (u32, u32)) -> Result<()> {
    let longer = u64::from(width.max(height));
    if longer > MAX_TEXELS as u64 {
        return Err(ReadError::Limit {
            path: path.to_path_buf(),
            what: format!("a texture of {width}×{height} pixels (its longer edge)"),
            requested: longer,
            limit: MAX_TEXELS as u64,
        });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_colour_pngs_in_colour_specular_maps_as_luminance_and_names_bad_files() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.png");
        // Two pixels: white and pure green.
        crate::write_image_rgb8(&path, 2, 1, &[255, 255, 255, 0, 255, 0]).unwrap();
        let texture = read_texture(&path).unwrap();
        assert_eq!(texture.size(), [2, 1]);
        assert!(texture.is_colour());
        assert_eq!(texture.sample(0.25, 0.5, 0), [1.0; 3]);
        assert_eq!(texture.sample(0.75, 0.5, 0), [0.0, 1.0, 0.0]);
        let map = read_specular_map(&path).unwrap();
        assert!(!map.is_colour());
        assert!((map.sample(0.75, 0.5, 0)[0] - 0.7152).abs() < 1.0 / 255.0);
        // A grey file: a grey texture.
        crate::write_image_rgb8(&path, 2, 1, &[90, 90, 90, 200, 200, 200]).unwrap();
        assert!(!read_texture(&path).unwrap().is_colour());
        let missing = dir.path().join("missing.png");
        let error = read_texture(&missing).unwrap_err().to_string();
        assert!(error.contains("missing.png"), "{error}");
        let not_png = dir.path().join("x.png");
        std::fs::write(&not_png, b"not a png").unwrap();
        let error = read_texture(&not_png).unwrap_err().to_string();
        assert!(error.contains("x.png") && error.contains("PNG"), "{error}");
    }

    /// A PNG header claiming 20000 × 20000 grey pixels, with a few bytes of image data.
    fn forged_png(width: u32, height: u32) -> Vec<u8> {
        let chunk = |kind: &[u8], data: &[u8]| {
            let mut crc = flate2::Crc::new();
            crc.update(kind);
            crc.update(data);
            let length = u32::try_from(data.len()).unwrap().to_be_bytes();
            [&length[..], kind, data, &crc.sum().to_be_bytes()].concat()
        };
        let header = [
            &width.to_be_bytes()[..],
            &height.to_be_bytes(),
            &[8, 0, 0, 0, 0],
        ]
        .concat();
        let data = [0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01];
        [
            &b"\x89PNG\r\n\x1a\n"[..],
            &chunk(b"IHDR", &header),
            &chunk(b"IDAT", &data),
            &chunk(b"IEND", &[]),
        ]
        .concat()
    }

    #[test]
    fn a_huge_png_is_refused_from_its_header() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        std::fs::write(&path, forged_png(20_000, 20_000)).unwrap();
        let error = read_texture(&path).unwrap_err();
        assert!(
            matches!(
                error,
                ReadError::Limit {
                    requested: 20_000,
                    limit: 8192,
                    ..
                }
            ),
            "{error}"
        );
        let message = error.to_string();
        assert!(
            message.contains("huge.png") && message.contains("20000×20000"),
            "{message}"
        );
    }
}
