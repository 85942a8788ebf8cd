//! Image-space views around the endoscope: an RGB [`Image`] with small drawing primitives and a
//! built-in bitmap [`font`], the orthogonal [`slices`] through the camera, and the
//! [`dashboard`] that puts the endoscopic view, the slices and an overview side by side, and
//! the [`stereo`] outputs that combine two eyes' views, the [`structure`] a command found
//! tinted on the slices, and the [`lens_marks`] that label the cube's faces and the panorama's
//! directions.
//!
//! No file formats here: the writers live in `endocast-io`.
//!
//! Image coordinates are continuous pixels as in [`Camera`](crate::render::Camera): `(0, 0)` is
//! the top-left corner of the image, pixel `(x, y)` covers `[x, x+1) × [y, y+1)` and its centre is
//! `(x + ½, y + ½)`. Drawing clips to the image and ignores NaN or infinite coordinates, so a
//! marker that projects far outside (or nowhere) simply does not show.
//!
//! ```
//! use endocast_core::views::{Image, WHITE};
//!
//! let mut image = Image::new(64, 16, [0, 0, 0]).unwrap();
//! image.text(2, 2, "12.5 mm", 1, WHITE);
//! image.line((0.0, 15.5), (63.9, 15.5), [255, 0, 0]);
//! assert_eq!(image.pixel(30, 15), Some([255, 0, 0]));
//! ```

pub mod dashboard;
pub mod font;
pub mod lens_marks;
pub mod slices;
pub mod stereo;
pub mod structure;

use crate::render::{Frame, MAX_IMAGE_EDGE};
use glam::DVec3;
use thiserror::Error;

/// An 8-bit sRGB colour.
pub type Rgb = [u8; 3];

/// White.
pub const WHITE: Rgb = [255, 255, 255];
/// The camera marker's colour on slices and overviews.
pub const CAMERA_COLOR: Rgb = [255, 220, 0];
/// The path's colour on overviews.
pub const PATH_COLOR: Rgb = [0, 200, 255];

