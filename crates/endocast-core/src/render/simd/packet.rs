//! The isosurface search (and its refinement, [`refine8`]) for eight rays at once, one ray per
//! AVX2 lane (ray-parallel SIMD, as packet ray tracers run): every lane walks its own bricks
//! ([`BrickDda`] step for step) and takes its own samples, two per lane and loop, so the
//! per-ray bookkeeping of the walk — brick steps, activity tests, sample ranges, crossing
//! tests — is done for eight rays by each instruction instead of one.
//!
//! A lane takes exactly the samples the one-ray walk
//! ([`crate::render::march::Walk::SEARCH`]) takes: in each active brick, from the last sample
//! before it to the first at or after its end (skipping those already taken), and tests each
//! sample against the one before it on the grid when that one was taken. Its first crossing,
//! values and all, is the one-ray search's, and the march is left where that search would leave
//! it for what follows (the volume behind the surface): at the sample after the crossing, the
//! brick it was found in pending.

use super::sample::trilinear;
use crate::render::march::MarchStats;
use crate::render::ray_task::{Bracket, RayTask};
use crate::render::traverse::{BrickDda, Segment};
use crate::render::voxel_grid::VoxelGrid;
use std::arch::x86_64::{
    __m256, __m256i, _mm256_add_epi32, _mm256_add_ps, _mm256_and_si256, _mm256_andnot_si256,
    _mm256_blendv_epi8, _mm256_blendv_ps, _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps,
    _mm256_cmpeq_epi32, _mm256_cmpgt_epi32, _mm256_cvtepi32_ps, _mm256_cvttps_epi32, _mm256_div_ps,
    _mm256_loadu_ps, _mm256_loadu_si256, _mm256_mask_i32gather_epi32, _mm256_max_epi32,
    _mm256_min_epi32, _mm256_min_epu32, _mm256_movemask_ps, _mm256_mul_ps, _mm256_mullo_epi32,
    _mm256_or_si256, _mm256_set1_epi32, _mm256_set1_ps, _mm256_setzero_si256, _mm256_srli_epi32,
    _mm256_srlv_epi32, _mm256_storeu_ps, _mm256_storeu_si256, _mm256_sub_epi32, _mm256_sub_ps,
    _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LT_OQ,
};

/// A lane mask: all bits set in a lane that is on.
pub(super) type Mask = __m256i;

/// The first crossings of `iso` of up to eight rays whose marches have not been walked yet, as
/// [`crate::render::integrate::Integrator::search`] finds them one ray at a time.
/// `directions[k]` says whether ray `k`'s crossing is rising, `active` holds the isovalue's
/// brick bits (`None`: every brick is searched). Each march is left as that search leaves it.
#[target_feature(enable = "avx2")]
pub(super) fn search8(
    sampler: &VoxelGrid<'_>,
    active: Option<&[u64]>,
    iso: f32,
    tasks: &mut [RayTask],
    directions: [bool; 8],
) -> [Option<Bracket>; 8] {
    debug_assert!(tasks.len() <= 8);
    let mut dda = Dda::load(tasks);
    let grid = Grid::load(tasks);
    let mut lanes = Lanes::new(tasks.len());
    let iso = _mm256_set1_ps(iso);
    let rising = mask(|k| directions[k]);
    let one = _mm256_set1_epi32(1);
    let mut found = Found::new();
    loop {
        // Lanes whose brick has no sample left step to their next brick.
        let need = _mm256_andnot_si256(_mm256_cmpgt_epi32(lanes.hi, lanes.n), lanes.live);
        if any(need) {
            lanes.next_brick(&mut dda, &grid, active, need);
        }
        // A lane that found its crossing walks on (its walk must not wait on its values), and
        // the loop ends once every lane has found one or ended.
        if !any(_mm256_andnot_si256(found.on, lanes.live)) {
            break;
        }
        let take = _mm256_and_si256(lanes.live, _mm256_cmpgt_epi32(lanes.hi, lanes.n));
        if !any(take) {
            continue;
        }
        // Two samples per lane and round (the second where the brick has one more): the
        // round's bookkeeping is shared by both, and the second is tested against the first.
        let second = _mm256_add_epi32(lanes.n, one);
        let take2 = _mm256_and_si256(take, _mm256_cmpgt_epi32(lanes.hi, second));
        let (v1, v2) = (grid.sample(sampler, lanes.n), grid.sample(sampler, second));
        let counted1 = _mm256_sub_epi32(lanes.samples, take);
        lanes.samples = _mm256_sub_epi32(counted1, take2);
        // The first is tested against the sample before it on the grid, if that one was taken.
        let follows = _mm256_cmpeq_epi32(lanes.n, lanes.next);
        let tested = _mm256_and_si256(take, _mm256_and_si256(lanes.has_previous, follows));
        let hit1 = _mm256_and_si256(tested, crossings(lanes.previous, v1, iso, rising));
        let hit2 = _mm256_and_si256(take2, crossings(v1, v2, iso, rising));
        if any(_mm256_andnot_si256(found.on, _mm256_or_si256(hit1, hit2))) {
            let first = (lanes.n, lanes.previous, v1, counted1);
            found.record(hit1, first, &lanes, &dda);
            found.record(hit2, (second, v1, v2, lanes.samples), &lanes, &dda);
        }
        lanes.previous = blend_ps(blend_ps(lanes.previous, v1, take), v2, take2);
        lanes.has_previous = _mm256_or_si256(lanes.has_previous, take);
        let after = _mm256_sub_epi32(second, take2);
        lanes.next = _mm256_blendv_epi8(lanes.next, after, take);
        lanes.n = _mm256_blendv_epi8(lanes.n, after, take);
    }
    found.store(&lanes, &dda, tasks, bits(rising))
}

