//! Which way is up in a head CT whose file does not say (a raw file, an NRRD without a space,
//! such as the Stanford CThead and VTK's headsq): read from the anatomy, so that the scan is not
//! drawn upside down.
//!
//! Two landmarks every head CT from the skull base down shows: the brain (the largest
//! connected soft tissue of 10–70 HU, two voxels in from its surface so that it does not join
//! the scalp and the face) lies *above* the densest 0.1 % of the head (at least 1500 HU: the
//! enamel of the teeth, or the petrous bones of the skull base where the teeth are not in the
//! scan). On the shared scans the brain's centre sits 34 % (CThead), 52 % (headsq) and 17 %
//! (the GE head, whose DICOM declares its orientation and agrees) of the scan's height above
//! them. Only up and down are guessed: left and right cannot be told from the anatomy, and
//! front and back not reliably from these two (the petrous bones lie behind the brain's
//! centre, the teeth in front), so those axes stay as the index axes say (L, P).

use super::bit_grid::BitGrid;
use super::lumen::largest_components;
use crate::tissue::{ScanValues, ValueKind};
use crate::Volume;

/// The least brain, ml: smaller soft tissue is no brain (a coarse, cropped headsq holds 133 ml).
const MIN_BRAIN_ML: f64 = 80.0;
/// The least separation of the brain's centre from the teeth along the slice axis, as a share
/// of the scan's height, for a guess.
const MIN_SHARE: f64 = 0.1;
/// The share of the head's voxels taken as the densest (the enamel of the teeth).
const DENSEST_SHARE: f64 = 0.001;
/// The least value of the densest voxels, HU: below it there are no teeth to go by.
const MIN_ENAMEL_HU: f64 = 1500.0;

/// An orientation read from the anatomy.
#[derive(Debug, Clone, PartialEq)]
pub struct UprightGuess {
    /// Where the index axes point (three of L/R, P/A, S/I), e.g. `"LPI"` for slices stored from
    /// the top of the head down.
    pub code: String,
    /// What it was read from, in words.
    pub reason: String,
}

/// Where a head CT's index axes point, guessed from the brain and the densest bone (slices
/// along `k`: only whether `k` runs up or down is guessed); `None` for a scan that is not CT in
/// HU, holds no brain or no such bone, or where they are too close along `k` to tell.
pub fn guess_head_orientation(volume: &Volume) -> Option<UprightGuess> {
    let ValueKind::Hounsfield { offset } = ScanValues::measure(volume).kind else {
        return None;
    };
    let dims = volume.dims();
    let brain = brain(volume, offset)?;
    let teeth = densest_centre(volume, offset)?;
    let share = |axis: usize| (brain[axis] - teeth[axis]) / dims[axis].max(2) as f64;
    let above = share(2);
    if above.abs() < MIN_SHARE {
        return None;
    }
    let vertical = if above > 0.0 { 'S' } else { 'I' };
    Some(UprightGuess {
        code: format!("LP{vertical}"),
        reason: format!(
            "the brain lies {:.0} % of the scan's height above the densest bone",
            above.abs() * 100.0
        ),
    })
}

/// The centre (voxel index) of the brain: the largest component of soft tissue eroded twice.
fn brain(volume: &Volume, offset: f64) -> Option<[f64; 3]> {
    let map = volume.value_map();
    let bounds = [10.0, 70.0].map(|hu| map.stored_from_physical(hu + offset));
    let (lo, hi) = (bounds[0].min(bounds[1]), bounds[0].max(bounds[1]));
    let dims = volume.dims();
    let mut soft = BitGrid::new(dims);
    for (n, &v) in volume.voxels().iter().enumerate() {
        if (lo..=hi).contains(&f64::from(v)) {
            soft.set(at(n, dims));
        }
    }
    let brain = largest_components(&eroded(&eroded(&soft)), 1).pop()?;
    let spacing = volume.geometry().spacing_mm();
    let (centre, count) = centre(dims, |n| brain.get_linear(n));
    let ml = count as f64 * spacing.x * spacing.y * spacing.z / 1000.0;
    (ml >= MIN_BRAIN_ML).then_some(centre)
}

