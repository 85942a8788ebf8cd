//! The exact isosurface search ([`crate::render::cell_walk`]) for eight rays at once, one ray
//! per AVX2 lane: every lane walks its own cells ([`CellDda`] step for step: the next face, the
//! brick's place in the cell mask and the cell's bit fetched by gathers, an empty brick left in
//! one jump), so the bookkeeping of the walk is done for eight rays by each instruction. The
//! lanes whose cell can hold the isovalue hand it to the scalar cubic
//! ([`CellWalk::in_cell`]), so every lane finds the one-ray walk's crossing, bit for bit.

use super::packet::{
    any, bits, blend_ps, floats, ints, lanes_f32_from, lanes_i32_from, mask, Mask,
};
use crate::render::bricks::BRICK_VOX;
use crate::render::cell_mask::BRICK_SHIFT;
use crate::render::cell_walk::{CellDda, CellWalk, Side};
use crate::render::ray_task::RayTask;
use crate::render::voxel_grid::SampleGrid;
use std::arch::x86_64::{
    __m256, __m256i, _mm256_add_epi32, _mm256_add_ps, _mm256_and_si256, _mm256_andnot_si256,
    _mm256_blendv_epi8, _mm256_blendv_ps, _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps,
    _mm256_cmpeq_epi32, _mm256_cmpgt_epi32, _mm256_cvtepi32_ps, _mm256_cvttps_epi32,
    _mm256_mask_i32gather_epi32, _mm256_max_ps, _mm256_min_epi32, _mm256_min_epu32, _mm256_min_ps,
    _mm256_mul_ps, _mm256_mullo_epi32, _mm256_or_si256, _mm256_set1_epi32, _mm256_set1_ps,
    _mm256_setzero_si256, _mm256_slli_epi32, _mm256_srai_epi32, _mm256_srli_epi32,
    _mm256_srlv_epi32, _mm256_sub_epi32, _mm256_sub_ps, _CMP_LT_OQ,
};

/// The first crossings of up to eight rays whose marches have not been walked yet, lane `k`
/// walking `tasks[k]`'s ray from the side `sides[k]` (`(rising, before)`) as
/// [`CellWalk::first_hit`] walks one (the marches are left alone).
#[target_feature(enable = "avx2")]
pub(super) fn first_hits8(
    walk: &CellWalk<'_>,
    tasks: &[RayTask],
    sides: [(bool, bool); 8],
) -> [Option<f32>; 8] {
    let mut hits = [None; 8];
    let (slots, words) = (walk.cells.slots(), walk.cells.words());
    if slots.is_empty() || words.is_empty() {
        // No brick can hold the isovalue.
        return hits;
    }
    let lines: [Option<SampleGrid>; 8] =
        std::array::from_fn(|k| tasks.get(k).map(|t| t.march.grid()));
    let ddas: [Option<CellDda>; 8] =
        std::array::from_fn(|k| tasks.get(k).map(|t| walk.dda(&t.march)));
    let mut sides = sides.map(Side::new);
    let mut lanes = Walk8::load(&lines, &ddas, walk.voxels.max_base);
    let mut done = mask(|k| ddas[k].is_none());
    loop {
        let running = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(lanes.t, lanes.t_end));
        let live = _mm256_andnot_si256(done, running);
        if !any(live) {
            return hits;
        }
        let slot = slot_of(slots, lanes.brick(walk.cells.bricks()), live);
        let empty = _mm256_and_si256(live, _mm256_cmpeq_epi32(slot, all()));
        let busy = _mm256_andnot_si256(empty, live);
        if any(busy) {
            let next = lanes.next_face();
            let flagged = _mm256_and_si256(busy, is_flagged(words, slot, lanes.cell, busy));
            if any(flagged) {
                let found = solve(
                    walk,
                    (&lines, &mut sides),
                    (&lanes, &next),
                    flagged,
                    &mut hits,
                );
                done = _mm256_or_si256(done, found);
            }
            lanes.step(&next, _mm256_andnot_si256(done, busy));
        }
        if any(empty) {
            lanes.leave_brick(empty);
        }
    }
}

/// All lanes on (and the slot of a brick without cells, [`crate::render::cell_mask::NONE`]).
#[target_feature(enable = "avx2")]
#[inline]
fn all() -> Mask {
    _mm256_set1_epi32(-1)
}