/// `steps` bisection steps of the brackets of up to eight rays (rays without one are left
/// alone), all steps in registers: each midpoint computed, sampled and kept as
/// [`crate::render::integrate::Integrator::refine`] keeps a single ray's.
#[target_feature(enable = "avx2")]
pub(super) fn refine8(sampler: &VoxelGrid<'_>, iso: f32, tasks: &mut [RayTask], steps: u32) {
    debug_assert!(tasks.len() <= 8);
    let grid = Grid::load(tasks);
    let ends = columns(tasks, |t| {
        t.bracket
            .map_or([0.0; 4], |b| [b.before.0, b.before.1, b.after.0, b.after.1])
    });
    let [mut t0, mut v0, mut t1, mut v1] = [0, 1, 2, 3].map(|i| lanes_f32_from(ends[i]));
    let rising = mask(|k| {
        tasks
            .get(k)
            .and_then(|t| t.bracket)
            .is_some_and(|b| b.rising)
    });
    let (iso, half) = (_mm256_set1_ps(iso), _mm256_set1_ps(0.5));
    for _ in 0..steps {
        let t = _mm256_mul_ps(half, _mm256_add_ps(t0, t1));
        let v = grid.value_at(sampler, t);
        // The midpoint replaces the end on its side: `(v >= iso) == rising`.
        let above = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(v, iso));
        let to_after = _mm256_cmpeq_epi32(above, rising);
        (t1, v1) = (blend_ps(t1, t, to_after), blend_ps(v1, v, to_after));
        (t0, v0) = (blend_ps(t, t0, to_after), blend_ps(v, v0, to_after));
    }
    let (t0, v0, t1, v1) = (floats(t0), floats(v0), floats(t1), floats(v1));
    for (k, task) in tasks.iter_mut().enumerate() {
        if let Some(b) = &mut task.bracket {
            (b.before, b.after) = ((t0[k], v0[k]), (t1[k], v1[k]));
        }
    }
}

/// A sample that crossed, per lane: its index, the values before it and at it, and the
/// samples counted up to it.
type Crossing = (__m256i, __m256, __m256, __m256i);

/// What each lane had when it found its crossing (at sample `n`, between the values `before`
/// and `after`): where its walk was and what it had counted.
struct Found {
    /// The lanes that found one.
    on: Mask,
    /// The sample after the crossing and the values either side of it.
    n: __m256i,
    before: __m256,
    after: __m256,
    /// The brick it was found in (the one-ray walk's pending brick).
    t0: __m256,
    t1: __m256,
    brick: __m256i,
    /// The brick walk's state ([`Dda`]'s fields that change).
    cell: [__m256i; 3],
    t_next: [__m256; 3],
    t: __m256,
    /// The counters ([`Lanes`]'s).
    samples: __m256i,
    visited: __m256i,
    skipped: __m256i,
}

impl Found {
    /// No lane has found a crossing.
    fn new() -> Self {
        // SAFETY: every field is a vector of integers or floats, for which all bits zero is a
        // valid value (zero, or a lane mask with no lane on).
        unsafe { std::mem::zeroed() }
    }

