//! A view's surface: pixel → surface point through the depth layer, and whether a world point
//! is on the surface the view shows.

use crate::camera::Camera;
use glam::DVec3;

/// Where a world point stands in a view.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Visibility {
    /// On the surface the view shows at its image position.
    Visible,
    /// Behind a nearer surface.
    Occluded,
    /// Its tissue is not there any more: the view's ray runs past it (a threshold change moved
    /// or removed that surface).
    Removed,
    /// Outside the image (or behind the camera).
    OutOfView,
}

/// A rendered view: its camera and the distance along each pixel's ray to the surface seen
/// there, mm (NaN where none), row 0 first — a [`Frame`](crate::render::Frame)'s `depth_mm`.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceView<'a> {
    /// The camera the view was rendered with.
    pub camera: &'a Camera,
    /// The depth layer, `width · height` values.
    pub depth_mm: &'a [f32],
    /// How far a point may lie from the surface seen and still count as on it, mm, besides
    /// the pixel's own footprint (what a slight threshold change moves the surface by: about a
    /// voxel or two; see [`SurfaceView::tolerance_for_spacing`]).
    pub tolerance_mm: f64,
}

impl<'a> SurfaceView<'a> {
    /// The view of `camera` with `depth_mm`, with a tolerance of 1.5 voxels of `spacing_mm`
    /// (the largest edge).
    pub fn new(camera: &'a Camera, depth_mm: &'a [f32], spacing_mm: DVec3) -> Self {
        Self {
            camera,
            depth_mm,
            tolerance_mm: Self::tolerance_for_spacing(spacing_mm),
        }
    }

    /// 1.5 times the largest voxel edge, mm.
    pub fn tolerance_for_spacing(spacing_mm: DVec3) -> f64 {
        1.5 * spacing_mm.max_element()
    }

    /// The depth at pixel `(column, row)`, when it shows a surface.
    fn depth_at(&self, column: i64, row: i64) -> Option<f64> {
        let [w, h] = self.camera.size();
        let (c, r) = (usize::try_from(column).ok()?, usize::try_from(row).ok()?);
        if c >= w || r >= h {
            return None;
        }
        let d = *self.depth_mm.get(c + w * r)?;
        d.is_finite().then_some(f64::from(d))
    }

    /// The surface point seen at pixel `(column, row)`, world mm.
    pub fn pick_pixel(&self, column: usize, row: usize) -> Option<DVec3> {
        let d = self.depth_at(column as i64, row as i64)?;
        self.camera.point_at(column, row, d)
    }

    /// The surface point seen at image position `(x, y)` (continuous pixels, centres at
    /// half-integers): on the exact ray through `(x, y)`, at the depth interpolated between
    /// the four nearest pixel centres — or the nearest pixel's depth where those four do not
    /// all show one smooth surface (a silhouette). `None` where no surface is seen.
    pub fn pick(&self, x: f64, y: f64) -> Option<DVec3> {
        let ray = self.camera.ray(x, y)?;
        let (fx, fy) = (x - 0.5, y - 0.5);
        let (c0, r0) = (fx.floor() as i64, fy.floor() as i64);
        let (tx, ty) = (fx - c0 as f64, fy - r0 as f64);
        let corners =
            [(0, 0), (1, 0), (0, 1), (1, 1)].map(|(dc, dr)| self.depth_at(c0 + dc, r0 + dr));
        let depth = match corners {
            [Some(a), Some(b), Some(c), Some(d)] if smooth([a, b, c, d], self.tolerance_mm) => {
                let top = a + (b - a) * tx;
                let bottom = c + (d - c) * tx;
                top + (bottom - top) * ty
            }
            _ => self.depth_at(x.floor() as i64, y.floor() as i64)?,
        };
        Some(ray.at(depth))
    }

    /// Whether `p_mm` lies on the surface this view shows (see [`Visibility`]): some pixel of
    /// the 3 × 3 around its image position sees a surface point within the tolerance plus one
    /// pixel footprint of it.
    pub fn visibility(&self, p_mm: DVec3) -> Visibility {
        let Some((x, y)) = self.camera.project(p_mm) else {
            return Visibility::OutOfView;
        };
        let [w, h] = self.camera.size();
        if !(x >= 0.0 && y >= 0.0 && x < w as f64 && y < h as f64) {
            return Visibility::OutOfView;
        }
        let Some(ray) = self.camera.ray(x, y) else {
            return Visibility::OutOfView;
        };
        let along = (p_mm - ray.origin).dot(ray.dir);
        let reach = self.tolerance_mm + 1.5 * self.footprint_mm(x, y, along);
        let (c, r) = (x.floor() as i64, y.floor() as i64);
        let mut nearer = false;
        for (dc, dr) in (-1..=1).flat_map(|dc| (-1..=1).map(move |dr| (dc, dr))) {
            let (cc, rr) = (c + dc, r + dr);
            let Some(d) = self.depth_at(cc, rr) else {
                continue;
            };
            let seen = self.camera.point_at(cc as usize, rr as usize, d);
            if seen.is_some_and(|s| s.distance(p_mm) <= reach) {
                return Visibility::Visible;
            }
            nearer |= d < along - reach;
        }
        if nearer {
            Visibility::Occluded
        } else {
            Visibility::Removed
        }
    }

    /// The width one pixel covers at distance `along_mm` on the ray through `(x, y)`, mm.
    fn footprint_mm(&self, x: f64, y: f64, along_mm: f64) -> f64 {
        let at = |x: f64| self.camera.ray(x, y).map(|r| r.at(along_mm));
        match (at(x), at(x + 1.0).or_else(|| at(x - 1.0))) {
            (Some(a), Some(b)) => a.distance(b),
            _ => 0.0,
        }
    }
}

/// Whether four depths lie within `tolerance_mm` of one another.
fn smooth(depths: [f64; 4], tolerance_mm: f64) -> bool {
    let lo = depths.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = depths.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    hi - lo <= tolerance_mm
}
