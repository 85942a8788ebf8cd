//! Samples along one ray, taken only in active bricks, on a sample grid fixed per ray.
//!
//! Sample `n` sits at `t_n = t_start + (n + offset) · Δt` whatever is skipped, so an image is the
//! same with and without empty-space skipping: a skipped brick holds only samples that would
//! have contributed nothing. For isosurfaces a crossing lies *between* two samples, so a walk
//! may ask for padded runs: one extra sample before and after each run of active bricks,
//! which puts both samples around any crossing inside an active brick into one run.

use super::sample::{Lanes, SampleGrid, Sampler};
use super::traverse::{ray_f32, BrickDda, Segment, VoxelRay};

/// One sample handed to a walk's visitor.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Sample {
    /// Distance from the eye, mm.
    pub t: f32,
    /// The trilinear stored value.
    pub value: f32,
    /// True when the previous sample of this walk was not the previous sample of the grid
    /// (first sample, or after a skipped gap): no crossing can be tested against it.
    pub fresh: bool,
}

/// What a visitor wants after a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Flow {
    /// Go on.
    Continue,
    /// Stop the walk; the sample is consumed.
    Stop,
    /// Stop the walk; the next walk starts again with this sample.
    StopBefore,
}

/// Up to eight consecutive samples of the grid, handed at once to a batch walk's visitor.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Batch {
    /// Grid index of the first sample.
    pub first: i32,
    /// The trilinear stored values; lanes from `count` on are unspecified.
    pub values: Lanes,
    /// How many lanes hold samples (1–8).
    pub count: usize,
    /// Whether the first sample is fresh (see [`Sample::fresh`]); the others never are.
    pub fresh: bool,
}

/// Where a batch visitor stopped its walk.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Stopped {
    /// Samples of the batch consumed (counted as taken).
    pub taken: usize,
    /// The grid index the next walk starts with.
    pub next: i32,
}

/// How a walk runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Walk {
    /// Runs include one sample before and after their active bricks' own samples, so both
    /// samples around any crossing inside an active brick lie in one run (isosurfaces).
    pub padded: bool,
    /// Consecutive active bricks make one run (fewer part-filled batches at brick faces). Not
    /// for walks whose activity changes as they go (MIP raises its extreme).
    pub join: bool,
    /// Compositing: many samples and no walk after it. Each batch is fetched while the one
    /// before it is visited, so that its gathers are in flight meanwhile, and the walk ends
    /// the ray when it stops. (A short walk, the isosurface search, would waste the batch
    /// fetched ahead, and is resumed after its stop.)
    pub long: bool,
}

impl Walk {
    /// The isosurface search (resumed after its hit).
    pub const SEARCH: Self = Self {
        padded: true,
        join: true,
        long: false,
    };
    /// Front-to-back compositing.
    pub const COMPOSITE: Self = Self {
        padded: false,
        join: true,
        long: true,
    };
    /// Compositing that tests isosurface crossings too.
    pub const COMPOSITE_CROSSINGS: Self = Self {
        padded: true,
        join: true,
        long: true,
    };
    /// Compositing in front of a peel: crossings tested too, and resumed after each one.
    pub const PEEL: Self = Self {
        padded: true,
        join: true,
        long: false,
    };
    /// MIP/MinIP: bricks judged one by one against the extreme so far.
    pub const EXTREME: Self = Self {
        padded: false,
        join: false,
        long: false,
    };
}

/// Counters of one ray's walks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub(crate) struct MarchStats {
    pub samples: u64,
    pub bricks_visited: u64,
    pub bricks_skipped: u64,
}

/// The state of one ray: where its brick walk is and which sample comes next.
#[derive(Debug, Clone)]
pub(crate) struct RayMarch {
    dda: BrickDda,
    /// A brick a stopped walk was in, to resume in.
    pending: Option<Segment>,
    grid: SampleGrid,
    /// First sample index not yet taken.
    next: i32,
    /// One past the last sample index (`t_n < t_end`).
    end: i32,
    /// Whether sample `next − 1` was taken by a walk.
    has_previous: bool,
    pub stats: MarchStats,
}

