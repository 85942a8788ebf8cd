//! Monochrome detail textures and their tri-planar projection (Krüger et al. §4.4, Figure 5):
//! the texture is projected along each world axis and the three are blended by the normal.
//! Built in: `mucosa` (a procedural, tileable pattern of mottled mucosa with fine vessels) and
//! `grid` (lines, the strongest shape cue); user textures come from any greyscale image.

use glam::Vec3;
use thiserror::Error;

/// The names [`Texture::built_in`] knows; `none` means no texture.
pub const BUILT_IN_TEXTURES: [&str; 3] = ["mucosa", "grid", "none"];

/// Edge of the built-in textures, texels.
const BUILT_IN_TEXELS: usize = 256;

/// The largest edge accepted, texels.
const MAX_TEXELS: usize = 8192;

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

/// A tiling greyscale texture, values 0 (dark) – 1 (bright), repeated in both directions.
#[derive(Debug, Clone, PartialEq)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<f32>,
}

impl Texture {
    /// A texture of `width × height` texels, row 0 first (`texels[x + width · y]`).
    pub fn from_luma(width: usize, height: usize, texels: Vec<f32>) -> Result<Self, TextureError> {
        let edge = 1..=MAX_TEXELS;
        if !edge.contains(&width) || !edge.contains(&height) || texels.len() != width * height {
            return Err(TextureError::BadSize {
                width,
                height,
                values: texels.len(),
            });
        }
        if let Some((index, &value)) = texels
            .iter()
            .enumerate()
            .find(|(_, v)| !(0.0..=1.0).contains(*v))
        {
            return Err(TextureError::BadValue { index, value });
        }
        Ok(Self {
            width,
            height,
            texels,
        })
    }

    /// The built-in texture called `name` (see [`BUILT_IN_TEXTURES`]); `None` for `none` and
    /// for unknown names.
    pub fn built_in(name: &str) -> Option<Self> {
        let n = BUILT_IN_TEXELS;
        let texel: fn(usize, usize) -> f32 = match name.trim().to_ascii_lowercase().as_str() {
            "mucosa" => mucosa,
            "grid" => grid,
            _ => return None,
        };
        let texels = (0..n * n).map(|i| texel(i % n, i / n)).collect();
        Some(Self {
            width: n,
            height: n,
            texels,
        })
    }

    /// Width and height in texels.
    pub fn size(&self) -> [usize; 2] {
        [self.width, self.height]
    }

    /// The bilinearly interpolated value at `(u, v)` in tiles (1 = one repetition), wrapping.
    #[inline]
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        let (w, h) = (self.width, self.height);
        let (x0, x1, fx) = texel_pair(u, w);
        let (y0, y1, fy) = texel_pair(v, h);
        let t = |x: usize, y: usize| self.texels[x + w * y];
        let top = t(x0, y0) + (t(x1, y0) - t(x0, y0)) * fx;
        let bottom = t(x0, y1) + (t(x1, y1) - t(x0, y1)) * fx;
        top + (bottom - top) * fy
    }

    /// The tri-planar value at world position `p` (in tiles: mm over the tile's size in mm)
    /// with unit normal `n`: the three axis projections blended by the normal as the paper's
    /// Figure 5 does (weights `max(0, 7 (|n| − 0.2))³`, normalised).
    pub fn triplanar(&self, p: Vec3, n: Vec3) -> f32 {
        let w = ((n.abs() - Vec3::splat(0.2)) * 7.0).max(Vec3::ZERO);
        let w = w * w * w;
        let sum = w.x + w.y + w.z;
        if sum <= 0.0 {
            return self.sample(p.x, p.y);
        }
        let mut value = 0.0;
        if w.x > 0.0 {
            value += w.x * self.sample(p.y, p.z);
        }
        if w.y > 0.0 {
            value += w.y * self.sample(p.x, p.z);
        }
        if w.z > 0.0 {
            value += w.z * self.sample(p.x, p.y);
        }
        value / sum
    }
}

/// The two texels either side of tile coordinate `u` on an edge of `n` texels (wrapping) and the
/// weight of the second: the bilinear filter's footprint along one axis.
#[inline(always)]
fn texel_pair(u: f32, n: usize) -> (usize, usize, f32) {
    // Texel centres lie at (i + 0.5) / n: x in [−0.5, n − 0.5).
    let x = (u - floor(u)) * n as f32 - 0.5;
    let x0 = floor(x);
    let fx = x - x0;
    // x0 is −1 … n − 1 (NaN gives 0); no division wraps it.
    let i = x0 as isize;
    let i0 = if i < 0 {
        n - 1
    } else {
        (i as usize).min(n - 1)
    };
    let i1 = if i0 + 1 == n { 0 } else { i0 + 1 };
    (i0, i1, fx)
}

