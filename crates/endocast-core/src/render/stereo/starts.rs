//! The second eye's start-up: from the first eye's depth image to a search start per pixel
//! (see the parent module's doc for the geometry). One parallel pass turns the depths along
//! the rays into depths along the view axis (`f32`, rounded down), one pass per row takes the
//! 3×3 minima, the suffix minima of `g_j` and walks the row's pixels; the per-column and
//! per-row terms (`q`, the entry depth, the rays' secants) are computed once per frame.

use super::super::Frame;
use crate::camera::Camera;
use rayon::prelude::*;

/// Relative amount by which the `f32` forward depths are made smaller than computed: more than
/// the rounding of their five `f32` operations (each at most 2⁻²⁴ relative).
const ROUND_DOWN: f32 = 1.0 - 1e-6;

/// What one stereo pair's start-up needs besides the depth image.
#[derive(Debug, Clone, Copy)]
pub(super) struct Geometry {
    /// `K = e / tan(fov/2) · h/2`, pixel·mm.
    pub k: f64,
    /// The focus distance, mm.
    pub focus_mm: f64,
    /// Subtracted from the left eye's 3×3 minimum depths, mm.
    pub margin: f64,
    /// Smallest gain (mm) between the check distance and the start worth a late start.
    pub min_gain: f64,
}

/// The start-up's buffers, reused from pair to pair.
#[derive(Debug, Clone, Default)]
pub(super) struct Buffers {
    /// The left eye's depths along its view axis, `f32` rounded down.
    depths: Vec<f32>,
    /// Per column of the right eye (see [`Column`]).
    columns: Vec<Column>,
}

/// What the right rays of one column share in every row.
#[derive(Debug, Clone, Copy)]
struct Column {
    /// `q = x + ½ − K/f`.
    q: f64,
    /// The depth where the column's rays enter the left image's field (`x_L = w`).
    z_enter: f64,
    /// The first left column the rays can leave the known-empty region at: `floor(q)`, or 0
    /// where `q < 0`, at most `w`.
    lo: usize,
}

/// The right eye's per-pixel `[check, start]` (mm along the ray; NaN where the search starts
/// at the eye) into `starts`, from the `left` eye's frame.
pub(super) fn fill(
    left: (&Camera, &Frame),
    right: &Camera,
    geometry: Geometry,
    buffers: &mut Buffers,
    starts: &mut Vec<[f32; 2]>,
) {
    let [w, h] = right.size();
    forward_depths(left.0, left.1, &mut buffers.depths);
    let k = geometry.k;
    buffers.columns.clear();
    buffers.columns.extend((0..w).map(|x| {
        let q = x as f64 + 0.5 - k / geometry.focus_mm;
        // Truncation is the floor from 0 up.
        let lo = (q.max(0.0) as usize).min(w);
        Column {
            q,
            z_enter: k / (w as f64 - q),
            lo,
        }
    }));
    let secants = PinholeSecants::of(right);
    starts.resize(w * h, [f32::NAN; 2]);
    let (depths, columns) = (&buffers.depths, &buffers.columns);
    starts.par_chunks_mut(w).enumerate().for_each_init(
        || RowBounds::with_width(w),
        |bounds, (y, row)| {
            bounds.fill(depths, [w, h], y, geometry);
            secants.row(y, &mut bounds.secant);
            let mut walker = bounds.walker();
            for ((start, column), &secant) in row.iter_mut().zip(columns).zip(&bounds.secant) {
                *start = [f32::NAN; 2];
                let Some(z_safe) = walker.empty_until(column, k) else {
                    continue;
                };
                let (check, skip) = (column.z_enter * secant, z_safe * secant);
                if skip > check + geometry.min_gain {
                    *start = [check as f32, skip as f32];
                }
            }
        },
    );
}

/// The secant of the angle between a pinhole camera's pixel rays and its view axis,
/// `√(1 + sx² + sy²)` (the rays pass through `forward + right·sx + up·sy`), from its
/// per-column and per-row terms.
pub(super) struct PinholeSecants {
    /// `sx²` per column, `sy²` per row.
    sx2: Vec<f64>,
    sy2: Vec<f64>,
}

