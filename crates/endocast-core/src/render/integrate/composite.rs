//! Front-to-back compositing (DVR): one sample or a batch of eight through the transfer
//! function with early termination, and pre-integrated segments on a stride that grows as the
//! transmittance halves (Engel et al. 2001).

use super::super::march::{Batch, Flow, RayMarch, Sample, Stopped, Walk};
use super::super::ray_task::PixelOut;
use super::super::sample::{Accum, SampleGrid};
use super::super::transfer::TfTable;
use super::{Classified, Integrator, Probe};
use glam::{Vec3, Vec3A, Vec4};

impl Integrator<'_> {
    /// Composites one DVR sample through the transfer function `table`, shaded on request.
    #[inline(always)]
    pub(super) fn add_sample(
        &self,
        table: &TfTable,
        acc: &mut Accum,
        line: SampleGrid,
        s: Sample,
        dir_world: Vec3,
        shade: bool,
    ) {
        self.add_entry(acc, table.lookup(s.value), (line, s.t), dir_world, shade);
    }

    /// Composites a premultiplied colour and opacity `entry` (a sample's or a segment's),
    /// shaded on request at distance `t` mm along `line`.
    #[inline(always)]
    fn add_entry(
        &self,
        acc: &mut Accum,
        entry: Vec4,
        (line, t): (SampleGrid, f32),
        dir_world: Vec3,
        shade: bool,
    ) {
        let alpha = entry.w;
        let mut rgb = Vec3A::from_vec4(entry);
        if shade {
            if alpha <= 0.0 {
                return;
            }
            rgb = Vec3A::from(self.surface(line.at(t), Vec3::from(rgb / alpha), dir_world)) * alpha;
        }
        // Unshaded, a transparent sample adds exact zeros: compositing it is a no-op, and
        // cheaper than a branch that mispredicts at every tissue boundary.
        acc.under(rgb, alpha);
    }

    /// Front-to-back DVR in TF-active bricks onto `out`, until early termination.
    pub(in crate::render) fn composite<P: Probe>(
        &self,
        march: &mut RayMarch,
        out: &mut PixelOut,
        dir_world: Vec3,
        shade: bool,
        probe: &mut P,
    ) {
        self.composite_with(self.before(), march, out, (dir_world, shade), None, probe);
    }

    /// The hybrid's unshaded DVR behind its surface at `out.depth_mm` (§3.3), onto `out`;
    /// pre-integrated, from the isovalue at the hit on.
    pub(in crate::render) fn composite_behind<P: Probe>(
        &self,
        march: &mut RayMarch,
        out: &mut PixelOut,
        dir_world: Vec3,
        probe: &mut P,
    ) {
        let front = Some((out.depth_mm, self.params.lower.iso));
        self.composite_with(self.before(), march, out, (dir_world, false), front, probe);
    }

    /// [`Self::composite`] through the transfer function `tf`; pre-integrated, from `front`
    /// (`(t, value)`: where the ray comes out of a surface) when given.
    pub(super) fn composite_with<P: Probe>(
        &self,
        tf: Classified<'_>,
        march: &mut RayMarch,
        out: &mut PixelOut,
        (dir_world, shade): (Vec3, bool),
        front: Option<(f32, f32)>,
        probe: &mut P,
    ) {
        let stop = self.params.early_termination;
        if out.accum.alpha() >= stop {
            out.terminated = true;
            return;
        }
        if let Some(stride) = self.params.dvr_stride {
            let ray = (dir_world, shade, stride);
            self.composite_segments(tf, march, out, ray, front, probe);
            return;
        }
        // A local copy the compiler keeps in registers through the walk.
        let mut acc = out.accum;
        let line = march.grid();
        let mode = Walk::COMPOSITE;
        let active = |b| self.active_in(tf.active, b);
        let terminated = if shade || P::TRACES {
            march.walk(&self.sampler, mode, active, |s: Sample| {
                self.add_sample(tf.table, &mut acc, line, s, dir_world, shade);
                probe.sample(s.t, s.value, acc.alpha());
                until_opaque(acc.alpha(), stop)
            })
        } else {
            march.walk_batches(&self.sampler, mode, active, |batch| {
                composite_batch(tf.table, &mut acc, &batch, stop)
            })
        };
        out.accum = acc;
        out.terminated = terminated;
    }

    /// [`Self::composite_with`] pre-integrated ([`TfTable::segment`]), every `stride`-th sample:
    /// each sample composites the segment from the sample before it (a fresh sample, whose
    /// predecessor was not taken, a constant segment of one step), the first one from `front`
    /// (`(t, value)`) when given. The walk is padded, so that the segment into a run of active
    /// bricks and the one out of it are integrated whole.
    ///
    /// The stride doubles each time the transmittance left falls to half (up to
    /// [`MAX_STRIDE`]): what lies behind weighs as much less as its segments are longer, so
    /// the error each coarser part adds to the pixel is bounded by what the first part at
    /// `stride` adds. A translucent wall in front (the hybrid's) starts it coarser.
    fn composite_segments<P: Probe>(
        &self,
        tf: Classified<'_>,
        march: &mut RayMarch,
        out: &mut PixelOut,
        (dir_world, shade, stride): (Vec3, bool, u32),
        front: Option<(f32, f32)>,
        probe: &mut P,
    ) {
        let stop = self.params.early_termination;
        let mut acc = out.accum;
        let mut coarsening = coarsening_at(stride, 1.0 - acc.alpha());
        march.every(stride * coarsening, front.map(|(t, _)| t));
        let mut previous = front.map_or(f32::NAN, |(_, value)| value);
        loop {
            // Stop where the stride doubles next, or at early termination.
            let until = if 2 * coarsening * stride <= MAX_STRIDE {
                stop.min(1.0 - 0.5 / coarsening as f32)
            } else {
                stop
            };
            let line = march.grid();
            let mode = Walk::COMPOSITE_CROSSINGS;
            let active = |b| self.active_in(tf.active, b);
            let stopped = if shade || P::TRACES {
                march.walk(&self.sampler, mode, active, |s: Sample| {
                    let front = if s.fresh { s.value } else { previous };
                    previous = s.value;
                    let entry = tf.table.segment(front, s.value, line.step);
                    self.add_entry(&mut acc, entry, (line, s.t), dir_world, shade);
                    probe.sample(s.t, s.value, acc.alpha());
                    until_opaque(acc.alpha(), until)
                })
            } else {
                march.walk_batches(&self.sampler, mode, active, |batch| {
                    let values = &batch.values;
                    let mut fronts = [0.0; 8];
                    fronts[0] = if batch.fresh { values[0] } else { previous };
                    fronts[1..].copy_from_slice(&values[..7]);
                    let entries = tf.table.segments8(&fronts, values, line.step);
                    let stopped = composite_entries(&entries, &mut acc, &batch, until);
                    let taken = stopped.map_or(batch.count, |s| s.taken);
                    previous = values[taken - 1];
                    stopped
                })
            };
            if !stopped || acc.alpha() >= stop {
                out.terminated = stopped;
                break;
            }
            let finer = coarsening;
            coarsening = coarsening_at(stride, 1.0 - acc.alpha()).max(2 * finer);
            let last = march.grid().t_of(march.next_index() - 1);
            march.every(coarsening / finer, Some(last));
        }
        out.accum = acc;
    }
}