/// The scalar cubic of each lane of `flagged` in the cell it is in, over its span to the next
/// face: records the hits in `hits`, and returns the lanes that found one.
#[target_feature(enable = "avx2")]
fn solve(
    walk: &CellWalk<'_>,
    (lines, sides): (&[Option<SampleGrid>; 8], &mut [Side; 8]),
    (lanes, next): (&Walk8, &NextFace),
    flagged: Mask,
    hits: &mut [Option<f32>; 8],
) -> Mask {
    let cell = lanes.cell.map(|c| ints(c));
    let (t, t_exit) = (floats(lanes.t), floats(next.t_exit));
    let mut found = [0i32; 8];
    let on = bits(flagged);
    for (k, (line, side)) in lines.iter().zip(sides.iter_mut()).enumerate() {
        let Some(line) = line.filter(|_| on >> k & 1 == 1) else {
            continue;
        };
        let span = (t[k], t_exit[k]);
        let place = [cell[0][k], cell[1][k], cell[2][k]];
        if let Some(hit) = walk.in_cell(&line, place, span, side, &mut |_| true) {
            hits[k] = Some(hit);
            found[k] = -1;
        }
    }
    lanes_i32_from(found)
}

/// The place of each lane's brick's cells in the cell mask (gathered from `slots` for the lanes
/// of `on`; the others read as bricks without cells).
#[target_feature(enable = "avx2")]
#[inline]
fn slot_of(slots: &[u32], brick: __m256i, on: Mask) -> __m256i {
    let last = i32::try_from(slots.len() - 1).unwrap_or(i32::MAX);
    let index = _mm256_min_epu32(brick, _mm256_set1_epi32(last));
    // SAFETY: every lane's index lies in [0, slots.len() − 1] (unsigned minimum above), and
    // scale 4 makes it an element of `slots`; lanes off `on` are not read.
    unsafe { _mm256_mask_i32gather_epi32::<4>(all(), slots.as_ptr().cast::<i32>(), index, on) }
}

/// Whether each lane's cell is set in its brick's cells (at place `slot` of `words`), for the
/// lanes of `on`.
#[target_feature(enable = "avx2")]
#[inline]
fn is_flagged(words: &[u64], slot: __m256i, cell: [__m256i; 3], on: Mask) -> Mask {
    let local = cell.map(|c| _mm256_and_si256(c, _mm256_set1_epi32(BRICK_VOX as i32 - 1)));
    // Bit `i + 8 j` of layer word `k`; as 32-bit words (x86 is little-endian): two per layer.
    let place = _mm256_add_epi32(local[0], _mm256_slli_epi32::<3>(local[1]));
    let per_brick = _mm256_set1_epi32(2 * BRICK_VOX as i32);
    let layer = _mm256_add_epi32(
        _mm256_slli_epi32::<1>(local[2]),
        _mm256_srli_epi32::<5>(place),
    );
    let word = _mm256_add_epi32(_mm256_mullo_epi32(slot, per_brick), layer);
    let last = i32::try_from(words.len() * 2 - 1).unwrap_or(i32::MAX);
    let word = _mm256_min_epu32(word, _mm256_set1_epi32(last));
    // SAFETY: every lane's index lies in [0, 2 · words.len() − 1] (unsigned minimum above), and
    // scale 4 makes it a 32-bit half of an element of `words`; lanes off `on` are not read.
    let bits = unsafe {
        _mm256_mask_i32gather_epi32::<4>(
            _mm256_setzero_si256(),
            words.as_ptr().cast::<i32>(),
            word,
            on,
        )
    };
    let one = _mm256_set1_epi32(1);
    let shift = _mm256_and_si256(place, _mm256_set1_epi32(31));
    _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_srlv_epi32(bits, shift), one), one)
}

/// Where each lane's ray leaves its cell: through which axis (lane masks, ties to the lower
/// axis, as `next_axis`) and when (clamped to the walk).
struct NextFace {
    is_axis: [Mask; 3],
    t_exit: __m256,
}

/// Eight lanes' cell walks ([`CellDda`]'s fields) and their rays.
struct Walk8 {
    origin: [__m256; 3],
    direction: [__m256; 3],
    inverse: [__m256; 3],
    /// Lanes that move along each axis, and those that move up it.
    moving: [Mask; 3],
    rising: [Mask; 3],
    /// −1, 0 or +1 per axis.
    step: [__m256i; 3],
    /// The cell each lane is in (its lowest voxel).
    cell: [__m256i; 3],
    /// Where each ray meets its next cell face per axis, and the distance between faces, mm.
    t_next: [__m256; 3],
    t_delta: [__m256; 3],
    /// Where each walk is and where it ends, mm.
    t: __m256,
    t_end: __m256,
    /// The volume's last cell per axis.
    max_base: [__m256i; 3],
}

