//! Detail textures, colour or grey, and their mip-mapped tri-planar projection (Krüger et al.
//! §4.4, Figures 5–6): the texture is projected along each world axis and the projections are
//! blended by the normal, each read at the level of its mip pyramid that the pixel's footprint
//! on the surface asks for (trilinear between two levels), so that far and grazing walls show
//! the texture's average, not its aliases.
//!
//! The blend keeps the texture's contrast: the projections' deviations from the mean are summed
//! with the blend weights and divided by the weights' Euclidean norm (variance-preserving
//! blending, Heitz and Neyret 2018), so where two projections meet the texture does not fade
//! toward grey as a plain weighted average of two unrelated patterns does (a visible band along
//! the 45° lines); sharp weights keep the zone where two images show through each other narrow.
//!
//! Built in: `mucosa` (the default of the realistic look: a low-contrast mottled base and sparse
//! fine vessels, [`procedural`]) and `grid` (lines, the strongest shape cue); user textures come
//! from any image, their colour kept.

mod procedural;
mod pyramid;
mod sample;

use super::lanes::{map, map3, Lanes, LANES};
use glam::Vec3;
use pyramid::Pyramid;
use sample::{log2, Levels};
use std::sync::OnceLock;
use thiserror::Error;

/// The names [`Texture::built_in`] knows; `none` means no texture.
pub const BUILT_IN_TEXTURES: [&str; 3] = ["mucosa", "grid", "none"];

/// The largest edge accepted, texels.
pub const MAX_TEXELS: usize = 8192;

/// Rec. 709 luminance weights of red, green and blue.
pub const LUMA: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// A projection's weight is `max(0, |n_axis| − BLEND_START)⁴` (then normalised): the others
/// start to show only within about 10° of the 45° lines, and one alone near the axes.
const BLEND_START: f32 = 0.45;
/// Weights below this share of their sum are dropped (and the rest renormalised): a
/// projection that would barely show is not read.
const BLEND_CUT: f32 = 0.02;

/// A texture that cannot be used.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TextureError {
    /// Zero or more than 8192 texels along an edge, or a value count that does not match.
    #[error("a texture of {width}×{height} texels with {values} values (edges 1–8192)")]
    BadSize {
        /// Width in texels.
        width: usize,
        /// Height in texels.
        height: usize,
        /// Values given.
        values: usize,
    },
    /// A value outside 0–1 (or NaN).
    #[error("texel {index} is {value}, outside [0, 1]")]
    BadValue {
        /// Index of the texel.
        index: usize,
        /// Its value.
        value: f32,
    },
}

/// A tiling texture, colour or grey, values 0 (dark) – 1 (bright) per channel, repeated in
/// both directions, with its mip pyramid (built once, here).
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    pyramid: Pyramid,
    /// Whether red, green and blue differ anywhere (else only red is read).
    colour: bool,
    /// The mean colour (every level's, up to rounding).
    mean: [f32; 3],
}

impl Texture {
    /// A grey texture of `width × height` texels, row 0 first (`texels[x + width · y]`).
    pub fn from_luma(width: usize, height: usize, texels: Vec<f32>) -> Result<Self, TextureError> {
        check_size(width, height, texels.len())?;
        check_values(&texels)?;
        Ok(Self::new(
            width,
            height,
            texels.into_iter().map(|v| [v; 3]).collect(),
        ))
    }

    /// A colour texture of `width × height` red, green and blue texels, row 0 first.
    pub fn from_rgb(
        width: usize,
        height: usize,
        texels: Vec<[f32; 3]>,
    ) -> Result<Self, TextureError> {
        check_size(width, height, texels.len())?;
        check_values(texels.as_flattened())?;
        Ok(Self::new(width, height, texels))
    }