impl RayMarch {
    /// The march along `ray` over `range` (mm) through `bricks`, with samples `step_mm` apart
    /// offset by `offset` (0–1) steps from `range.0`.
    pub fn new(
        ray: &VoxelRay,
        range: (f64, f64),
        bricks: [usize; 3],
        step_mm: f32,
        offset: f32,
    ) -> Self {
        let dda = BrickDda::new(ray, range, bricks);
        Self::with_walk(dda, ray, range, step_mm, offset)
    }

    /// [`Self::new`] with the brick walk `dda` already set up (as `BrickDda::new` sets it up).
    pub(crate) fn with_walk(
        dda: BrickDda,
        ray: &VoxelRay,
        range: (f64, f64),
        step_mm: f32,
        offset: f32,
    ) -> Self {
        let (origin, direction) = ray_f32(ray);
        let grid = SampleGrid {
            origin,
            direction,
            t_start: range.0 as f32,
            offset,
            step: step_mm,
        };
        let mut march = Self {
            dda,
            pending: None,
            grid,
            next: 0,
            end: 0,
            has_previous: false,
            stats: MarchStats::default(),
        };
        march.end = march.index_at(range.1 as f32).max(0);
        march
    }

    /// Ends the ray at `t_max_mm` from the eye if it ends later (opaque geometry in front of
    /// the volume's far side): no sample at or past it is taken, and the brick walk stops
    /// there. NaN leaves the ray as it is. For a march not yet walked, or one a search has
    /// stopped (what is left of the walk then ends there).
    pub fn limit(&mut self, t_max_mm: f32) {
        if t_max_mm < self.dda.t_end {
            self.dda.t_end = t_max_mm.max(self.dda.t);
            self.end = self.end.min(self.index_at(t_max_mm).max(self.next));
        }
    }

    /// Moves the sample grid by `shift` steps (wrapped to an offset in 0–1): a still frame's
    /// per-frame jitter. For a march not yet walked.
    pub fn shift_grid(&mut self, shift: f32) {
        debug_assert!(self.next == 0 && !self.has_previous);
        let offset = self.grid.offset + shift;
        self.grid.offset = offset - offset.floor();
        // The end as `with_walk` sets it, from the range's end the brick walk keeps.
        self.end = self.index_at(self.dda.t_end).max(0);
    }

    /// Keeps only every `stride`-th sample of a grid from here on (a grid `stride` times
    /// coarser): from `from` mm when given, a point taken (the new grid's sample 0: the next
    /// walk goes on from it, not fresh), else from the first sample not yet taken, the one
    /// before forgotten (the next walk's first sample is fresh). Pre-integrated compositing.
    pub(crate) fn every(&mut self, stride: u32, from: Option<f32>) {
        let grid = &mut self.grid;
        grid.t_start = from.unwrap_or_else(|| grid.t_of(self.next));
        grid.offset = 0.0;
        grid.step *= stride as f32;
        self.next = i32::from(from.is_some());
        self.has_previous = from.is_some();
        self.end = self.index_at(self.dda.t_end).max(self.next);
    }

    /// The first sample index not yet taken.
    pub(crate) fn next_index(&self) -> i32 {
        self.next
    }

    /// The part of this march's ray from `t0` to `t1` mm (samples `t0 ≤ t_n < t1` of the same
    /// grid, none this march has taken), to walk next: a ray split at a translucent surface
    /// walks its parts in turn (`scene_pass`). The part starts one sample before `t0` where
    /// this march did not take that sample, so that a padded walk still sees both samples
    /// around a crossing there; it is not fresh where this march took the sample before it.
    /// `t1` must not lie past this ray's end ([`Self::span`]).
    pub(crate) fn part(&self, ray: &VoxelRay, (t0, t1): (f32, f32), bricks: [usize; 3]) -> Self {
        let dda = BrickDda::new(ray, (f64::from(t0), f64::from(t1.max(t0))), bricks);
        let next = self.next.max(self.index_at(t0) - 1);
        Self {
            dda,
            pending: None,
            grid: self.grid,
            next,
            end: self.index_at(t1).max(next),
            has_previous: self.has_previous && next == self.next,
            stats: MarchStats::default(),
        }
    }

