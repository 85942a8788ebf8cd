//! Volumetric depth peeling (Borland, Clarke, Fielding, Taylor: "Volumetric depth peeling for
//! medical image display", SPIE 2006). The paper's rule (its algorithm box did not survive the
//! text extraction; `shared/papers/README.md` quotes it): march the ray as usual; each time the
//! sample crosses the peel threshold (into the brighter material, or the darker one), count one
//! peel and reset or scale the colour and opacity accumulated so far; composite only after the
//! wanted peel (n-th surface), or keep resetting to the last crossing (last surface).
//!
//! Here the crossing that makes the wanted peel is also drawn as the surface the other modes
//! draw (refined by bisection, shaded; its distance is the pixel's depth) and the ray goes on
//! behind it through the transfer function of after the peel. In front of it the ray is
//! composited only when some of that can show (a keep factor above 0, or context for rays that
//! are never peeled); otherwise the march is a search for crossings alone, which skips every
//! brick that cannot hold the threshold. Compositing in front skips only bricks that can hold
//! no crossing and are transparent under the transfer function of before the peel; behind it,
//! bricks transparent under the one of after.

use super::composite::until_opaque;
use super::{Integrator, Probe};
use crate::render::crossing::crosses;
use crate::render::march::{Flow, RayMarch, Sample, Walk};
use crate::render::ray_task::{Bracket, PixelOut};
use crate::render::sample::Accum;
use glam::Vec3;

/// The peel as the integrator reads it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct PeelParams {
    /// The wanted peel: `Some(n)` for the n-th (n ≥ 1), `None` for the last.
    pub nth: Option<u32>,
    /// Whether a peel is a crossing of the threshold (the lower surface's isovalue, stored
    /// units) from below it to above it.
    pub rising: bool,
    /// Share of the colour and opacity accumulated before the peel that is kept, 0–1.
    pub keep: f32,
    /// Whether rays without the wanted peel show their composite through the transfer function
    /// of before the peel (else nothing).
    pub context: bool,
}

/// The march in front of the wanted peel: what it composited and the last sample it took.
struct Front {
    acc: Accum,
    /// `(t, value)` of the last sample taken (ignored before the first).
    previous: (f32, f32),
    /// Whether the samples are composited (else only searched for crossings).
    composite: bool,
    /// Whether an opaque front ends the ray (its colour is then the pixel's whatever follows).
    can_stop: bool,
    /// Whether it did.
    terminated: bool,
}

/// The crossing that made the wanted peel, and what was composited in front of it.
struct Peeled {
    bracket: Bracket,
    before: Accum,
}

impl Integrator<'_> {
    /// Depth peeling ([`super::Mode::Peel`]): the wanted peel's surface and what lies behind it,
    /// over the faded front; rays that never reach it show their front as context, or nothing.
    pub(super) fn peel(
        &self,
        march: &mut RayMarch,
        dir_world: Vec3,
        probe: &mut impl Probe,
    ) -> PixelOut {
        let peel = self.params.peel;
        let mut front = Front {
            acc: Accum::default(),
            previous: (0.0, 0.0),
            composite: peel.keep > 0.0 || peel.context,
            // A last peel is known only at the ray's end: its front may not stop early.
            can_stop: peel.keep >= 1.0 && peel.context && peel.nth.is_some(),
            terminated: false,
        };
        let found = match peel.nth {
            Some(n) => self.nth_peel(march, n, &mut front, dir_world, probe),
            None => self.last_peel(march, &mut front, dir_world, probe),
        };
        let mut out = PixelOut::default();
        let Some(Peeled { bracket, before }) = found else {
            if peel.context {
                out.accum = front.acc;
                out.terminated = front.terminated;
            }
            return out;
        };
        out.accum = faded(before, peel.keep);
        let surface = self.params.lower;
        out.depth_mm = self.refine(march.grid(), surface.iso, bracket);
        let lit = self.surface(march.grid().at(out.depth_mm), surface.color, dir_world);
        out.accum.under_surface(lit, surface.opacity);
        let shade = self.params.shade_dvr;
        let front = Some((out.depth_mm, surface.iso));
        let ray = (dir_world, shade);
        self.composite_with(self.after, march, &mut out, ray, front, probe);
        out
    }

    /// The `n`-th peel, the march left just after it; `None` where the ray has fewer.
    fn nth_peel(
        &self,
        march: &mut RayMarch,
        n: u32,
        front: &mut Front,
        dir_world: Vec3,
        probe: &mut impl Probe,
    ) -> Option<Peeled> {
        let mut bracket = None;
        for _ in 0..n {
            bracket = Some(self.next_peel(march, front, dir_world, probe)?);
        }
        bracket.map(|bracket| Peeled {
            bracket,
            before: front.acc,
        })
    }

    /// The last peel, the march put back to just after it (the samples counted stay counted).
    fn last_peel(
        &self,
        march: &mut RayMarch,
        front: &mut Front,
        dir_world: Vec3,
        probe: &mut impl Probe,
    ) -> Option<Peeled> {
        let mut last = None;
        while let Some(bracket) = self.next_peel(march, front, dir_world, probe) {
            let peeled = Peeled {
                bracket,
                before: front.acc,
            };
            last = Some((march.clone(), peeled));
        }
        let (resume, peeled) = last?;
        let stats = march.stats;
        *march = resume;
        march.stats = stats;
        Some(peeled)
    }

    /// The next crossing of the peel threshold in the peel's direction, the march left so that
    /// its next walk starts with the sample after it; in front of it the samples are composited
    /// through the transfer function of before the peel when `front` asks.
    fn next_peel(
        &self,
        march: &mut RayMarch,
        front: &mut Front,
        dir_world: Vec3,
        probe: &mut impl Probe,
    ) -> Option<Bracket> {
        let (iso, rising) = (self.params.lower.iso, self.params.peel.rising);
        if !front.composite {
            let bracket = self.search_from(march, (iso, rising), front.previous, probe)?;
            front.previous = bracket.after;
            return Some(bracket);
        }
        let (line, tf) = (march.grid(), self.before());
        let (shade, stop, can_stop) = (
            self.params.shade_dvr,
            self.params.early_termination,
            front.can_stop,
        );
        let (acc, previous) = (&mut front.acc, &mut front.previous);
        let mut hit = None;
        let active = |b| self.iso_active(b) || self.active_in(tf.active, b);
        let stopped = march.walk(&self.sampler, Walk::PEEL, active, |s: Sample| {
            if !s.fresh && crosses(previous.1, s.value, iso, rising) {
                let after = (s.t, s.value);
                hit = Some(Bracket {
                    before: *previous,
                    after,
                    rising,
                });
                // The next walk starts with this sample, behind the crossing.
                *previous = after;
                return Flow::StopBefore;
            }
            self.add_sample(tf.table, acc, line, s, dir_world, shade);
            *previous = (s.t, s.value);
            probe.sample(s.t, s.value, acc.alpha());
            if can_stop {
                until_opaque(acc.alpha(), stop)
            } else {
                Flow::Continue
            }
        });
        front.terminated = stopped && hit.is_none();
        hit
    }
}

/// `acc` with its colour and opacity scaled by `keep` (0–1).
fn faded(acc: Accum, keep: f32) -> Accum {
    if keep >= 1.0 {
        return acc;
    }
    Accum {
        rgb: acc.rgb * keep,
        transmittance: 1.0 - keep * acc.alpha(),
    }
}
