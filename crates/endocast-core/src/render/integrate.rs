//! The integrators: one small function per render mode, each a composition of the shared
//! pieces — [`Integrator::search`] and [`Integrator::refine`] (the isosurface hit of §3.3),
//! [`Integrator::surface`] (gradient, normal, Blinn-Phong), [`Integrator::composite`]
//! (front-to-back DVR with early termination) — over a [`RayMarch`]. Finding a crossing in a
//! batch and bisecting its bracket are in [`super::crossing`]; compositing is in [`composite`], depth peeling in [`peel`].

mod composite;
mod peel;

pub(crate) use peel::PeelParams;

use composite::until_opaque;

use super::bricks::{Activity, BitSet, BrickGrid};
use super::cell_mask::CellMask;
use super::cell_walk::CellWalk;
use super::crossing::{bisect, crosses, first_crossing, BISECTION_LEVELS};
use super::march::{Flow, RayMarch, Sample, Stopped, Walk};
use super::ray_task::Bracket;
use super::ray_task::{PixelOut, RayTask};
use super::sample::{Accum, SampleGrid, Sampler, Shader};
use super::settings::{Crossing, Mode};
use super::transfer::TfTable;
use glam::Vec3;
use std::cell::Cell;

/// Receives every sample an integrator composites or tests (the `--debug-pixel` trace). `()`
/// ignores them at no cost.
pub(crate) trait Probe {
    /// Whether samples are traced (compositing then goes one sample at a time).
    const TRACES: bool = true;

    /// A sample at `t` mm of stored value `value`; `alpha` is the opacity accumulated after it.
    fn sample(&mut self, t: f32, value: f32, alpha: f32);
}

impl Probe for () {
    const TRACES: bool = false;

    #[inline]
    fn sample(&mut self, _t: f32, _value: f32, _alpha: f32) {}
}

/// An isosurface as the integrators need it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Surface {
    /// Isovalue, stored units.
    pub iso: f32,
    /// Opacity, 0–1.
    pub opacity: f32,
    /// Colour before shading.
    pub color: Vec3,
}

/// The numbers derived from the settings that the integrators read.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Params {
    pub mode: Mode,
    pub lower: Surface,
    pub upper: Surface,
    pub crossing: Crossing,
    pub early_termination: f32,
    pub refine_steps: u32,
    pub exact_hits: bool,
    pub shade_dvr: bool,
    /// Pre-integrated compositing, every `dvr_stride`-th sample ([`super::RenderSettings`]);
    /// `None`: each sample classified by its own value.
    pub dvr_stride: Option<u32>,
    pub skip_empty: bool,
    pub peel: PeelParams,
}

/// A transfer function as a walk reads it: its lookup table and the bricks in which it is not
/// transparent.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Classified<'a> {
    pub table: &'a TfTable,
    pub active: &'a BitSet,
}

/// The per-frame context of the integrators.
pub(crate) struct Integrator<'a> {
    pub sampler: Sampler<'a>,
    pub grid: &'a BrickGrid,
    pub activity: &'a Activity,
    /// The cells that can hold the lower isosurface, for the exact search (iso and hybrid).
    pub cells: &'a CellMask,
    pub table: &'a TfTable,
    /// The transfer function behind a peel ([`Mode::Peel`]; the same as `table` otherwise).
    pub after: Classified<'a>,
    pub shader: Shader,
    pub params: Params,
    /// The eye (voxel space) and the crossing side of the lower isovalue for rays starting
    /// there.
    pub eye_side: Option<(Vec3, bool)>,
}

