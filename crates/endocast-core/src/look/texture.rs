//! Monochrome detail textures and their tri-planar projection (Krüger et al. §4.4, Figure 5):
//! the texture is projected along each world axis and the three are blended by the normal.
//! Built in: `mucosa` (a procedural, tileable pattern of mottled mucosa with fine vessels) and
//! `grid` (lines, the strongest shape cue); user textures come from any greyscale image.

use super::lanes::{map, map3, Lanes, LANES};
use glam::Vec3;
use thiserror::Error;

/// The names [`Texture::built_in`] knows; `none` means no texture.
pub const BUILT_IN_TEXTURES: [&str; 3] = ["mucosa", "grid", "none"];

/// Edge of the built-in textures, texels.
const BUILT_IN_TEXELS: usize = 256;

/// The largest edge accepted, texels.
pub const MAX_TEXELS: usize = 8192;

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
    pub fn sample(&self, u: f32, v: f32) -> f32 {
        self.sample8(&[u; LANES], &[v; LANES])[0]
    }

    /// [`Self::sample`] at eight points (their `u` and `v` lanes).
    #[inline(always)]
    pub(super) fn sample8(&self, u: &Lanes, v: &Lanes) -> Lanes {
        let w = self.width;
        let (x0, x1, fx) = texel_pairs(u, w);
        let (y0, y1, fy) = texel_pairs(v, self.height);
        let last = self.texels.len() - 1;
        // The four texels around each point; every index is inside (x < width, y < height),
        // and `min` shows it to the compiler.
        let mut corner = [[0.0; LANES]; 4];
        for k in 0..LANES {
            let (row0, row1) = (w * y0[k] as usize, w * y1[k] as usize);
            let (i0, i1) = (x0[k] as usize, x1[k] as usize);
            for (c, i) in [i0 + row0, i1 + row0, i0 + row1, i1 + row1]
                .into_iter()
                .enumerate()
            {
                corner[c][k] = self.texels[i.min(last)];
            }
        }
        let [a, b, c, d] = &corner;
        map(|k| {
            let top = a[k] + (b[k] - a[k]) * fx[k];
            let bottom = c[k] + (d[k] - c[k]) * fx[k];
            top + (bottom - top) * fy[k]
        })
    }

    /// The tri-planar value at world position `p` (in tiles: mm over the tile's size in mm)
    /// with unit normal `n`: the three axis projections blended by the normal as the paper's
    /// Figure 5 does (weights `max(0, 7 (|n| − 0.2))³`, normalised).
    pub fn triplanar(&self, p: Vec3, n: Vec3) -> f32 {
        let lanes = |v: Vec3| v.to_array().map(|c| [c; LANES]);
        self.triplanar8(&lanes(p), &lanes(n))[0]
    }

    /// [`Self::triplanar`] for eight positions (`p`: x, y and z lanes) and unit normals `n`. A
    /// projection no lane weights is not sampled.
    #[inline(always)]
    pub(super) fn triplanar8(&self, p: &[Lanes; 3], n: &[Lanes; 3]) -> Lanes {
        let w = map3(|a, k| {
            let w = ((n[a][k].abs() - 0.2) * 7.0).max(0.0);
            w * w * w
        });
        let sum = map(|k| w[0][k] + w[1][k] + w[2][k]);
        let used = |axis: usize| w[axis].iter().any(|&w| w > 0.0);
        let x = self.projection8(&p[1], &p[2], used(0));
        let y = self.projection8(&p[0], &p[2], used(1));
        // The (x, y) projection is also the fallback where no axis has weight.
        let z = self.projection8(&p[0], &p[1], used(2) || sum.iter().any(|&s| s <= 0.0));
        map(|k| {
            if sum[k] <= 0.0 {
                z[k]
            } else {
                (w[0][k] * x[k] + w[1][k] * y[k] + w[2][k] * z[k]) / sum[k]
            }
        })
    }
}

impl Texture {
    /// One projection's values at `(u, v)` where it is `needed`, else zeros.
    #[inline(always)]
    fn projection8(&self, u: &Lanes, v: &Lanes, needed: bool) -> Lanes {
        if needed {
            self.sample8(u, v)
        } else {
            [0.0; LANES]
        }
    }
}

/// The two texels either side of tile coordinates `u` on an edge of `n` texels (wrapping) and
/// the weights of the second: the bilinear filter's footprint along one axis. `floor` is one
/// instruction where [`crate::render::with_avx2`] compiles this (SSE4.1), else a library call.
#[inline(always)]
fn texel_pairs(u: &Lanes, n: usize) -> ([u32; LANES], [u32; LANES], Lanes) {
    // At most MAX_TEXELS: exact.
    let (n, last) = (n as f32, n as f32 - 1.0);
    // Texel centres lie at (i + 0.5) / n: x in [−0.5, n − 0.5).
    let x = map(|k| (u[k] - u[k].floor()) * n - 0.5);
    let x0 = map(|k| x[k].floor());
    let fx = map(|k| x[k] - x0[k]);
    // x0 is −1 … n − 1 (NaN gives 0); no division wraps it.
    let first = map(|k| {
        if x0[k] >= 0.0 {
            x0[k].min(last)
        } else if x0[k] < 0.0 {
            last
        } else {
            0.0
        }
    });
    let second = map(|k| {
        if first[k] == last {
            0.0
        } else {
            first[k] + 1.0
        }
    });
    (whole(&first), whole(&second), fx)
}

/// Whole numbers 0 … 2²³ as integers: their bits once 2²³ is added (exact, and unlike `as`,
/// which saturates, one vector operation).
#[inline(always)]
fn whole(v: &Lanes) -> [u32; LANES] {
    const TWO_23: f32 = 8_388_608.0;
    let mut out = [0; LANES];
    for (o, v) in out.iter_mut().zip(v) {
        *o = (v + TWO_23).to_bits() - TWO_23.to_bits();
    }
    out
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
    fn sampling_wraps() {
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