    /// Records the lanes of `hit` not recorded yet, whose sample crossed as `crossing` says.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn record(&mut self, hit: Mask, crossing: Crossing, lanes: &Lanes, dda: &Dda) {
        let (n, before, after, samples) = crossing;
        let hit = _mm256_andnot_si256(self.on, hit);
        let int = |old: __m256i, new: __m256i| _mm256_blendv_epi8(old, new, hit);
        let float = |old: __m256, new: __m256| blend_ps(old, new, hit);
        self.on = _mm256_or_si256(self.on, hit);
        self.n = int(self.n, n);
        self.before = float(self.before, before);
        self.after = float(self.after, after);
        self.t0 = float(self.t0, lanes.t0);
        self.t1 = float(self.t1, lanes.t1);
        self.brick = int(self.brick, lanes.brick);
        for axis in 0..3 {
            self.cell[axis] = int(self.cell[axis], dda.cell[axis]);
            self.t_next[axis] = float(self.t_next[axis], dda.t_next[axis]);
        }
        self.t = float(self.t, dda.t);
        self.samples = int(self.samples, samples);
        self.visited = int(self.visited, lanes.visited);
        self.skipped = int(self.skipped, lanes.skipped);
    }

    /// Leaves each task's march as the one-ray search would, and returns the brackets: a lane
    /// that found a crossing as it was then, another as its walk ended.
    #[target_feature(enable = "avx2")]
    fn store(
        &self,
        lanes: &Lanes,
        dda: &Dda,
        tasks: &mut [RayTask],
        rising: u32,
    ) -> [Option<Bracket>; 8] {
        let hit = self.on;
        let int = |mine: __m256i, walked: __m256i| ints(_mm256_blendv_epi8(walked, mine, hit));
        let float = |mine: __m256, walked: __m256| floats(blend_ps(walked, mine, hit));
        let n = int(self.n, lanes.next);
        let samples = int(self.samples, lanes.samples);
        let visited = int(self.visited, lanes.visited);
        let skipped = int(self.skipped, lanes.skipped);
        let cell: [[i32; 8]; 3] = std::array::from_fn(|a| int(self.cell[a], dda.cell[a]));
        let t_next: [[f32; 8]; 3] = std::array::from_fn(|a| float(self.t_next[a], dda.t_next[a]));
        let t = float(self.t, dda.t);
        let (t0, t1, brick) = (floats(self.t0), floats(self.t1), ints(self.brick));
        let (before, after, hit) = (floats(self.before), floats(self.after), ints(hit));
        let mut brackets = [None; 8];
        for (k, task) in tasks.iter_mut().enumerate() {
            let (walk, grid, _) = task.march.parts();
            let mut walk = *walk;
            for axis in 0..3 {
                walk.cell[axis] = cell[axis][k];
                walk.t_next[axis] = t_next[axis][k];
            }
            walk.t = t[k];
            let hit = hit[k] != 0;
            let stats = MarchStats {
                samples: samples[k] as u64,
                bricks_visited: visited[k] as u64,
                bricks_skipped: skipped[k] as u64,
            };
            let pending = hit.then(|| Segment {
                t0: t0[k],
                t1: t1[k],
                brick: brick[k] as u32,
            });
            brackets[k] = hit.then(|| Bracket {
                before: (grid.t_of(n[k] - 1), before[k]),
                after: (grid.t_of(n[k]), after[k]),
                rising: rising >> k & 1 == 1,
            });
            task.march.searched(walk, n[k], pending, stats);
        }
        brackets
    }
}

/// Eight lanes' brick walks.
struct Dda {
    cell: [__m256i; 3],
    step: [__m256i; 3],
    t_next: [__m256; 3],
    t_delta: [__m256; 3],
    t: __m256,
    t_end: __m256,
    bricks: [__m256i; 3],
}

impl Dda {
    /// The tasks' walks, read in a pass over them per number type; missing lanes have ended.
    #[target_feature(enable = "avx2")]
    fn load(tasks: &[RayTask]) -> Self {
        let [c0, c1, c2, s0, s1, s2, b0, b1, b2] = columns(tasks, |task| {
            let BrickDda {
                cell: c,
                step: s,
                bricks: b,
                ..
            } = *task.march.parts().0;
            [c[0], c[1], c[2], s[0], s[1], s[2], b[0], b[1], b[2]]
        });
        let [n0, n1, n2, d0, d1, d2, t, t_end] = columns(tasks, |task| {
            let d = task.march.parts().0;
            let [n, delta] = [d.t_next, d.t_delta];
            [n[0], n[1], n[2], delta[0], delta[1], delta[2], d.t, d.t_end]
        });
        let (f, i) = (|v| lanes_f32_from(v), |v| lanes_i32_from(v));
        Self {
            cell: [i(c0), i(c1), i(c2)],
            step: [i(s0), i(s1), i(s2)],
            t_next: [f(n0), f(n1), f(n2)],
            t_delta: [f(d0), f(d1), f(d2)],
            t: f(t),
            t_end: f(t_end),
            bricks: [i(b0), i(b1), i(b2)],
        }
    }

