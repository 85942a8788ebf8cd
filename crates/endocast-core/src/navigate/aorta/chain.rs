//! The aorta's round sections and the longest chain of them: every bright 4-connected section
//! of an axial slice of the aorta's size and round enough, linked from slice to slice where the
//! centre moves by less than a radius and the radius changes little.

use super::super::lumen::LumenSide;
use super::super::section::{sections, Section};
use crate::Volume;
use rayon::prelude::*;

/// Radius of a candidate section, mm: the aorta's 8–15 mm with a millimetre of slack for
/// partial volume at the threshold.
pub(super) const RADIUS_MM: (f64, f64) = (7.0, 16.0);
/// Smallest roundness of a section that starts a chain (see `Section::roundness`): an ellipse
/// 1.6 times as long as wide passes, a section with a vertebra or a kidney attached does not.
const MIN_ROUNDNESS: f64 = 0.6;
/// Smallest roundness of a section that continues a chain: an aorta cut obliquely where it
/// bends, or ringed by a stent graft whose struts and their halo cling to its section (the
/// stent CTA), is round to 0.25–0.6 for tens of slices; in line with the chain, of its size,
/// it is still the aorta.
const MIN_ROUNDNESS_FOLLOWED: f64 = 0.25;
/// How far a section's centre may move from the previous one's, in radii.
pub(super) const MAX_SHIFT: f64 = 0.6;
/// How much a section's radius may differ from the previous one's (ratio).
pub(super) const MAX_RATIO: f64 = 1.4;

/// A section of the aorta in slice `k`: a round candidate, or a core followed past one.
pub(super) struct Candidate {
    pub(super) k: usize,
    /// Centroid, in-slice mm from the slice's first pixel.
    pub(super) at: [f64; 2],
    pub(super) radius_mm: f64,
    /// Round enough to start a chain ([`MIN_ROUNDNESS`]); others only continue one.
    pub(super) starts: bool,
    pub(super) section: Section,
}

impl Candidate {
    /// The candidate for `section` of slice `k` with pixels of `pixel_mm` (`[x, y]`).
    pub(super) fn new(k: usize, section: Section, pixel_mm: [f64; 2], starts: bool) -> Self {
        Self {
            k,
            at: [section.mean[0] * pixel_mm[0], section.mean[1] * pixel_mm[1]],
            radius_mm: section.radius_mm(pixel_mm),
            starts,
            section,
        }
    }
}

/// Every round section of the aorta's size, slice by slice (slices in parallel), sorted by
/// slice.
pub(super) fn candidates(volume: &Volume, threshold: f64, side: LumenSide) -> Vec<Candidate> {
    let spacing = volume.geometry().spacing_mm();
    let pixel_mm = [spacing.x, spacing.y];
    let pixel_mm2 = spacing.x * spacing.y;
    let area = |r: f64| std::f64::consts::PI * r * r;
    let sized = |n: usize| {
        let a = n as f64 * pixel_mm2;
        a >= area(RADIUS_MM.0) && a <= area(RADIUS_MM.1)
    };
    let nx = volume.dims()[0];
    (0..volume.dims()[2])
        .into_par_iter()
        .flat_map_iter(|k| {
            sections(volume, k, threshold, side, sized)
                .into_iter()
                .map(|s| (s.roundness(pixel_mm, nx), s))
                .filter(|(round, _)| *round >= MIN_ROUNDNESS_FOLLOWED)
                .map(move |(round, section)| {
                    Candidate::new(k, section, pixel_mm, round >= MIN_ROUNDNESS)
                })
                .collect::<Vec<_>>()
        })
        .collect()
}

/// Whether candidate `b` continues `a` (a few slices further): centres within [`MAX_SHIFT`]
/// radii, radii within [`MAX_RATIO`].
fn continues(a: &Candidate, b: &Candidate) -> bool {
    let r = a.radius_mm.max(b.radius_mm);
    let shift = (a.at[0] - b.at[0]).hypot(a.at[1] - b.at[1]);
    shift <= MAX_SHIFT * r && r <= MAX_RATIO * a.radius_mm.min(b.radius_mm)
}

/// Indices (into `candidates`, which are sorted by slice) of the longest chain of candidates
/// each continuing the one before within `max_gap` skipped slices and holding one that
/// [`Candidate::starts`], by length along the slices; among equally long ones, the one with
/// the most sections (bridging no slice that has a section in line), then the first found.
pub(super) fn longest_chain(candidates: &[Candidate], max_gap: usize) -> Option<Vec<usize>> {
    // Per candidate, of the best chain ending there: whether it holds a starting section, the
    // slices it spans, its sections, and its predecessor. Chains holding a starting section
    // are preferred.
    let mut best: Vec<((bool, usize, usize), Option<usize>)> = Vec::with_capacity(candidates.len());
    let mut first_of_slice = 0;
    for (n, c) in candidates.iter().enumerate() {
        while candidates[first_of_slice].k + max_gap + 1 < c.k {
            first_of_slice += 1;
        }
        let through = |p: usize| {
            let (starts, span, count) = best[p].0;
            (starts || c.starts, span + c.k - candidates[p].k, count + 1)
        };
        let from = (first_of_slice..n)
            .filter(|&p| candidates[p].k < c.k && continues(&candidates[p], c))
            .max_by_key(|&p| (through(p), std::cmp::Reverse(p)));
        best.push(match from {
            Some(p) => (through(p), Some(p)),
            None => ((c.starts, 1, 1), None),
        });
    }
    let mut end = (0..candidates.len())
        .filter(|&n| best[n].0 .0)
        .max_by_key(|&n| (best[n].0, std::cmp::Reverse(n)))?;
    let mut chain = vec![end];
    while let Some(p) = best[end].1 {
        chain.push(p);
        end = p;
    }
    chain.reverse();
    Some(chain)
}
