//! Reduced quality: rays cast at a half or a quarter of the width and height, by a camera of
//! the same pose and field of view, and the result upsampled to the full frame.
//!
//! The upsampling is depth-aware (a joint-bilateral filter guided by the low-resolution depth):
//! each full pixel takes the bilinear weights of the four nearest low-resolution samples, each
//! scaled by how close its first-hit depth lies to that of the *nearest* sample, and zero across
//! a depth discontinuity (or between a hit and a miss). Smooth surfaces are interpolated, while
//! a silhouette stays as sharp as the coarse grid allows instead of blending the near wall into
//! the far one. Where no ray hit a surface (DVR, MIP), depths are all NaN and the filter is
//! plain bilinear. Cells whose four samples lie on one smooth surface (most of them) take the
//! plain bilinear path without weights: 128² → 512² takes about a millisecond on two cores.

use super::frame::{Frame, Layers, Premultiplied};
use super::options::{Cancelled, Quality, RenderOptions};
use super::{Camera, Prepared};
use rayon::prelude::*;

/// Relative depth difference (to the nearest sample's depth) at which a sample's weight falls
/// to zero: neighbours on one smooth wall differ by a few per cent even at grazing angles,
/// while a silhouette in a lumen jumps by tens.
const DEPTH_EDGE: f32 = 0.1;

/// The camera that casts `camera`'s rays at `size`: the same pose, projection, field, lens,
/// stereo eye and near distance.
///
/// # Panics
///
/// When `size` is zero or larger than [`super::MAX_IMAGE_EDGE`] along an edge (a reduced size
/// of a valid camera is neither).
pub fn reduced_camera(camera: &Camera, size: [usize; 2]) -> Camera {
    match camera.with_size(size) {
        Ok(c) => c,
        Err(e) => unreachable!("a valid camera at a smaller size: {e}"),
    }
}

/// Renders `camera`'s frame at `quality` (below full) into `frame`.
pub(crate) fn render_reduced(
    prepared: &Prepared,
    camera: &Camera,
    quality: Quality,
    options: &RenderOptions<'_>,
    frame: &mut Frame,
) -> Result<(), Cancelled> {
    let full = camera.size();
    let size = quality.reduced_size(full);
    let small = reduced_camera(camera, size);
    let map = PixelMap::new(full, size);
    // Each ray takes the limit of the full pixel its centre falls in.
    let max_small: Option<Vec<f32>> = options.max_distance_mm.map(|max| {
        let mut limits = Vec::with_capacity(size[0] * size[1]);
        for y in 0..size[1] {
            let fy = map.full_of(y as f32 + 0.5, full[1], size[1]);
            for x in 0..size[0] {
                let fx = map.full_of(x as f32 + 0.5, full[0], size[0]);
                limits.push(max[fx + full[0] * fy]);
            }
        }
        limits
    });
    let low_options = RenderOptions {
        quality: Quality::Full,
        max_distance_mm: max_small.as_deref(),
        ..*options
    };
    let mut low = Frame::default();
    prepared.render_tiles(&small, &low_options, &mut low)?;
    upsample(&low, full, frame);
    Ok(())
}

/// Where full-resolution pixel centres fall on the low-resolution grid. The reduced camera has
/// the same vertical field of view, so both axes scale by `low height / full height` about the
/// image centre (exact even where rounding the size up changed the aspect ratio).
#[derive(Debug, Clone, Copy)]
struct PixelMap {
    scale: f32,
    full: [usize; 2],
    low: [usize; 2],
}

impl PixelMap {
    fn new(full: [usize; 2], low: [usize; 2]) -> Self {
        Self {
            scale: low[1] as f32 / full[1] as f32,
            full,
            low,
        }
    }

    /// The low-resolution position (pixel centres at integers) of full pixel centre `c`
    /// (pixels, centres at half-integers) along an axis.
    fn low_of(&self, c: f32, horizontal: bool) -> f32 {
        let (full, low) = if horizontal {
            (self.full[0], self.low[0])
        } else {
            (self.full[1], self.low[1])
        };
        (c - full as f32 / 2.0) * self.scale + low as f32 / 2.0 - 0.5
    }

    /// The full pixel (index) that low-resolution position `c` (centres at half-integers)
    /// falls in.
    fn full_of(&self, c: f32, full: usize, low: usize) -> usize {
        let x = (c - low as f32 / 2.0) / self.scale + full as f32 / 2.0;
        (x.max(0.0) as usize).min(full - 1)
    }