impl PinholeSecants {
    /// The secants of `camera`'s pixel rays.
    pub fn of(camera: &Camera) -> Self {
        let [w, h] = camera.size().map(|n| n as f64);
        let tan = (camera.fov_deg().to_radians() / 2.0).tan();
        let shift = camera.eye_shift().map_or(0.0, |e| e.offset_mm / e.focus_mm);
        let [columns, rows] = camera.size();
        let sx = |x: usize| (1.0 / w - 1.0) * tan * w / h - shift + 2.0 * tan / h * x as f64;
        let sy = |y: usize| (1.0 - 1.0 / h) * tan - 2.0 * tan / h * y as f64;
        Self {
            sx2: (0..columns).map(|x| sx(x) * sx(x)).collect(),
            sy2: (0..rows).map(|y| sy(y) * sy(y)).collect(),
        }
    }

    /// The secants of row `y` into `out` (one per column).
    pub fn row(&self, y: usize, out: &mut [f64]) {
        let base = 1.0 + self.sy2[y];
        for (s, sx2) in out.iter_mut().zip(&self.sx2) {
            *s = (base + sx2).sqrt();
        }
    }
}

/// A pinhole's hit depths along its view axis (mm), rounded down, into `out`; `+∞` where a ray
/// hit nothing.
pub(in crate::render) fn forward_depths(camera: &Camera, frame: &Frame, out: &mut Vec<f32>) {
    let [w, _] = camera.size();
    let secants = PinholeSecants::of(camera);
    let sx2: Vec<f32> = secants.sx2.iter().map(|&s| s as f32).collect();
    out.resize(frame.depth_mm.len(), 0.0);
    out.par_chunks_mut(w)
        .zip(frame.depth_mm.par_chunks(w))
        .enumerate()
        .for_each(|(y, (row, depths))| {
            let base = 1.0 + secants.sy2[y] as f32;
            for ((z, &d), &sx2) in row.iter_mut().zip(depths).zip(&sx2) {
                let forward = d / (base + sx2).sqrt() * ROUND_DOWN;
                *z = if d.is_finite() {
                    forward
                } else {
                    f32::INFINITY
                };
            }
        });
}

/// One row of the left image as the right rays of that row see it, and the row's secants
/// (buffers reused from row to row).
struct RowBounds {
    /// Per left column: the three-row minimum of the forward depths.
    three_rows: Vec<f32>,
    /// Per left column `j`: the conservative empty depth `Z_j` (mm).
    depth: Vec<f64>,
    /// Suffix minima of `g_j = j − K/Z_j`: `suffix[j] = min over i ≥ j`, non-decreasing (the
    /// `g_j` themselves while they are filled in).
    suffix: Vec<f64>,
    /// The right eye's secants of the row.
    secant: Vec<f64>,
}

impl RowBounds {
    fn with_width(w: usize) -> Self {
        Self {
            three_rows: vec![0.0; w],
            depth: vec![0.0; w],
            suffix: vec![0.0; w],
            secant: vec![0.0; w],
        }
    }

    /// Takes row `y` of the forward `depths`: each column's depth is the minimum over the 3×3
    /// pixels around it, less the margin. (The depths hold no NaN, so the minima are plain
    /// comparisons, which vectorise.)
    fn fill(&mut self, depths: &[f32], [w, h]: [usize; 2], y: usize, geometry: Geometry) {
        let (first, last) = (y.saturating_sub(1), (y + 1).min(h - 1));
        let rows = &mut self.three_rows;
        rows.copy_from_slice(&depths[first * w..][..w]);
        for r in first + 1..=last {
            for (m, &d) in rows.iter_mut().zip(&depths[r * w..][..w]) {
                *m = smaller(*m, d);
            }
        }
        let nearest = |j: usize| {
            let (a, b) = (rows[j.saturating_sub(1)], rows[(j + 1).min(w - 1)]);
            smaller(smaller(a, rows[j]), b)
        };
        for (j, (depth, g)) in self.depth.iter_mut().zip(&mut self.suffix).enumerate() {
            *depth = f64::from(nearest(j)) - geometry.margin;
            // Computed either way and then chosen, so that the loop has no branch.
            let behind = j as f64 - geometry.k / *depth;
            *g = if *depth > 0.0 {
                behind
            } else {
                f64::NEG_INFINITY
            };
        }
        let mut running = f64::INFINITY;
        for g in self.suffix.iter_mut().rev() {
            running = if *g < running { *g } else { running };
            *g = running;
        }
    }

