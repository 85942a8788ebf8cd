//! Depth-aware image-space smoothing of the G-buffer (Krüger et al. §4.4): depth, hit
//! positions, normals and secretion are averaged over a small window, each neighbour weighted by
//! its distance in pixels and by how close its depth lies to the centre's, so sampling noise
//! goes while silhouettes stay: across a depth discontinuity (a fold in front of a far wall) a
//! neighbour's weight is zero.
//!
//! Two one-dimensional passes (rows, then columns), each weighting by the centre pixel's depth:
//! the usual separable form of a cross-bilateral filter. They run on bands of rows (the rows'
//! pass over the band and the window's rows above and below it, then the columns' pass), each
//! band's channels in planes that stay in the cache, eight pixels at a time
//! ([`super::lanes`]); [`SmoothBands::run`] hands each smoothed row on as it is done, so the
//! shading reads it from the cache instead of a smoothed G-buffer in memory.

use super::gbuffer::GBuffer;
use super::lanes::{load, map, normalize_or_zero, padded, Lanes, LANES};
use crate::render::with_avx2;
use rayon::prelude::*;

/// Relative depth difference (to the centre's depth) at which a neighbour's weight falls to
/// zero; up to half of it the weight is full. Neighbours on one wall differ by a few per cent
/// even at grazing angles, while a silhouette jumps by tens.
pub const DEPTH_EDGE: f32 = 0.08;

/// Channels smoothed per pixel: depth, hit position (3), normal (3), secretion.
pub(super) const CHANNELS: usize = 8;
/// The depth's channel.
pub(super) const DEPTH: usize = 0;
/// The hit position's first channel (x; y and z follow).
pub(super) const HIT: usize = 1;
/// The normal's first channel.
pub(super) const NORMAL: usize = 4;
/// The secretion's channel.
pub(super) const SECRETION: usize = 7;

/// Rows per band: each band also filters the window's rows above and below it.
pub(super) const BAND_ROWS: usize = 16;

/// The depth of "no hit" in the smoothing's planes: finite, so that its zero weight times it
/// adds nothing, and so far that no centre gives it weight.
const NO_HIT: f32 = f32::MAX;

/// A row of channel planes, each [`padded`] to whole lane sets.
pub(super) type Planes = [Vec<f32>; CHANNELS];

/// The weight of a neighbour at depth `d` for a centre at depth `centre` (both finite).
#[inline]
pub fn depth_weight(d: f32, centre: f32) -> f32 {
    weight_by_distance(d - centre, inverse_edge(centre))
}

/// One over the depth difference at which a neighbour of a centre at depth `centre` loses all
/// weight (computed once per centre).
#[inline(always)]
fn inverse_edge(centre: f32) -> f32 {
    1.0 / (DEPTH_EDGE * centre.abs()).max(1e-3)
}

/// The weight of a neighbour `difference` deeper than the centre, `inverse` its
/// [`inverse_edge`].
#[inline(always)]
fn weight_by_distance(difference: f32, inverse: f32) -> f32 {
    (2.0 - 2.0 * difference.abs() * inverse).clamp(0.0, 1.0)
}

/// `gbuffer` smoothed over a window of `2 · radius + 1` pixels each way (0: unchanged; the
/// secretion's surface normals and the clipped pixels are never smoothed: the shading reads them as traced). Pixels
/// without a hit stay without one (NaN depth, position and normal, no secretion) and give no
/// weight to those with one.
pub fn smooth(gbuffer: &GBuffer, radius: usize) -> GBuffer {
    if radius == 0 || gbuffer.is_empty() {
        return gbuffer.clone();
    }
    let (w, n) = (gbuffer.width, gbuffer.len());
    let mut out = GBuffer {
        width: w,
        height: gbuffer.height,
        depth_mm: vec![0.0; n],
        hit_mm: vec![[0.0; 3]; n],
        normal: vec![[0.0; 3]; n],
        secretion_mm: vec![0.0; n],
        secretion_normal: gbuffer.secretion_normal.clone(),
        clipped: gbuffer.clipped.clone(),
        stats: gbuffer.stats,
    };
    let bands = SmoothBands::new(gbuffer, radius);
    let band = bands.band_pixels();
    out.depth_mm
        .par_chunks_mut(band)
        .zip(out.hit_mm.par_chunks_mut(band))
        .zip(out.normal.par_chunks_mut(band))
        .zip(out.secretion_mm.par_chunks_mut(band))
        .enumerate()
        .for_each_init(
            || bands.scratch(),
            |scratch, (b, (((depth, hit), normal), secretion))| {
                bands.run(
                    b,
                    scratch,
                    #[inline(always)]
                    |row, planes| {
                        let at = row * w;
                        for x in 0..w {
                            let c = |channel: usize| planes[channel][x];
                            depth[at + x] = c(DEPTH);
                            hit[at + x] = [c(HIT), c(HIT + 1), c(HIT + 2)];
                            normal[at + x] = [c(NORMAL), c(NORMAL + 1), c(NORMAL + 2)];
                            secretion[at + x] = c(SECRETION);
                        }
                    },
                );
            },
        );
    out
}