    /// Where the march's ray starts and ends, mm from the eye (after [`Self::limit`]).
    pub(crate) fn span(&self) -> (f32, f32) {
        (self.grid.t_start, self.dda.t_end)
    }

    /// The distance of the last sample a walk may still take (after early termination: the
    /// sample that ended the ray), or `None` where there is none.
    pub(crate) fn last_sample_t(&self) -> Option<f32> {
        (self.end > 0).then(|| self.grid.t_of(self.end - 1))
    }

    /// The first sample index at or after `t`.
    #[inline]
    fn index_at(&self, t: f32) -> i32 {
        // A ceiling without libm's `ceilf` (a call on baseline x86-64); `as` saturates.
        let g = &self.grid;
        let x = (t - g.t_start) / g.step - g.offset;
        let truncated = x as i32;
        truncated + i32::from((truncated as f32) < x)
    }

    /// The ray's sample grid.
    #[inline]
    pub fn grid(&self) -> SampleGrid {
        self.grid
    }

    /// The brick walk, the sample grid and one past the last sample index of a march not yet
    /// walked, for a search run outside it ([`super::packet`]).
    pub(crate) fn parts(&self) -> (&BrickDda, SampleGrid, i32) {
        (&self.dda, self.grid, self.end)
    }

    /// Leaves the march as a search walk would have: its brick walk at `dda`, `next` the first
    /// sample not yet taken (the one after a crossing, counted as taken), `pending` the brick to
    /// resume in, and the counters of what was walked.
    pub(crate) fn searched(
        &mut self,
        dda: BrickDda,
        next: i32,
        pending: Option<Segment>,
        stats: MarchStats,
    ) {
        self.dda = dda;
        self.next = next;
        self.has_previous = stats.samples > 0;
        self.pending = pending;
        self.stats = stats;
    }

    /// Leaves a march not yet walked as a search walk leaves it after a crossing at `t` mm found
    /// outside it (the exact search, [`super::cell_walk`]): the brick walk past the brick holding
    /// `t`, that brick pending, the next sample the first at or past `t`. The bricks before it
    /// count as skipped (no sample was taken in them).
    pub(crate) fn found_at(&mut self, t: f32) {
        debug_assert!(self.pending.is_none());
        for segment in self.dda.by_ref() {
            if segment.t1 > t {
                self.stats.bricks_visited += 1;
                self.pending = Some(segment);
                break;
            }
            self.stats.bricks_skipped += 1;
        }
        self.next = self.next.max(self.index_at(t));
        self.has_previous = false;
    }

    /// Samples, in order, the bricks for which `active(brick)` holds, handing each sample to
    /// `visit` until it stops the walk (returns true) or the ray ends (returns false), as
    /// `walk` says (see [`Walk`]).
    #[inline]
    pub fn walk(
        &mut self,
        sampler: &Sampler<'_>,
        walk: Walk,
        active: impl FnMut(u32) -> bool,
        mut visit: impl FnMut(Sample) -> Flow,
    ) -> bool {
        let grid = self.grid;
        self.walk_batches(sampler, walk, active, |batch| {
            for (i, &value) in batch.values[..batch.count].iter().enumerate() {
                let n = batch.first + i as i32;
                let sample = Sample {
                    t: grid.t_of(n),
                    value,
                    fresh: batch.fresh && i == 0,
                };
                let flow = visit(sample);
                if flow != Flow::Continue {
                    // `StopBefore` hands this sample to the next walk.
                    let next = if flow == Flow::StopBefore { n } else { n + 1 };
                    return Some(Stopped { taken: i + 1, next });
                }
            }
            None
        })
    }

