//! Each pixel's search start of the new frame: past the clear ball around the eye, and from
//! there as far as the previous frame's depths show the ray empty (see the parent module's doc
//! for the geometry).

use super::pyramid::MinPyramid;
use super::SearchStarts;
use crate::camera::{Camera, PinholeRays};
use glam::{DVec3, Vec3};

/// At most this many rounds of "a box around the rest of the ray, its smallest depth, the
/// empty stretch up to it" per pixel.
const ROUNDS: usize = 6;

/// Relative amount by which a start is made smaller before it is stored in `f32`.
const ROUND_DOWN: f64 = 1.0 - 1e-6;

/// How distances along a ray map to voxels, and the sample step.
#[derive(Debug, Clone, Copy)]
pub(super) struct Scale {
    /// An upper bound of the voxels a millimetre spans in any direction.
    pub voxels_per_mm: f64,
    /// The sample step, mm.
    pub step_mm: f64,
}

/// A pinhole camera's rays in closed form, as [`Camera::ray`] makes them.
#[derive(Debug, Clone, Copy)]
struct Pinhole {
    rays: PinholeRays,
    size: [f64; 2],
}

impl Pinhole {
    fn of(camera: &Camera) -> Option<Self> {
        let [w, h] = camera.size();
        camera.fast_pinhole().map(|rays| Self {
            rays,
            size: [w as f64, h as f64],
        })
    }

    /// The unit direction of pixel `(x, y)`'s ray.
    fn dir(&self, x: usize, y: usize) -> DVec3 {
        let p = &self.rays;
        let [w, h] = self.size;
        let (px, py) = (
            x as f64 + 0.5 + p.pixel_offset[0],
            y as f64 + 0.5 + p.pixel_offset[1],
        );
        let sx = (2.0 * px / w - 1.0) * p.tan_half_fov * w / h - p.shift.unwrap_or(0.0);
        let sy = (1.0 - 2.0 * py / h) * p.tan_half_fov;
        (p.forward + p.right * sx + p.up * sy).normalize()
    }
}

/// The previous frame as the new rays see it.
#[derive(Debug, Clone, Copy)]
struct Reprojection<'a> {
    camera: Pinhole,
    depths: &'a MinPyramid,
    /// The new eye less the old, in the old camera's right, up, forward axes.
    moved: DVec3,
    /// Pixels per unit of the image plane at distance 1.
    focal: f64,
}

impl Reprojection<'_> {
    /// The old camera's pixel, as `[x, y]` (continuous), of the image-plane point `(a, b)` at
    /// forward distance 1.
    fn pixel(&self, a: f64, b: f64) -> [f64; 2] {
        let p = &self.camera.rays;
        let [w, h] = self.camera.size;
        [
            (a + p.shift.unwrap_or(0.0)) * self.focal + w / 2.0 - p.pixel_offset[0],
            h / 2.0 - b * self.focal - p.pixel_offset[1],
        ]
    }

    /// How far (mm) the new ray in direction `dir` is shown empty, given that it is up to `t`.
    fn extend(&self, dir: DVec3, mut t: f64, min_gain: f64) -> f64 {
        let p = &self.camera.rays;
        let (a, b, c) = (dir.dot(p.right), dir.dot(p.up), dir.dot(p.forward));
        if c.is_nan() || c <= 1e-6 {
            return t;
        }
        let far = self.pixel(a / c, b / c);
        let m = self.moved;
        for _ in 0..ROUNDS {
            let z = m.z + t * c;
            if z.is_nan() || z <= 0.0 {
                break;
            }
            let near = self.pixel((m.x + t * a) / z, (m.y + t * b) / z);
            let Some((xs, ys)) = self.pixel_box(near, far) else {
                break;
            };
            let s = (f64::from(self.depths.min_in(xs, ys)) - m.z) / c;
            if s.is_nan() || s <= t + min_gain {
                break;
            }
            t = s;
        }
        t
    }

    /// The pixels between continuous positions `p` and `q`, if all lie in the image.
    fn pixel_box(&self, p: [f64; 2], q: [f64; 2]) -> Option<([usize; 2], [usize; 2])> {
        let [w, h] = self.camera.size;
        let span = |a: f64, b: f64, n: f64| {
            let (lo, hi) = (a.min(b).floor(), a.max(b).floor());
            // Truncation is the floor of these non-negative values.
            (lo >= 0.0 && hi < n).then_some([lo as usize, hi as usize])
        };
        Some((span(p[0], q[0], w)?, span(p[1], q[1], h)?))
    }
}

/// How the starts of one new frame are made.
#[derive(Debug, Clone, Copy)]
pub(super) struct Plan<'a> {
    camera: Pinhole,
    previous: Option<Reprojection<'a>>,
    /// Where every ray leaves the clear ball around the eye (mm): the check distance.
    ball_mm: f64,
    /// Smallest gain (mm) worth a late start.
    min_gain: f64,
    size: [usize; 2],
}

impl<'a> Plan<'a> {
    /// The plan for `camera` (a pinhole), with `previous` — the old camera and its depths —
    /// where they may be used, and the clear ball's radius (voxels) around the eye.
    pub fn new(
        camera: &Camera,
        previous: Option<(&Camera, &'a MinPyramid)>,
        (radius_vox, scale): (f32, Scale),
    ) -> Option<Self> {
        let new = Pinhole::of(camera)?;
        let previous = previous.and_then(|(old, depths)| {
            let old = Pinhole::of(old)?;
            let p = &old.rays;
            let moved = new.rays.origin - p.origin;
            Some(Reprojection {
                camera: old,
                depths,
                moved: DVec3::new(moved.dot(p.right), moved.dot(p.up), moved.dot(p.forward)),
                focal: old.size[1] / (2.0 * p.tan_half_fov),
            })
        });
        // The sample after the check must lie in the ball too (see `LateStarts`), a hair
        // inside it (the samples are taken in f32).
        let ball_mm = 0.998 * f64::from(radius_vox) / scale.voxels_per_mm - scale.step_mm;
        Some(Self {
            camera: new,
            previous,
            ball_mm: ball_mm.max(0.0),
            min_gain: 2.0 * scale.step_mm,
            size: camera.size(),
        })
    }

    /// Fills `out` with every pixel's `[check, start]` and the clear ball `clear` (the eye in
    /// voxel space, the radius in voxels); returns how many pixels start late.
    pub fn fill(&self, out: &mut SearchStarts, clear: (Vec3, f32)) -> usize {
        let count = std::sync::atomic::AtomicUsize::new(0);
        let check = self.ball_mm;
        out.fill_rows(self.size, clear, |y, row| {
            let mut late = 0;
            for (x, start) in row.iter_mut().enumerate() {
                let end = match &self.previous {
                    Some(previous) => previous.extend(self.camera.dir(x, y), check, self.min_gain),
                    None => check,
                };
                *start = if end > self.min_gain {
                    late += 1;
                    [check as f32, (end * ROUND_DOWN) as f32]
                } else {
                    [f32::NAN; 2]
                };
            }
            count.fetch_add(late, std::sync::atomic::Ordering::Relaxed);
        });
        count.into_inner()
    }
}
