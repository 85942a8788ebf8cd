//! Pre-integrated classification (Engel, Kraus and Ertl 2001): the colour and opacity of a whole
//! ray segment between two samples, the stored value taken to vary linearly between them, so
//! that a transfer function's narrow peaks and steep edges are integrated exactly whatever the
//! step, and the step can grow at equal quality.
//!
//! The segment's optical depth is `d · (T(b) − T(f)) / (b − f)` for front and back values `f`
//! and `b` and length `d`, `T` the integral of the extinction over stored values — the 2-D
//! table of (front, back) of the paper, evaluated from its 1-D integral functions at full
//! resolution (a 2-D table at one entry per stored value would hold 16 M entries for 12-bit
//! CT). Its colour is the extinction-weighted mean colour `(K(b) − K(f)) / (T(b) − T(f))`
//! (`K` the integral of extinction × colour) times the segment's opacity: exact for a constant
//! segment, where it is the ordinary step's `1 − (1 − α)^d`; for a varying one it neglects the
//! attenuation inside the segment, the approximation of the paper's fast table.

use super::simd::sse;
use super::voxel_grid::Lanes;
use glam::{BVec4A, Vec3A, Vec4};

/// The largest extinction per mm: opacity 1 per mm becomes 1 − e^−13.8 ≈ 1 − 10⁻⁶ per mm
/// (a finite optical depth keeps the integrals finite).
const MAX_EXTINCTION: f64 = 13.8;

/// Segments whose values differ by less than this (stored units) are taken as constant, at
/// their midpoint: the integrals' difference would lose its precision to cancellation, while
/// the transfer function, one entry per stored value, cannot change much over it.
const CONSTANT_BELOW: f32 = 0.25;

/// The extinction and extinction-weighted colour per stored value, and their integrals, of
/// one transfer function over a stored range.
#[derive(Debug, Clone)]
pub(crate) struct SegmentTable {
    /// Stored value of entry 0.
    first: f32,
    /// Index of the last entry (exact in `f32`).
    top: usize,
    /// Per entry `[τ·r, τ·g, τ·b, τ]` (τ the extinction per mm), then a copy of the last.
    density: Vec<Vec4>,
    /// Per entry the integral of `density` (linear between entries) from entry 0, then the
    /// integral one entry past the last.
    integral: Vec<Vec4>,
}

impl SegmentTable {
    /// The table of opacities per mm and colours `points[i]` at stored value `first + i`
    /// (at least one).
    pub fn new(first: u16, points: impl ExactSizeIterator<Item = (f32, [f32; 3])>) -> Self {
        let mut density: Vec<Vec4> = points
            .map(|(alpha, [r, g, b])| {
                let tau = extinction(alpha);
                Vec4::new(r * tau, g * tau, b * tau, tau)
            })
            .collect();
        assert!(!density.is_empty(), "a segment table needs an entry");
        let top = density.len() - 1;
        density.push(density[top]);
        let mut table = Self {
            first: f32::from(first),
            top,
            density,
            integral: Vec::new(),
        };
        table.integrate();
        table
    }

    /// The running integral of the density (trapezoids: exact for the linear interpolation).
    fn integrate(&mut self) {
        let mut sum = Vec4::ZERO;
        self.integral = std::iter::once(Vec4::ZERO)
            .chain(self.density.windows(2).map(|pair| {
                sum += 0.5 * (pair[0] + pair[1]);
                sum
            }))
            .collect();
    }

    /// Makes every entry whose stored value lies in `[lo, hi]` transparent (see
    /// [`super::transfer::TfTable::make_transparent_between`]).
    pub fn make_transparent_between(&mut self, lo: f32, hi: f32) {
        for (index, entry) in self.density[..=self.top].iter_mut().enumerate() {
            let stored = self.first + index as f32;
            if stored >= lo && stored <= hi {
                *entry = Vec4::ZERO;
            }
        }
        self.density[self.top + 1] = self.density[self.top];
        self.integrate();
    }

    /// A stored value clamped to the table's entries (NaN to the first).
    #[inline(always)]
    fn clamped(&self, stored: f32) -> f32 {
        (stored - self.first).max(0.0).min(self.top as f32) + self.first
    }