    /// [`Self::walk`] a batch at a time: `visit` gets up to eight consecutive samples of one
    /// run and says where it stopped, if it did.
    #[inline]
    pub fn walk_batches(
        &mut self,
        sampler: &Sampler<'_>,
        Walk { padded, join, long }: Walk,
        mut active: impl FnMut(u32) -> bool,
        mut visit: impl FnMut(Batch) -> Option<Stopped>,
    ) -> bool {
        let pad = i32::from(padded);
        // The per-batch state lives in locals (registers) and is written back when the walk
        // stops or ends.
        let (mut next, mut has_previous, mut samples) = (self.next, self.has_previous, 0u64);
        while let Some((segment, resumed)) = self.next_segment() {
            if !resumed && !active(segment.brick) {
                self.stats.bricks_skipped += 1;
                continue;
            }
            self.stats.bricks_visited += 1;
            let first = (self.index_at(segment.t0) - pad).max(next);
            // A joining walk's run grows brick by brick while active ones follow, as far as
            // its batches need (a ray that terminates early never steps the DDA through the
            // rest of its bricks).
            let mut run = Run {
                segment,
                last: (self.index_at(segment.t1) + pad).min(self.end),
                open: join,
            };
            self.grow(&mut run, first + 8, pad, &mut active);
            if first >= run.last {
                continue;
            }
            let grid = self.grid;
            let fetch = |n: i32, last: i32| sampler.grid8(&grid, n, (last - n).min(8) as usize);
            let mut values = fetch(first, run.last);
            // Samples a run must reach past a batch's start: enough to know the batch and
            // whether another follows; a long walk's next batch, fetched ahead, needs all of it.
            let reach = if long { 16 } else { 9 };
            let mut batch = first;
            loop {
                self.grow(&mut run, batch + reach, pad, &mut active);
                let last = run.last;
                let count = (last - batch).min(8) as usize;
                let more = batch + 8 < last;
                let ahead = (long && more).then(|| fetch(batch + 8, last));
                let fresh = !(has_previous && batch == next);
                if let Some(stopped) = visit(Batch {
                    first: batch,
                    values,
                    count,
                    fresh,
                }) {
                    self.next = stopped.next;
                    self.has_previous = true;
                    self.stats.samples += samples + stopped.taken as u64;
                    if long {
                        self.end = (batch + stopped.taken as i32).min(self.end);
                    }
                    // Where the walk may go on after all (a coarser grid, `every`).
                    self.pending = Some(run.segment);
                    return true;
                }
                samples += count as u64;
                next = batch + count as i32;
                has_previous = true;
                if !more {
                    break;
                }
                values = match ahead {
                    Some(values) => values,
                    None => {
                        self.grow(&mut run, batch + 16, pad, &mut active);
                        fetch(batch + 8, run.last)
                    }
                };
                batch += 8;
            }
        }
        self.next = next;
        self.has_previous = has_previous;
        self.stats.samples += samples;
        false
    }

    /// The run a stopped walk was in (`true`: sampled whatever the activity, as it may span
    /// several bricks; an inactive brick's samples add nothing, so the image is the same),
    /// else the next brick.
    #[inline]
    fn next_segment(&mut self) -> Option<(Segment, bool)> {
        match self.pending.take() {
            Some(run) => Some((run, true)),
            None => self.dda.next().map(|s| (s, false)),
        }
    }

    /// Extends a joining walk's `run` over the active bricks that follow until it reaches sample
    /// `wanted` (exclusive); the first inactive brick is consumed as skipped and closes the run,
    /// as does the end of the ray.
    #[inline(always)]
    fn grow(&mut self, run: &mut Run, wanted: i32, pad: i32, active: &mut impl FnMut(u32) -> bool) {
        if run.open && run.last < wanted {
            self.extend(run, wanted, pad, active);
        }
    }

    /// [`Self::grow`] past its test: steps the DDA.
    fn extend(
        &mut self,
        run: &mut Run,
        wanted: i32,
        pad: i32,
        active: &mut impl FnMut(u32) -> bool,
    ) {
        while run.open && run.last < wanted {
            let Some(following) = self.dda.next() else {
                run.open = false;
                return;
            };
            if !active(following.brick) {
                self.stats.bricks_skipped += 1;
                run.open = false;
                return;
            }
            self.stats.bricks_visited += 1;
            run.segment.t1 = following.t1;
            run.last = (self.index_at(following.t1) + pad).min(self.end);
        }
    }
}

/// The samples a walk takes in one go: one active brick, or for a joining walk the active
/// bricks that follow each other.
struct Run {
    /// The bricks' extent along the ray; `brick` is the first brick's index.
    segment: Segment,
    /// One past the run's last sample index.
    last: i32,
    /// Whether the run may still grow.
    open: bool,
}