/// The smoothing of one G-buffer, band by band: `run` smooths band `b` (rows
/// `b · BAND_ROWS ..`) and hands on each smoothed row. Bands are independent, so they run in
/// parallel, each with its own [`Scratch`].
pub(super) struct SmoothBands<'a> {
    gbuffer: &'a GBuffer,
    /// Gaussian weights by distance in pixels, 0 ..= radius.
    kernel: Vec<f32>,
}

/// A band's working rows (reused from band to band).
pub(super) struct Scratch {
    /// One G-buffer row, `radius` pixels of padding (no hit) either side.
    input: Planes,
    /// The rows' pass over the band and `radius` rows either side, one padded row after the
    /// other; no hit ([`NO_HIT`], zero channels) beyond the image.
    across: Planes,
    /// The smoothed row handed on.
    out: Planes,
}

impl<'a> SmoothBands<'a> {
    /// The smoothing of `gbuffer` over a window of `2 · radius + 1` pixels each way (0: each
    /// pixel as it is, its normal renormalised).
    pub fn new(gbuffer: &'a GBuffer, radius: usize) -> Self {
        let sigma = 0.5 * radius as f32 + 0.5;
        let kernel = (0..=radius)
            .map(|k| (-0.5 * (k as f32 / sigma).powi(2)).exp())
            .collect();
        Self { gbuffer, kernel }
    }

    /// Pixels a band's rows hold.
    pub fn band_pixels(&self) -> usize {
        BAND_ROWS * self.gbuffer.width
    }

    /// Working rows for [`Self::run`].
    pub fn scratch(&self) -> Scratch {
        let (w, r) = (padded(self.gbuffer.width), self.radius());
        let planes = |n: usize| std::array::from_fn(|_| vec![0.0; n]);
        Scratch {
            input: planes(w + 2 * r),
            across: planes(w * (BAND_ROWS + 2 * r)),
            out: planes(w),
        }
    }

    fn radius(&self) -> usize {
        self.kernel.len() - 1
    }

    /// Smooths band `b` and calls `emit(row in the band, planes)` on each of its rows in turn:
    /// the planes hold the smoothed depth (NaN without a hit), hit position, unit normal (NaN
    /// without a hit) and secretion of its pixels `0 .. width` (those past it are padding).
    /// Compiled for AVX2 where the CPU has it, with `emit` inlined.
    #[inline(always)]
    pub fn run(&self, b: usize, scratch: &mut Scratch, mut emit: impl FnMut(usize, &Planes)) {
        with_avx2(
            #[inline(always)]
            || {
                let (h, r) = (self.gbuffer.height, self.radius() as isize);
                let rows = b * BAND_ROWS..((b + 1) * BAND_ROWS).min(h);
                let first = rows.start as isize - r;
                for (slot, y) in (first..rows.end as isize + r).enumerate() {
                    let y = usize::try_from(y).ok().filter(|&y| y < h);
                    self.across_row(y, slot, scratch);
                }
                for row in 0..rows.len() {
                    self.down_row(row + r as usize, scratch);
                    emit(row, &scratch.out);
                }
            },
        );
    }

    /// The rows' pass over G-buffer row `y` (`None`: beyond the image) into slot `slot` of
    /// `scratch.across`.
    #[inline(always)]
    fn across_row(&self, y: Option<usize>, slot: usize, scratch: &mut Scratch) {
        let w = padded(self.gbuffer.width);
        let at = slot * w;
        let Some(y) = y else {
            for (channel, plane) in scratch.across.iter_mut().enumerate() {
                plane[at..at + w].fill(if channel == DEPTH { NO_HIT } else { 0.0 });
            }
            return;
        };
        self.gather(y, &mut scratch.input);
        let r = self.radius();
        for x0 in (0..w).step_by(LANES) {
            let mut window = Window::new(load(&scratch.input[DEPTH], x0 + r));
            for k in 0..=2 * r {
                window.add(self.kernel[k.abs_diff(r)], |c| {
                    load(&scratch.input[c], x0 + k)
                });
            }
            let mean = window.mean([NO_HIT, 0.0]);
            for (plane, m) in scratch.across.iter_mut().zip(&mean) {
                plane[at + x0..at + x0 + LANES].copy_from_slice(m);
            }
        }
    }

