//! The aorta with no seed: the bright round section of an aorta's size in the axial slices,
//! followed from slice to slice. Grown on its threshold alone, contrast-filled blood joins the
//! heart, the kidneys and (touching it) the spine; the aorta is the longest chain of round
//! sections of 7–16 mm radius whose centres move by less than a radius from one slice to the
//! next ([`chain`]), followed past both ends of the chain by its round core where a branch
//! clings to its section ([`follow`]): from the top of the scan (or where it becomes round) to
//! the bifurcation, where it splits into two smaller sections, or the scan's end. Every limit
//! is in millimetres, converted with the scan's spacing. A scan stored in sagittal or
//! coronal slices is read in an axial copy.

mod chain;
mod follow;

use super::axial::AxialCopy;
use super::bit_grid::BitGrid;
use super::lumen::{Lumen, LumenSide};
use crate::Volume;
use chain::{candidates, longest_chain, Candidate};
use follow::follow;
use glam::DVec3;

/// How far along the slices a chain bridges slices without a round section, mm (a branch's
/// origin makes the section irregular for a few millimetres): two slices of 3 mm.
const MAX_GAP_MM: f64 = 6.0;
/// A bridged slice keeps the lumen within this many radii of the interpolated centre.
const GAP_REACH: f64 = 1.2;
/// The shortest chain taken for an aorta, mm.
const MIN_LENGTH_MM: f64 = 30.0;

/// The aorta found in a scan.
#[derive(Debug, Clone, PartialEq)]
pub struct Aorta {
    /// Its lumen: the chain's sections, the cores followed past its ends, and the bridged
    /// slices near their centre.
    pub lumen: Lumen,
    /// Centre of its highest section (largest world `z`), world mm.
    pub top_mm: DVec3,
    /// Centre of its lowest section, world mm.
    pub bottom_mm: DVec3,
    /// Centres of its sections from top to bottom, world mm.
    pub centres_mm: Vec<DVec3>,
    /// Radius of each section (of the disc of the same area) from top to bottom, mm.
    pub radii_mm: Vec<f64>,
    /// Median radius of its sections, mm.
    pub radius_mm: f64,
    /// Length along the slices, mm.
    pub length_mm: f64,
}

/// The aorta on `side` of `threshold` (contrast above 130 HU): the longest chain of round
/// candidate sections (see the module doc), at least [`MIN_LENGTH_MM`] long, followed past
/// both ends. `None` when no slice has a round bright section of the aorta's size, or no chain
/// is long enough. A scan stored in other than axial slices is searched in an axial copy
/// ([`AxialCopy`]).
pub fn find_aorta(volume: &Volume, threshold: f64, side: LumenSide) -> Option<Aorta> {
    if !threshold.is_finite() {
        return None;
    }
    match AxialCopy::of(volume) {
        Some(copy) => aorta_in_axial(copy.volume(), threshold, side).map(|aorta| Aorta {
            lumen: copy.lumen_back(&aorta.lumen),
            ..aorta
        }),
        None => aorta_in_axial(volume, threshold, side),
    }
}