    /// The two low-resolution samples around position `p` along an axis of `n` samples, the
    /// weight of the second, and which of the two is nearer.
    fn taps(p: f32, n: usize) -> Taps {
        let last = n - 1;
        let p = p.clamp(0.0, last as f32);
        let i0 = (p as usize).min(last);
        let i1 = (i0 + 1).min(last);
        let t = p - i0 as f32;
        Taps {
            i0,
            i1,
            t,
            nearest_second: t > 0.5,
        }
    }
}

/// Two neighbouring low-resolution samples along one axis.
#[derive(Debug, Clone, Copy)]
struct Taps {
    i0: usize,
    i1: usize,
    /// Bilinear weight of `i1`.
    t: f32,
    nearest_second: bool,
}

/// How much a sample of depth `d` counts beside the nearest sample's depth `reference`: fully
/// up to half a relative difference of [`DEPTH_EDGE`] (so a smooth wall is plain bilinear),
/// then less, and not at all from [`DEPTH_EDGE`] on; NaN (no hit) is only like NaN.
#[inline]
fn depth_weight(d: f32, reference: f32) -> f32 {
    match (d.is_nan(), reference.is_nan()) {
        (true, true) => 1.0,
        (false, false) => {
            let r = (d - reference) / (DEPTH_EDGE * reference.abs()).max(f32::MIN_POSITIVE);
            (2.0 - 2.0 * r.abs()).clamp(0.0, 1.0)
        }
        _ => 0.0,
    }
}

/// Upsamples `low` to a frame of `size` into `frame`, depth-aware (see the module's doc): colour,
/// depth and value are weighted means of the samples that count; the optional layers come
/// from the nearest sample. The counters are `low`'s.
pub fn upsample(low: &Frame, size: [usize; 2], frame: &mut Frame) {
    let layers = low.layers();
    frame.resize(size, layers);
    frame.stats = low.stats;
    if low.is_empty() || frame.is_empty() {
        return;
    }
    let map = PixelMap::new(size, [low.width, low.height]);
    let columns: Vec<Taps> = (0..size[0])
        .map(|x| PixelMap::taps(map.low_of(x as f32 + 0.5, true), low.width))
        .collect();
    let w = size[0];
    let smooth = smooth_cells(low);
    frame
        .color
        .par_chunks_mut(w)
        .zip(frame.depth_mm.par_chunks_mut(w))
        .zip(frame.value.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, ((color, depth), value))| {
            let row = PixelMap::taps(map.low_of(y as f32 + 0.5, false), low.height);
            let smooth_row = &smooth[row.i0 * low.width..][..low.width];
            for (x, tx) in columns.iter().enumerate() {
                (color[x], depth[x], value[x]) = if smooth_row[tx.i0] {
                    bilinear(low, tx, &row)
                } else {
                    blend(low, tx, &row)
                };
            }
        });
    if !layers.is_empty() {
        let nearest = |x: usize, y: usize| {
            let (tx, ty) = (
                &columns[x],
                PixelMap::taps(map.low_of(y as f32 + 0.5, false), low.height),
            );
            let lx = if tx.nearest_second { tx.i1 } else { tx.i0 };
            let ly = if ty.nearest_second { ty.i1 } else { ty.i0 };
            lx + low.width * ly
        };
        let copy = |to: &mut Vec<[f32; 3]>, from: &[[f32; 3]]| {
            to.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
                for (x, out) in row.iter_mut().enumerate() {
                    *out = from[nearest(x, y)];
                }
            });
        };
        if layers.contains(Layers::HIT_POSITION) {
            copy(&mut frame.hit_mm, &low.hit_mm);
        }
        if layers.contains(Layers::NORMAL) {
            copy(&mut frame.normal, &low.normal);
        }
        if layers.contains(Layers::DEPTHS) {
            let from = &low.layer_depths_mm;
            frame
                .layer_depths_mm
                .par_chunks_mut(w)
                .enumerate()
                .for_each(|(y, row)| {
                    for (x, out) in row.iter_mut().enumerate() {
                        *out = from[nearest(x, y)];
                    }
                });
        }
    }
}

