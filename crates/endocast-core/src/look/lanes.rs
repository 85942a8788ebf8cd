//! Eight pixels at once: the deferred stage works on rows of channel planes (one `f32` slice per
//! channel) eight pixels at a time, in loops over fixed lanes that LLVM turns into one AVX2
//! operation each where [`crate::render::with_avx2`] compiles them for it (else two SSE2 ones),
//! with the same bits either way.

/// Pixels handled together.
pub(super) const LANES: usize = 8;

/// One value per pixel of a lane set.
pub(super) type Lanes = [f32; LANES];

/// The `LANES` values of `plane` from `at` on.
#[inline(always)]
pub(super) fn load(plane: &[f32], at: usize) -> Lanes {
    let mut out = [0.0; LANES];
    out.copy_from_slice(&plane[at..at + LANES]);
    out
}

/// `f` lane by lane.
#[inline(always)]
pub(super) fn map(f: impl Fn(usize) -> f32) -> Lanes {
    let mut out = [0.0; LANES];
    for (k, o) in out.iter_mut().enumerate() {
        *o = f(k);
    }
    out
}

/// `f(axis, lane)` for three axes of lanes.
#[inline(always)]
pub(super) fn map3(f: impl Fn(usize, usize) -> f32) -> [Lanes; 3] {
    let mut out = [[0.0; LANES]; 3];
    for (axis, o) in out.iter_mut().enumerate() {
        for (k, o) in o.iter_mut().enumerate() {
            *o = f(axis, k);
        }
    }
    out
}

/// `n` rounded up to whole lane sets.
pub(super) fn padded(n: usize) -> usize {
    n.div_ceil(LANES) * LANES
}

/// The unit vector along `(x, y, z)` per lane, zero where it has no direction (zero, infinite
/// or NaN length): glam's `normalize_or_zero`, operation for operation.
#[inline(always)]
pub(super) fn normalize_or_zero(v: [Lanes; 3]) -> [Lanes; 3] {
    let [x, y, z] = v;
    let rcp = map(|k| 1.0 / (x[k] * x[k] + y[k] * y[k] + z[k] * z[k]).sqrt());
    let ok = |k: usize| rcp[k].is_finite() && rcp[k] > 0.0;
    map3(|a, k| if ok(k) { v[a][k] * rcp[k] } else { 0.0 })
}
