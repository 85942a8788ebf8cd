//! Transfer functions: piecewise-linear colour and opacity keyed in physical units, and the
//! lookup table the sample loop reads.
//!
//! Opacity is given "per millimetre" (the reference step Δs₀ = 1 mm, the convention of VTK's
//! `ScalarOpacityUnitDistance = 1`), so a transfer function means the same thing at any step
//! size and on any voxel spacing; [`TfTable`] corrects it for the actual step:
//! α' = 1 − (1 − α)^(Δs / Δs₀).

use super::preintegrate::SegmentTable;
use super::simd::sse;
use crate::ValueMap;
use glam::Vec4;
use thiserror::Error;

/// The reference length opacities are given for, mm.
pub const OPACITY_UNIT_MM: f64 = 1.0;

/// A transfer function that cannot be built.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum TransferError {
    /// The opacity or colour list is empty.
    #[error("the {0} list of a transfer function is empty")]
    Empty(&'static str),
    /// A value or component is NaN or infinite.
    #[error("the {0} list holds a NaN or infinite number")]
    NotFinite(&'static str),
    /// The points are not sorted by value.
    #[error("the {0} points are not sorted by value (value {1} follows a larger one)")]
    Unsorted(&'static str, f64),
    /// An opacity or colour component lies outside [0, 1].
    #[error("the {0} list holds {1}, outside [0, 1]")]
    OutOfRange(&'static str, f32),
}

/// Piecewise-linear opacity (per [`OPACITY_UNIT_MM`]) and colour over physical values (HU for
/// CT). Outside the first and last points the end values hold.
#[derive(Debug, Clone, PartialEq)]
pub struct TransferFunction {
    opacity: Vec<(f64, f32)>,
    color: Vec<(f64, [f32; 3])>,
}

impl TransferFunction {
    /// A transfer function from `(value, opacity)` and `(value, [r, g, b])` points, each list
    /// sorted by value (equal values make a step). Opacity and colour components must lie in
    /// [0, 1]; colours are display (sRGB-encoded) values, composited as given, like VTK does.
    pub fn from_points(
        opacity: &[(f64, f32)],
        color: &[(f64, [f32; 3])],
    ) -> Result<Self, TransferError> {
        check_points("opacity", opacity.iter().map(|(v, a)| (*v, vec![*a])))?;
        check_points("colour", color.iter().map(|(v, c)| (*v, c.to_vec())))?;
        Ok(Self {
            opacity: opacity.to_vec(),
            color: color.to_vec(),
        })
    }

    /// A simple ramp: transparent below `lo_hu`, opacity rising linearly to 1 per mm at `hi_hu`,
    /// grey from black at `lo_hu` to white at `hi_hu`. Bounds are swapped when given reversed.
    pub fn ramp(lo_hu: f64, hi_hu: f64) -> Self {
        let (lo, hi) = (lo_hu.min(hi_hu), lo_hu.max(hi_hu));
        Self {
            opacity: vec![(lo, 0.0), (hi, 1.0)],
            color: vec![(lo, [0.0; 3]), (hi, [1.0; 3])],
        }
    }

    /// The names [`TransferFunction::preset`] knows, in a fixed order.
    pub const PRESETS: [&'static str; 8] = [
        "ramp",
        "complex",
        "colonoscopy",
        "bronchoscopy",
        "angioscopy",
        "sinus",
        "ventricles",
        "arthroscopy",
    ];

    /// A named preset (see [`TransferFunction::PRESETS`]), thresholds from the measured values of
    /// the shared scans (CT in HU; "ventricles" in T1 MR intensity units):
    /// - `ramp`: the paper's Table 1 "simple alpha ramp", −700 → −300 HU, so tissue behind the
    ///   wall becomes opaque within a few millimetres and early termination pays.
    /// - `complex`: the paper's Table 2 kind, several faint peaks (lumen edge, fat, soft tissue)
    ///   and a brighter one for contrast and bone: rays rarely reach full opacity.
    /// - `colonoscopy`: faint fat and soft tissue behind the wall, vessels and bone bright.
    /// - `bronchoscopy`: faint lung and soft tissue behind the airway wall, cartilage/bone bright.
    /// - `angioscopy`: for a contrast-filled lumen (≈ 190–300 HU) seen from inside: wall and fat
    ///   faint, calcification and metal opaque.
    /// - `sinus`: mucosa faint, bone (> ≈ 400 HU) clearly visible through it.
    /// - `ventricles`: T1 MRI (CSF ≈ 30, white matter ≈ 120): tissue faint, brightest white.
    /// - `arthroscopy`: T1 MRI of a joint (joint space ≈ 5–20, muscle and cartilage ≈ 25–40,
    ///   marrow ≈ 48, fat brighter): soft tissue faint, marrow and fat ivory.
    pub fn preset(name: &str) -> Option<Self> {
        type Points = (&'static [(f64, f32)], &'static [(f64, [f32; 3])]);
        let (opacity, color): Points = match name.trim().to_ascii_lowercase().as_str() {
            "ramp" => return Some(Self::ramp(-700.0, -300.0)),
            "complex" => (
                &[
                    (-1024.0, 0.0),
                    (-650.0, 0.0),
                    (-500.0, 0.02),
                    (-350.0, 0.0),
                    (-150.0, 0.0),
                    (-100.0, 0.008),
                    (-60.0, 0.0),
                    (0.0, 0.0),
                    (40.0, 0.015),
                    (90.0, 0.0),
                    (200.0, 0.0),
                    (400.0, 0.25),
                    (3071.0, 0.5),
                ],
                &[
                    (-1024.0, [0.0, 0.0, 0.0]),
                    (-500.0, [0.9, 0.7, 0.6]),
                    (-100.0, [0.95, 0.85, 0.4]),
                    (40.0, [0.85, 0.35, 0.3]),
                    (400.0, [1.0, 1.0, 0.95]),
                ],
            ),
            "colonoscopy" => (
                &[
                    (-1024.0, 0.0),
                    (-300.0, 0.0),
                    (-100.0, 0.003),
                    (0.0, 0.01),
                    (100.0, 0.03),
                    (300.0, 0.5),
                    (3071.0, 0.9),
                ],
                &[
                    (-1024.0, [0.0, 0.0, 0.0]),
                    (-100.0, [0.9, 0.8, 0.35]),
                    (40.0, [0.85, 0.35, 0.3]),
                    (300.0, [1.0, 1.0, 1.0]),
                ],
            ),
            "bronchoscopy" => (
                &[
                    (-1024.0, 0.0),
                    (-900.0, 0.0),
                    (-800.0, 0.002),
                    (-200.0, 0.002),
                    (0.0, 0.01),
                    (100.0, 0.02),
                    (400.0, 0.6),
                    (3071.0, 0.9),
                ],
                &[
                    (-1024.0, [0.0, 0.0, 0.0]),
                    (-800.0, [0.6, 0.6, 0.75]),
                    (40.0, [0.85, 0.4, 0.35]),
                    (400.0, [1.0, 1.0, 0.95]),
                ],
            ),
            "angioscopy" => (
                &[
                    (-1024.0, 0.0),
                    (-150.0, 0.0),
                    (-100.0, 0.004),
                    (40.0, 0.02),
                    (120.0, 0.0),
                    (500.0, 0.0),
                    (700.0, 0.8),
                    (3071.0, 1.0),
                ],
                &[
                    (-1024.0, [0.0, 0.0, 0.0]),
                    (-100.0, [0.9, 0.8, 0.35]),
                    (40.0, [0.8, 0.3, 0.25]),
                    (700.0, [1.0, 1.0, 1.0]),
                ],
            ),
            "sinus" => (
                &[
                    (-1024.0, 0.0),
                    (-300.0, 0.0),
                    (0.0, 0.004),
                    (100.0, 0.006),
                    (400.0, 0.3),
                    (1500.0, 0.8),
                ],
                &[
                    (-1024.0, [0.0, 0.0, 0.0]),
                    (40.0, [0.85, 0.45, 0.4]),
                    (400.0, [1.0, 0.97, 0.9]),
                ],
            ),
            "ventricles" => (
                &[
                    (0.0, 0.0),
                    (75.0, 0.0),
                    (110.0, 0.01),
                    (160.0, 0.05),
                    (255.0, 0.2),
                ],
                &[
                    (0.0, [0.0, 0.0, 0.0]),
                    (75.0, [0.8, 0.6, 0.55]),
                    (130.0, [0.95, 0.9, 0.85]),
                    (255.0, [1.0, 1.0, 1.0]),
                ],
            ),
            "arthroscopy" => (
                &[
                    (0.0, 0.0),
                    (22.0, 0.0),
                    (30.0, 0.01),
                    (40.0, 0.05),
                    (60.0, 0.3),
                    (200.0, 0.5),
                ],
                &[
                    (0.0, [0.0, 0.0, 0.0]),
                    (30.0, [0.8, 0.45, 0.4]),
                    (45.0, [0.93, 0.88, 0.78]),
                    (200.0, [1.0, 1.0, 0.95]),
                ],
            ),
            _ => return None,
        };
        Some(Self {
            opacity: opacity.to_vec(),
            color: color.to_vec(),
        })
    }

    /// Opacity per [`OPACITY_UNIT_MM`] at a physical value.
    pub fn opacity_at(&self, value: f64) -> f32 {
        interpolate(&self.opacity, value, |a, b, t| a + (b - a) * t)
    }

    /// Colour at a physical value.
    pub fn color_at(&self, value: f64) -> [f32; 3] {
        interpolate(&self.color, value, |a, b, t| {
            [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
        })
    }

    /// The `(value, opacity)` points.
    pub fn opacity_points(&self) -> &[(f64, f32)] {
        &self.opacity
    }

    /// The `(value, colour)` points.
    pub fn color_points(&self) -> &[(f64, [f32; 3])] {
        &self.color
    }
}

/// Validates one list of points: non-empty, finite, sorted, components in [0, 1].
fn check_points(
    what: &'static str,
    points: impl Iterator<Item = (f64, Vec<f32>)>,
) -> Result<(), TransferError> {
    let mut previous = f64::NEG_INFINITY;
    let mut any = false;
    for (value, components) in points {
        any = true;
        if !value.is_finite() || components.iter().any(|c| !c.is_finite()) {
            return Err(TransferError::NotFinite(what));
        }
        if value < previous {
            return Err(TransferError::Unsorted(what, value));
        }
        if let Some(&c) = components.iter().find(|c| !(0.0..=1.0).contains(*c)) {
            return Err(TransferError::OutOfRange(what, c));
        }
        previous = value;
    }
    if any {
        Ok(())
    } else {
        Err(TransferError::Empty(what))
    }
}

/// Piecewise-linear interpolation over sorted, non-empty points (every constructor checks),
/// clamped at the ends.
fn interpolate<T: Copy>(points: &[(f64, T)], value: f64, lerp: impl Fn(T, T, f32) -> T) -> T {
    let upper = points.partition_point(|(v, _)| *v <= value);
    if upper == 0 {
        return points[0].1;
    }
    let Some(&(v1, y1)) = points.get(upper) else {
        return points[upper - 1].1;
    };
    let (v0, y0) = points[upper - 1];
    let t = if v1 > v0 {
        (value - v0) / (v1 - v0)
    } else {
        1.0
    };
    lerp(y0, y1, t as f32)
}

/// A transfer function sampled at every stored value of a volume, for the sample loop:
/// premultiplied colour and step-corrected opacity per stored value, interpolated linearly
/// between entries, and a prefix count of non-transparent entries so that "is every value in
/// this range transparent?" costs O(1) (the paper's summed-area table, in one dimension).
#[derive(Debug, Clone)]
pub struct TfTable {
    /// Stored value of entry 0.
    first: u16,
    /// Premultiplied colour and opacity per stored value `first + index`, then a copy of the
    /// last entry, so that an entry's upper neighbour always exists.
    entries: Vec<Vec4>,
    /// Plain (not premultiplied) colour per entry, for MIP/MinIP.
    colors: Vec<[f32; 3]>,
    /// `opaque_before[i]` = number of entries below `i` with non-zero opacity.
    opaque_before: Vec<u32>,
    /// The same transfer function for whole segments between samples (pre-integrated).
    segments: SegmentTable,
}

impl TfTable {
    /// Samples `tf` at every stored value in `stored_range` (inclusive) through `value_map`,
    /// correcting opacity for a step of `step_mm` (α' = 1 − (1 − α)^(step/1 mm)).
    pub fn new(
        tf: &TransferFunction,
        value_map: ValueMap,
        stored_range: (u16, u16),
        step_mm: f64,
    ) -> Self {
        let (lo, hi) = (
            stored_range.0.min(stored_range.1),
            stored_range.0.max(stored_range.1),
        );
        let exponent = step_mm / OPACITY_UNIT_MM;
        let points: Vec<(f32, [f32; 3])> = (lo..=hi)
            .map(|stored| {
                let value = value_map.physical(stored);
                (tf.opacity_at(value), tf.color_at(value))
            })
            .collect();
        let (mut entries, colors): (Vec<Vec4>, Vec<[f32; 3]>) = points
            .iter()
            .map(|&(alpha, [r, g, b])| {
                let alpha = corrected_opacity(alpha, exponent);
                (Vec4::new(r * alpha, g * alpha, b * alpha, alpha), [r, g, b])
            })
            .unzip();
        entries.push(entries[entries.len() - 1]);
        let mut table = Self {
            first: lo,
            entries,
            colors,
            opaque_before: Vec::new(),
            segments: SegmentTable::new(lo, points.into_iter()),
        };
        table.count_opaque();
        table
    }

    fn count_opaque(&mut self) {
        let mut count = 0u32;
        self.opaque_before = std::iter::once(0)
            .chain(self.entries[..self.colors.len()].iter().map(|e| {
                count += u32::from(e.w > 0.0);
                count
            }))
            .collect();
    }

    /// Makes every entry whose stored value lies in `[lo, hi]` (stored units) transparent: the
    /// two-isosurface mode renders only what lies outside its two isovalues by DVR.
    pub fn make_transparent_between(&mut self, lo: f32, hi: f32) {
        let first = f32::from(self.first);
        for (index, entry) in self.entries.iter_mut().enumerate() {
            let stored = first + index as f32;
            if stored >= lo && stored <= hi {
                *entry = Vec4::ZERO;
            }
        }
        let last = self.colors.len() - 1;
        self.entries[last + 1] = self.entries[last];
        self.count_opaque();
        self.segments.make_transparent_between(lo, hi);
    }

    /// True when some stored value in `[stored_lo, stored_hi]` has non-zero opacity. One stored
    /// unit of margin on each side covers the interpolation between neighbouring entries and
    /// rounding of trilinear samples, so a `false` is safe for skipping.
    pub fn any_opacity(&self, stored_lo: u16, stored_hi: u16) -> bool {
        let len = self.colors.len();
        let first = usize::from(self.first);
        let lo = usize::from(stored_lo)
            .saturating_sub(1)
            .saturating_sub(first);
        let hi = (usize::from(stored_hi) + 2).saturating_sub(first).min(len);
        lo < hi && self.opaque_before[hi] > self.opaque_before[lo]
    }

    /// Entry index and interpolation weight towards the next entry of a (continuous) stored
    /// value, clamped to the table: one `i32` conversion (`as` saturates and maps NaN to 0; the
    /// table has far fewer than 2³¹ entries).
    #[inline(always)]
    fn locate(&self, stored: f32) -> (usize, f32) {
        let x = (stored - f32::from(self.first)).max(0.0);
        let i = (x as i32).min(self.colors.len() as i32 - 1);
        (i as usize, (x - i as f32).min(1.0))
    }

    /// Premultiplied colour and step-corrected opacity at a continuous stored value: the entry
    /// and its upper neighbour (always there: the table ends with a copy of its last entry),
    /// one SIMD lerp of the four channels.
    #[inline(always)]
    pub fn lookup(&self, stored: f32) -> Vec4 {
        let (i, weight) = self.locate(stored);
        let pair = &self.entries[i..i + 2];
        pair[0] + (pair[1] - pair[0]) * weight
    }

    /// [`Self::lookup`] of eight values at once: the same operations, the entry positions and
    /// weights computed for all lanes together.
    #[inline(always)]
    pub fn lookup8(&self, values: &[f32; 8]) -> [Vec4; 8] {
        let top = self.colors.len() - 1;
        sse::lookup8(&self.entries, f32::from(self.first), top, values)
    }

    /// Premultiplied colour and opacity of a ray segment `length_mm` long whose stored value
    /// runs linearly from `front` to `back`, pre-integrated ([`super::preintegrate`]).
    #[inline(always)]
    pub(crate) fn segment(&self, front: f32, back: f32, length_mm: f32) -> Vec4 {
        self.segments.segment(front, back, length_mm)
    }

    /// [`Self::segment`] of eight segments at once: the same bits as one at a time.
    #[inline(always)]
    pub(crate) fn segments8(
        &self,
        fronts: &[f32; 8],
        backs: &[f32; 8],
        length_mm: f32,
    ) -> [Vec4; 8] {
        self.segments.segments8(fronts, backs, length_mm)
    }

    /// Plain colour at a continuous stored value (for maximum/minimum intensity projections).
    #[inline]
    pub fn color(&self, stored: f32) -> [f32; 3] {
        let (i, t) = self.locate(stored);
        let (a, b) = (
            self.colors[i],
            self.colors[(i + 1).min(self.colors.len() - 1)],
        );
        [0, 1, 2].map(|c| a[c] + (b[c] - a[c]) * t)
    }
}

/// Opacity for a step of `exponent` reference lengths.
fn corrected_opacity(alpha: f32, exponent: f64) -> f32 {
    let alpha = f64::from(alpha.clamp(0.0, 1.0));
    (1.0 - (1.0 - alpha).powf(exponent)) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_points() {
        let c = [(0.0, [1.0; 3])];
        assert!(TransferFunction::from_points(&[], &c).is_err());
        assert!(TransferFunction::from_points(&[(0.0, 0.5)], &[]).is_err());
        assert!(TransferFunction::from_points(&[(f64::NAN, 0.5)], &c).is_err());
        assert!(TransferFunction::from_points(&[(0.0, f32::INFINITY)], &c).is_err());
        assert!(TransferFunction::from_points(&[(1.0, 0.5), (0.0, 0.5)], &c).is_err());
        assert!(TransferFunction::from_points(&[(0.0, 1.5)], &c).is_err());
        assert!(TransferFunction::from_points(&[(0.0, 0.5)], &[(0.0, [0.0, -0.1, 0.0])]).is_err());
        assert!(TransferFunction::from_points(&[(0.0, 0.0), (0.0, 1.0)], &c).is_ok());
    }

    #[test]
    fn interpolates_and_clamps() {
        let tf = TransferFunction::ramp(100.0, 0.0);
        assert_eq!(tf.opacity_at(-5.0), 0.0);
        assert_eq!(tf.opacity_at(25.0), 0.25);
        assert_eq!(tf.opacity_at(500.0), 1.0);
        assert_eq!(tf.color_at(50.0), [0.5; 3]);
        for name in TransferFunction::PRESETS {
            let tf = TransferFunction::preset(name).unwrap();
            let again =
                TransferFunction::from_points(tf.opacity_points(), tf.color_points()).unwrap();
            assert_eq!(tf, again, "{name}");
        }
        assert!(TransferFunction::preset("nope").is_none());
    }

    #[test]
    fn table_corrects_opacity_and_counts_transparent_ranges() {
        let tf = TransferFunction::from_points(
            &[
                (0.0, 0.0),
                (10.0, 0.0),
                (10.0, 0.5),
                (20.0, 0.5),
                (20.0, 0.0),
            ],
            &[(0.0, [1.0, 0.5, 0.0])],
        )
        .unwrap();
        let map = ValueMap::new(1.0, -100.0).unwrap();
        let table = TfTable::new(&tf, map, (100, 140), 0.5);
        // Stored 115 = 15 HU: α = 0.5 per mm, over 0.5 mm: 1 − 0.5^0.5.
        let expected = 1.0 - 0.5f32.sqrt();
        let [r, g, b, a] = table.lookup(115.0).to_array();
        assert!((a - expected).abs() < 1e-6);
        assert!((r - expected).abs() < 1e-6 && (g - 0.5 * expected).abs() < 1e-6 && b == 0.0);
        assert!(!table.any_opacity(100, 108));
        assert!(table.any_opacity(100, 109));
        assert!(table.any_opacity(115, 115));
        assert!(!table.any_opacity(122, 140));
        assert!(!table.any_opacity(0, 50));
        assert_eq!(table.color(300.0), [1.0, 0.5, 0.0]);
        let mut masked = table.clone();
        masked.make_transparent_between(105.0, 130.0);
        assert!(!masked.any_opacity(100, 140));
        // Eight at a time: the same entries bit for bit, below, inside and past the table.
        let values = [0.0, 99.5, 109.3, 110.0, 115.7, 139.9, 140.5, f32::NAN];
        for (entry, value) in table.lookup8(&values).iter().zip(values) {
            let bits = |v: Vec4| v.to_array().map(f32::to_bits);
            assert_eq!(bits(*entry), bits(table.lookup(value)));
        }
    }
}