impl Walk8 {
    /// The walks of `ddas` along `lines`; missing lanes have ended.
    #[target_feature(enable = "avx2")]
    fn load(
        lines: &[Option<SampleGrid>; 8],
        ddas: &[Option<CellDda>; 8],
        max_base: [i32; 3],
    ) -> Self {
        let float = |f: &dyn Fn(&SampleGrid, &CellDda) -> f32| {
            lanes_f32_from(std::array::from_fn(|k| match (&lines[k], &ddas[k]) {
                (Some(line), Some(dda)) => f(line, dda),
                _ => 0.0,
            }))
        };
        let int = |f: &dyn Fn(&CellDda) -> i32| {
            lanes_i32_from(std::array::from_fn(|k| ddas[k].as_ref().map_or(0, f)))
        };
        let step: [__m256i; 3] = std::array::from_fn(|a| int(&|d| d.step[a]));
        let zero = _mm256_setzero_si256();
        Self {
            origin: std::array::from_fn(|a| float(&|l, _| l.origin[a])),
            direction: std::array::from_fn(|a| float(&|l, _| l.direction[a])),
            inverse: std::array::from_fn(|a| float(&|_, d| d.inverse[a])),
            moving: step.map(|s| _mm256_andnot_si256(_mm256_cmpeq_epi32(s, zero), all())),
            rising: step.map(|s| _mm256_cmpgt_epi32(s, zero)),
            step,
            cell: std::array::from_fn(|a| int(&|d| d.cell[a])),
            t_next: std::array::from_fn(|a| float(&|_, d| d.t_next[a])),
            t_delta: std::array::from_fn(|a| float(&|_, d| d.t_delta[a])),
            // Missing lanes: 0 < 0 fails, they never run.
            t: float(&|_, d| d.t),
            t_end: float(&|_, d| d.t_end),
            max_base: max_base.map(|m| _mm256_set1_epi32(m)),
        }
    }

    /// The index of each lane's brick (`CellMask::brick_of`).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn brick(&self, bricks: [i32; 3]) -> __m256i {
        let [i, j, k] = self
            .cell
            .map(|c| _mm256_srai_epi32::<{ BRICK_SHIFT as i32 }>(c));
        let (bx, by) = (_mm256_set1_epi32(bricks[0]), _mm256_set1_epi32(bricks[1]));
        _mm256_add_epi32(
            i,
            _mm256_mullo_epi32(bx, _mm256_add_epi32(j, _mm256_mullo_epi32(by, k))),
        )
    }

    /// Where each lane leaves its cell (`CellDda::step`'s first half).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn next_face(&self) -> NextFace {
        let (is_axis, t_face) = nearest(self.t_next);
        let t_exit = _mm256_min_ps(_mm256_max_ps(t_face, self.t), self.t_end);
        NextFace { is_axis, t_exit }
    }

    /// `CellDda::step`'s second half in the lanes of `on`: into the next cell through `next`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn step(&mut self, next: &NextFace, on: Mask) {
        let select = |v: &[__m256i; 3]| pick(v, &next.is_axis);
        let cell = _mm256_add_epi32(select(&self.cell), select(&self.step));
        let outside = outside(cell, select(&self.max_base));
        for axis in 0..3 {
            let moves = _mm256_and_si256(next.is_axis[axis], on);
            self.cell[axis] = _mm256_blendv_epi8(self.cell[axis], cell, moves);
            let stepped = _mm256_add_ps(self.t_next[axis], self.t_delta[axis]);
            self.t_next[axis] = blend_ps(self.t_next[axis], stepped, moves);
        }
        let t = blend_ps(next.t_exit, self.t_end, outside);
        self.t = blend_ps(self.t, t, on);
    }

    /// `CellDda::leave_brick` in the lanes of `on`.
    #[target_feature(enable = "avx2")]
    fn leave_brick(&mut self, on: Mask) {
        let edge = _mm256_set1_epi32(BRICK_VOX as i32);
        let first = self
            .cell
            .map(|c| _mm256_and_si256(c, _mm256_set1_epi32(!(BRICK_VOX as i32 - 1))));
        let exits: [__m256; 3] = std::array::from_fn(|a| {
            let face = _mm256_add_epi32(first[a], _mm256_and_si256(edge, self.rising[a]));
            self.face_t(a, _mm256_cvtepi32_ps(face))
        });
        let (is_axis, t_exit) = nearest(exits);
        let t = _mm256_max_ps(t_exit, self.t);
        let one = _mm256_set1_epi32(1);
        let behind: [__m256i; 3] = std::array::from_fn(|a| {
            let up = _mm256_add_epi32(first[a], edge);
            _mm256_blendv_epi8(_mm256_sub_epi32(first[a], one), up, self.rising[a])
        });
        for (a, behind) in behind.iter().enumerate() {
            let at = _mm256_add_ps(self.origin[a], _mm256_mul_ps(self.direction[a], t));
            let last = _mm256_min_epi32(
                _mm256_sub_epi32(_mm256_add_epi32(first[a], edge), one),
                self.max_base[a],
            );
            let inside = cell_at(at, first[a], last);
            let cell = _mm256_blendv_epi8(inside, *behind, is_axis[a]);
            self.cell[a] = _mm256_blendv_epi8(self.cell[a], cell, on);
        }
        for a in 0..3 {
            let up = _mm256_and_si256(_mm256_castps_si256(_mm256_set1_ps(1.0)), self.rising[a]);
            let face = _mm256_add_ps(_mm256_cvtepi32_ps(self.cell[a]), _mm256_castsi256_ps(up));
            self.t_next[a] = blend_ps(self.t_next[a], self.face_t(a, face), on);
        }
        let outside = outside(pick(&behind, &is_axis), pick(&self.max_base, &is_axis));
        self.t = blend_ps(self.t, blend_ps(t, self.t_end, outside), on);
    }

    /// Where each lane's ray meets the plane at `face` of `axis` (`CellDda::face_t`).
    #[target_feature(enable = "avx2")]
    #[inline]
    fn face_t(&self, axis: usize, face: __m256) -> __m256 {
        let t = _mm256_mul_ps(_mm256_sub_ps(face, self.origin[axis]), self.inverse[axis]);
        blend_ps(_mm256_set1_ps(f32::INFINITY), t, self.moving[axis])
    }
}