    /// Entry and weight towards the next of a clamped stored value, as
    /// [`super::transfer::TfTable`]'s lookup finds them (the same operations, so that
    /// [`sse::lookup8`] gives the same bits).
    #[inline(always)]
    fn lerp(&self, table: &[Vec4], stored: f32) -> Vec4 {
        let x = (stored - self.first).max(0.0);
        let i = (x as i32).min(self.top as i32);
        let weight = (x - i as f32).min(1.0);
        let pair = &table[i as usize..i as usize + 2];
        pair[0] + (pair[1] - pair[0]) * weight
    }

    /// Premultiplied colour and opacity of a segment `length_mm` long whose stored value runs
    /// linearly from `front` to `back`: the integral linear between entries, the density of a
    /// nearly constant segment at its midpoint.
    #[inline(always)]
    pub fn segment(&self, front: f32, back: f32, length_mm: f32) -> Vec4 {
        let (a, b) = (self.clamped(front), self.clamped(back));
        let integrals = [self.lerp(&self.integral, a), self.lerp(&self.integral, b)];
        let constant = self.lerp(&self.density, 0.5 * (a + b));
        let mean = mean_density(b - a, integrals, constant);
        let alpha = 1.0 - exp_of_negative(mean.w * length_mm);
        premultiplied(mean, alpha)
    }

    /// [`Self::segment`] of eight segments, the table reads eight at a time ([`sse::lookup8`])
    /// and the exponentials in one loop the compiler vectorizes: the same bits.
    #[inline(always)]
    pub fn segments8(&self, fronts: &Lanes, backs: &Lanes, length_mm: f32) -> [Vec4; 8] {
        let a: Lanes = std::array::from_fn(|k| self.clamped(fronts[k]));
        let b: Lanes = std::array::from_fn(|k| self.clamped(backs[k]));
        let mid: Lanes = std::array::from_fn(|k| 0.5 * (a[k] + b[k]));
        let lookup = |table: &[Vec4], at: &Lanes| sse::lookup8(table, self.first, self.top, at);
        let (from, to) = (lookup(&self.integral, &a), lookup(&self.integral, &b));
        let constant = lookup(&self.density, &mid);
        let means: [Vec4; 8] =
            std::array::from_fn(|k| mean_density(b[k] - a[k], [from[k], to[k]], constant[k]));
        let mut alphas = [0.0f32; 8];
        for (alpha, mean) in alphas.iter_mut().zip(&means) {
            *alpha = mean.w * length_mm;
        }
        for alpha in &mut alphas {
            *alpha = 1.0 - exp_of_negative(*alpha);
        }
        std::array::from_fn(|k| premultiplied(means[k], alphas[k]))
    }
}

/// The mean density over a segment spanning `span` stored units between the integrals
/// `[from, to]`, or `constant` (its midpoint's) where the span is too short to divide by. No
/// branch: both are there, one is selected. The extinction is kept non-negative.
#[inline(always)]
fn mean_density(span: f32, [from, to]: [Vec4; 2], constant: Vec4) -> Vec4 {
    let varying = (to - from) / span;
    let mean = Vec4::select(
        BVec4A::splat(span.abs() < CONSTANT_BELOW),
        constant,
        varying,
    );
    mean.max(Vec4::ZERO)
}

/// The premultiplied colour and opacity of a segment of mean density `mean` (its extinction-
/// weighted colour) and opacity `alpha`. A transparent segment has alpha 0: so has its colour.
#[inline(always)]
fn premultiplied(mean: Vec4, alpha: f32) -> Vec4 {
    let rgb = Vec3A::from_vec4(mean) * (alpha / mean.w.max(f32::MIN_POSITIVE));
    rgb.extend(alpha)
}

