//! The aorta with no seed: the bright round section of an aorta's size in the axial slices,
//! followed from slice to slice. Grown on its threshold alone, contrast-filled blood joins the
//! heart, the kidneys and (touching it) the spine; the aorta is the longest chain of round
//! sections of 7–16 mm radius whose centres move by less than a radius from one slice to the
//! next, from the top of the scan (or where it becomes round) to the bifurcation, where it
//! splits into two smaller sections, or the scan's end.

use super::lumen::{BitGrid, Lumen, LumenSide};
use super::section::{sections, Section};
use crate::Volume;
use glam::DVec3;
use rayon::prelude::*;

/// Radius of a candidate section, mm: the aorta's 8–15 mm with a millimetre of slack for
/// partial volume at the threshold.
pub const RADIUS_MM: (f64, f64) = (7.0, 16.0);
/// Smallest roundness of a section that starts a chain (see `Section::roundness`): an ellipse
/// 1.6 times as long as wide passes, a section with a vertebra or a kidney attached does not.
const MIN_ROUNDNESS: f64 = 0.6;
/// Smallest roundness of a section that continues a chain: an aorta cut obliquely where it
/// bends, or ringed by a stent graft whose struts and their halo cling to its section (the
/// stent CTA), is round to 0.25–0.6 for tens of slices; in line with the chain, of its size,
/// it is still the aorta.
const MIN_ROUNDNESS_FOLLOWED: f64 = 0.25;
/// How far a section's centre may move from the previous one's, in radii.
const MAX_SHIFT: f64 = 0.6;
/// How much a section's radius may differ from the previous one's (ratio).
const MAX_RATIO: f64 = 1.4;
/// Slices without a round section that a chain bridges (a branch's origin, SMA or renal, makes
/// the section irregular for a slice or two).
const MAX_GAP: usize = 2;
/// A bridged slice keeps the lumen within this many radii of the interpolated centre.
const GAP_REACH: f64 = 1.2;
/// The shortest chain taken for an aorta, mm.
const MIN_LENGTH_MM: f64 = 30.0;

/// The aorta found in a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Aorta {
    /// Its lumen: the chain's sections (and the bridged slices near their centre).
    pub lumen: Lumen,
    /// Centre of its highest section (largest world `z`), world mm.
    pub top_mm: DVec3,
    /// Centre of its lowest section, world mm.
    pub bottom_mm: DVec3,
    /// Centres of its sections from top to bottom, world mm.
    pub centres_mm: Vec<DVec3>,
    /// Median radius of its sections (of the disc of the same area), mm.
    pub radius_mm: f64,
    /// Length along the slices, mm.
    pub length_mm: f64,
}

/// A round section of an aorta's size in slice `k`.
struct Candidate {
    k: usize,
    /// Centroid, in-slice mm from the slice's first pixel.
    at: [f64; 2],
    radius_mm: f64,
    /// Round enough to start a chain ([`MIN_ROUNDNESS`]); others only continue one.
    starts: bool,
    section: Section,
}

/// The aorta on `side` of `threshold` (contrast above 130 HU): the longest chain of round
/// candidate sections (see the module doc), at least [`MIN_LENGTH_MM`] long. `None` when no
/// slice has a round bright section of the aorta's size, or no chain is long enough.
pub fn find_aorta(volume: &Volume, threshold: f64, side: LumenSide) -> Option<Aorta> {
    if !threshold.is_finite() {
        return None;
    }
    let candidates = candidates(volume, threshold, side);
    let spacing = volume.geometry().spacing_mm();
    let chain = longest_chain(&candidates)?;
    let length_mm = (candidates[chain[chain.len() - 1]].k - candidates[chain[0]].k) as f64
        * spacing.z
        + spacing.z;
    if length_mm < MIN_LENGTH_MM {
        return None;
    }
    let chain: Vec<&Candidate> = chain.iter().map(|&n| &candidates[n]).collect();
    let allowed = allowed_voxels(volume, &chain);
    let middle = chain[chain.len() / 2];
    let seed = [middle.section.centre[0], middle.section.centre[1], middle.k];
    let lumen = Lumen::within(volume, seed, threshold, side, &allowed).ok()?;
    let g = volume.geometry();
    let world = |c: &Candidate| {
        let [i, j] = c.section.mean;
        g.world_of(DVec3::new(i, j, c.k as f64))
    };
    let mut centres_mm: Vec<DVec3> = chain.iter().map(|c| world(c)).collect();
    if centres_mm[0].z < centres_mm[centres_mm.len() - 1].z {
        centres_mm.reverse();
    }
    let mut radii: Vec<f64> = chain.iter().map(|c| c.radius_mm).collect();
    radii.sort_by(f64::total_cmp);
    Some(Aorta {
        lumen,
        top_mm: centres_mm[0],
        bottom_mm: centres_mm[centres_mm.len() - 1],
        centres_mm,
        radius_mm: radii[radii.len() / 2],
        length_mm,
    })
}

