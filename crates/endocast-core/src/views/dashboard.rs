//! The fly-through dashboard: one RGB image with the endoscopic view large on the left, the
//! axial, coronal and sagittal slices and the cross-section perpendicular to the path in a 2×2
//! grid beside it, an overview of the whole lumen with the path and the camera on the right, and
//! a line of text below (frame number, arc position, coverage).
//!
//! ```text
//! +-------------------+-------+-------+-------------------+
//! |                   | axial |coronal|                   |
//! |    endoscope      +-------+-------+     overview      |
//! |      w × h        |sagitt.| cross |       h × h       |
//! +-------------------+-------+-------+-------------------+
//! | FRAME 12   ARC 123.4 mm   COVERAGE 81.0%              |
//! +-------------------------------------------------------+
//! ```
//!
//! Every size follows from the endoscope image's: slice tiles are `h/2` square, the overview
//! `h` square, and both dimensions are rounded up to even numbers (video encoders using 4:2:0
//! chroma need them).

use super::{font, Image, Rgb, ViewError, CAMERA_COLOR, PATH_COLOR, WHITE};
use crate::render::Camera;
use glam::DVec3;

/// Colour of the lines between the panels and of the text bar.
const FRAME_COLOR: Rgb = [70, 70, 70];
/// Colour of the panel titles.
const TITLE_COLOR: Rgb = [200, 200, 200];

/// A rectangle of pixels: top-left corner and size.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rect {
    /// Left column.
    pub x: usize,
    /// Top row.
    pub y: usize,
    /// Width, pixels.
    pub width: usize,
    /// Height, pixels.
    pub height: usize,
}

/// Where each panel goes (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DashboardLayout {
    /// Width of the whole image, pixels (even).
    pub width: usize,
    /// Height of the whole image, pixels (even).
    pub height: usize,
    /// The endoscopic view, at its own size.
    pub endoscope: Rect,
    /// The axial, coronal, sagittal and cross-section tiles (row by row): render slices at this
    /// size.
    pub slices: [Rect; 4],
    /// The overview: render it at this size so nothing is rescaled.
    pub overview: Rect,
    /// The text bar along the bottom.
    pub text: Rect,
    /// Image pixels per font pixel of the text.
    pub text_scale: usize,
}

impl DashboardLayout {
    /// The layout around an endoscope image of `width × height` pixels (each edge 3 to 8192).
    pub fn for_endoscope(width: usize, height: usize) -> Result<Self, ViewError> {
        if !(3..=8192).contains(&width) || !(3..=8192).contains(&height) {
            return Err(ViewError::BadSize(width, height));
        }
        let tile = height / 2;
        let text_scale = (height / 256).max(1);
        let pad = 3 * text_scale;
        let bar = font::GLYPH_HEIGHT * text_scale + 2 * pad;
        let total_width = (width + 2 * tile + height).next_multiple_of(2);
        let total_height = (height + bar).next_multiple_of(2);
        let rect = |x, y, width, height| Rect {
            x,
            y,
            width,
            height,
        };
        Ok(Self {
            width: total_width,
            height: total_height,
            endoscope: rect(0, 0, width, height),
            slices: [0, 1, 2, 3].map(|n| rect(width + n % 2 * tile, n / 2 * tile, tile, tile)),
            overview: rect(width + 2 * tile, 0, height, height),
            text: rect(0, height, total_width, total_height - height),
            text_scale,
        })
    }
}

/// What one dashboard frame shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DashboardInfo {
    /// Frame number, from 0.
    pub frame: usize,
    /// Position along the path, mm of arc.
    pub arc_mm: f64,
    /// Fraction of the wall seen so far, 0–1, when coverage is tracked.
    pub coverage: Option<f64>,
}

impl DashboardInfo {
    /// The text line, e.g. `FRAME 12   ARC 123.4 mm   COVERAGE 81.0%`.
    pub fn line(&self) -> String {
        let mut line = format!("FRAME {}   ARC {:.1} mm", self.frame, self.arc_mm);
        if let Some(c) = self.coverage {
            line += &format!("   COVERAGE {:.1}%", 100.0 * c);
        }
        line
    }
}

