//! Isosurface crossings between samples: finding the first one in a batch of eight (bit masks
//! of the lanes' sides, all lanes at once) and refining its bracket by bisection, several steps
//! per batch of samples (§3.3 of the paper: four steps, then the hit interpolated inside).

use super::march::Batch;
use super::sample::{SampleGrid, Sampler};
use super::simd::sse::sides;

/// Bisection steps per round of samples: the seven midpoints of three steps fill one batch (a
/// fourth step is one more sample; fifteen midpoints in two batches measured slower).
pub(crate) const BISECTION_LEVELS: u32 = 3;

/// `levels` (1–[`BISECTION_LEVELS`]) bisection steps of the bracket `[before, after]` with one
/// batch of samples: the batch holds the whole tree of midpoints those steps can visit (heap
/// order, node `i`'s halves at `2i` and `2i + 1`), each computed as the step-by-step bisection
/// would, so the bracket ends the same, only without waiting on each sample in turn.
pub(crate) fn bisect(
    sampler: &Sampler<'_>,
    line: SampleGrid,
    (iso, rising): (f32, bool),
    levels: u32,
    (before, after): (&mut (f32, f32), &mut (f32, f32)),
) {
    debug_assert!((1..=BISECTION_LEVELS).contains(&levels));
    let nodes = 1usize << levels;
    let (mut lo, mut hi, mut t) = ([0.0f32; 8], [0.0f32; 8], [0.0f32; 8]);
    (lo[1], hi[1]) = (before.0, after.0);
    t[1] = 0.5 * (lo[1] + hi[1]);
    for i in 2..nodes {
        let parent = i / 2;
        (lo[i], hi[i]) = if i % 2 == 0 {
            (lo[parent], t[parent])
        } else {
            (t[parent], hi[parent])
        };
        t[i] = 0.5 * (lo[i] + hi[i]);
    }
    // One step is one sample; more fill a batch (lane 0 is unused).
    let values = if nodes == 2 {
        [
            0.0,
            sampler.value(line.at(t[1])),
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
        ]
    } else {
        sampler.along8(&line, &t)
    };
    let mut node = 1;
    for _ in 0..levels {
        let m = (t[node], values[node]);
        node *= 2;
        if (m.1 >= iso) == rising {
            *after = m;
        } else {
            *before = m;
            node += 1;
        }
    }
}

/// The first lane of `batch` whose value crossed `iso` (in the given direction) since the
/// sample before it: the previous lane, or `previous` (the walk's last sample) for lane 0 unless
/// the batch starts fresh. All lanes are compared at once, branch-free, as [`crosses`] compares.
#[inline(always)]
pub(crate) fn first_crossing(
    batch: &Batch,
    previous: f32,
    iso: f32,
    rising: bool,
) -> Option<usize> {
    let (below, above) = sides(&batch.values, iso);
    // Bit k: the side of the sample before lane k.
    let below_before = below << 1 | u32::from(previous < iso);
    let above_before = above << 1 | u32::from(previous >= iso);
    let mut mask = if rising {
        below_before & above
    } else {
        above_before & below
    };
    // Lanes past `count` hold no samples; lane 0 has nothing before it when fresh.
    mask &= (1u32 << batch.count) - 1;
    mask &= !u32::from(batch.fresh);
    (mask != 0).then(|| mask.trailing_zeros() as usize)
}

/// Whether the value goes from `before` to `after` across `iso` in the given direction.
#[inline]
pub(crate) fn crosses(before: f32, after: f32, iso: f32, rising: bool) -> bool {
    if rising {
        before < iso && after >= iso
    } else {
        before >= iso && after < iso
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};
    use crate::render::Lanes;
    use glam::Vec3;

    /// Step-by-step bisection, the reference the batched tree must equal.
    fn sequential(
        sampler: &Sampler<'_>,
        line: SampleGrid,
        (iso, rising): (f32, bool),
        steps: u32,
        (mut a, mut b): ((f32, f32), (f32, f32)),
    ) -> ((f32, f32), (f32, f32)) {
        for _ in 0..steps {
            let t = 0.5 * (a.0 + b.0);
            let m = (t, sampler.value(line.at(t)));
            if (m.1 >= iso) == rising {
                b = m;
            } else {
                a = m;
            }
        }
        (a, b)
    }

    #[test]
    fn batch_crossing_test_equals_the_sample_by_sample_one() {
        // Values on a coarse grid around the isovalue, so equalities and repeats are common.
        let mut state = 12345u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 29) as f32 - 3.0
        };
        for round in 0..4000 {
            let values: Lanes = std::array::from_fn(|_| next());
            let previous = if round % 97 == 0 { f32::NAN } else { next() };
            let batch = Batch {
                first: 0,
                values,
                count: 1 + round % 8,
                fresh: round % 5 == 0,
            };
            for rising in [true, false] {
                let expected = (0..batch.count).find(|&k| {
                    let before = if k == 0 { previous } else { values[k - 1] };
                    !(k == 0 && batch.fresh) && crosses(before, values[k], 0.0, rising)
                });
                let found = first_crossing(&batch, previous, 0.0, rising);
                assert_eq!(found, expected, "{values:?} {previous} {rising}");
            }
        }
    }

    #[test]
    fn batched_bisection_ends_on_the_step_by_step_bracket() {
        let options = PhantomOptions {
            size: 32,
            noise_hu: 30.0,
            ..Default::default()
        };
        let (volume, _) = phantom::sphere_shell(&options);
        let sampler = Sampler::new(&volume);
        for k in 0..200u16 {
            let f = f32::from(k);
            let line = SampleGrid {
                origin: Vec3::new(3.0 + f % 7.0, 16.0, 4.0 + f % 11.0),
                direction: Vec3::new(0.3 + f % 3.0 * 0.1, -0.2, 0.9).normalize(),
                t_start: 0.0,
                offset: 0.5,
                step: 0.5,
            };
            let (t0, t1) = (f * 0.1 % 20.0, f * 0.1 % 20.0 + 0.5);
            let a = (t0, sampler.value(line.at(t0)));
            let b = (t1, sampler.value(line.at(t1)));
            let iso = 0.5 * (a.1 + b.1);
            let rising = a.1 < b.1;
            for levels in 1..=BISECTION_LEVELS {
                let expected = sequential(&sampler, line, (iso, rising), levels, (a, b));
                let (mut before, mut after) = (a, b);
                bisect(
                    &sampler,
                    line,
                    (iso, rising),
                    levels,
                    (&mut before, &mut after),
                );
                assert_eq!((before, after), expected, "{k} {levels}");
            }
        }
    }
}