impl Integrator<'_> {
    /// Renders one ray in the configured mode; `dir_world` is its unit world direction.
    pub fn run(&self, march: &mut RayMarch, dir_world: Vec3, probe: &mut impl Probe) -> PixelOut {
        match self.params.mode {
            Mode::Iso => self.iso(march, dir_world, probe, false),
            Mode::Hybrid => self.iso(march, dir_world, probe, true),
            Mode::Dvr => {
                let mut out = PixelOut::default();
                self.composite(march, &mut out, dir_world, self.params.shade_dvr, probe);
                out
            }
            Mode::TwoIso => self.two_iso(march, dir_world, probe),
            Mode::Mip => self.extreme(march, probe, |a, b| a > b),
            Mode::Minip => self.extreme(march, probe, |a, b| a < b),
            Mode::Peel => self.peel(march, dir_world, probe),
        }
    }

    /// The transfer function of every mode but the part of a peel behind its surface.
    fn before(&self) -> Classified<'_> {
        Classified {
            table: self.table,
            active: &self.activity.tf,
        }
    }

    /// Whether brick `b` can hold an isosurface crossing.
    #[inline]
    fn iso_active(&self, b: u32) -> bool {
        !self.params.skip_empty || self.activity.iso.get(b as usize)
    }

    /// Whether brick `b` can hold a visible DVR sample.
    #[inline]
    fn tf_active(&self, b: u32) -> bool {
        self.active_in(&self.activity.tf, b)
    }

    /// Whether brick `b` is set in `active` (every brick is without empty-space skipping).
    #[inline]
    fn active_in(&self, active: &BitSet, b: u32) -> bool {
        !self.params.skip_empty || active.get(b as usize)
    }

    /// Renders a group of rays, each as [`Self::run`] would. Iso and hybrid go phase by phase
    /// (every ray's search, then every refinement, then every shading, then the volume behind):
    /// each ray's phases are a chain of dependent steps, while the rays are independent, so
    /// taking one phase across the group lets the CPU overlap their chains. Without `shade`
    /// (iso only), the surfaces are found but not shaded: the colour stays transparent.
    /// `composite_ends` (empty, or one per ray, mm) ends the hybrid compositing behind the
    /// surface where opaque geometry lies, while the search may have looked further.
    pub fn run_group(&self, tasks: &mut [RayTask], shade: bool, composite_ends: &[f32]) {
        let volume_behind = match self.params.mode {
            Mode::Iso => false,
            Mode::Hybrid => true,
            _ => {
                for task in tasks {
                    task.out = self.run(&mut task.march, task.dir_world, &mut ());
                }
                return;
            }
        };
        let surface = self.params.lower;
        if self.sampled_hits() {
            self.search_group(tasks, surface.iso);
            self.refine_group(tasks, surface.iso);
        } else {
            self.exact_group(tasks, volume_behind);
        }
        if !shade && !volume_behind {
            return;
        }
        for chunk in tasks.chunks_mut(8) {
            self.lit_surfaces(chunk);
        }
        if volume_behind {
            for (k, task) in tasks.iter_mut().enumerate() {
                if task.out.depth_mm.is_nan() {
                    continue;
                }
                if let Some(&end) = composite_ends.get(k) {
                    task.march.limit(end);
                }
                let out = &mut task.out;
                self.composite_behind(&mut task.march, out, task.dir_world, &mut ());
            }
        }
    }

    /// [`Self::search`] for each ray of a group, eight at once on AVX2
    /// ([`super::simd::Avx2::search8`]).
    fn search_group(&self, tasks: &mut [RayTask], iso: f32) {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.sampler.avx2() {
            let active = self.params.skip_empty.then(|| self.activity.iso.words());
            for chunk in tasks.chunks_mut(8) {
                let mut rising = [false; 8];
                for (r, task) in rising.iter_mut().zip(chunk.iter()) {
                    *r = self.rising(&task.march, iso);
                }
                let brackets = avx2.search8(self.sampler.voxel_grid(), active, iso, chunk, rising);
                for (task, bracket) in chunk.iter_mut().zip(brackets) {
                    task.bracket = bracket;
                }
            }
            return;
        }
        for task in tasks.iter_mut() {
            task.bracket = self.search(&mut task.march, iso, &mut ());
        }
    }

    /// [`Self::first_hit`] by the cell walk for each ray of a group, into its depth, eight at once
    /// on AVX2 ([`super::simd::Avx2::first_hits8`]); the marches are left for the volume behind
    /// the hits only where `volume_behind`.
    fn exact_group(&self, tasks: &mut [RayTask], volume_behind: bool) {
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.sampler.avx2() {
            let walk = self.cell_walk();
            let iso = self.params.lower.iso;
            for chunk in tasks.chunks_mut(8) {
                let mut sides = [(true, true); 8];
                for (side, task) in sides.iter_mut().zip(chunk.iter()) {
                    *side = self.side(&task.march, iso);
                }
                let hits = avx2.first_hits8(&walk, chunk, sides);
                for (task, hit) in chunk.iter_mut().zip(hits) {
                    task.out.depth_mm = hit.unwrap_or(f32::NAN);
                    if let (Some(t), true) = (hit, volume_behind) {
                        task.march.found_at(t);
                    }
                }
            }
            return;
        }
        for task in tasks.iter_mut() {
            let hit = self.first_hit(&mut task.march, &mut ());
            task.out.depth_mm = hit.unwrap_or(f32::NAN);
        }
    }

    /// Iso and hybrid: the first hit, the shaded surface weighted by its opacity, then (hybrid)
    /// unshaded DVR behind it from that opacity on (§3.3).
    fn iso(
        &self,
        march: &mut RayMarch,
        dir_world: Vec3,
        probe: &mut impl Probe,
        volume_behind: bool,
    ) -> PixelOut {
        let mut out = PixelOut::default();
        let Some(depth) = self.first_hit(march, probe) else {
            return out;
        };
        out.depth_mm = depth;
        self.lit_surface(march, dir_world, &mut out);
        if volume_behind {
            self.composite_behind(march, &mut out, dir_world, probe);
        }
        out
    }

    /// Whether iso and hybrid find their surface by the samples' search and bisection rather
    /// than exactly by the cell walk ([`super::RenderSettings::exact_hits`]); other modes
    /// always search by samples.
    pub(super) fn sampled_hits(&self) -> bool {
        !(self.params.exact_hits && matches!(self.params.mode, Mode::Iso | Mode::Hybrid))
    }

    /// The exact search for the lower isovalue ([`Self::sampled_hits`] false).
    fn cell_walk(&self) -> CellWalk<'_> {
        CellWalk {
            voxels: self.sampler.voxel_grid(),
            cells: self.cells,
            iso: self.params.lower.iso,
        }
    }

    /// The direction of the first crossing of `iso` along a fresh `march` ([`Self::rising`]),
    /// and whether the ray starts on its near side (always in auto mode: the start decides).
    fn side(&self, march: &RayMarch, iso: f32) -> (bool, bool) {
        let rising = self.rising(march, iso);
        let before = self.params.crossing == Crossing::Auto || {
            let grid = march.grid();
            (self.sampler.value(grid.at(grid.t_start)) < iso) == rising
        };
        (rising, before)
    }

    /// The first hit of the lower isosurface along a fresh `march`, mm, as
    /// [`Self::sampled_hits`] says; the march is left for the volume behind it.
    pub(super) fn first_hit(&self, march: &mut RayMarch, probe: &mut impl Probe) -> Option<f32> {
        let iso = self.params.lower.iso;
        if self.sampled_hits() {
            let bracket = self.search(march, iso, probe)?;
            return Some(self.refine(march.grid(), iso, bracket));
        }
        let hit = self.cell_walk().first_hit(march, self.side(march, iso))?;
        probe.sample(hit, iso, 0.0);
        Some(hit)
    }

    /// [`Self::lit_surface`] for each ray of up to eight that hit, their gradients in batches
    /// across the rays.
    fn lit_surfaces(&self, tasks: &mut [RayTask]) {
        let mut points = [Vec3::ZERO; 8];
        for (point, task) in points.iter_mut().zip(tasks.iter()) {
            if !task.out.depth_mm.is_nan() {
                *point = task.march.grid().at(task.out.depth_mm);
            }
        }
        let gradients = self.sampler.gradients8(&points);
        let surface = self.params.lower;
        for (gradient, task) in gradients.iter().zip(tasks.iter_mut()) {
            if !task.out.depth_mm.is_nan() {
                let lit = self.shaded(*gradient, surface.color, task.dir_world);
                task.out.accum.under_surface(lit, surface.opacity);
            }
        }
    }

    /// Composites the lower isosurface, shaded at the hit `out.depth_mm`, onto `out`.
    pub(super) fn lit_surface(&self, march: &RayMarch, dir_world: Vec3, out: &mut PixelOut) {
        let surface = self.params.lower;
        let lit = self.surface(march.grid().at(out.depth_mm), surface.color, dir_world);
        out.accum.under_surface(lit, surface.opacity);
    }

    /// Whether the value rises through `iso` at the surface, for a ray starting at `march`. In
    /// auto mode the value at the start decides; a brick that cannot hold `iso` tells which side
    /// it lies on without a sample.
    pub fn rising(&self, march: &RayMarch, iso: f32) -> bool {
        let grid = march.grid();
        match self.eye_side {
            Some((eye, rising))
                if grid.t_start == 0.0 && grid.origin == eye && iso == self.params.lower.iso =>
            {
                rising
            }
            _ => self.rising_at(grid.at(grid.t_start), iso),
        }
    }

    /// [`Self::rising`] for a ray starting at voxel position `start`.
    pub fn rising_at(&self, start: Vec3, iso: f32) -> bool {
        match self.params.crossing {
            Crossing::Rising => true,
            Crossing::Falling => false,
            Crossing::Auto => {
                let brick = self.grid.brick_at(start);
                if self.activity.iso.get(brick) {
                    self.sampler.value(start) < iso
                } else {
                    f32::from(self.grid.max(brick)) < iso
                }
            }
        }
    }

    /// The first crossing of `iso` in iso-active bricks; the march is left so that the next walk
    /// starts with the first sample past the crossing.
    pub(super) fn search<P: Probe>(
        &self,
        march: &mut RayMarch,
        iso: f32,
        probe: &mut P,
    ) -> Option<Bracket> {
        let rising = self.rising(march, iso);
        self.search_from(march, (iso, rising), (0.0, 0.0), probe)
    }

    /// [`Self::search`] for a crossing in the direction `rising`, the walk's last sample so far
    /// being `previous` (`(t, value)`; ignored on a fresh march): resumes a march a search left
    /// after its hit, whose next sample is the one after that crossing.
    fn search_from<P: Probe>(
        &self,
        march: &mut RayMarch,
        (iso, rising): (f32, bool),
        mut previous: (f32, f32),
        probe: &mut P,
    ) -> Option<Bracket> {
        let active = |b| self.iso_active(b);
        let grid = march.grid();
        // `previous`: the sample before the one under test; `hit`: the bracket once found.
        let mut hit = None;
        if P::TRACES {
            march.walk(&self.sampler, Walk::SEARCH, active, |s: Sample| {
                probe.sample(s.t, s.value, 0.0);
                if !s.fresh && crosses(previous.1, s.value, iso, rising) {
                    hit = Some(previous);
                    previous = (s.t, s.value);
                    return Flow::StopBefore;
                }
                previous = (s.t, s.value);
                Flow::Continue
            });
        } else {
            march.walk_batches(&self.sampler, Walk::SEARCH, active, |batch| {
                let Some(k) = first_crossing(&batch, previous.1, iso, rising) else {
                    previous.1 = batch.values[batch.count - 1];
                    return None;
                };
                let n = batch.first + k as i32;
                let before = if k == 0 {
                    previous.1
                } else {
                    batch.values[k - 1]
                };
                hit = Some((grid.t_of(n - 1), before));
                previous = (grid.t_of(n), batch.values[k]);
                // As the one-by-one walk's `StopBefore`: the sample after the crossing is
                // counted and the next walk starts with it.
                Some(Stopped {
                    taken: k + 1,
                    next: n,
                })
            });
        }
        hit.map(|before| Bracket {
            before,
            after: previous,
            rising,
        })
    }

    /// The distances of the successive crossings of the lower isovalue along a fresh march,
    /// nearest first, into `depths_mm` (left as they are past the last crossing): the first as
    /// [`Self::run`] finds it, then each next one by resuming the search after the hit, in the
    /// other direction (out of the wall, into the next). The march is left after the last
    /// crossing found.
    pub fn crossings(&self, march: &mut RayMarch, depths_mm: &mut [f32]) {
        let iso = self.params.lower.iso;
        if !self.sampled_hits() {
            self.cell_walk()
                .crossings(march, self.side(march, iso), depths_mm);
            return;
        }
        let mut rising = self.rising(march, iso);
        let mut previous = (0.0, 0.0);
        for depth in depths_mm {
            let Some(bracket) = self.search_from(march, (iso, rising), previous, &mut ()) else {
                return;
            };
            *depth = self.refine(march.grid(), iso, bracket);
            previous = bracket.after;
            rising = !rising;
        }
    }

    /// The unit world normal of the lower isosurface's field at distance `t_mm` along `march`'s
    /// ray (up the value gradient).
    pub fn normal_at(&self, march: &RayMarch, t_mm: f32) -> Vec3 {
        let gradient = self.sampler.gradient(march.grid().at(t_mm));
        self.shader.normal(gradient)
    }

    /// Bisection of the bracket `(t, value)` before and after a crossing (the two samples the
    /// march took, so their values are not fetched again), then linear interpolation inside the
    /// final bracket (no refinement: the sample after the crossing).
    pub(super) fn refine(&self, line: SampleGrid, iso: f32, bracket: Bracket) -> f32 {
        let Bracket {
            mut before,
            mut after,
            rising,
        } = bracket;
        let mut left = self.params.refine_steps;
        while left > 0 {
            let levels = left.min(BISECTION_LEVELS);
            let bracket = (&mut before, &mut after);
            bisect(&self.sampler, line, (iso, rising), levels, bracket);
            left -= levels;
        }
        self.hit_in(iso, before, after)
    }

    /// [`Self::refine`] for every bracketed ray of a group, into its `out.depth_mm`: the same
    /// brackets, eight rays' midpoints per batch (the rays' steps are independent), under half
    /// the samples of [`bisect`]'s tree of midpoints per ray.
    fn refine_group(&self, tasks: &mut [RayTask], iso: f32) {
        self.bisect_group(tasks, iso);
        for task in tasks.iter_mut() {
            if let Some(b) = task.bracket {
                task.out.depth_mm = self.hit_in(iso, b.before, b.after);
            }
        }
    }

    /// Every bisection step of each bracketed ray of a group: on AVX2 all steps of eight rays
    /// in registers ([`super::simd::Avx2::refine8`]), else a step at a time across eight rays.
    fn bisect_group(&self, tasks: &mut [RayTask], iso: f32) {
        let steps = self.params.refine_steps;
        #[cfg(target_arch = "x86_64")]
        if let Some(avx2) = self.sampler.avx2() {
            for chunk in tasks.chunks_mut(8) {
                avx2.refine8(self.sampler.voxel_grid(), iso, chunk, steps);
            }
            return;
        }
        for _ in 0..steps {
            for chunk in tasks.chunks_mut(8) {
                self.bisect_across(chunk, iso);
            }
        }
    }

    /// One bisection step of each bracketed ray of up to eight, their midpoints in one batch
    /// (each computed as [`bisect`] computes a single step's).
    fn bisect_across(&self, tasks: &mut [RayTask], iso: f32) {
        debug_assert!(tasks.len() <= 8);
        let mut t = [0.0f32; 8];
        let mut at = [[0.0f32; 8]; 3];
        for (k, task) in tasks.iter().enumerate() {
            if let Some(b) = &task.bracket {
                t[k] = 0.5 * (b.before.0 + b.after.0);
                let p = task.march.grid().at(t[k]);
                (at[0][k], at[1][k], at[2][k]) = (p.x, p.y, p.z);
            }
        }
        let values = self.sampler.points8(&at);
        for (k, task) in tasks.iter_mut().enumerate() {
            if let Some(b) = &mut task.bracket {
                let m = (t[k], values[k]);
                if (m.1 >= iso) == b.rising {
                    b.after = m;
                } else {
                    b.before = m;
                }
            }
        }
    }

    /// The hit inside the final bracket: linear interpolation of the isovalue between its ends
    /// (no refinement: the sample after the crossing).
    fn hit_in(&self, iso: f32, (a, va): (f32, f32), (b, vb): (f32, f32)) -> f32 {
        if self.params.refine_steps == 0 {
            return b;
        }
        let span = vb - va;
        let f = if span != 0.0 {
            ((iso - va) / span).clamp(0.0, 1.0)
        } else {
            0.5
        };
        a + (b - a) * f
    }

    /// The shaded colour of a surface of base colour `color` at voxel position `p`.
    fn surface(&self, p: Vec3, color: Vec3, dir_world: Vec3) -> Vec3 {
        self.shaded(self.sampler.gradient(p), color, dir_world)
    }

    /// The shaded colour of a surface of base colour `color` whose voxel-space gradient is
    /// `gradient`.
    fn shaded(&self, gradient: Vec3, color: Vec3, dir_world: Vec3) -> Vec3 {
        self.shader
            .shade(color, self.shader.normal(gradient), dir_world)
    }

    /// Two surfaces and DVR outside both: every sample is tested for a crossing of either
    /// isovalue since the previous one (surfaces composited in depth order), then composited by
    /// the transfer function if it lies outside the band between the isovalues.
    fn two_iso(&self, march: &mut RayMarch, dir_world: Vec3, probe: &mut impl Probe) -> PixelOut {
        let mut out = PixelOut::default();
        self.two_iso_part(march, dir_world, &mut out, &mut (0.0, 0.0), probe);
        out
    }

    /// [`Self::two_iso`] over one part of a ray onto `out`, `previous` (`(t, value)`) the last
    /// sample of the part before (ignored where the march's first sample is fresh); left at the
    /// part's last sample.
    pub(super) fn two_iso_part(
        &self,
        march: &mut RayMarch,
        dir_world: Vec3,
        out: &mut PixelOut,
        previous: &mut (f32, f32),
        probe: &mut impl Probe,
    ) {
        let (lower, upper) = (self.params.lower, self.params.upper);
        let stop = self.params.early_termination;
        let mut last = *previous;
        let line = march.grid();
        let acc = &mut out.accum;
        let depth = &mut out.depth_mm;
        let terminated = march.walk(
            &self.sampler,
            Walk::COMPOSITE_CROSSINGS,
            |b| self.iso_active(b) || self.tf_active(b),
            |s: Sample| {
                // The test every sample takes stays small; the rare crossing is handled aside.
                let crossed = |iso: f32| (last.1 < iso) != (s.value < iso);
                if !s.fresh && (crossed(lower.iso) || crossed(upper.iso)) {
                    let after = (s.t, s.value);
                    self.add_crossed_surfaces(acc, depth, (line, dir_world), last, after);
                }
                if s.value < lower.iso || s.value > upper.iso {
                    let shade = self.params.shade_dvr;
                    self.add_sample(self.table, acc, line, s, dir_world, shade);
                }
                last = (s.t, s.value);
                probe.sample(s.t, s.value, acc.alpha());
                until_opaque(acc.alpha(), stop)
            },
        );
        *previous = last;
        out.terminated = terminated;
    }

    /// Two-iso: the surfaces crossed between samples `before` and `after` (`(t, value)`),
    /// refined and shaded, composited in depth order; the first one's depth into `depth`.
    #[cold]
    #[inline(never)]
    fn add_crossed_surfaces(
        &self,
        acc: &mut Accum,
        depth: &mut f32,
        (line, dir_world): (SampleGrid, Vec3),
        before: (f32, f32),
        after: (f32, f32),
    ) {
        let mut hits = [self.params.lower, self.params.upper].map(|surface| {
            let rising = before.1 < surface.iso;
            crosses(before.1, after.1, surface.iso, rising).then(|| {
                let bracket = Bracket {
                    before,
                    after,
                    rising,
                };
                (self.refine(line, surface.iso, bracket), surface)
            })
        });
        if let [Some(a), Some(b)] = &hits {
            if b.0 < a.0 {
                hits.swap(0, 1);
            }
        }
        for (t, surface) in hits.into_iter().flatten() {
            if depth.is_nan() {
                *depth = t;
            }
            let lit = self.surface(line.at(t), surface.color, dir_world);
            acc.under_surface(lit, surface.opacity);
        }
    }

    /// MIP (`better = >`) or MinIP (`better = <`): the extreme sample; bricks whose range cannot
    /// beat the current extreme are skipped.
    fn extreme(
        &self,
        march: &mut RayMarch,
        probe: &mut impl Probe,
        better: impl Fn(f32, f32) -> bool,
    ) -> PixelOut {
        let best = Cell::new(f32::NAN);
        let maximum = better(1.0, 0.0);
        // Not a long walk: joining bricks would test them against an extreme not yet raised by
        // the bricks before them (3.8× slower).
        march.walk(
            &self.sampler,
            Walk::EXTREME,
            |b| {
                let bound = if maximum {
                    self.grid.max(b as usize)
                } else {
                    self.grid.min(b as usize)
                };
                !self.params.skip_empty
                    || best.get().is_nan()
                    || better(f32::from(bound), best.get())
            },
            |s: Sample| {
                if best.get().is_nan() || better(s.value, best.get()) {
                    best.set(s.value);
                }
                probe.sample(s.t, s.value, 0.0);
                Flow::Continue
            },
        );
        let mut out = PixelOut::default();
        let value = best.get();
        if !value.is_nan() {
            out.value = value;
            out.accum
                .under_surface(Vec3::from(self.table.color(value)), 1.0);
        }
        out
    }
}