/// Every round section of the aorta's size, slice by slice (slices in parallel).
fn candidates(volume: &Volume, threshold: f64, side: LumenSide) -> Vec<Candidate> {
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
                .map(move |(round, section)| Candidate {
                    k,
                    at: [section.mean[0] * pixel_mm[0], section.mean[1] * pixel_mm[1]],
                    radius_mm: section.radius_mm(pixel_mm),
                    starts: round >= MIN_ROUNDNESS,
                    section,
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
/// each continuing the one before within [`MAX_GAP`] skipped slices and holding one that
/// [`Candidate::starts`], by length along the slices; among equally long ones, the first found.
fn longest_chain(candidates: &[Candidate]) -> Option<Vec<usize>> {
    // Per candidate, of the best chain ending there: whether it holds a starting section, the
    // slices it spans, and its predecessor. Chains holding a starting section are preferred.
    let mut best: Vec<(bool, usize, Option<usize>)> = Vec::with_capacity(candidates.len());
    let mut first_of_slice = 0;
    for (n, c) in candidates.iter().enumerate() {
        while candidates[first_of_slice].k + MAX_GAP + 1 < c.k {
            first_of_slice += 1;
        }
        let through = |p: usize| (best[p].0, best[p].1 + c.k - candidates[p].k);
        let from = (first_of_slice..n)
            .filter(|&p| candidates[p].k < c.k && continues(&candidates[p], c))
            .max_by_key(|&p| (through(p), std::cmp::Reverse(p)));
        best.push(match from {
            Some(p) => {
                let (starts, span) = through(p);
                (starts || c.starts, span, Some(p))
            }
            None => (c.starts, 1, None),
        });
    }
    let mut end = (0..candidates.len())
        .filter(|&n| best[n].0)
        .max_by_key(|&n| (best[n].1, std::cmp::Reverse(n)))?;
    let mut chain = vec![end];
    while let Some(p) = best[end].2 {
        chain.push(p);
        end = p;
    }
    chain.reverse();
    Some(chain)
}

/// The voxels the aorta may hold: each chain section's pixels, and in the slices a link skips,
/// those within [`GAP_REACH`] radii of the centre interpolated between its two ends.
fn allowed_voxels(volume: &Volume, chain: &[&Candidate]) -> BitGrid {
    let dims = volume.dims();
    let nx = dims[0];
    let spacing = volume.geometry().spacing_mm();
    let mut allowed = BitGrid::new(dims);
    for c in chain {
        for &n in &c.section.pixels {
            allowed.set([n % nx, n / nx, c.k]);
        }
    }
    for pair in chain.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for k in a.k + 1..b.k {
            let t = (k - a.k) as f64 / (b.k - a.k) as f64;
            let mean =
                [0, 1].map(|x| a.section.mean[x] + t * (b.section.mean[x] - a.section.mean[x]));
            let reach = GAP_REACH * a.radius_mm.max(b.radius_mm);
            let span = [spacing.x, spacing.y].map(|s| (reach / s).ceil() as isize);
            for dj in -span[1]..=span[1] {
                for di in -span[0]..=span[0] {
                    let (i, j) = (mean[0].round() as isize + di, mean[1].round() as isize + dj);
                    let (x, y) = (
                        (i as f64 - mean[0]) * spacing.x,
                        (j as f64 - mean[1]) * spacing.y,
                    );
                    let inside = i >= 0 && j >= 0 && (i as usize) < nx && (j as usize) < dims[1];
                    if inside && x.hypot(y) <= reach {
                        allowed.set([i as usize, j as usize, k]);
                    }
                }
            }
        }
    }
    allowed
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn a_straight_bright_tube_is_followed_end_to_end() {
        // The straight tube's air column, seen as a bright lumen in the inverted phantom: a
        // vertical tube of aorta size on 1 mm voxels.
        let (tube, shape) = phantom::straight_tube(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        let map = tube.value_map();
        let voxels: Vec<u16> = tube.voxels().to_vec();
        let volume = Volume::new(
            *tube.geometry(),
            voxels,
            crate::ValueMap::new(-map.scale(), -map.offset()).unwrap(),
            crate::Modality::Ct,
        )
        .unwrap();
        let aorta = find_aorta(&volume, 480.0, LumenSide::Above).unwrap();
        assert!(
            (aorta.radius_mm - shape.radius_vox).abs() < 1.0,
            "{}",
            aorta.radius_mm
        );
        assert!((aorta.length_mm - 48.0).abs() < 1e-9);
        assert!(aorta.top_mm.z > aorta.bottom_mm.z);
        assert!(aorta.lumen.contains([24, 24, 0]) && aorta.lumen.contains([24, 24, 47]));
        // Nothing bright enough: no aorta.
        assert!(find_aorta(&volume, 5000.0, LumenSide::Above).is_none());
    }
}