/// Per low-resolution sample, whether the cell it spans with its right and lower neighbours
/// (clamped at the edges) is smooth: the four depths all NaN, or all finite and within the
/// range where [`depth_weight`] is 1 for any of them as reference; their values all NaN or all
/// finite. A smooth cell's pixels are plain bilinear ([`bilinear`]).
fn smooth_cells(low: &Frame) -> Vec<bool> {
    let (w, h) = (low.width, low.height);
    let mut smooth = vec![false; w * h];
    smooth.par_chunks_mut(w).enumerate().for_each(|(j, row)| {
        let j1 = (j + 1).min(h - 1);
        for (i, cell) in row.iter_mut().enumerate() {
            let i1 = (i + 1).min(w - 1);
            let index = [i + w * j, i1 + w * j, i + w * j1, i1 + w * j1];
            let depths = index.map(|k| low.depth_mm[k]);
            let values = index.map(|k| low.value[k]);
            let all_nan = |v: [f32; 4]| v.iter().all(|x| x.is_nan());
            let none_nan = |v: [f32; 4]| v.iter().all(|x| !x.is_nan());
            let depths_smooth = all_nan(depths) || {
                let lo = depths.iter().copied().fold(f32::INFINITY, f32::min);
                let hi = depths.iter().copied().fold(f32::NEG_INFINITY, f32::max);
                // `depth_weight` is 1 up to half of DEPTH_EDGE relative to the reference; the
                // smallest depth is the strictest reference.
                none_nan(depths) && lo > 0.0 && hi - lo <= 0.5 * DEPTH_EDGE * lo
            };
            *cell = depths_smooth && (all_nan(values) || none_nan(values));
        }
    });
    smooth
}

/// One full pixel of a smooth cell: bilinear, as two lerps across and one down (exact where
/// the four samples agree, and NaN where they are all NaN).
#[inline]
fn bilinear(low: &Frame, tx: &Taps, ty: &Taps) -> (Premultiplied, f32, f32) {
    let w = low.width;
    let (a, b, c, d) = (
        tx.i0 + w * ty.i0,
        tx.i1 + w * ty.i0,
        tx.i0 + w * ty.i1,
        tx.i1 + w * ty.i1,
    );
    let lerp2 = |v: [f32; 4]| {
        let top = v[0] + (v[1] - v[0]) * tx.t;
        let bottom = v[2] + (v[3] - v[2]) * tx.t;
        top + (bottom - top) * ty.t
    };
    let color = &low.color;
    let channel = |k: usize| {
        lerp2([
            color[a].rgb[k],
            color[b].rgb[k],
            color[c].rgb[k],
            color[d].rgb[k],
        ])
    };
    let t = |i: usize| color[i].transmittance;
    let premultiplied = Premultiplied {
        rgb: [channel(0), channel(1), channel(2)],
        transmittance: lerp2([t(a), t(b), t(c), t(d)]),
    };
    let (depth, value) = (&low.depth_mm, &low.value);
    (
        premultiplied,
        lerp2([depth[a], depth[b], depth[c], depth[d]]),
        lerp2([value[a], value[b], value[c], value[d]]),
    )
}