    /// The texture of checked `rgb` texels.
    fn new(width: usize, height: usize, rgb: Vec<[f32; 3]>) -> Self {
        let colour = rgb.iter().any(|c| c[0] != c[1] || c[0] != c[2]);
        let count = rgb.len() as f64;
        let sums = rgb.iter().fold([0.0f64; 3], |s, c| {
            [
                s[0] + f64::from(c[0]),
                s[1] + f64::from(c[1]),
                s[2] + f64::from(c[2]),
            ]
        });
        Self {
            pyramid: Pyramid::build(width, height, rgb),
            colour,
            mean: sums.map(|s| (s / count) as f32),
        }
    }

    /// The built-in texture called `name` (see [`BUILT_IN_TEXTURES`]); `None` for `none` and
    /// for unknown names. Each is computed once per process.
    pub fn built_in(name: &str) -> Option<Self> {
        static MUCOSA: OnceLock<Texture> = OnceLock::new();
        static GRID: OnceLock<Texture> = OnceLock::new();
        let n = procedural::BUILT_IN_TEXELS;
        let (cell, texels): (_, fn() -> Vec<[f32; 3]>) =
            match name.trim().to_ascii_lowercase().as_str() {
                "mucosa" => (&MUCOSA, procedural::mucosa),
                "grid" => (&GRID, procedural::grid),
                _ => return None,
            };
        Some(cell.get_or_init(|| Self::new(n, n, texels())).clone())
    }

    /// Width and height in texels.
    pub fn size(&self) -> [usize; 2] {
        let level = self.pyramid.levels[0];
        [level.width, level.height]
    }

    /// Whether the texture has colour (its channels differ somewhere).
    pub fn is_colour(&self) -> bool {
        self.colour
    }

    /// The mean colour.
    pub fn mean(&self) -> [f32; 3] {
        self.mean
    }

    /// The number of mip levels (level 0 the texture, the last one texel).
    pub fn levels(&self) -> usize {
        self.pyramid.levels.len()
    }

    /// The bilinearly interpolated colour at `(u, v)` in tiles (1 = one repetition), wrapping,
    /// of mip level `level` (0 the texture itself; past the last, the last).
    pub fn sample(&self, u: f32, v: f32, level: usize) -> [f32; 3] {
        let rgb = self
            .pyramid
            .bilinear8::<3>(&[u; LANES], &[v; LANES], &[level; LANES]);
        rgb.map(|c| c[0])
    }

    /// The tri-planar colour at world position `p` (in tiles: mm over the tile's size in mm)
    /// with unit normal `n`, for a pixel whose footprint on the surface is `footprint` tiles
    /// wide (0: the finest level): the three axis projections, each trilinear between the two
    /// mip levels of that footprint, blended by the normal, contrast kept (see the module).
    pub fn triplanar(&self, p: Vec3, n: Vec3, footprint: f32) -> [f32; 3] {
        let lanes = |v: Vec3| v.to_array().map(|c| [c; LANES]);
        let rgb = self.triplanar8(&lanes(p), &lanes(n), &[footprint; LANES]);
        rgb.map(|c| c[0])
    }

    /// [`Self::triplanar`] for eight positions (`p`: x, y and z lanes), unit normals `n` and
    /// footprints. A projection no lane weights is not read, nor a coarser level no lane needs.
    #[inline(always)]
    pub(in crate::look) fn triplanar8(
        &self,
        p: &[Lanes; 3],
        n: &[Lanes; 3],
        footprint: &Lanes,
    ) -> [Lanes; 3] {
        let [w, h] = self.size();
        let edge = w.max(h) as f32;
        let levels = Levels::of(&log2(&map(|k| footprint[k] * edge)), self.levels());
        let (weights, scale) = blend_weights(n);
        let mean = self.mean;
        let mut sum = map3(|_, _| 0.0);
        // The (x, y) projection is also the fallback where no axis has weight (a NaN normal).
        let fallback = scale.iter().any(|&s| s <= 0.0);
        for (axis, (a, b)) in [(1, 2), (0, 2), (0, 1)].into_iter().enumerate() {
            let used = weights[axis].iter().any(|&w| w > 0.0) || (axis == 2 && fallback);
            if !used {
                continue;
            }
            let rgb = self.trilinear8(&p[a], &p[b], &levels);
            sum = map3(|c, k| sum[c][k] + weights[axis][k] * (rgb[c][k] - mean[c]));
            if axis == 2 && fallback {
                sum = map3(|c, k| {
                    if scale[k] > 0.0 {
                        sum[c][k]
                    } else {
                        rgb[c][k] - mean[c]
                    }
                });
            }
        }
        map3(|c, k| {
            let s = if scale[k] > 0.0 { scale[k] } else { 1.0 };
            mean[c] + sum[c][k] * s
        })
    }

