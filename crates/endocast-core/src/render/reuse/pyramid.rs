//! A frame's conservative forward depths as a min-pyramid: level 0 holds per pixel the smallest
//! forward depth of the 3×3 pixels around it less a margin (the stereo pair's `Z_j`), each
//! level above the minimum of 2×2 cells of the one below, so that the minimum over any box of
//! pixels is bounded from below by at most four reads.

use rayon::prelude::*;

/// One level: `width × height` cells, row by row.
#[derive(Debug, Clone, Default)]
struct Level {
    width: usize,
    height: usize,
    z: Vec<f32>,
}

/// Conservative forward depths (mm) and their minima over ever larger blocks.
#[derive(Debug, Clone, Default)]
pub(super) struct MinPyramid {
    levels: Vec<Level>,
}

impl MinPyramid {
    /// Rebuilds the pyramid in place (its buffers reused) from `forward` depths (mm, `+∞` where a
    /// ray hit nothing, none NaN) of an image of `[width, height]` pixels: level 0 is the 3×3
    /// minimum less `margin`.
    pub fn rebuild(&mut self, forward: &[f32], [width, height]: [usize; 2], margin: f32) {
        let mut sizes = vec![[width, height]];
        while let Some(&[w, h]) = sizes.last().filter(|[w, h]| *w > 1 || *h > 1) {
            sizes.push([w.div_ceil(2), h.div_ceil(2)]);
        }
        self.levels.resize_with(sizes.len(), Level::default);
        for (level, &[w, h]) in self.levels.iter_mut().zip(&sizes) {
            (level.width, level.height) = (w, h);
            level.z.resize(w * h, 0.0);
        }
        nearest_3x3(forward, &mut self.levels[0], margin);
        for k in 1..self.levels.len() {
            let (below, above) = self.levels.split_at_mut(k);
            halve(&below[k - 1], &mut above[0]);
        }
    }

    /// A lower bound of the level-0 values over pixels `x0..=x1` × `y0..=y1` (inside the
    /// image): the minimum of the at most 2×2 cells of the lowest level whose cells cover the
    /// box so.
    pub fn min_in(&self, [x0, x1]: [usize; 2], [y0, y1]: [usize; 2]) -> f32 {
        let span = (x0 ^ x1).max(y0 ^ y1);
        // The lowest level at which both ends fall into the same or neighbouring cells.
        let mut k = (usize::BITS - span.leading_zeros()).saturating_sub(1) as usize;
        while (x1 >> k) - (x0 >> k) > 1 || (y1 >> k) - (y0 >> k) > 1 {
            k += 1;
        }
        let level = &self.levels[k];
        let at = |x: usize, y: usize| level.z[(x >> k) + level.width * (y >> k)];
        at(x0, y0).min(at(x1, y0)).min(at(x0, y1)).min(at(x1, y1))
    }
}

/// Level 0: per pixel the minimum of the 3×3 `forward` depths around it, less `margin`.
fn nearest_3x3(forward: &[f32], level: &mut Level, margin: f32) {
    let (w, h) = (level.width, level.height);
    level.z.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let rows = y.saturating_sub(1)..=(y + 1).min(h - 1);
        for (x, z) in row.iter_mut().enumerate() {
            let columns = x.saturating_sub(1)..=(x + 1).min(w - 1);
            let mut nearest = f32::INFINITY;
            for r in rows.clone() {
                for &d in &forward[r * w..][columns.clone()] {
                    nearest = nearest.min(d);
                }
            }
            *z = nearest - margin;
        }
    });
}

/// The level above `below`: each cell the minimum of its (up to) 2×2 cells below.
fn halve(below: &Level, above: &mut Level) {
    let (bw, bh) = (below.width, below.height);
    for y in 0..above.height {
        let rows = [2 * y, (2 * y + 1).min(bh - 1)];
        for x in 0..above.width {
            let columns = [2 * x, (2 * x + 1).min(bw - 1)];
            let mut m = f32::INFINITY;
            for r in rows {
                for c in columns {
                    m = m.min(below.z[c + bw * r]);
                }
            }
            above.z[x + above.width * y] = m;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_rng::Rng;

    /// Every box's bound is at most the true minimum of its 3×3-widened pixels less the
    /// margin, and not far below it for a box of one pixel.
    #[test]
    fn box_bounds_lie_below_the_true_minimum() {
        let (w, h) = (37, 23);
        let mut rng = Rng::new(3);
        let forward: Vec<f32> = (0..w * h)
            .map(|_| {
                let v = rng.vec().x as f32;
                if v > 0.8 {
                    f32::INFINITY
                } else {
                    10.0 + 50.0 * v.abs()
                }
            })
            .collect();
        let mut pyramid = MinPyramid::default();
        pyramid.rebuild(&forward, [w, h], 0.5);
        let truth = |[x0, x1]: [usize; 2], [y0, y1]: [usize; 2]| {
            let mut m = f32::INFINITY;
            for y in y0.saturating_sub(1)..=(y1 + 1).min(h - 1) {
                for x in x0.saturating_sub(1)..=(x1 + 1).min(w - 1) {
                    m = m.min(forward[x + w * y]);
                }
            }
            m - 0.5
        };
        for _ in 0..2000 {
            let v = rng.vec();
            let pick = |a: f64, n: usize| ((a.abs() * n as f64) as usize).min(n - 1);
            let (xa, xb) = (pick(v.x, w), pick(v.y, w));
            let (ya, yb) = (pick(v.z, h), pick(v.x * v.y, h));
            let (xs, ys) = ([xa.min(xb), xa.max(xb)], [ya.min(yb), ya.max(yb)]);
            assert!(pyramid.min_in(xs, ys) <= truth(xs, ys), "{xs:?} {ys:?}");
            if xa == xb && ya == yb {
                assert_eq!(pyramid.min_in(xs, ys), truth(xs, ys));
            }
        }
    }
}
