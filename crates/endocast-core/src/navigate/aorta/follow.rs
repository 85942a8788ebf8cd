//! Following the aorta past the ends of its chain of round sections. Where a branch leaves it
//! (the coeliac trunk, the superior mesenteric artery, a renal artery) its bright section joins
//! the branch's and stops being round, and through a renal artery it joins the kidney's. Its
//! round core — the largest disc inscribed in the bright region near where the aorta is
//! expected — is still the aorta: it is followed slice by slice, the centre predicted from the
//! last sections, the radius within [`MAX_RATIO`] of theirs, until the aorta divides into the
//! iliac arteries (two smaller cores, off the predicted centre), the core grows (it ran into
//! something larger) or the scan ends.

use super::super::lumen::LumenSide;
use super::super::section::{section_of, Section};
use super::chain::{Candidate, MAX_RATIO, MAX_SHIFT, RADIUS_MM};
use crate::Volume;

/// Sections whose centres and radii predict the next one.
const HISTORY: usize = 5;
/// The narrowest core followed (the radius of its inscribed disc), mm: the infrarenal aorta
/// of a small adult is 6–7 mm in radius at the threshold, its inscribed disc 5–6 mm (on the
/// abdomen, with a pixel of noise at its rim); the common iliac arteries are 4–5 mm.
const MIN_RADIUS_MM: f64 = 4.0;

/// One followed section: its slice, centre (pixel coordinates) and core radius, mm.
#[derive(Clone, Copy)]
struct Known {
    k: usize,
    centre: [f64; 2],
    radius_mm: f64,
}

/// The slices of a scan seen as bright regions with round cores.
struct Cores<'a> {
    volume: &'a Volume,
    threshold: f64,
    side: LumenSide,
    pixel_mm: [f64; 2],
    /// In-slice offsets `[di, dj]` within the largest core radius looked for (and a pixel),
    /// nearest first, with their length, mm.
    offsets: Vec<([isize; 2], f64)>,
}

impl<'a> Cores<'a> {
    fn new(volume: &'a Volume, threshold: f64, side: LumenSide) -> Self {
        let s = volume.geometry().spacing_mm();
        let pixel_mm = [s.x, s.y];
        let cap = RADIUS_MM.1 * MAX_RATIO + s.x.max(s.y);
        let span = [0, 1].map(|a| (cap / pixel_mm[a]).ceil() as isize);
        let mut offsets: Vec<([isize; 2], f64)> = (-span[1]..=span[1])
            .flat_map(|dj| (-span[0]..=span[0]).map(move |di| [di, dj]))
            .map(|d| {
                (
                    d,
                    (d[0] as f64 * pixel_mm[0]).hypot(d[1] as f64 * pixel_mm[1]),
                )
            })
            .filter(|&(_, r)| r > 0.0 && r <= cap)
            .collect();
        offsets.sort_by(|a, b| a.1.total_cmp(&b.1));
        Self {
            volume,
            threshold,
            side,
            pixel_mm,
            offsets,
        }
    }

    /// Whether pixel `[i, j]` of slice `k` lies on the lumen side (`false` outside the slice).
    fn open(&self, k: usize, [i, j]: [isize; 2]) -> bool {
        let [nx, ny, _] = self.volume.dims();
        if i < 0 || j < 0 || i as usize >= nx || j as usize >= ny {
            return false;
        }
        let stored = self.volume.voxels()[i as usize + nx * (j as usize + ny * k)];
        let value = self.volume.value_map().physical(stored);
        self.side.holds(value, self.threshold)
    }

    /// Whether pixel `p` of slice `k` is wall: off the lumen side, and not a lone pixel of
    /// noise in the lumen (one whose four neighbours are all on the lumen side).
    fn wall(&self, k: usize, p: [isize; 2]) -> bool {
        !self.open(k, p)
            && [[-1, 0], [1, 0], [0, -1], [0, 1]]
                .iter()
                .any(|d| !self.open(k, [p[0] + d[0], p[1] + d[1]]))
    }

    /// Distance from the centre of open pixel `p` of slice `k` to the nearest wall pixel's
    /// centre, mm (the largest offset's length when none is that near).
    fn depth(&self, k: usize, p: [isize; 2]) -> f64 {
        self.offsets
            .iter()
            .find(|(d, _)| self.wall(k, [p[0] + d[0], p[1] + d[1]]))
            .map_or_else(|| self.offsets.last().map_or(0.0, |o| o.1), |o| o.1)
    }

