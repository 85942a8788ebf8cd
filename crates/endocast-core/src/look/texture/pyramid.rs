//! The mip pyramid of a texture, built once: level 0 the texture itself, each next level half
//! the size (rounded up) and the area average of the one before, down to one texel; every
//! level's texels packed as 8-bit red, green and blue in one `u32` (one load per tap).

/// Where a level's texels lie in [`Pyramid::texels`], and its size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Level {
    /// Width in texels.
    pub width: usize,
    /// Height in texels.
    pub height: usize,
    /// Index of its first texel (row 0 first, `x + width · y`).
    pub start: usize,
}

/// Every level of a texture, finest first.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Pyramid {
    /// The levels, level 0 the texture.
    pub levels: Vec<Level>,
    /// All levels' texels, packed ([`pack`]).
    pub texels: Vec<u32>,
}

impl Pyramid {
    /// The pyramid of `width × height` texels `rgb` (0–1, row 0 first).
    pub fn build(width: usize, height: usize, rgb: Vec<[f32; 3]>) -> Self {
        let mut pyramid = Self {
            levels: Vec::new(),
            texels: Vec::new(),
        };
        let (mut w, mut h, mut level) = (width, height, rgb);
        loop {
            pyramid.levels.push(Level {
                width: w,
                height: h,
                start: pyramid.texels.len(),
            });
            pyramid.texels.extend(level.iter().map(|&c| pack(c)));
            if w == 1 && h == 1 {
                return pyramid;
            }
            let (half_w, half_h) = (w.div_ceil(2), h.div_ceil(2));
            level = shrink(&level, [w, h], [half_w, half_h]);
            (w, h) = (half_w, half_h);
        }
    }
}

/// `rgb` (0–1) as 8-bit red, green and blue in the low three bytes.
pub(super) fn pack(rgb: [f32; 3]) -> u32 {
    let byte = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u32;
    byte(rgb[0]) | byte(rgb[1]) << 8 | byte(rgb[2]) << 16
}

/// Channel `c` (0 red, 1 green, 2 blue) of a packed texel, 0–1.
#[inline(always)]
pub(super) fn channel(texel: u32, c: usize) -> f32 {
    ((texel >> (8 * c)) & 0xFF) as f32 * (1.0 / 255.0)
}

/// The area average of `texels` (`from` = width, height) on a grid of `to` texels covering the
/// same tile: separable, each new texel the mean of the old ones under it, those cut by its
/// edge by the share they cover (the exact 2 × 2 box for even sizes).
fn shrink(texels: &[[f32; 3]], from: [usize; 2], to: [usize; 2]) -> Vec<[f32; 3]> {
    let (across, down) = (box_weights(from[0], to[0]), box_weights(from[1], to[1]));
    let rows: Vec<[f32; 3]> = (0..from[1])
        .flat_map(|y| {
            let row = &texels[y * from[0]..(y + 1) * from[0]];
            across.iter().map(move |taps| average(taps, |x| row[x]))
        })
        .collect();
    (0..to[1])
        .flat_map(|y| {
            let (rows, taps) = (&rows, &down[y]);
            (0..to[0]).map(move |x| average(taps, |j| rows[x + to[0] * j]))
        })
        .collect()
}

/// The weighted sum of `value` over `taps`.
fn average(taps: &[(usize, f32)], value: impl Fn(usize) -> [f32; 3]) -> [f32; 3] {
    taps.iter().fold([0.0; 3], |sum, &(i, w)| {
        let v = value(i);
        [sum[0] + w * v[0], sum[1] + w * v[1], sum[2] + w * v[2]]
    })
}

/// For each of `m` cells covering an edge of `n` texels (`m ≤ n`), the texels under it and
/// the share of the cell each covers (summing to 1).
fn box_weights(n: usize, m: usize) -> Vec<Vec<(usize, f32)>> {
    let ratio = n as f64 / m as f64;
    (0..m)
        .map(|i| {
            let (lo, hi) = (i as f64 * ratio, (i + 1) as f64 * ratio);
            (lo.floor() as usize..(hi.ceil() as usize).min(n))
                .map(|j| {
                    let covered = (hi.min(j as f64 + 1.0) - lo.max(j as f64)).max(0.0);
                    (j, (covered / ratio) as f32)
                })
                .filter(|&(_, w)| w > 0.0)
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_halve_to_one_texel_and_keep_the_mean() {
        let rgb: Vec<[f32; 3]> = (0..5 * 3)
            .map(|i| [i as f32 / 14.0, 0.5, 1.0 - i as f32 / 14.0])
            .collect();
        let p = Pyramid::build(5, 3, rgb);
        let sizes: Vec<_> = p.levels.iter().map(|l| [l.width, l.height]).collect();
        assert_eq!(sizes, [[5, 3], [3, 2], [2, 1], [1, 1]]);
        assert_eq!(p.texels.len(), 15 + 6 + 2 + 1);
        let last = p.texels[p.levels[3].start];
        assert!((channel(last, 0) - 0.5).abs() < 2.0 / 255.0);
        assert!((channel(last, 2) - 0.5).abs() < 2.0 / 255.0);
        // Even sizes: the exact 2 × 2 box.
        let p = Pyramid::build(2, 2, vec![[0.0; 3], [1.0; 3], [1.0; 3], [1.0; 3]]);
        assert_eq!(channel(p.texels[4], 1), 191.0 / 255.0);
    }
}
