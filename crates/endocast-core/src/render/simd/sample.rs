//! Eight trilinear samples at once on AVX2. Voxels along x are adjacent in memory, so one 32-bit
//! gather at a cell's base index reads both x-corners of a (y, z) corner pair: four gathers fetch
//! the eight corners of eight cells. Every other step repeats the scalar [`Sampler::value`]
//! operation for operation — clamp, truncate, the same lerps in the same order, no fused
//! multiply-add — so the lanes equal the scalar values bit for bit.

use crate::render::voxel_grid::{Lanes, SampleGrid, VoxelGrid, BRICK_LEN, EDGE, VOX};
use std::arch::x86_64::{
    __m256, __m256i, _mm256_add_epi32, _mm256_add_ps, _mm256_and_si256, _mm256_cvtepi32_ps,
    _mm256_cvttps_epi32, _mm256_i32gather_epi32, _mm256_loadu_ps, _mm256_max_ps, _mm256_min_epi32,
    _mm256_min_ps, _mm256_mul_ps, _mm256_mullo_epi32, _mm256_set1_epi32, _mm256_set1_ps,
    _mm256_setr_epi32, _mm256_setzero_ps, _mm256_slli_epi32, _mm256_srli_epi32, _mm256_storeu_ps,
    _mm256_sub_ps,
};

/// Samples `n .. n + 8` of `grid`.
#[target_feature(enable = "avx2")]
pub(super) fn grid8(sampler: &VoxelGrid<'_>, grid: &SampleGrid, n: i32) -> Lanes {
    let index = _mm256_add_epi32(
        _mm256_set1_epi32(n),
        _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
    );
    // t_n = t_start + (n + offset) · step, as `SampleGrid::t_of`.
    let grid_steps = _mm256_add_ps(_mm256_cvtepi32_ps(index), _mm256_set1_ps(grid.offset));
    let t = _mm256_add_ps(
        _mm256_set1_ps(grid.t_start),
        _mm256_mul_ps(grid_steps, _mm256_set1_ps(grid.step)),
    );
    at_distances(sampler, grid, t)
}

/// The values at `line.at(t[k])`.
#[target_feature(enable = "avx2")]
pub(super) fn along8(sampler: &VoxelGrid<'_>, line: &SampleGrid, t: &Lanes) -> Lanes {
    // SAFETY: `t` holds exactly eight f32; unaligned loads are allowed.
    at_distances(sampler, line, unsafe { _mm256_loadu_ps(t.as_ptr()) })
}

/// The values at `line.at(t)` per lane.
#[target_feature(enable = "avx2")]
#[inline]
fn at_distances(sampler: &VoxelGrid<'_>, line: &SampleGrid, t: __m256) -> Lanes {
    let x = along(line.origin.x, line.direction.x, t);
    let y = along(line.origin.y, line.direction.y, t);
    let z = along(line.origin.z, line.direction.z, t);
    store(trilinear(sampler, x, y, z))
}

/// The values at eight positions given as their x, y and z lanes.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn points8(sampler: &VoxelGrid<'_>, [x, y, z]: [&Lanes; 3]) -> Lanes {
    // SAFETY: each array holds exactly eight f32; unaligned loads are allowed.
    let load = |lanes: &Lanes| unsafe { _mm256_loadu_ps(lanes.as_ptr()) };
    store(trilinear(sampler, load(x), load(y), load(z)))
}

/// `origin + direction · t` per lane, as `SampleGrid::at`.
#[target_feature(enable = "avx2")]
#[inline]
fn along(origin: f32, direction: f32, t: __m256) -> __m256 {
    _mm256_add_ps(
        _mm256_set1_ps(origin),
        _mm256_mul_ps(_mm256_set1_ps(direction), t),
    )
}

/// `a + (b − a) · t` per lane, as the scalar lerps.
#[target_feature(enable = "avx2")]
#[inline]
fn lerp(a: __m256, b: __m256, t: __m256) -> __m256 {
    _mm256_add_ps(a, _mm256_mul_ps(_mm256_sub_ps(b, a), t))
}

/// Base index (clamped to `max_base`) and fraction of positions along one axis clamped to
/// `[0, extent]`; NaN clamps to 0 like the scalar `f32::max`.
#[target_feature(enable = "avx2")]
#[inline]
fn cell(p: __m256, extent: f32, max_base: i32) -> (__m256i, __m256) {
    let p = _mm256_min_ps(
        _mm256_max_ps(p, _mm256_setzero_ps()),
        _mm256_set1_ps(extent),
    );
    let base = _mm256_min_epi32(_mm256_cvttps_epi32(p), _mm256_set1_epi32(max_base));
    (base, _mm256_sub_ps(p, _mm256_cvtepi32_ps(base)))
}