/// The centre of the densest [`DENSEST_SHARE`] of the head (above −300 HU), when they are
/// enamel (at least [`MIN_ENAMEL_HU`]).
fn densest_centre(volume: &Volume, offset: f64) -> Option<[f64; 3]> {
    let map = volume.value_map();
    let body = map.stored_from_physical(-300.0 + offset);
    let enamel = map.stored_from_physical(MIN_ENAMEL_HU + offset);
    if map.scale() <= 0.0 {
        return None;
    }
    let mut counts = vec![0usize; 1 << 16];
    for &v in volume.voxels() {
        counts[usize::from(v)] += 1;
    }
    let head: usize = counts.iter().skip(body.max(0.0).ceil() as usize).sum();
    let wanted = (head as f64 * DENSEST_SHARE).ceil() as usize;
    let mut above = 0;
    let threshold = (0..counts.len()).rev().find(|&v| {
        above += counts[v];
        above >= wanted.max(1)
    })?;
    if (threshold as f64) < enamel {
        return None;
    }
    let voxels = volume.voxels();
    let (centre, _) = centre(volume.dims(), |n| usize::from(voxels[n]) >= threshold);
    Some(centre)
}

/// The mean index of the voxels `holds` accepts, and their number.
fn centre(dims: [usize; 3], holds: impl Fn(usize) -> bool) -> ([f64; 3], usize) {
    let mut sum = [0.0; 3];
    let mut count = 0;
    for n in (0..dims[0] * dims[1] * dims[2]).filter(|&n| holds(n)) {
        let v = at(n, dims);
        for a in 0..3 {
            sum[a] += v[a] as f64;
        }
        count += 1;
    }
    (sum.map(|s| s / count.max(1) as f64), count)
}

/// The voxels of `grid` whose six neighbours are all set (none on the box's faces).
fn eroded(grid: &BitGrid) -> BitGrid {
    let dims = grid.dims;
    let mut out = BitGrid::new(dims);
    for n in (0..dims[0] * dims[1] * dims[2]).filter(|&n| grid.get_linear(n)) {
        let v = at(n, dims);
        let inside = (0..3).all(|a| v[a] > 0 && v[a] + 1 < dims[a]);
        let full = inside
            && (0..3).all(|a| {
                let (mut below, mut beyond) = (v, v);
                below[a] -= 1;
                beyond[a] += 1;
                grid.get(below) && grid.get(beyond)
            });
        if full {
            out.set(v);
        }
    }
    out
}

/// The voxel at linear index `n` of a `dims` grid.
fn at(n: usize, dims: [usize; 3]) -> [usize; 3] {
    [n % dims[0], n / dims[0] % dims[1], n / (dims[0] * dims[1])]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Geometry, Modality, ValueMap};
    use glam::DVec3;

    /// A 2 mm head: air, a skull of bone, a brain ball in its upper half and teeth in front
    /// below it; `upside_down` stores the slices from the top down.
    fn head(upside_down: bool, teeth: bool) -> Volume {
        let n = 80;
        let geometry = Geometry::axis_aligned([n; 3], DVec3::splat(2.0), DVec3::ZERO).unwrap();
        let mut voxels = vec![0u16; n * n * n];
        for k in 0..n {
            for j in 0..n {
                for i in 0..n {
                    let p = DVec3::new(i as f64, j as f64, k as f64);
                    let r = (p - DVec3::new(40.0, 40.0, 40.0)).length();
                    let brain = (p - DVec3::new(40.0, 44.0, 50.0)).length();
                    let tooth = (p - DVec3::new(40.0, 14.0, 22.0)).length();
                    let hu: f64 = if teeth && tooth < 4.5 {
                        2500.0
                    } else if brain < 18.0 {
                        35.0
                    } else if r < 36.0 {
                        if r > 33.0 {
                            900.0
                        } else {
                            120.0
                        }
                    } else {
                        -1000.0
                    };
                    let kk = if upside_down { n - 1 - k } else { k };
                    voxels[i + n * (j + n * kk)] = (hu + 1024.0) as u16;
                }
            }
        }
        let map = ValueMap::new(1.0, -1024.0).unwrap();
        Volume::new(geometry, voxels, map, Modality::Ct).unwrap()
    }

    #[test]
    fn a_head_is_read_upright_whichever_way_its_slices_run() {
        let upright = guess_head_orientation(&head(false, true)).unwrap();
        assert_eq!(upright.code, "LPS", "{}", upright.reason);
        let flipped = guess_head_orientation(&head(true, true)).unwrap();
        assert_eq!(flipped.code, "LPI", "{}", flipped.reason);
    }

    #[test]
    fn without_teeth_there_is_no_guess() {
        assert_eq!(guess_head_orientation(&head(false, false)), None);
    }
}