    /// A walk along the row's pixels, left to right.
    fn walker(&self) -> RowWalker<'_> {
        RowWalker {
            bounds: self,
            below: 0,
        }
    }
}

/// The right rays of one row, taken left to right (`q` growing), so the suffix-minimum search
/// moves one way: `O(w)` a row.
struct RowWalker<'a> {
    bounds: &'a RowBounds,
    /// How many leading suffix minima are ≤ the last `q` (they are non-decreasing).
    below: usize,
}

impl RowWalker<'_> {
    /// For the right ray of `column` (whose `q` is not smaller than the last call's): the
    /// depth where it leaves the known-empty region; `None` where it never enters the left
    /// image or leaves at once.
    fn empty_until(&mut self, column: &Column, k: f64) -> Option<f64> {
        let (depth, suffix) = (&self.bounds.depth, &self.bounds.suffix);
        let Column { q, z_enter, lo } = *column;
        let w = depth.len();
        if w as f64 - q <= 0.0 {
            return None;
        }
        // The largest column j ≥ lo with g_j ≤ q: the last suffix minimum ≤ q (non-decreasing
        // in j, and the answer non-decreasing in q).
        while self.below < w && suffix[self.below] <= q {
            self.below += 1;
        }
        let z_safe = if self.below > lo {
            let j = self.below - 1;
            let z_entry = k / (j as f64 + 1.0 - q);
            z_entry.max(depth[j])
        } else if q < 0.0 {
            // Leaves the left image through its left edge.
            k / -q
        } else {
            f64::INFINITY
        };
        (z_safe > z_enter).then_some(z_safe)
    }
}

/// The smaller of `a` and `b`, neither NaN.
#[inline]
fn smaller(a: f32, b: f32) -> f32 {
    if b < a {
        b
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::StereoRig;
    use glam::DVec3;

    #[test]
    fn closed_form_secants_are_the_rays() {
        let camera = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 75.0, [37, 20]).unwrap();
        let rig = StereoRig {
            eye_separation_mm: 1.0,
            focus_mm: 9.0,
        };
        for eye in [camera, rig.eyes(&camera).unwrap()[1]] {
            let secants = PinholeSecants::of(&eye);
            let mut row = vec![0.0; 37];
            for (x, y) in [(0, 0), (36, 19), (18, 3)] {
                secants.row(y, &mut row);
                let cos = eye.pixel_ray(x, y).unwrap().dir.dot(eye.forward());
                assert!((row[x] * cos - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn forward_depths_are_rounded_down_and_close() {
        let camera = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0, [64, 48]).unwrap();
        let mut frame = Frame {
            depth_mm: (0..64 * 48)
                .map(|i| 1.0 + (i % 997) as f32 * 0.37)
                .collect(),
            ..Default::default()
        };
        frame.depth_mm[5] = f32::NAN;
        let mut out = Vec::new();
        forward_depths(&camera, &frame, &mut out);
        assert_eq!(out[5], f32::INFINITY);
        for (i, (&z, &d)) in out.iter().zip(&frame.depth_mm).enumerate() {
            if i == 5 {
                continue;
            }
            let ray = camera.pixel_ray(i % 64, i / 64).unwrap();
            let exact = f64::from(d) * ray.dir.dot(camera.forward());
            assert!(f64::from(z) <= exact && f64::from(z) > exact * (1.0 - 2e-6));
        }
    }
}