/// [`find_aorta`] in a scan stored as axial slices.
fn aorta_in_axial(volume: &Volume, threshold: f64, side: LumenSide) -> Option<Aorta> {
    let spacing = volume.geometry().spacing_mm();
    let max_gap = ((MAX_GAP_MM / spacing.z).floor() as usize).max(1);
    let span_mm = |chain: &[&Candidate]| {
        (chain[chain.len() - 1].k - chain[0].k) as f64 * spacing.z + spacing.z
    };
    let candidates = candidates(volume, threshold, side);
    let chain: Vec<&Candidate> = longest_chain(&candidates, max_gap)?
        .into_iter()
        .map(|n| &candidates[n])
        .collect();
    if span_mm(&chain) < MIN_LENGTH_MM {
        return None;
    }
    let reversed: Vec<&Candidate> = chain.iter().rev().copied().collect();
    let before = follow(volume, threshold, side, &reversed, -1, max_gap);
    let after = follow(volume, threshold, side, &chain, 1, max_gap);
    let chain: Vec<&Candidate> = before.iter().rev().chain(chain).chain(&after).collect();
    let length_mm = span_mm(&chain);
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
    let mut radii_mm: Vec<f64> = chain.iter().map(|c| c.radius_mm).collect();
    if centres_mm[0].z < centres_mm[centres_mm.len() - 1].z {
        centres_mm.reverse();
        radii_mm.reverse();
    }
    let mut sorted = radii_mm.clone();
    sorted.sort_by(f64::total_cmp);
    Some(Aorta {
        lumen,
        top_mm: centres_mm[0],
        bottom_mm: centres_mm[centres_mm.len() - 1],
        centres_mm,
        radius_mm: sorted[sorted.len() / 2],
        radii_mm,
        length_mm,
    })
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

    /// A synthetic contrast CT in HU (1.25 × 1.25 × 3 mm voxels, 96 × 64 × 50, world = index ×
    /// spacing, the top at k = 49), with a little noise: an aorta of radius 11 mm at x 50,
    /// y 30 mm from the top down to slice 16, dividing below into two iliac arteries of 6.5 mm
    /// that move apart (a figure of eight in slice 15); at slices 30–34 a renal artery 8 mm
    /// wide leaves it for a kidney (an ellipse of 12 × 24 mm at x 95, slices 24–40); behind
    /// it a spine of round vertebral bodies (radius 14 mm at y 62, 24 mm tall, 9 mm discs).
    fn abdomen() -> Volume {
        let dims = [96, 64, 50];
        let spacing = DVec3::new(1.25, 1.25, 3.0);
        let mut rng = crate::test_rng::Rng::new(17);
        let mut voxels = Vec::with_capacity(dims[0] * dims[1] * dims[2]);
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let (x, y) = (i as f64 * spacing.x, j as f64 * spacing.y);
                    let within = |cx: f64, cy: f64, r: f64| (x - cx).hypot(y - cy) <= r;
                    let apart = 4.0 + 3.0 * (15.0 - k as f64);
                    let vessel = if k >= 16 {
                        within(50.0, 30.0, 11.0)
                    } else {
                        within(50.0 - apart, 30.0, 6.5) || within(50.0 + apart, 30.0, 6.5)
                    };
                    let branch = (30..=34).contains(&k) && (50.0..=95.0).contains(&x);
                    let kidney = (24..=40).contains(&k)
                        && ((x - 95.0) / 12.0).powi(2) + ((y - 30.0) / 24.0).powi(2) <= 1.0;
                    let hu = if vessel || (branch && (y - 30.0).abs() <= 4.0) {
                        200.0
                    } else if kidney {
                        180.0
                    } else if k % 11 < 8 && within(50.0, 62.0, 14.0) {
                        400.0
                    } else {
                        40.0
                    };
                    voxels.push((hu + 1024.0 + 30.0 * (rng.unit() - 0.5)) as u16);
                }
            }
        }
        let g = crate::Geometry::axis_aligned(dims, spacing, DVec3::ZERO).unwrap();
        let map = crate::ValueMap::new(1.0, -1024.0).unwrap();
        Volume::new(g, voxels, map, crate::Modality::Ct).unwrap()
    }

    #[test]
    fn the_aorta_is_followed_past_a_branch_to_its_division_and_not_into_the_spine() {
        let volume = abdomen();
        let aorta = find_aorta(&volume, 130.0, LumenSide::Above).unwrap();
        let voxel =
            |x: f64, y: f64, k: usize| [(x / 1.25).round() as usize, (y / 1.25) as usize, k];
        // From the top slice, through the renal artery's slices (where the section, joined
        // to the kidney's, is no aorta-sized region), to the last slice before the division.
        assert_eq!(aorta.top_mm.z, 49.0 * 3.0);
        let bottom = aorta.bottom_mm.z / 3.0;
        assert!((15.0..=17.0).contains(&bottom), "bottom at slice {bottom}");
        for k in 16..50 {
            assert!(aorta.lumen.contains(voxel(50.0, 30.0, k)), "slice {k}");
        }
        assert!((aorta.radius_mm - 11.0).abs() < 1.0, "{}", aorta.radius_mm);
        assert!(
            (aorta.length_mm - 34.0 * 3.0).abs() <= 6.0,
            "{}",
            aorta.length_mm
        );
        // Not the kidney, the iliac arteries below the division, nor the spine.
        assert!(!aorta.lumen.contains(voxel(95.0, 30.0, 32)));
        assert!(!aorta.lumen.contains(voxel(75.0, 30.0, 32)));
        for k in [5, 12] {
            let apart = 4.0 + 3.0 * (15.0 - k as f64);
            assert!(!aorta.lumen.contains(voxel(50.0 - apart, 30.0, k)));
            assert!(!aorta.lumen.contains(voxel(50.0 + apart, 30.0, k)));
        }
        assert!((0..50).all(|k| !aorta.lumen.contains(voxel(50.0, 62.0, k))));
    }

    #[test]
    fn an_abdomen_stored_in_coronal_slices_gives_the_same_aorta() {
        let volume = abdomen();
        let axial = find_aorta(&volume, 130.0, LumenSide::Above).unwrap();
        // Stored as coronal slices: `j` superior, `k` posterior.
        let coronal = volume.with_axes([0, 2, 1]).unwrap();
        let aorta = find_aorta(&coronal, 130.0, LumenSide::Above).unwrap();
        assert_eq!(aorta.lumen.volume_dims(), coronal.dims());
        let mut back: Vec<[usize; 3]> = aorta.lumen.voxels().map(|[a, b, c]| [a, c, b]).collect();
        back.sort_by_key(|&[i, j, k]| (k, j, i));
        assert_eq!(back, axial.lumen.voxels().collect::<Vec<_>>());
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-9;
        assert!(close(aorta.top_mm, axial.top_mm) && close(aorta.bottom_mm, axial.bottom_mm));
        assert_eq!(aorta.radii_mm, axial.radii_mm);
    }
}