    /// One [`BrickDda::next`] in the lanes of `on` (which must not have ended): the segments'
    /// `t0`, `t1` and brick index.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn step(&mut self, on: Mask) -> (__m256, __m256, __m256i) {
        let [x, y, z] = self.t_next;
        // The axis whose face comes next, ties to the lower axis, as `BrickDda::next_axis`.
        let y_first = _mm256_cmp_ps::<_CMP_LT_OQ>(y, x);
        let nearer = _mm256_blendv_ps(x, y, y_first);
        let z_first = _mm256_cmp_ps::<_CMP_LT_OQ>(z, nearer);
        let t_face = _mm256_blendv_ps(nearer, z, z_first);
        let (y_first, z_first) = (_mm256_castps_si256(y_first), _mm256_castps_si256(z_first));
        let select = |v: &[__m256i; 3]| {
            _mm256_blendv_epi8(_mm256_blendv_epi8(v[0], v[1], y_first), v[2], z_first)
        };
        let next_cell = _mm256_add_epi32(select(&self.cell), select(&self.step));
        let last_cell = _mm256_sub_epi32(select(&self.bricks), _mm256_set1_epi32(1));
        let leaving = _mm256_or_si256(
            _mm256_cmpgt_epi32(_mm256_setzero_si256(), next_cell),
            _mm256_cmpgt_epi32(next_cell, last_cell),
        );
        // `t_face.clamp(t, t_end)`, comparison for comparison.
        let below = _mm256_cmp_ps::<_CMP_LT_OQ>(t_face, self.t);
        let clamped = _mm256_blendv_ps(t_face, self.t, below);
        let above = _mm256_cmp_ps::<_CMP_GT_OQ>(clamped, self.t_end);
        let clamped = _mm256_blendv_ps(clamped, self.t_end, above);
        let t1 = blend_ps(clamped, self.t_end, leaving);
        let [i, j, k] = self.cell;
        let [bx, by, _] = self.bricks;
        let brick = _mm256_add_epi32(
            i,
            _mm256_mullo_epi32(bx, _mm256_add_epi32(j, _mm256_mullo_epi32(by, k))),
        );
        let t0 = self.t;
        self.t = blend_ps(self.t, t1, on);
        let is_x = _mm256_andnot_si256(_mm256_or_si256(y_first, z_first), on);
        let is_y = _mm256_and_si256(_mm256_andnot_si256(z_first, y_first), on);
        let is_z = _mm256_and_si256(z_first, on);
        for (axis, moves) in [is_x, is_y, is_z].into_iter().enumerate() {
            self.cell[axis] = _mm256_blendv_epi8(self.cell[axis], next_cell, moves);
            let stepped = _mm256_add_ps(self.t_next[axis], self.t_delta[axis]);
            self.t_next[axis] = blend_ps(self.t_next[axis], stepped, moves);
        }
        (t0, t1, brick)
    }
}

/// Eight lanes' sample grids and ends.
struct Grid {
    origin: [__m256; 3],
    direction: [__m256; 3],
    t_start: __m256,
    offset: __m256,
    step: __m256,
    /// One past the last sample index.
    end: __m256i,
}

impl Grid {
    /// The tasks' sample grids, read in a pass over them per number type; missing lanes are
    /// zero.
    #[target_feature(enable = "avx2")]
    fn load(tasks: &[RayTask]) -> Self {
        let [ox, oy, oz, dx, dy, dz, t_start, offset, step] = columns(tasks, |task| {
            let g = task.march.grid();
            let (o, d) = (g.origin, g.direction);
            [o.x, o.y, o.z, d.x, d.y, d.z, g.t_start, g.offset, g.step]
        });
        let [end] = columns(tasks, |task| [task.march.parts().2]);
        let f = |v| lanes_f32_from(v);
        Self {
            origin: [f(ox), f(oy), f(oz)],
            direction: [f(dx), f(dy), f(dz)],
            t_start: f(t_start),
            offset: f(offset),
            step: f(step),
            end: lanes_i32_from(end),
        }
    }