/// Eight trilinear values at voxel positions `(x, y, z)` (lanes: any positions, they are
/// clamped to the volume).
#[target_feature(enable = "avx2")]
#[inline]
pub(crate) fn trilinear(s: &VoxelGrid<'_>, x: __m256, y: __m256, z: __m256) -> __m256 {
    let (bx, fx) = cell(x, s.extent.x, s.max_base[0]);
    let (by, fy) = cell(y, s.extent.y, s.max_base[1]);
    let (bz, fz) = cell(z, s.extent.z, s.max_base[2]);
    let (voxels, base, sy, sz) = match s.bricked {
        Some((voxels, bricks)) => {
            let (base, sy, sz) = bricked_base(bricks, bx, by, bz);
            (voxels, base, sy, sz)
        }
        None => {
            // `Sampler::new` enables this path only when every index fits an i32.
            let [_, sy, sz] = s.stride.map(|stride| stride as i32);
            let base = _mm256_add_epi32(
                bx,
                _mm256_add_epi32(
                    _mm256_mullo_epi32(by, _mm256_set1_epi32(sy)),
                    _mm256_mullo_epi32(bz, _mm256_set1_epi32(sz)),
                ),
            );
            (s.voxels, base, sy, sz)
        }
    };
    let pair = |offset: i32| {
        let index = _mm256_add_epi32(base, _mm256_set1_epi32(offset));
        // SAFETY: linear: the base lies in [0, len − 1 − (1 + sy + sz)] (bx ≤ nx − 2, by ≤ ny − 2
        // or sy = 0, bz ≤ nz − 2 or sz = 0; x has two voxels or more, so the x stride is 1);
        // bricked: the cell's brick holds its whole footprint (local index + 1 + sy + sz <
        // BRICK_LEN). Either way the four bytes at u16 index `base + offset` (offset ≤ sy + sz)
        // are inside the slice. Gathers need no alignment.
        let both = unsafe { _mm256_i32gather_epi32::<2>(voxels.as_ptr().cast::<i32>(), index) };
        let low = _mm256_cvtepi32_ps(_mm256_and_si256(both, _mm256_set1_epi32(0xFFFF)));
        let high = _mm256_cvtepi32_ps(_mm256_srli_epi32::<16>(both));
        lerp(low, high, fx)
    };
    let (c00, c10, c01, c11) = (pair(0), pair(sy), pair(sz), pair(sy + sz));
    lerp(lerp(c00, c10, fy), lerp(c01, c11, fy), fz)
}

/// The bricked index of cells with base `(bx, by, bz)` and the y and z strides inside a brick:
/// the brick's offset as three independent products (not a chain of them), the cell's inside
/// it by shifts.
#[target_feature(enable = "avx2")]
#[inline]
fn bricked_base(bricks: [i32; 3], bx: __m256i, by: __m256i, bz: __m256i) -> (__m256i, i32, i32) {
    const SHIFT: i32 = VOX.trailing_zeros() as i32;
    let (edge, len) = (EDGE as i32, BRICK_LEN as i32);
    let offset = |c: __m256i, stride: i32| {
        _mm256_mullo_epi32(_mm256_srli_epi32::<SHIFT>(c), _mm256_set1_epi32(stride))
    };
    let brick = _mm256_add_epi32(
        offset(bx, len),
        _mm256_add_epi32(
            offset(by, len * bricks[0]),
            offset(bz, len * bricks[0] * bricks[1]),
        ),
    );
    // EDGE = 2^SHIFT + 1: l · EDGE = (l << SHIFT) + l.
    let local = |c: __m256i| _mm256_and_si256(c, _mm256_set1_epi32(VOX as i32 - 1));
    let times_edge = |c: __m256i| _mm256_add_epi32(_mm256_slli_epi32::<SHIFT>(c), c);
    let inside = _mm256_add_epi32(
        local(bx),
        times_edge(_mm256_add_epi32(local(by), times_edge(local(bz)))),
    );
    (_mm256_add_epi32(brick, inside), edge, edge * edge)
}

/// The lanes as an array.
#[target_feature(enable = "avx2")]
#[inline]
fn store(v: __m256) -> Lanes {
    let mut out = [0.0; 8];
    // SAFETY: `out` holds exactly eight f32; unaligned stores are allowed.
    unsafe { _mm256_storeu_ps(out.as_mut_ptr(), v) };
    out
}