/// Unshaded compositing of a whole batch through `table` ([`composite_entries`]).
#[inline(always)]
fn composite_batch(table: &TfTable, acc: &mut Accum, batch: &Batch, stop: f32) -> Option<Stopped> {
    composite_entries(&table.lookup8(&batch.values), acc, batch, stop)
}

/// Unshaded compositing of a whole batch's premultiplied colours and opacities `entries`, with
/// the same operations in the same order as one sample at a time, but without a test per
/// sample: the opacity only grows, so the batch is redone one by one only when it ends at or
/// past `stop`, to stop at the exact sample.
#[inline(always)]
fn composite_entries(
    entries: &[Vec4; 8],
    acc: &mut Accum,
    batch: &Batch,
    stop: f32,
) -> Option<Stopped> {
    let entries = &entries[..batch.count];
    let mut whole = *acc;
    for entry in entries {
        whole.under(Vec3A::from_vec4(*entry), entry.w);
    }
    if whole.alpha() < stop {
        *acc = whole;
        return None;
    }
    let mut taken = 0;
    for entry in entries {
        acc.under(Vec3A::from_vec4(*entry), entry.w);
        taken += 1;
        if acc.alpha() >= stop {
            break;
        }
    }
    Some(Stopped {
        taken,
        next: batch.first + taken as i32,
    })
}

/// The stride (in steps) up to which pre-integrated compositing coarsens as the transmittance
/// falls ([`Integrator::composite_segments`]): two voxels at the default step.
const MAX_STRIDE: u32 = 4;

/// The factor of the pre-integrated stride `stride` for a transmittance left of
/// `transmittance`: 2^k for a transmittance at or below 2^−k, as long as the stride stays
/// within [`MAX_STRIDE`].
fn coarsening_at(stride: u32, transmittance: f32) -> u32 {
    let mut factor = 1;
    while 2 * factor * stride <= MAX_STRIDE && transmittance <= 0.5 / factor as f32 {
        factor *= 2;
    }
    factor
}

/// Stop the march once the accumulated opacity reaches the early-termination threshold.
#[inline]
pub(super) fn until_opaque(alpha: f32, stop: f32) -> Flow {
    if alpha >= stop {
        Flow::Stop
    } else {
        Flow::Continue
    }
}