    /// `t_n` per lane, as `SampleGrid::t_of`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn t_of(&self, n: __m256i) -> __m256 {
        let steps = _mm256_add_ps(_mm256_cvtepi32_ps(n), self.offset);
        _mm256_add_ps(self.t_start, _mm256_mul_ps(steps, self.step))
    }

    /// Sample `n` of each lane's grid.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn sample(&self, sampler: &VoxelGrid<'_>, n: __m256i) -> __m256 {
        self.value_at(sampler, self.t_of(n))
    }

    /// The value at distance `t` along each lane's line, as `SampleGrid::at` places it.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn value_at(&self, sampler: &VoxelGrid<'_>, t: __m256) -> __m256 {
        let at = |axis: usize| along(self.origin[axis], self.direction[axis], t);
        trilinear(sampler, at(0), at(1), at(2))
    }

    /// The first sample index at or after `t` per lane, as `RayMarch::index_at`.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn index_at(&self, t: __m256) -> __m256i {
        let x = _mm256_sub_ps(
            _mm256_div_ps(_mm256_sub_ps(t, self.t_start), self.step),
            self.offset,
        );
        let truncated = _mm256_cvttps_epi32(x);
        let up = _mm256_cmp_ps::<_CMP_LT_OQ>(_mm256_cvtepi32_ps(truncated), x);
        _mm256_sub_epi32(truncated, _mm256_castps_si256(up))
    }
}

/// The lanes' search state.
struct Lanes {
    /// Still searching.
    live: Mask,
    /// Next sample index to take in the current brick, and one past its last.
    n: __m256i,
    hi: __m256i,
    /// One past the last sample taken, and whether one was.
    next: __m256i,
    has_previous: Mask,
    /// The last sample taken.
    previous: __m256,
    /// The current brick's segment.
    t0: __m256,
    t1: __m256,
    brick: __m256i,
    samples: __m256i,
    visited: __m256i,
    skipped: __m256i,
}

impl Lanes {
    /// The state of `count` fresh lanes (the others never search).
    #[target_feature(enable = "avx2")]
    fn new(count: usize) -> Self {
        Self {
            live: mask(|k| k < count),
            // SAFETY: as in `Found::new`: all bits zero is a valid value of every other field.
            ..unsafe { std::mem::zeroed() }
        }
    }

    /// Steps the walks of the lanes `need` to their next brick: an active brick gives the lane
    /// its sample range (padded by one sample either side, as the one-ray search's runs), an
    /// inactive one is skipped, a walk past its end stops the lane.
    #[target_feature(enable = "avx2")]
    #[inline]
    fn next_brick(&mut self, dda: &mut Dda, grid: &Grid, active: Option<&[u64]>, need: Mask) {
        let running = _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(dda.t, dda.t_end));
        self.live = _mm256_andnot_si256(_mm256_andnot_si256(running, need), self.live);
        let stepping = _mm256_and_si256(need, running);
        if !any(stepping) {
            return;
        }
        let (t0, t1, brick) = dda.step(stepping);
        let on = match active {
            Some(words) => _mm256_and_si256(stepping, active_bits(words, brick, stepping)),
            None => stepping,
        };
        let off = _mm256_andnot_si256(on, stepping);
        self.visited = _mm256_sub_epi32(self.visited, on);
        self.skipped = _mm256_sub_epi32(self.skipped, off);
        self.t0 = blend_ps(self.t0, t0, on);
        self.t1 = blend_ps(self.t1, t1, on);
        self.brick = _mm256_blendv_epi8(self.brick, brick, on);
        let one = _mm256_set1_epi32(1);
        let lo = _mm256_max_epi32(_mm256_sub_epi32(grid.index_at(t0), one), self.next);
        let hi = _mm256_min_epi32(_mm256_add_epi32(grid.index_at(t1), one), grid.end);
        self.n = _mm256_blendv_epi8(self.n, lo, on);
        self.hi = _mm256_blendv_epi8(self.hi, hi, on);
    }
}