    /// G-buffer row `y` into `input`: no hit ([`NO_HIT`], zero channels) in the padding
    /// and where the ray missed.
    #[inline(always)]
    fn gather(&self, y: usize, input: &mut Planes) {
        let g = self.gbuffer;
        let (w, r) = (g.width, self.radius());
        let row = w * y..w * (y + 1);
        let depth = &g.depth_mm[row.clone()];
        for (channel, plane) in input.iter_mut().enumerate() {
            let miss = if channel == DEPTH { NO_HIT } else { 0.0 };
            plane[..r].fill(miss);
            plane[r + w..].fill(miss);
            let (out, rows) = (&mut plane[r..r + w], row.clone());
            match channel {
                DEPTH => copy_hits(out, depth.iter().copied(), depth, miss),
                SECRETION => copy_hits(out, g.secretion_mm[rows].iter().copied(), depth, miss),
                c if c < NORMAL => {
                    copy_hits(out, g.hit_mm[rows].iter().map(|p| p[c - HIT]), depth, miss)
                }
                c => copy_hits(
                    out,
                    g.normal[rows].iter().map(|n| n[c - NORMAL]),
                    depth,
                    miss,
                ),
            }
        }
    }

    /// The columns' pass for the band's row in slot `slot` of `scratch.across` into
    /// `scratch.out`, its normals renormalised.
    #[inline(always)]
    fn down_row(&self, slot: usize, scratch: &mut Scratch) {
        let w = padded(self.gbuffer.width);
        let r = self.radius();
        let across = &scratch.across;
        for x0 in (0..w).step_by(LANES) {
            let mut window = Window::new(load(&across[DEPTH], slot * w + x0));
            for k in 0..=2 * r {
                let at = (slot + k - r) * w + x0;
                window.add(self.kernel[k.abs_diff(r)], |c| load(&across[c], at));
            }
            let mut mean = window.mean([f32::NAN, 0.0]);
            let normal = [NORMAL, NORMAL + 1, NORMAL + 2];
            let unit = normalize_or_zero([mean[NORMAL], mean[NORMAL + 1], mean[NORMAL + 2]]);
            let hit = map(|k| if window.hit(k) { 1.0 } else { f32::NAN });
            for (c, u) in normal.into_iter().zip(unit) {
                // NaN without a hit.
                mean[c] = map(|k| u[k] * hit[k]);
            }
            for position in &mut mean[HIT..HIT + 3] {
                *position = map(|k| position[k] * hit[k]);
            }
            for (plane, m) in scratch.out.iter_mut().zip(&mean) {
                plane[x0..x0 + LANES].copy_from_slice(m);
            }
        }
    }
}

/// `values` into `out` where `depth` has a hit, `miss` elsewhere: a select per pixel, in a loop
/// that vectorises.
#[inline(always)]
fn copy_hits(out: &mut [f32], values: impl Iterator<Item = f32>, depth: &[f32], miss: f32) {
    for ((out, v), d) in out.iter_mut().zip(values).zip(depth) {
        *out = if d.is_nan() { miss } else { v };
    }
}

/// The weighted sums of one pass's window over eight centre pixels.
struct Window {
    centre: Lanes,
    inverse: Lanes,
    sum: [Lanes; CHANNELS],
    total: Lanes,
}

impl Window {
    /// An empty window around centres at depths `centre` ([`NO_HIT`]: none).
    #[inline(always)]
    fn new(centre: Lanes) -> Self {
        Self {
            centre,
            inverse: map(|k| inverse_edge(centre[k])),
            sum: [[0.0; LANES]; CHANNELS],
            total: [0.0; LANES],
        }
    }

    /// Whether centre `k` has a hit.
    #[inline(always)]
    fn hit(&self, k: usize) -> bool {
        self.centre[k] < NO_HIT
    }

    /// Adds the neighbours whose channel `c` is `texel(c)`, at a distance of Gaussian weight
    /// `tap`. A neighbour without a hit ([`NO_HIT`], zero channels) adds zero.
    #[inline(always)]
    fn add(&mut self, tap: f32, texel: impl Fn(usize) -> Lanes) {
        let depth = texel(DEPTH);
        let weight = map(|k| tap * weight_by_distance(depth[k] - self.centre[k], self.inverse[k]));
        for (total, weight) in self.total.iter_mut().zip(&weight) {
            *total += weight;
        }
        for (c, sum) in self.sum.iter_mut().enumerate() {
            let v = if c == DEPTH { depth } else { texel(c) };
            for k in 0..LANES {
                sum[k] += weight[k] * v[k];
            }
        }
    }

    /// The weighted means; without a hit, `miss[0]` for the depth and `miss[1]` for the rest.
    /// The centre always counts fully, so a hit's total weight is at least 1.
    #[inline(always)]
    fn mean(&self, miss: [f32; 2]) -> [Lanes; CHANNELS] {
        let mut mean = [[0.0; LANES]; CHANNELS];
        for (c, (mean, sum)) in mean.iter_mut().zip(&self.sum).enumerate() {
            let miss = miss[usize::from(c != DEPTH)];
            for k in 0..LANES {
                mean[k] = if self.hit(k) {
                    sum[k] / self.total[k]
                } else {
                    miss
                };
            }
        }
        mean
    }
}
