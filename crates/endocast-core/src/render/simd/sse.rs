//! Batches of eight `f32` on SSE and SSE2, part of the x86-64 baseline (no detection needed):
//! the sides of a batch's samples against an isovalue, and transfer-table lookups. Each has its
//! scalar form on other targets, with the same results.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{
    __m128, _mm_cmpge_ps, _mm_cmplt_ps, _mm_cvtepi32_ps, _mm_cvttps_epi32, _mm_loadu_ps,
    _mm_max_ps, _mm_min_ps, _mm_movemask_ps, _mm_set1_ps, _mm_setr_ps, _mm_setzero_ps,
    _mm_storeu_ps, _mm_storeu_si128, _mm_sub_ps,
};

use crate::render::sample::Lanes;
use glam::Vec4;

/// The lanes of `values` below `iso` and at or above it, as bit masks (lane k, bit k; ordered
/// comparisons, so a NaN is in neither).
#[inline(always)]
pub(crate) fn sides(values: &Lanes, iso: f32) -> (u32, u32) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE is part of the x86-64 baseline every build targets.
    unsafe {
        let v = values;
        let (low, high) = (
            _mm_setr_ps(v[0], v[1], v[2], v[3]),
            _mm_setr_ps(v[4], v[5], v[6], v[7]),
        );
        let iso = _mm_set1_ps(iso);
        let bits =
            |low: __m128, high: __m128| (_mm_movemask_ps(low) | _mm_movemask_ps(high) << 4) as u32;
        (
            bits(_mm_cmplt_ps(low, iso), _mm_cmplt_ps(high, iso)),
            bits(_mm_cmpge_ps(low, iso), _mm_cmpge_ps(high, iso)),
        )
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let (mut below, mut above) = (0u32, 0u32);
        for (k, &v) in values.iter().enumerate() {
            below |= u32::from(v < iso) << k;
            above |= u32::from(v >= iso) << k;
        }
        (below, above)
    }
}

/// `TfTable::lookup8`'s reads: for each of eight stored values, entries `i` and `i + 1` of
/// `entries` (whose first is stored value `first`) lerped by the weight, `i` clamped to
/// `[0, top]` as `TfTable::locate` clamps it.
///
/// # Panics
/// Where `entries` has no entry past `top`, or `top` ≥ 2²⁴ (not exact in `f32`; tables hold
/// at most 2¹⁶ + 1 entries).
#[inline(always)]
pub(crate) fn lookup8(entries: &[Vec4], first: f32, top: usize, values: &[f32; 8]) -> [Vec4; 8] {
    assert!(top < 1 << 24 && top + 1 < entries.len());
    let (index, weight) = locate8(values, first, top as f32);
    std::array::from_fn(|k| {
        let i = index[k] as usize;
        debug_assert!(i <= top);
        // SAFETY: `locate8` clamps i to [0, top] (`top` is exact in f32), and top + 1 <
        // entries.len() (asserted above), so entries i and i + 1 exist.
        let (lo, hi) = unsafe { (*entries.get_unchecked(i), *entries.get_unchecked(i + 1)) };
        lo + (hi - lo) * weight[k]
    })
}

/// `TfTable::locate` of eight values for a table whose first entry is stored value `first`
/// and last entry index `top`: entry indices clamped to `[0, top]` and weights. Four lanes at a
/// time on SSE2 (part of every x86-64 CPU), with the scalar path's results: `maxps` and `minps`
/// return their second operand for a NaN first one, as `f32::max` and `f32::min` ignore NaN.
#[inline(always)]
fn locate8(values: &[f32; 8], first: f32, top: f32) -> ([i32; 8], [f32; 8]) {
    let (mut index, mut weight) = ([0i32; 8], [0.0f32; 8]);
    #[cfg(target_arch = "x86_64")]
    for half in [0, 4] {
        // SAFETY: SSE2 is part of the x86-64 baseline; each load and store touches the four
        // elements `half .. half + 4` of an eight-element array.
        unsafe {
            let v = _mm_loadu_ps(values.as_ptr().add(half));
            let x = _mm_max_ps(_mm_sub_ps(v, _mm_set1_ps(first)), _mm_setzero_ps());
            // x.min(top) lies in [0, top]: truncation is exact and in range.
            let i = _mm_cvttps_epi32(_mm_min_ps(x, _mm_set1_ps(top)));
            let w = _mm_min_ps(_mm_sub_ps(x, _mm_cvtepi32_ps(i)), _mm_set1_ps(1.0));
            _mm_storeu_si128(index.as_mut_ptr().add(half).cast(), i);
            _mm_storeu_ps(weight.as_mut_ptr().add(half), w);
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    for k in 0..8 {
        let x = (values[k] - first).max(0.0);
        index[k] = x.min(top) as i32;
        weight[k] = (x - index[k] as f32).min(1.0);
    }
    (index, weight)
}