    /// One projection's colours at `(u, v)`: trilinear between the two levels of `levels`.
    #[inline(always)]
    fn trilinear8(&self, u: &Lanes, v: &Lanes, levels: &Levels) -> [Lanes; 3] {
        let finer = self.bilinear8(u, v, &levels.finer);
        if !levels.blends() {
            return finer;
        }
        let coarser = self.bilinear8(u, v, &levels.coarser(self.levels()));
        map3(|c, k| finer[c][k] + (coarser[c][k] - finer[c][k]) * levels.blend[k])
    }

    /// The bilinear colours of one level per lane: three channels, or red copied for grey.
    #[inline(always)]
    fn bilinear8(&self, u: &Lanes, v: &Lanes, level: &[usize; LANES]) -> [Lanes; 3] {
        if self.colour {
            self.pyramid.bilinear8::<3>(u, v, level)
        } else {
            let [grey] = self.pyramid.bilinear8::<1>(u, v, level);
            [grey; 3]
        }
    }
}

/// The projections' blend weights for unit normals `n` (along x, y and z: the projections on
/// the (y, z), (x, z) and (x, y) planes), summing to 1, and per lane the factor that keeps the
/// contrast, `1 / √(Σ w²)` (0 where no axis has weight: a NaN or zero normal).
#[inline(always)]
fn blend_weights(n: &[Lanes; 3]) -> ([Lanes; 3], Lanes) {
    let raw = map3(|a, k| {
        let w = (n[a][k].abs() - BLEND_START).max(0.0);
        let w2 = w * w;
        w2 * w2
    });
    let total = map(|k| raw[0][k] + raw[1][k] + raw[2][k]);
    let cut = map3(|a, k| (raw[a][k] - BLEND_CUT * total[k]).max(0.0));
    let kept = map(|k| cut[0][k] + cut[1][k] + cut[2][k]);
    let inverse = map(|k| if kept[k] > 0.0 { 1.0 / kept[k] } else { 0.0 });
    let weights = map3(|a, k| cut[a][k] * inverse[k]);
    let norm = map(|k| {
        let [x, y, z] = [weights[0][k], weights[1][k], weights[2][k]];
        (x * x + y * y + z * z).sqrt()
    });
    let scale = map(|k| if norm[k] > 0.0 { 1.0 / norm[k] } else { 0.0 });
    (weights, scale)
}

/// `Ok` for `width × height` texels (edges 1–[`MAX_TEXELS`]) given as `values` texels.
fn check_size(width: usize, height: usize, values: usize) -> Result<(), TextureError> {
    let edge = 1..=MAX_TEXELS;
    if edge.contains(&width) && edge.contains(&height) && values == width * height {
        Ok(())
    } else {
        Err(TextureError::BadSize {
            width,
            height,
            values,
        })
    }
}

/// `Ok` when every value lies in [0, 1].
fn check_values(values: &[f32]) -> Result<(), TextureError> {
    match values
        .iter()
        .enumerate()
        .find(|(_, v)| !(0.0..=1.0).contains(*v))
    {
        Some((index, &value)) => Err(TextureError::BadValue { index, value }),
        None => Ok(()),
    }
}

#[cfg(test)]
pub(super) mod tests;
