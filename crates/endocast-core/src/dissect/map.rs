//! The flat image's map back to 3D: the wall point (world mm) each pixel shows, NaN where none.

use glam::DVec3;

/// The wall point of each pixel of a flat image, `width × height`, row 0 at the top: three
/// float32 coordinates per pixel (world mm, LPS for scans read as such), NaN where the pixel
/// shows no wall (the margins, rays that met none). Laid out as NumPy's
/// `(height, width, 3)` array.
#[derive(Debug, Clone, PartialEq)]
pub struct WallMap {
    width: usize,
    height: usize,
    points: Vec<f32>,
}

impl WallMap {
    /// A map of `width × height` pixels showing no wall.
    pub(super) fn empty(width: usize, height: usize) -> Self {
        Self {
            width,
            height,
            points: vec![f32::NAN; width * height * 3],
        }
    }

    /// Records that pixel `(x, y)` shows `point`.
    pub(super) fn set(&mut self, x: usize, y: usize, point: DVec3) {
        let n = (y * self.width + x) * 3;
        self.points[n..n + 3].copy_from_slice(&point.as_vec3().to_array());
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The wall point of pixel `(x, y)`, world mm; `None` outside the image or where the pixel
    /// shows no wall.
    pub fn at(&self, x: usize, y: usize) -> Option<DVec3> {
        if x >= self.width || y >= self.height {
            return None;
        }
        let n = (y * self.width + x) * 3;
        let p = DVec3::new(
            f64::from(self.points[n]),
            f64::from(self.points[n + 1]),
            f64::from(self.points[n + 2]),
        );
        p.is_finite().then_some(p)
    }

    /// All coordinates, pixel by pixel (x, y, z of each), rows from the top.
    pub fn as_slice(&self) -> &[f32] {
        &self.points
    }
}