/// One full pixel from the four low-resolution samples around it.
#[inline]
fn blend(low: &Frame, tx: &Taps, ty: &Taps) -> (Premultiplied, f32, f32) {
    let w = low.width;
    let index = [
        tx.i0 + w * ty.i0,
        tx.i1 + w * ty.i0,
        tx.i0 + w * ty.i1,
        tx.i1 + w * ty.i1,
    ];
    let bilinear = [
        (1.0 - tx.t) * (1.0 - ty.t),
        tx.t * (1.0 - ty.t),
        (1.0 - tx.t) * ty.t,
        tx.t * ty.t,
    ];
    let nearest = usize::from(tx.nearest_second) + 2 * usize::from(ty.nearest_second);
    let reference = low.depth_mm[index[nearest]];
    let (mut rgb, mut transmittance, mut total) = ([0.0f32; 3], 0.0f32, 0.0f32);
    let (mut depth, mut value, mut value_weight) = (0.0f32, 0.0f32, 0.0f32);
    for (&i, &b) in index.iter().zip(&bilinear) {
        let d = low.depth_mm[i];
        let weight = b * depth_weight(d, reference);
        if weight == 0.0 {
            continue;
        }
        let c = &low.color[i];
        for (sum, c) in rgb.iter_mut().zip(c.rgb) {
            *sum += weight * c;
        }
        transmittance += weight * c.transmittance;
        total += weight;
        if !d.is_nan() {
            depth += weight * d;
        }
        let v = low.value[i];
        if !v.is_nan() {
            value += weight * v;
            value_weight += weight;
        }
    }
    // The nearest sample always counts (bilinear weight ≥ ¼, depth weight 1), so `total` > 0.
    let color = Premultiplied {
        rgb: rgb.map(|c| c / total),
        transmittance: transmittance / total,
    };
    let depth = if reference.is_nan() {
        f32::NAN
    } else {
        depth / total
    };
    let value = if low.value[index[nearest]].is_nan() {
        f32::NAN
    } else {
        value / value_weight
    };
    (color, depth, value)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A low-resolution frame whose left half is a near red wall and right half a far blue
    /// one.
    fn two_walls(size: [usize; 2]) -> Frame {
        let mut low = Frame::default();
        low.resize(size, Layers::NONE);
        for y in 0..size[1] {
            for x in 0..size[0] {
                let i = x + size[0] * y;
                let near = x < size[0] / 2;
                low.depth_mm[i] = if near { 10.0 } else { 100.0 };
                low.color[i] = Premultiplied {
                    rgb: if near {
                        [1.0, 0.0, 0.0]
                    } else {
                        [0.0, 0.0, 1.0]
                    },
                    transmittance: 0.0,
                };
            }
        }
        low
    }

    #[test]
    fn upsampling_keeps_a_silhouette_sharp() {
        let low = two_walls([8, 6]);
        let mut full = Frame::default();
        upsample(&low, [32, 24], &mut full);
        assert_eq!([full.width, full.height], [32, 24]);
        let red = Premultiplied {
            rgb: [1.0, 0.0, 0.0],
            transmittance: 0.0,
        };
        let blue = Premultiplied {
            rgb: [0.0, 0.0, 1.0],
            transmittance: 0.0,
        };
        for y in 0..24 {
            for x in 0..32 {
                let i = x + 32 * y;
                // Every pixel is one wall or the other, never a blend, and the edge lies where
                // the coarse grid put it (between low columns 3 and 4: full column 16).
                let (color, depth) = if x < 16 { (red, 10.0) } else { (blue, 100.0) };
                assert_eq!(full.color[i], color, "({x}, {y})");
                assert_eq!(full.depth_mm[i], depth, "({x}, {y})");
            }
        }
        // Plain bilinear filtering would have blended the columns next to the edge.
        let mut plain = low.clone();
        plain.depth_mm.fill(f32::NAN);
        upsample(&plain, [32, 24], &mut full);
        let blended = full.color[15].rgb;
        assert!(blended[0] > 0.0 && blended[2] > 0.0, "{blended:?}");
    }

    #[test]
    fn upsampling_interpolates_a_smooth_wall() {
        // A gently sloping wall (depths 50–53.5 mm) with a colour ramp: bilinear inside.
        let mut low = Frame::default();
        low.resize([8, 8], Layers::NONE);
        for i in 0..64 {
            let x = (i % 8) as f32;
            low.depth_mm[i] = 50.0 + 0.5 * x;
            low.color[i].rgb = [x / 8.0, 0.0, 0.0];
            low.color[i].transmittance = 0.0;
        }
        let mut full = Frame::default();
        upsample(&low, [32, 32], &mut full);
        // Full column 6 (centre 6.5) lies at low position 6.5 / 4 − 0.5 = 1.125.
        let expected = 1.125 / 8.0;
        assert!((full.color[6 + 32 * 10].rgb[0] - expected).abs() < 1e-6);
        assert!((full.depth_mm[6 + 32 * 10] - (50.0 + 0.5 * 1.125)).abs() < 1e-5);
    }
}

#[cfg(test)]
mod timing {
    use super::*;
    use std::time::Instant;

    #[test]
    #[ignore = "timing: run with --release -- --ignored --nocapture"]
    fn timing_upsample_quarter_to_512() {
        let mut low = Frame::default();
        low.resize([128, 128], Layers::NONE);
        for (i, d) in low.depth_mm.iter_mut().enumerate() {
            *d = 20.0 + (i % 128) as f32 * 0.05 + if i % 37 == 0 { 30.0 } else { 0.0 };
        }
        let mut full = Frame::default();
        let mut ms = Vec::new();
        for _ in 0..50 {
            let start = Instant::now();
            upsample(&low, [512, 512], &mut full);
            ms.push(start.elapsed().as_secs_f64() * 1e3);
        }
        ms.sort_by(f64::total_cmp);
        eprintln!(
            "upsample 128² → 512²: median {:.2} ms, min {:.2} ms",
            ms[25], ms[0]
        );
    }
}
