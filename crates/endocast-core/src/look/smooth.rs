//! Depth-aware image-space smoothing of the G-buffer (Krüger et al. §4.4): depth, hit
//! positions, normals and secretion are averaged over a small window, each neighbour weighted by
//! its distance in pixels and by how close its depth lies to the centre's, so sampling noise
//! goes while silhouettes stay: across a depth discontinuity (a fold in front of a far wall) a
//! neighbour's weight is zero.
//!
//! Two one-dimensional passes (rows, then columns), each weighting by the centre pixel's depth:
//! the usual separable form of a cross-bilateral filter.

use super::gbuffer::GBuffer;
use rayon::prelude::*;

/// Relative depth difference (to the centre's depth) at which a neighbour's weight falls to
/// zero; up to half of it the weight is full. Neighbours on one wall differ by a few per cent
/// even at grazing angles, while a silhouette jumps by tens.
pub const DEPTH_EDGE: f32 = 0.08;

/// Channels smoothed per pixel: depth, hit position (3), normal (3), secretion.
const CHANNELS: usize = 8;

type Texel = [f32; CHANNELS];

/// The weight of a neighbour at depth `d` for a centre at depth `centre` (both finite).
#[inline]
pub fn depth_weight(d: f32, centre: f32) -> f32 {
    weight_by_distance(d - centre, inverse_edge(centre))
}

/// One over the depth difference at which a neighbour of a centre at depth `centre` loses all
/// weight (computed once per centre).
#[inline]
fn inverse_edge(centre: f32) -> f32 {
    1.0 / (DEPTH_EDGE * centre.abs()).max(1e-3)
}

/// The weight of a neighbour `difference` deeper than the centre, `inverse` its
/// [`inverse_edge`].
#[inline]
fn weight_by_distance(difference: f32, inverse: f32) -> f32 {
    (2.0 - 2.0 * difference.abs() * inverse).clamp(0.0, 1.0)
}

/// `gbuffer` smoothed over a window of `2 · radius + 1` pixels each way (0: unchanged). Pixels
/// without a hit stay without one and give no weight to those with one.
pub fn smooth(gbuffer: &GBuffer, radius: usize) -> GBuffer {
    if radius == 0 || gbuffer.is_empty() {
        return gbuffer.clone();
    }
    let (w, h) = (gbuffer.width, gbuffer.height);
    let kernel: Vec<f32> = (0..=radius)
        .map(|k| {
            let sigma = 0.5 * radius as f32 + 0.5;
            (-0.5 * (k as f32 / sigma).powi(2)).exp()
        })
        .collect();
    // Rows, each gathered into texels once (a row's worth stays in the cache).
    let mut across = vec![[f32::NAN; CHANNELS]; w * h];
    across.par_chunks_mut(w).enumerate().for_each(|(y, row)| {
        let texels: Vec<Texel> = (0..w).map(|x| texel(gbuffer, x + w * y)).collect();
        for (x, out) in row.iter_mut().enumerate() {
            *out = filtered(&texels, &kernel, x, |k| {
                usize::try_from(x as isize + k).ok().filter(|&x| x < w)
            });
        }
    });
    // Columns, written straight into the smoothed buffer's layers.
    let n = w * h;
    let mut out = GBuffer {
        width: w,
        height: h,
        depth_mm: vec![0.0; n],
        hit_mm: vec![[0.0; 3]; n],
        normal: vec![[0.0; 3]; n],
        secretion_mm: vec![0.0; n],
        stats: gbuffer.stats,
    };
    out.depth_mm
        .par_chunks_mut(w)
        .zip(out.hit_mm.par_chunks_mut(w))
        .zip(out.normal.par_chunks_mut(w))
        .zip(out.secretion_mm.par_chunks_mut(w))
        .enumerate()
        .for_each(|(y, (((depth, hit), normal), secretion))| {
            for x in 0..w {
                let t = filtered(&across, &kernel, x + w * y, |k| {
                    let y = usize::try_from(y as isize + k).ok().filter(|&y| y < h)?;
                    Some(x + w * y)
                });
                depth[x] = t[0];
                hit[x] = [t[1], t[2], t[3]];
                let n = glam::Vec3::new(t[4], t[5], t[6]).normalize_or_zero();
                normal[x] = n.to_array();
                secretion[x] = t[7];
            }
        });
    out
}

/// Pixel `i` of `gbuffer` as one texel of channels.
fn texel(gbuffer: &GBuffer, i: usize) -> Texel {
    let [px, py, pz] = gbuffer.hit_mm[i];
    let [nx, ny, nz] = gbuffer.normal[i];
    [
        gbuffer.depth_mm[i],
        px,
        py,
        pz,
        nx,
        ny,
        nz,
        gbuffer.secretion_mm[i],
    ]
}

/// The weighted mean of texel `centre`'s neighbours `neighbour(k)` for `k` in
/// `−radius..=radius` (`None` past the image's edge).
#[inline]
fn filtered(
    texels: &[Texel],
    kernel: &[f32],
    centre: usize,
    neighbour: impl Fn(isize) -> Option<usize>,
) -> Texel {
    let c = texels[centre];
    if c[0].is_nan() {
        return c;
    }
    let r = kernel.len() as isize - 1;
    let inverse = inverse_edge(c[0]);
    let (mut sum, mut total) = ([0.0; CHANNELS], 0.0);
    for k in -r..=r {
        let Some(j) = neighbour(k) else { continue };
        let t = &texels[j];
        if t[0].is_nan() {
            continue;
        }
        let weight = kernel[k.unsigned_abs()] * weight_by_distance(t[0] - c[0], inverse);
        if weight > 0.0 {
            for (s, v) in sum.iter_mut().zip(t) {
                *s += weight * v;
            }
            total += weight;
        }
    }
    // The centre itself always counts fully.
    sum.map(|s| s / total)
}