/// The panels of one dashboard frame. Images of another size than their tile are rescaled
/// (nearest neighbour) after the path is drawn, so markers stay where they belong.
#[derive(Debug, Clone, Copy)]
pub struct Dashboard<'a> {
    /// The endoscopic view; must have the layout's endoscope size.
    pub endoscope: &'a Image,
    /// The axial, coronal and sagittal slices and the cross-section perpendicular to the path.
    pub slices: [&'a Image; 4],
    /// An outside render of the lumen.
    pub overview: &'a Image,
    /// The camera the overview was rendered with (for projecting the path onto it).
    pub overview_camera: &'a Camera,
    /// The path's points, world mm.
    pub path_mm: &'a [DVec3],
    /// The endoscope's camera.
    pub camera: &'a Camera,
}

impl Dashboard<'_> {
    /// Composes the frame on `layout`.
    pub fn compose(
        &self,
        layout: &DashboardLayout,
        info: &DashboardInfo,
    ) -> Result<Image, ViewError> {
        let e = layout.endoscope;
        if [self.endoscope.width(), self.endoscope.height()] != [e.width, e.height] {
            return Err(ViewError::BadSize(
                self.endoscope.width(),
                self.endoscope.height(),
            ));
        }
        let mut out = Image::new(layout.width, layout.height, [0; 3])?;
        out.blit(self.endoscope, 0, 0);
        let names = ["AXIAL", "CORONAL", "SAGITTAL", "CROSS-SECTION"];
        for ((slice, tile), name) in self.slices.iter().zip(layout.slices).zip(names) {
            place(&mut out, slice, tile)?;
            out.text_shadowed(tile.x as i64 + 3, tile.y as i64 + 3, name, 1, TITLE_COLOR);
        }
        let mut overview = self.overview.clone();
        draw_path(
            &mut overview,
            self.overview_camera,
            self.path_mm,
            self.camera,
        );
        place(&mut out, &overview, layout.overview)?;
        let t = layout.text;
        let s = layout.text_scale;
        out.line(
            (0.0, t.y as f64 + 0.5),
            (t.width as f64, t.y as f64 + 0.5),
            FRAME_COLOR,
        );
        out.text(4 * s as i64, (t.y + 3 * s) as i64, &info.line(), s, WHITE);
        Ok(out)
    }
}

/// Copies `image` into `tile` (rescaled when the sizes differ) and outlines the tile.
fn place(out: &mut Image, image: &Image, tile: Rect) -> Result<(), ViewError> {
    let (x, y) = (tile.x as i64, tile.y as i64);
    if [image.width(), image.height()] == [tile.width, tile.height] {
        out.blit(image, x, y);
    } else {
        out.blit(&image.resized(tile.width, tile.height)?, x, y);
    }
    out.rect_outline(x, y, tile.width, tile.height, FRAME_COLOR);
    Ok(())
}