/// `x.floor()` without a call into the maths library (the baseline x86-64 target has no
/// rounding instruction): truncation, one down for negative non-integers; exact for every
/// `f32` (those of magnitude 2²³ and more are integers already).
#[inline(always)]
fn floor(x: f32) -> f32 {
    if x.is_nan() || x.abs() >= 8_388_608.0 {
        return x;
    }
    let t = x as i32 as f32;
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// A lattice value in [0, 1) at integer point `(x, y)` of a lattice repeating every `period`.
fn lattice(x: usize, y: usize, period: usize, seed: u32) -> f32 {
    let (x, y) = ((x % period) as u32, (y % period) as u32);
    let mut h = x.wrapping_mul(0x8DA6_B343) ^ y.wrapping_mul(0xD816_3841) ^ seed;
    h ^= h >> 13;
    h = h.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 16;
    (h >> 8) as f32 / (1u32 << 24) as f32
}

/// Smooth value noise at texel `(x, y)` of the built-in tile, `cells` lattice cells across it
/// (tileable: the lattice repeats with the tile).
fn value_noise(x: usize, y: usize, cells: usize, seed: u32) -> f32 {
    let scale = cells as f32 / BUILT_IN_TEXELS as f32;
    let (u, v) = ((x as f32 + 0.5) * scale, (y as f32 + 0.5) * scale);
    let (i, j) = (u.floor() as usize, v.floor() as usize);
    let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
    let (fx, fy) = (smooth(u.fract()), smooth(v.fract()));
    let c = |di: usize, dj: usize| lattice(i + di, j + dj, cells, seed);
    let top = c(0, 0) + (c(1, 0) - c(0, 0)) * fx;
    let bottom = c(0, 1) + (c(1, 1) - c(0, 1)) * fx;
    top + (bottom - top) * fy
}

/// Mucosa: mottled fractal noise, darker fine vessels where a ridged noise peaks.
fn mucosa(x: usize, y: usize) -> f32 {
    let fbm = [(4, 0.5), (8, 0.25), (16, 0.15), (32, 0.1)]
        .iter()
        .enumerate()
        .map(|(o, &(cells, weight))| weight * value_noise(x, y, cells, o as u32))
        .sum::<f32>();
    let ridge = |cells: usize, seed: u32| {
        let r = 1.0 - (2.0 * value_noise(x, y, cells, seed) - 1.0).abs();
        r.powi(12)
    };
    let vessels = (ridge(6, 11) + 0.6 * ridge(14, 12)).min(1.0);
    (0.25 + 0.6 * fbm - 0.35 * vessels).clamp(0.0, 1.0)
}

/// Grid: dark lines two texels wide every 32 texels on a light ground.
fn grid(x: usize, y: usize) -> f32 {
    if x % 32 < 2 || y % 32 < 2 {
        0.15
    } else {
        0.7
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn built_in_textures_tile_and_vary() {
        let mucosa = Texture::built_in("Mucosa").unwrap();
        assert_eq!(mucosa.size(), [256, 256]);
        let (lo, hi) = mucosa
            .texels
            .iter()
            .fold((1.0f32, 0.0f32), |(l, h), &v| (l.min(v), h.max(v)));
        assert!(lo >= 0.0 && hi <= 1.0 && hi - lo > 0.4, "{lo}..{hi}");
        // Seamless: one tile over is the same value, and the seam is no edge.
        assert!((mucosa.sample(0.3, 0.7) - mucosa.sample(1.3, -0.3)).abs() < 1e-5);
        assert!((mucosa.sample(0.0, 0.5) - mucosa.sample(0.999, 0.5)).abs() < 0.1);
        assert!(Texture::built_in("none").is_none());
        assert!(Texture::built_in("marble").is_none());
        let grid = Texture::built_in("grid").unwrap();
        assert!(grid.sample(1.0 / 256.0, 0.5) < grid.sample(16.0 / 256.0, 16.0 / 256.0));
    }

    #[test]
    fn floor_and_wrapping_match_the_library() {
        for x in [
            -2.5f32,
            -1.0,
            -0.3,
            -0.0,
            0.0,
            0.7,
            3.0,
            1e9,
            -1e9,
            8_388_607.5,
        ] {
            assert_eq!(floor(x), x.floor(), "{x}");
        }
        assert!(floor(f32::NAN).is_nan());
        let t = Texture::from_luma(3, 1, vec![0.0, 0.5, 1.0]).unwrap();
        // Between the last texel and the first (wrapped), and at a texel's centre.
        for u in [0.0, 3.0, -1.0] {
            assert!((t.sample(u, 0.0) - 0.5).abs() < 1e-5, "{u}");
        }
        assert_eq!(t.sample(0.5, 0.0), 0.5);
        assert_eq!(t.sample(-4.5, 0.0), 0.5);
        assert!((t.sample(1.0 / 3.0, 0.0) - 0.25).abs() < 1e-5);
    }

    #[test]
    fn triplanar_takes_the_plane_facing_the_normal() {
        let t = Texture::from_luma(2, 1, vec![0.0, 1.0]).unwrap();
        // Facing z: the (x, y) projection, which varies along x.
        let p = Vec3::new(0.75, 0.2, 0.25);
        assert_eq!(t.triplanar(p, Vec3::Z), t.sample(0.75, 0.2));
        // Facing x: the (y, z) projection.
        assert_eq!(t.triplanar(p, Vec3::X), t.sample(0.2, 0.25));
        let mixed = t.triplanar(p, Vec3::new(1.0, 0.0, 1.0).normalize());
        assert!((mixed - 0.5 * (t.sample(0.75, 0.2) + t.sample(0.2, 0.25))).abs() < 1e-6);
    }

    #[test]
    fn bad_textures_are_refused() {
        assert!(matches!(
            Texture::from_luma(0, 4, vec![]),
            Err(TextureError::BadSize { .. })
        ));
        assert!(matches!(
            Texture::from_luma(2, 2, vec![0.5; 3]),
            Err(TextureError::BadSize { .. })
        ));
        assert!(Texture::from_luma(1, 1, vec![f32::NAN]).is_err());
        assert_eq!(
            Texture::from_luma(1, 2, vec![0.5, 1.5]).map(|_| ()),
            Err(TextureError::BadValue {
                index: 1,
                value: 1.5
            })
        );
    }
}