    /// The round core of slice `k`'s lumen-side region near `near` (pixel coordinates): the
    /// open pixel within `reach_mm` of it farthest from the wall (the centre of the largest
    /// inscribed disc; among equals, the nearest `near`), and the open pixels 4-connected to it
    /// within a pixel of that disc, with the disc's radius (to the wall pixel's edge), mm.
    /// `None` when no pixel there is open, or the core touches the slice's border.
    fn core(&self, k: usize, near: [f64; 2], reach_mm: f64) -> Option<(Section, f64)> {
        let span = [0, 1].map(|a| (reach_mm / self.pixel_mm[a]).ceil() as isize);
        let at = near.map(|x| x.round() as isize);
        let off = |p: [isize; 2]| {
            let d = [0, 1].map(|a| (p[a] as f64 - near[a]) * self.pixel_mm[a]);
            d[0].hypot(d[1])
        };
        let (centre, depth) = (-span[1]..=span[1])
            .flat_map(|dj| (-span[0]..=span[0]).map(move |di| [at[0] + di, at[1] + dj]))
            .filter(|&p| off(p) <= reach_mm && self.open(k, p))
            .map(|p| (p, self.depth(k, p)))
            .max_by(|a, b| a.1.total_cmp(&b.1).then(off(b.0).total_cmp(&off(a.0))))?;
        let half_pixel = 0.5 * self.pixel_mm[0].max(self.pixel_mm[1]);
        let pixels = self.disc_fill(k, centre, depth + 2.0 * half_pixel);
        let [nx, ny, _] = self.volume.dims();
        Some((section_of(&pixels, nx, ny)?, depth - half_pixel))
    }

    /// The open pixels of slice `k` 4-connected to `centre` within `radius_mm` of it, linear
    /// in-slice indices.
    fn disc_fill(&self, k: usize, centre: [isize; 2], radius_mm: f64) -> Vec<usize> {
        let nx = self.volume.dims()[0] as isize;
        let within = |p: [isize; 2]| {
            let d = [0, 1].map(|a| (p[a] - centre[a]) as f64 * self.pixel_mm[a]);
            d[0].hypot(d[1]) <= radius_mm && self.open(k, p)
        };
        let mut seen = std::collections::HashSet::from([centre]);
        let mut stack = vec![centre];
        let mut pixels = Vec::new();
        while let Some(p) = stack.pop() {
            pixels.push((p[0] + nx * p[1]) as usize);
            for d in [[-1, 0], [1, 0], [0, -1], [0, 1]] {
                let q = [p[0] + d[0], p[1] + d[1]];
                if within(q) && seen.insert(q) {
                    stack.push(q);
                }
            }
        }
        pixels
    }
}

/// The aorta's sections beyond the end of `chain` (its sections in slice order, the end
/// followed from last), one slice at a time in direction `step` (±1), in the order found. At
/// most `max_gap` slices in a row may lack an acceptable core; those trailing the last one
/// found are not taken.
pub(super) fn follow(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    chain: &[&Candidate],
    step: isize,
    max_gap: usize,
) -> Vec<Candidate> {
    let cores = Cores::new(volume, threshold, side);
    let mut known: Vec<Known> = chain[chain.len().saturating_sub(HISTORY)..]
        .iter()
        .map(|c| {
            let reach = MAX_SHIFT * c.radius_mm;
            let radius_mm = cores
                .core(c.k, c.section.mean, reach)
                .map_or(c.radius_mm, |(_, r)| r);
            Known {
                k: c.k,
                centre: c.section.mean,
                radius_mm,
            }
        })
        .collect();
    let nz = volume.dims()[2] as isize;
    let mut found = Vec::new();
    let mut k = chain[chain.len() - 1].k as isize;
    let mut missed = 0;
    while missed <= max_gap {
        k += step;
        if k < 0 || k >= nz {
            break;
        }
        let expected = predict(&known, k);
        match cores.core(k as usize, expected.centre, MAX_SHIFT * expected.radius_mm) {
            Some((section, r)) if plausible(r, expected.radius_mm) => {
                known.push(Known {
                    k: k as usize,
                    centre: section.mean,
                    radius_mm: r,
                });
                known.remove(0);
                found.push(Candidate::new(k as usize, section, cores.pixel_mm, false));
                missed = 0;
            }
            _ => missed += 1,
        }
    }
    found
}

/// The section expected in slice `k` from the `known` ones (oldest first): the centre
/// extrapolated along their drift, the median radius.
fn predict(known: &[Known], k: isize) -> Known {
    let (first, last) = (known[0], known[known.len() - 1]);
    let slices = last.k as f64 - first.k as f64;
    let ahead = k as f64 - last.k as f64;
    let centre = [0, 1].map(|a| {
        let drift = if slices == 0.0 {
            0.0
        } else {
            (last.centre[a] - first.centre[a]) / slices
        };
        last.centre[a] + drift * ahead
    });
    let mut radii: Vec<f64> = known.iter().map(|s| s.radius_mm).collect();
    radii.sort_by(f64::total_cmp);
    Known {
        k: k as usize,
        centre,
        radius_mm: radii[radii.len() / 2],
    }
}

/// Whether a core of radius `r` mm continues sections of radius `expected`: within
/// [`MAX_RATIO`] of it, and within the radii of an aorta followed ([`MIN_RADIUS_MM`] to the
/// largest candidate's).
fn plausible(r: f64, expected: f64) -> bool {
    r >= MIN_RADIUS_MM && r <= RADIUS_MM.1 && r * MAX_RATIO >= expected && r <= expected * MAX_RATIO
}