/// Draws `path_mm` and the endoscope `camera` on an overview `image` rendered with `view`
/// (projected with [`Camera::project`], scaled when the image's size differs from the
/// camera's): the path as a polyline (segments with an end behind `view` are left out), the eye
/// as a dot and its view direction as an arrow a sixteenth of the image long.
pub fn draw_path(image: &mut Image, view: &Camera, path_mm: &[DVec3], camera: &Camera) {
    let [w, h] = view.size();
    let (sx, sy) = (
        image.width() as f64 / w as f64,
        image.height() as f64 / h as f64,
    );
    let project = |p: DVec3| view.project(p).map(|(x, y)| (x * sx, y * sy));
    for pair in path_mm.windows(2) {
        if let (Some(a), Some(b)) = (project(pair[0]), project(pair[1])) {
            image.line(a, b, PATH_COLOR);
        }
    }
    let Some(eye) = project(camera.eye_mm()) else {
        return;
    };
    let size = image.width().max(image.height()) as f64;
    // One millimetre ahead gives the on-screen direction; its length is set in pixels.
    if let Some(ahead) = project(camera.eye_mm() + camera.forward()) {
        let (dx, dy) = (ahead.0 - eye.0, ahead.1 - eye.1);
        let length = dx.hypot(dy);
        if length > 1e-9 {
            let reach = size / 16.0;
            let tip = (eye.0 + dx / length * reach, eye.1 + dy / length * reach);
            image.arrow(eye, tip, (size / 50.0).max(3.0), CAMERA_COLOR);
        }
    }
    image.disc(eye, (size / 80.0).max(2.0), CAMERA_COLOR);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_fits_without_overlap_and_is_even() {
        for (w, h) in [(512, 512), (129, 97), (640, 480), (3, 3)] {
            let l = DashboardLayout::for_endoscope(w, h).unwrap();
            assert_eq!((l.width % 2, l.height % 2), (0, 0));
            let mut cover = vec![0u8; l.width * l.height];
            for r in [l.endoscope, l.overview, l.text].iter().chain(&l.slices) {
                assert!(
                    r.x + r.width <= l.width && r.y + r.height <= l.height,
                    "{r:?}"
                );
                for y in r.y..r.y + r.height {
                    for x in r.x..r.x + r.width {
                        cover[x + l.width * y] += 1;
                    }
                }
            }
            assert!(cover.iter().all(|&c| c <= 1), "{w}×{h}");
            assert_eq!(l.overview.width, h);
        }
        assert!(DashboardLayout::for_endoscope(2, 100).is_err());
        assert!(DashboardLayout::for_endoscope(100, 100_000).is_err());
    }

    #[test]
    fn composes_panels_path_camera_and_text() {
        let layout = DashboardLayout::for_endoscope(96, 96).unwrap();
        let endoscope = Image::new(96, 96, [200, 100, 100]).unwrap();
        let slice = Image::new(50, 50, [90, 90, 90]).unwrap();
        let overview = Image::new(96, 96, [10, 40, 10]).unwrap();
        // Looking down −z at a path in the z = 0 plane from 100 mm.
        let view =
            Camera::look_at(DVec3::Z * 100.0, DVec3::ZERO, DVec3::Y, 60.0, [96, 96]).unwrap();
        let path: Vec<DVec3> = (0..20)
            .map(|n| DVec3::new(f64::from(n) * 2.0 - 20.0, 0.0, 0.0))
            .collect();
        let camera = Camera::look_at(path[15], path[16], DVec3::Z, 90.0, [96, 96]).unwrap();
        let dashboard = Dashboard {
            endoscope: &endoscope,
            slices: [&slice; 4],
            overview: &overview,
            overview_camera: &view,
            path_mm: &path,
            camera: &camera,
        };
        let info = DashboardInfo {
            frame: 7,
            arc_mm: 30.0,
            coverage: Some(0.5),
        };
        let out = dashboard.compose(&layout, &info).unwrap();
        assert_eq!(out.pixel(40, 60), Some([200, 100, 100]));
        let s = layout.slices[2];
        assert_eq!(
            out.pixel(s.x + s.width / 2, s.y + s.height - 5),
            Some([90; 3])
        );
        let o = layout.overview;
        let at = |p: DVec3| {
            let (x, y) = view.project(p).unwrap();
            out.pixel(o.x + x as usize, o.y + y as usize)
        };
        assert_eq!(at(path[3]), Some(PATH_COLOR));
        assert_eq!(at(path[15]), Some(CAMERA_COLOR));
        assert_eq!(at(DVec3::new(0.0, 30.0, 0.0)), Some([10, 40, 10]));
        let t = layout.text;
        let text_pixels = (t.y..t.y + t.height)
            .flat_map(|y| (0..t.width).map(move |x| (x, y)))
            .filter(|&(x, y)| out.pixel(x, y) == Some(WHITE))
            .count();
        assert!(text_pixels > 100);
        assert_eq!(info.line(), "FRAME 7   ARC 30.0 mm   COVERAGE 50.0%");
        let small = Image::new(95, 96, [0; 3]).unwrap();
        let bad = Dashboard {
            endoscope: &small,
            ..dashboard
        };
        assert!(bad.compose(&layout, &info).is_err());
    }
}