/// The activity bits of `brick` in the lanes of `on` (a lane all ones where set).
#[target_feature(enable = "avx2")]
#[inline]
fn active_bits(words: &[u64], brick: __m256i, on: Mask) -> Mask {
    // As 32-bit words (x86 is little-endian): bit b is bit b % 32 of word b / 32. The index is
    // clamped to the words, so no lane reads outside them.
    let last = i32::try_from((words.len() * 2).saturating_sub(1)).unwrap_or(i32::MAX);
    let word = _mm256_min_epu32(_mm256_srli_epi32::<5>(brick), _mm256_set1_epi32(last));
    // SAFETY: every lane's index lies in [0, 2 · words.len() − 1] (unsigned minimum above) and
    // scale 4 makes it a 32-bit word of `words`; lanes off `on` are not read.
    let bits = unsafe {
        _mm256_mask_i32gather_epi32::<4>(
            _mm256_setzero_si256(),
            words.as_ptr().cast::<i32>(),
            word,
            on,
        )
    };
    let one = _mm256_set1_epi32(1);
    let shift = _mm256_and_si256(brick, _mm256_set1_epi32(31));
    _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_srlv_epi32(bits, shift), one), one)
}

/// Lanes where the value went across `iso` in the lane's direction, as `crossing::crosses`.
#[target_feature(enable = "avx2")]
#[inline]
fn crossings(before: __m256, after: __m256, iso: __m256, rising: Mask) -> Mask {
    let below = |v| _mm256_castps_si256(_mm256_cmp_ps::<_CMP_LT_OQ>(v, iso));
    let above = |v| _mm256_castps_si256(_mm256_cmp_ps::<_CMP_GE_OQ>(v, iso));
    let up = _mm256_and_si256(below(before), above(after));
    let down = _mm256_and_si256(above(before), below(after));
    _mm256_blendv_epi8(down, up, rising)
}

/// `origin + direction · t` per lane, as `SampleGrid::at`.
#[target_feature(enable = "avx2")]
#[inline]
fn along(origin: __m256, direction: __m256, t: __m256) -> __m256 {
    _mm256_add_ps(origin, _mm256_mul_ps(direction, t))
}

/// `b` in the lanes of `on`, else `a`.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn blend_ps(a: __m256, b: __m256, on: Mask) -> __m256 {
    _mm256_blendv_ps(a, b, _mm256_castsi256_ps(on))
}

/// Whether any lane of `m` is on.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn any(m: Mask) -> bool {
    _mm256_movemask_ps(_mm256_castsi256_ps(m)) != 0
}

/// The lanes `k` for which `on(k)` holds.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn mask(on: impl Fn(usize) -> bool) -> Mask {
    lanes_i32_from(std::array::from_fn(|k| -i32::from(on(k))))
}

/// The lanes of `m` as bits.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn bits(m: Mask) -> u32 {
    _mm256_movemask_ps(_mm256_castsi256_ps(m)) as u32
}

/// `N` numbers of each task, `fields`, as `N` rows of eight lanes, read in one pass over the
/// tasks (one read of each task instead of one per number); zero past the last task.
#[inline]
fn columns<T: Copy + Default, const N: usize>(
    tasks: &[RayTask],
    fields: impl Fn(&RayTask) -> [T; N],
) -> [[T; 8]; N] {
    let mut rows = [[T::default(); 8]; N];
    for (k, task) in tasks.iter().enumerate().take(8) {
        for (row, value) in rows.iter_mut().zip(fields(task)) {
            row[k] = value;
        }
    }
    rows
}

/// Eight floats as lanes.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn lanes_f32_from(lanes: [f32; 8]) -> __m256 {
    // SAFETY: eight f32 are read from an array of eight.
    unsafe { _mm256_loadu_ps(lanes.as_ptr()) }
}

/// Eight integers as lanes.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn lanes_i32_from(lanes: [i32; 8]) -> __m256i {
    // SAFETY: 32 bytes are read from an array of 32 bytes.
    unsafe { _mm256_loadu_si256(lanes.as_ptr().cast()) }
}

/// The lanes of `v`.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn floats(v: __m256) -> [f32; 8] {
    let mut lanes = [0.0f32; 8];
    // SAFETY: eight f32 are written to an array of eight.
    unsafe { _mm256_storeu_ps(lanes.as_mut_ptr(), v) };
    lanes
}

/// The lanes of `v`.
#[target_feature(enable = "avx2")]
#[inline]
pub(super) fn ints(v: __m256i) -> [i32; 8] {
    let mut lanes = [0i32; 8];
    // SAFETY: 32 bytes are written to an array of 32 bytes.
    unsafe { _mm256_storeu_si256(lanes.as_mut_ptr().cast(), v) };
    lanes
}
