//! Eight lookups at a time: the level each lane reads (from its footprint, trilinear between
//! two levels) and the bilinear filter within a level, wrapping.

use super::super::lanes::{map, Lanes, LANES};
use super::pyramid::{channel, Pyramid};

/// The two levels eight lookups read and the weight of the coarser: `lod` (log₂ of the
/// footprint in level-0 texels) clamped to the pyramid; at or below 0 (magnified) only level
/// 0, at or past the last level only the last.
pub(super) struct Levels {
    /// The finer level per lane.
    pub finer: [usize; LANES],
    /// The weight of the next coarser level, 0–1.
    pub blend: Lanes,
}

impl Levels {
    /// The levels of `lod` in a pyramid of `count` levels. NaN reads level 0.
    #[inline(always)]
    pub fn of(lod: &Lanes, count: usize) -> Self {
        let last = (count - 1) as f32;
        let lod = map(|k| if lod[k] > 0.0 { lod[k].min(last) } else { 0.0 });
        let finer = map(|k| lod[k].floor());
        let blend = map(|k| lod[k] - finer[k]);
        let whole = whole(&finer);
        Self {
            finer: whole.map(|l| l as usize),
            blend,
        }
    }

    /// Whether any lane reads a coarser level too.
    #[inline(always)]
    pub fn blends(&self) -> bool {
        self.blend.iter().any(|&b| b > 0.0)
    }

    /// The coarser level per lane (the finer one where it is the last).
    #[inline(always)]
    pub fn coarser(&self, count: usize) -> [usize; LANES] {
        self.finer.map(|l| (l + 1).min(count - 1))
    }
}

/// `log₂ x` for positive finite `x`, within 0.002: the exponent's bits plus a cubic in the
/// mantissa (vectorises, unlike the library's). Garbage, never a panic, for other inputs.
#[inline(always)]
pub(super) fn log2(x: &Lanes) -> Lanes {
    map(|k| {
        let bits = x[k].to_bits();
        let exponent = ((bits >> 23) & 0xFF) as f32 - 127.0;
        let m = f32::from_bits((bits & 0x007F_FFFF) | 0x3F80_0000) - 1.0;
        // log₂(1 + m) on [0, 1): exact at both ends.
        exponent + m * (1.420_86 + m * (-0.577_25 + m * 0.156_39))
    })
}

impl Pyramid {
    /// The bilinearly filtered colours (the first `C` channels) at tile coordinates `(u, v)`
    /// (1 = one repetition, wrapping) of level `level[k]` per lane.
    #[inline(always)]
    pub fn bilinear8<const C: usize>(
        &self,
        u: &Lanes,
        v: &Lanes,
        level: &[usize; LANES],
    ) -> [Lanes; C] {
        let last_level = self.levels.len() - 1;
        let levels = level.map(|l| self.levels[l.min(last_level)]);
        let (x0, x1, fx) = texel_pairs(u, &map(|k| levels[k].width as f32));
        let (y0, y1, fy) = texel_pairs(v, &map(|k| levels[k].height as f32));
        let last = self.texels.len() - 1;
        // The four texels around each point; every index is inside its level (x < width,
        // y < height), and `min` shows the compiler it is inside the texels.
        let mut corner = [[0u32; LANES]; 4];
        for k in 0..LANES {
            let (w, start) = (levels[k].width, levels[k].start);
            let (row0, row1) = (start + w * y0[k] as usize, start + w * y1[k] as usize);
            let (i0, i1) = (x0[k] as usize, x1[k] as usize);
            for (c, i) in [i0 + row0, i1 + row0, i0 + row1, i1 + row1]
                .into_iter()
                .enumerate()
            {
                corner[c][k] = self.texels[i.min(last)];
            }
        }
        let [a, b, c, d] = &corner;
        std::array::from_fn(|ch| {
            map(|k| {
                let (a, b) = (channel(a[k], ch), channel(b[k], ch));
                let (c, d) = (channel(c[k], ch), channel(d[k], ch));
                let top = a + (b - a) * fx[k];
                let bottom = c + (d - c) * fx[k];
                top + (bottom - top) * fy[k]
            })
        })
    }
}

/// The two texels either side of tile coordinates `u` on edges of `n` texels (per lane,
/// wrapping) and the weights of the second: the bilinear filter's footprint along one axis.
/// `floor` is one instruction where [`crate::render::with_avx2`] compiles this (SSE4.1), else a
/// library call.
#[inline(always)]
fn texel_pairs(u: &Lanes, n: &Lanes) -> ([u32; LANES], [u32; LANES], Lanes) {
    // Texel centres lie at (i + 0.5) / n: x in [−0.5, n − 0.5).
    let x = map(|k| (u[k] - u[k].floor()) * n[k] - 0.5);
    let x0 = map(|k| x[k].floor());
    let fx = map(|k| x[k] - x0[k]);
    // x0 is −1 … n − 1 (NaN gives 0); no division wraps it.
    let first = map(|k| {
        let last = n[k] - 1.0;
        if x0[k] >= 0.0 {
            x0[k].min(last)
        } else if x0[k] < 0.0 {
            last
        } else {
            0.0
        }
    });
    let second = map(|k| {
        if first[k] == n[k] - 1.0 {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fast_log2_is_close() {
        let x = [1e-6, 0.01, 0.3, 1.0, 1.5, 2.0, 7.7, 5000.0];
        let got = log2(&x);
        for (x, got) in x.iter().zip(got) {
            assert!((got - x.log2()).abs() < 0.002, "{x}: {got}");
        }
    }

    #[test]
    fn levels_clamp_to_the_pyramid() {
        let levels = Levels::of(&[-3.0, 0.0, 0.25, 1.5, 2.0, 9.0, f32::NAN, 2.75], 4);
        assert_eq!(levels.finer, [0, 0, 0, 1, 2, 3, 0, 2]);
        assert_eq!(levels.blend, [0.0, 0.0, 0.25, 0.5, 0.0, 0.0, 0.0, 0.75]);
        assert_eq!(levels.coarser(4), [1, 1, 1, 2, 3, 3, 1, 3]);
    }
}