/// The axis with the nearest of `t` per lane (ties to the lower axis, as `next_axis`), and that
/// distance.
#[target_feature(enable = "avx2")]
#[inline]
fn nearest([x, y, z]: [__m256; 3]) -> ([Mask; 3], __m256) {
    let y_first = _mm256_cmp_ps::<_CMP_LT_OQ>(y, x);
    let nearer = _mm256_blendv_ps(x, y, y_first);
    let z_first = _mm256_cmp_ps::<_CMP_LT_OQ>(z, nearer);
    let t = _mm256_blendv_ps(nearer, z, z_first);
    let (y_first, z_first) = (_mm256_castps_si256(y_first), _mm256_castps_si256(z_first));
    let is_x = _mm256_andnot_si256(_mm256_or_si256(y_first, z_first), all());
    let is_y = _mm256_andnot_si256(z_first, y_first);
    ([is_x, is_y, z_first], t)
}

/// The lane of `v` of the axis `is_axis` says, per lane.
#[target_feature(enable = "avx2")]
#[inline]
fn pick(v: &[__m256i; 3], is_axis: &[Mask; 3]) -> __m256i {
    let yz = _mm256_blendv_epi8(v[1], v[2], is_axis[2]);
    _mm256_blendv_epi8(v[0], yz, _mm256_andnot_si256(is_axis[0], all()))
}

/// Lanes whose `cell` lies outside `[0, max_base]`.
#[target_feature(enable = "avx2")]
#[inline]
fn outside(cell: __m256i, max_base: __m256i) -> Mask {
    _mm256_or_si256(
        _mm256_cmpgt_epi32(_mm256_setzero_si256(), cell),
        _mm256_cmpgt_epi32(cell, max_base),
    )
}

/// `cell_at` per lane: the cell holding `p`, kept in `[lo, hi]`.
#[target_feature(enable = "avx2")]
#[inline]
fn cell_at(p: __m256, lo: __m256i, hi: __m256i) -> __m256i {
    // `p.max(lo).min(hi)`: `max_ps` gives its second operand where the first is NaN, as
    // `f32::max` gives the number.
    let clamped = _mm256_min_ps(
        _mm256_max_ps(p, _mm256_cvtepi32_ps(lo)),
        _mm256_cvtepi32_ps(hi),
    );
    _mm256_cvttps_epi32(clamped)
}
