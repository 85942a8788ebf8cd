//! Samples along one ray, taken only in active bricks, on a sample grid fixed per ray.
//!
//! Sample `n` sits at `t_n = t_start + (n + offset) · Δt` whatever is skipped, so an image is the
//! same with and without empty-space skipping: a skipped brick holds only samples that would
//! have contributed nothing. For isosurfaces a crossing lies *between* two samples, so a walk
//! may ask for padded runs: one extra sample before and after every active brick's samples,
//! which puts both samples around any crossing inside an active brick into one run.

use super::sample::Sampler;
use super::traverse::{ray_f32, BrickDda, Segment, VoxelRay};
use glam::Vec3;

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

/// The ray's straight line in voxel space, parametrised by mm from the eye (`Copy`, so closures
/// can read it while a walk holds the march).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Line {
    origin: Vec3,
    direction: Vec3,
}

impl Line {
    /// Voxel position at distance `t` (mm).
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.direction * t
    }
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
    line: Line,
    t_start: f32,
    step: f32,
    offset: f32,
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
        let (origin, direction) = ray_f32(ray);
        let mut march = Self {
            dda: BrickDda::new(ray, range, bricks),
            pending: None,
            line: Line { origin, direction },
            t_start: range.0 as f32,
            step: step_mm,
            offset,
            next: 0,
            end: 0,
            has_previous: false,
            stats: MarchStats::default(),
        };
        march.end = march.index_at(range.1 as f32).max(0);
        march
    }

    /// The first sample index at or after `t`.
    #[inline]
    fn index_at(&self, t: f32) -> i32 {
        // A ceiling without libm's `ceilf` (a call on baseline x86-64); `as` saturates.
        let x = (t - self.t_start) / self.step - self.offset;
        let truncated = x as i32;
        truncated + i32::from((truncated as f32) < x)
    }

    /// Distance of sample `n` from the eye, mm.
    #[inline]
    pub fn t_of(&self, n: i32) -> f32 {
        self.t_start + (n as f32 + self.offset) * self.step
    }

    /// The ray's line.
    #[inline]
    pub fn line(&self) -> Line {
        self.line
    }

    /// Where the ray starts (mm) — on the near plane or where it enters the volume.
    pub fn t_start(&self) -> f32 {
        self.t_start
    }

    /// Samples, in order, the bricks for which `active(brick)` holds, handing each sample to
    /// `visit` until it stops the walk (returns true) or the ray ends (returns false). With
    /// `padded`, runs include one sample before and after each active brick's own samples.
    #[inline]
    pub fn walk(
        &mut self,
        sampler: &Sampler<'_>,
        padded: bool,
        mut active: impl FnMut(u32) -> bool,
        mut visit: impl FnMut(Sample) -> Flow,
    ) -> bool {
        let pad = i32::from(padded);
        while let Some(segment) = self.pending.take().or_else(|| self.dda.next()) {
            if !active(segment.brick) {
                self.stats.bricks_skipped += 1;
                continue;
            }
            self.stats.bricks_visited += 1;
            let first = (self.index_at(segment.t0) - pad).max(self.next);
            let last = (self.index_at(segment.t1) + pad).min(self.end);
            for n in first..last {
                let t = self.t_of(n);
                let sample = Sample {
                    t,
                    value: sampler.value(self.line.at(t)),
                    fresh: !(self.has_previous && n == self.next),
                };
                self.stats.samples += 1;
                self.next = n + 1;
                self.has_previous = true;
                match visit(sample) {
                    Flow::Continue => {}
                    Flow::Stop => {
                        self.pending = Some(segment);
                        return true;
                    }
                    Flow::StopBefore => {
                        self.next = n;
                        self.pending = Some(segment);
                        return true;
                    }
                }
            }
        }
        false
    }
}