/// e^−x for x ≥ 0 (x past 87 taken as 87: 1 − e^−87 is 1 in `f32`), to within 5 × 10⁻⁷
/// relative: 2^−n by its exponent bits times a degree-6 Taylor polynomial of e^r,
/// |r| ≤ ln 2 / 2, ln 2 split in two so that `n ln 2` stays exact — no call to libm's `expf`,
/// and the same operations on every CPU.
#[inline(always)]
fn exp_of_negative(x: f32) -> f32 {
    let x = x.clamp(0.0, 87.0);
    // n = round(x / ln 2), as truncation of a non-negative number plus a half.
    let n = (x * std::f32::consts::LOG2_E + 0.5) as i32;
    // ln 2 = LN2_HI + LN2_LO, LN2_HI with 9 significant bits (n · LN2_HI is exact).
    const LN2_HI: f32 = 0.693_359_4;
    const LN2_LO: f32 = -2.121_944_4e-4;
    let r = (n as f32 * LN2_HI - x) + n as f32 * LN2_LO;
    let p = 1.0
        + r * (1.0
            + r * (0.5
                + r * (1.0 / 6.0 + r * (1.0 / 24.0 + r * (1.0 / 120.0 + r * (1.0 / 720.0))))));
    p * f32::from_bits(((127 - n) as u32) << 23)
}

/// The extinction per mm of an opacity per mm, bounded by [`MAX_EXTINCTION`].
fn extinction(alpha: f32) -> f32 {
    let alpha = f64::from(alpha.clamp(0.0, 1.0));
    (-(1.0 - alpha).ln()).min(MAX_EXTINCTION) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Opacity 0.3 per mm from stored value 10 to 20, 0 elsewhere; red.
    fn block() -> SegmentTable {
        let points = (0..40u16).map(|v| {
            let alpha = if (10..=20).contains(&v) { 0.3 } else { 0.0 };
            (alpha, [1.0, 0.0, 0.0])
        });
        SegmentTable::new(100, points.collect::<Vec<_>>().into_iter())
    }

    #[test]
    fn a_constant_segment_is_the_ordinary_step() {
        let table = block();
        for length in [0.1f32, 0.5, 1.0, 2.0] {
            let ordinary = 1.0 - 0.7f32.powf(length);
            let s = table.segment(115.0, 115.0, length);
            assert!(
                (s.w - ordinary).abs() < 1e-5,
                "{length}: {} vs {ordinary}",
                s.w
            );
            assert!((s.x - ordinary).abs() < 1e-5 && s.y == 0.0 && s.z == 0.0);
            // Nearly constant: the same within the table's resolution.
            let near = table.segment(115.0, 115.1, length);
            assert!((near.w - ordinary).abs() < 1e-5);
        }
        assert_eq!(table.segment(102.0, 102.0, 1.0), Vec4::ZERO);
    }

    #[test]
    fn a_segment_across_a_peak_integrates_it() {
        let table = block();
        // From 100 to 139 (the table's last entry) over 3.9 mm: the ray spends 1 mm in the
        // block, plus the ramps of one stored value on each side (half an entry each: 0.1 mm).
        let s = table.segment(100.0, 139.0, 3.9);
        let tau = -(0.7f32.ln());
        let expected = 1.0 - (-tau * 1.1).exp();
        assert!((s.w - expected).abs() < 1e-4, "{} vs {expected}", s.w);
        // Both directions alike; a point sample at either end sees nothing.
        let back = table.segment(139.0, 100.0, 3.9);
        assert!((back.w - s.w).abs() < 1e-6);
        assert_eq!(table.segment(100.0, 100.0, 4.0), Vec4::ZERO);
        // Out of range and NaN clamp to the ends.
        assert_eq!(table.segment(-5.0, f32::NAN, 1.0), Vec4::ZERO);
    }

    #[test]
    fn the_exponential_is_close_to_libm() {
        for k in 0..1740 {
            let x = k as f32 * 0.05;
            let (fast, exact) = (exp_of_negative(x), (-f64::from(x)).exp());
            assert!(
                (f64::from(fast) - exact).abs() <= 5e-7 * exact,
                "{x}: {fast}"
            );
        }
    }

    #[test]
    fn transparent_between_clears_the_integral() {
        let mut table = block();
        table.make_transparent_between(100.0, 125.0);
        assert_eq!(table.segment(100.0, 140.0, 4.0), Vec4::ZERO);
    }
}