/// A view that cannot be made.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum ViewError {
    /// An image edge is zero or larger than [`MAX_IMAGE_EDGE`].
    #[error("image size {0}×{1} must be between 1 and 16384 pixels per edge")]
    BadSize(usize, usize),
    /// A pixel buffer does not hold `width · height · 3` bytes.
    #[error("a {width}×{height} RGB image needs {expected} bytes, the buffer holds {found}")]
    BufferLength {
        /// Image width, pixels.
        width: usize,
        /// Image height, pixels.
        height: usize,
        /// `width · height · 3`.
        expected: usize,
        /// The buffer's length.
        found: usize,
    },
    /// A point or direction has a NaN or infinite coordinate.
    #[error("{0} {1:?} is not finite")]
    NotFinite(&'static str, [f64; 3]),
    /// A direction is zero, or two directions that must span a plane are parallel.
    #[error("{0} {1:?} is zero or parallel to the other direction")]
    Degenerate(&'static str, [f64; 3]),
    /// A number is NaN, infinite or outside its range.
    #[error("{name} = {value} must be {range}")]
    OutOfRange {
        /// The parameter.
        name: &'static str,
        /// The rejected value.
        value: f64,
        /// The accepted range, in words.
        range: &'static str,
    },
    /// Two images that must have one size do not.
    #[error("the two images differ in size ({0:?} and {1:?} pixels)")]
    SizesDiffer([usize; 2], [usize; 2]),
}

/// An RGB image, 8 bits per channel, row 0 at the top, `R G B` interleaved.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Image {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

/// Checks an image size against `1..=MAX_IMAGE_EDGE` per edge.
fn check_size(width: usize, height: usize) -> Result<(), ViewError> {
    let edge = 1..=MAX_IMAGE_EDGE;
    if edge.contains(&width) && edge.contains(&height) {
        Ok(())
    } else {
        Err(ViewError::BadSize(width, height))
    }
}

impl Image {
    /// The bytes a pixel takes: 8-bit red, green and blue.
    pub const BYTES_PER_PIXEL: usize = 3;

    /// An image of `width × height` pixels filled with `fill`.
    pub fn new(width: usize, height: usize, fill: Rgb) -> Result<Self, ViewError> {
        check_size(width, height)?;
        Ok(Self {
            width,
            height,
            rgb: fill.repeat(width * height),
        })
    }

    /// An image from `width · height · 3` bytes, row 0 at the top.
    pub fn from_rgb(width: usize, height: usize, rgb: Vec<u8>) -> Result<Self, ViewError> {
        check_size(width, height)?;
        let expected = width * height * Self::BYTES_PER_PIXEL;
        if rgb.len() != expected {
            return Err(ViewError::BufferLength {
                width,
                height,
                expected,
                found: rgb.len(),
            });
        }
        Ok(Self { width, height, rgb })
    }

    /// Draws with `draw` on a `width · height · 4` RGBA buffer (row 0 at the top) as on an
    /// image: every pixel it changes takes the new colour and becomes opaque. Nothing happens
    /// when the buffer is not that size.
    pub fn draw_on_rgba(
        rgba: &mut [u8],
        [width, height]: [usize; 2],
        draw: impl FnOnce(&mut Self),
    ) {
        let rgb: Vec<u8> = rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect();
        if rgba.len() != 4 * width * height {
            return;
        }
        let Ok(mut image) = Self::from_rgb(width, height, rgb) else {
            return;
        };
        draw(&mut image);
        for (pixel, marked) in rgba.chunks_exact_mut(4).zip(image.rgb().chunks_exact(3)) {
            if pixel[..3] != *marked {
                pixel[..3].copy_from_slice(marked);
                pixel[3] = 255;
            }
        }
    }

    /// A rendered frame's colour over `background` (display values, 0–1).
    pub fn from_frame(frame: &Frame, background: [f32; 3]) -> Result<Self, ViewError> {
        Self::from_rgb(frame.width, frame.height, frame.to_rgb8(background))
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, `width · height · 3` bytes, row 0 at the top.
    pub fn rgb(&self) -> &[u8] {
        &self.rgb
    }

    /// Gives the pixel buffer back.
    pub fn into_rgb(self) -> Vec<u8> {
        self.rgb
    }

    /// The colour of pixel `(x, y)`, or `None` outside the image.
    pub fn pixel(&self, x: usize, y: usize) -> Option<Rgb> {
        (x < self.width && y < self.height).then(|| {
            let i = 3 * (x + self.width * y);
            [self.rgb[i], self.rgb[i + 1], self.rgb[i + 2]]
        })
    }

    /// Sets pixel `(x, y)`; nothing happens outside the image.
    pub fn put(&mut self, x: i64, y: i64, color: Rgb) {
        if let Some(i) = self.offset(x, y) {
            self.rgb[i..i + 3].copy_from_slice(&color);
        }
    }

    /// Blends `color` over pixel `(x, y)` with weight `amount` (0 keeps the pixel, 1 replaces
    /// it); nothing happens outside the image.
    pub fn blend(&mut self, x: i64, y: i64, color: Rgb, amount: f32) {
        let a = if amount.is_finite() {
            amount.clamp(0.0, 1.0)
        } else {
            0.0
        };
        if let Some(i) = self.offset(x, y) {
            for (c, new) in self.rgb[i..i + 3].iter_mut().zip(color) {
                let mixed = f32::from(*c) * (1.0 - a) + f32::from(new) * a;
                *c = mixed.round() as u8;
            }
        }
    }

    /// Byte offset of pixel `(x, y)`, or `None` outside.
    fn offset(&self, x: i64, y: i64) -> Option<usize> {
        let x = usize::try_from(x).ok().filter(|&x| x < self.width)?;
        let y = usize::try_from(y).ok().filter(|&y| y < self.height)?;
        Some(3 * (x + self.width * y))
    }

    /// Draws a one-pixel line between two image points (continuous pixel coordinates).
    pub fn line(&mut self, from: (f64, f64), to: (f64, f64), color: Rgb) {
        // Clipping first keeps the step count bounded for points that project far away.
        let Some((a, b)) = clip_segment(from, to, self.width as f64, self.height as f64) else {
            return;
        };
        let steps = (b.0 - a.0).abs().max((b.1 - a.1).abs()).ceil().max(1.0) as usize;
        for n in 0..=steps {
            let t = n as f64 / steps as f64;
            let (x, y) = (a.0 + (b.0 - a.0) * t, a.1 + (b.1 - a.1) * t);
            self.put(x.floor() as i64, y.floor() as i64, color);
        }
    }

    /// Fills the disc of `radius` pixels around `centre` (every pixel whose centre lies inside,
    /// and at least the pixel holding `centre`).
    pub fn disc(&mut self, centre: (f64, f64), radius: f64, color: Rgb) {
        let (cx, cy) = centre;
        if !(cx.is_finite() && cy.is_finite() && radius.is_finite()) {
            return;
        }
        let r = radius.clamp(0.0, (self.width + self.height) as f64);
        let x0 = (cx - r).floor().max(0.0) as i64;
        let y0 = (cy - r).floor().max(0.0) as i64;
        let x1 = (cx + r).ceil().min(self.width as f64) as i64;
        let y1 = (cy + r).ceil().min(self.height as f64) as i64;
        for y in y0..y1 {
            for x in x0..x1 {
                let (dx, dy) = (x as f64 + 0.5 - cx, y as f64 + 0.5 - cy);
                if dx * dx + dy * dy <= r * r {
                    self.put(x, y, color);
                }
            }
        }
        self.put(cx.floor() as i64, cy.floor() as i64, color);
    }

    /// Draws an arrow from `from` to `to` with a head of two strokes `head_px` long at ±30°.
    pub fn arrow(&mut self, from: (f64, f64), to: (f64, f64), head_px: f64, color: Rgb) {
        self.line(from, to, color);
        let (dx, dy) = (from.0 - to.0, from.1 - to.1);
        let length = dx.hypot(dy);
        if !length.is_finite() || length <= 0.0 {
            return;
        }
        let (ux, uy) = (dx / length * head_px, dy / length * head_px);
        let (sin, cos) = 30f64.to_radians().sin_cos();
        for s in [sin, -sin] {
            let tip = (to.0 + ux * cos - uy * s, to.1 + ux * s + uy * cos);
            self.line(to, tip, color);
        }
    }

    /// Draws the one-pixel outline of the `width × height` rectangle whose top-left pixel is
    /// `(x, y)`.
    pub fn rect_outline(&mut self, x: i64, y: i64, width: usize, height: usize, color: Rgb) {
        if width == 0 || height == 0 {
            return;
        }
        let (x1, y1) = (x + width as i64 - 1, y + height as i64 - 1);
        for xx in x.max(0)..=x1.min(self.width as i64) {
            self.put(xx, y, color);
            self.put(xx, y1, color);
        }
        for yy in y.max(0)..=y1.min(self.height as i64) {
            self.put(x, yy, color);
            self.put(x1, yy, color);
        }
    }

    /// Copies `source` with its top-left pixel at `(x, y)`, clipped to this image.
    pub fn blit(&mut self, source: &Image, x: i64, y: i64) {
        let x0 = x.max(0);
        let x1 = (x + source.width as i64).min(self.width as i64);
        if x1 <= x0 {
            return;
        }
        for sy in 0..source.height {
            let ty = y + sy as i64;
            let Some(dst) = self.offset(x0, ty) else {
                continue;
            };
            let src = 3 * ((x0 - x) as usize + source.width * sy);
            let n = 3 * (x1 - x0) as usize;
            self.rgb[dst..dst + n].copy_from_slice(&source.rgb[src..src + n]);
        }
    }

    /// A copy scaled to `width × height` by nearest-neighbour sampling (sharp text and markers).
    pub fn resized(&self, width: usize, height: usize) -> Result<Image, ViewError> {
        check_size(width, height)?;
        let mut rgb = Vec::with_capacity(width * height * 3);
        for y in 0..height {
            let sy = y * self.height / height;
            for x in 0..width {
                let sx = x * self.width / width;
                let i = 3 * (sx + self.width * sy);
                rgb.extend_from_slice(&self.rgb[i..i + 3]);
            }
        }
        Ok(Image { width, height, rgb })
    }

    /// Writes `text` in the built-in [`font`] with its top-left corner at pixel `(x, y)`, each
    /// font pixel a `scale × scale` block (a scale of 0 draws nothing).
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: usize, color: Rgb) {
        let s = scale as i64;
        for (n, c) in text.chars().enumerate() {
            let left = x + (n * font::ADVANCE) as i64 * s;
            for (row, bits) in font::glyph(c).iter().enumerate() {
                for col in 0..font::GLYPH_WIDTH {
                    if bits >> (font::GLYPH_WIDTH - 1 - col) & 1 == 1 {
                        self.fill_block(left + col as i64 * s, y + row as i64 * s, s, color);
                    }
                }
            }
        }
    }

    /// Like [`Image::text`], over a black shadow one font pixel down and right, so the text
    /// reads on light and dark backgrounds alike.
    pub fn text_shadowed(&mut self, x: i64, y: i64, text: &str, scale: usize, color: Rgb) {
        let s = scale as i64;
        self.text(x + s, y + s, text, scale, [0; 3]);
        self.text(x, y, text, scale, color);
    }

    /// Fills the `size × size` block whose top-left pixel is `(x, y)`.
    fn fill_block(&mut self, x: i64, y: i64, size: i64, color: Rgb) {
        for yy in y..y + size {
            for xx in x..x + size {
                self.put(xx, yy, color);
            }
        }
    }
}

/// The part of the segment `a`–`b` inside the box `[-1, width+1] × [-1, height+1]`
/// (Liang–Barsky), or `None` when none is (or a coordinate is not finite).
fn clip_segment(a: (f64, f64), b: (f64, f64), width: f64, height: f64) -> Option<TwoPoints> {
    if ![a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    let edges = [
        (-dx, a.0 + 1.0),
        (dx, width + 1.0 - a.0),
        (-dy, a.1 + 1.0),
        (dy, height + 1.0 - a.1),
    ];
    for (p, q) in edges {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else if p < 0.0 {
            t0 = t0.max(q / p);
        } else {
            t1 = t1.min(q / p);
        }
    }
    (t0 <= t1).then(|| {
        let at = |t: f64| (a.0 + dx * t, a.1 + dy * t);
        (at(t0), at(t1))
    })
}

/// Two image points.
type TwoPoints = ((f64, f64), (f64, f64));

/// The patient direction a world (LPS) vector points to most: `L`, `R`, `P`, `A`, `S` or `I`.
pub fn patient_letter(v: DVec3) -> char {
    let a = v.abs();
    if a.x >= a.y && a.x >= a.z {
        if v.x >= 0.0 {
            'L'
        } else {
            'R'
        }
    } else if a.y >= a.z {
        if v.y >= 0.0 {
            'P'
        } else {
            'A'
        }
    } else if v.z >= 0.0 {
        'S'
    } else {
        'I'
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RED: Rgb = [255, 0, 0];

    fn count(image: &Image, color: Rgb) -> usize {
        image.rgb.chunks(3).filter(|p| *p == color).count()
    }

    #[test]
    fn checks_sizes_and_buffers() {
        assert!(Image::new(0, 3, RED).is_err());
        assert!(Image::new(MAX_IMAGE_EDGE + 1, 3, RED).is_err());
        assert!(Image::from_rgb(2, 2, vec![0; 11]).is_err());
        let image = Image::from_rgb(2, 1, vec![1, 2, 3, 4, 5, 6]).unwrap();
        assert_eq!(image.pixel(1, 0), Some([4, 5, 6]));
        assert_eq!(image.pixel(2, 0), None);
    }

    #[test]
    fn lines_reach_their_ends_and_survive_wild_points() {
        let mut image = Image::new(20, 10, [0; 3]).unwrap();
        image.line((0.5, 0.5), (19.5, 9.5), RED);
        assert_eq!(image.pixel(0, 0), Some(RED));
        assert_eq!(image.pixel(19, 9), Some(RED));
        assert!(count(&image, RED) >= 20);
        // A point projected almost onto the camera plane lies very far away: clipped, no hang.
        let mut wild = Image::new(20, 10, [0; 3]).unwrap();
        wild.line((5.5, 5.5), (1e15, 5.5), RED);
        assert_eq!(count(&wild, RED), 15);
        wild.line((f64::NAN, 1.0), (3.0, 3.0), WHITE);
        wild.line((-50.0, -50.0), (-40.0, -1e9), WHITE);
        assert_eq!(count(&wild, WHITE), 0);
    }

    #[test]
    fn discs_rectangles_arrows_and_blits() {
        let mut image = Image::new(21, 21, [0; 3]).unwrap();
        image.disc((10.5, 10.5), 3.0, RED);
        // Pixel centres within 3 px: the 29 lattice points of a radius-3 disc.
        assert_eq!(count(&image, RED), 29);
        image.disc((f64::INFINITY, 0.0), 3.0, WHITE);
        assert_eq!(count(&image, WHITE), 0);
        image.rect_outline(0, 0, 21, 21, WHITE);
        assert_eq!(count(&image, WHITE), 80);
        let mut arrow = Image::new(21, 21, [0; 3]).unwrap();
        arrow.arrow((2.5, 10.5), (18.5, 10.5), 5.0, RED);
        assert_eq!(arrow.pixel(18, 10), Some(RED));
        assert_eq!(arrow.pixel(14, 8), Some(RED)); // the upper stroke of the head
        let mut big = Image::new(30, 30, [0; 3]).unwrap();
        big.blit(&arrow, 20, -5);
        assert_eq!(big.pixel(20 + 2, 10 - 5), Some(RED));
        assert_eq!(big.pixel(29, 5), arrow.pixel(9, 10)); // clipped at the right edge
        assert_eq!(
            count(&big, RED),
            (0..10)
                .map(|x| (0..16)
                    .filter(|&y| arrow.pixel(x, y + 5) == Some(RED))
                    .count())
                .sum::<usize>()
        );
        let small = arrow.resized(7, 7).unwrap();
        assert_eq!(small.width(), 7);
    }

    #[test]
    fn text_draws_glyph_pixels() {
        let mut image = Image::new(40, 20, [0; 3]).unwrap();
        image.text(1, 1, "L", 2, WHITE);
        // 'L': a vertical bar of 7 font pixels and a bottom row of 5, sharing one: 11 · 4.
        assert_eq!(count(&image, WHITE), 44);
        assert_eq!(image.pixel(1, 1), Some(WHITE));
        assert_eq!(image.pixel(3, 1), Some([0; 3]));
        assert_eq!(patient_letter(DVec3::new(0.1, -0.9, 0.3)), 'A');
        assert_eq!(patient_letter(-DVec3::X), 'R');
        assert_eq!(patient_letter(-DVec3::Z), 'I');
    }
}
