//! The nasal cavity with no seed: air inside the head, cut off from the outside air at the
//! nostrils. Grown on its threshold alone, the nasal cavity joins the air around the head
//! through the nostrils (and an open mouth). In an axial slice the air around the head reaches
//! the slice's border, while the nasal cavity above the nostrils, the sinuses, the pharynx and
//! the mastoid air cells are holes in the head; the nostrils open downwards, so the slices cut
//! them off. The nasal cavity is the largest 3D component of those holes that crosses the
//! head's mid-sagittal plane: the mastoid cells lie to the sides. The axial slices and the
//! left–right axis are taken from the scan's orientation (the index axes nearest the patient's
//! superior–inferior and left–right), so a head stored in sagittal or coronal slices, or
//! flipped, is read the same way.

use super::axial::BodyAxes;
use super::bit_grid::BitGrid;
use super::distance::DistanceField;
use super::faces::Faces;
use super::lumen::{Lumen, LumenSide};
use super::section::neighbours4;
use crate::Volume;
use glam::DVec3;
use rayon::prelude::*;

/// How far from the mid-sagittal plane the nasal passages reach, mm: the septum lies on it,
/// the passages and turbinates within about a centimetre either side; the maxillary sinuses
/// begin further out.
pub const PASSAGE_HALF_WIDTH_MM: f64 = 10.0;

/// The nasal cavity found in a head.
#[derive(Debug, Clone, PartialEq)]
pub struct NasalCavity {
    /// The air inside the head joined to it: the nasal cavity, the sinuses open to it and the
    /// pharynx.
    pub lumen: Lumen,
    /// Its nasal passages and nasopharynx: the largest component of the same air within
    /// [`PASSAGE_HALF_WIDTH_MM`] of the mid-sagittal plane, where an endoscope goes.
    pub passages: Lumen,
    /// Where an endoscope starts, world mm: the most central point of the passages' front
    /// [`FRONT_SHARE`] (anterior, −y in LPS), just behind the nostrils.
    pub start_mm: DVec3,
    /// Where an endoscope of [`SCOPE_RADIUS_MM`] goes from the start: the passages' voxels
    /// that far from the wall's surface, joined to the start; `None` when the start itself is
    /// narrower.
    pub route: Option<Lumen>,
    /// Where a flight through the passages ends, world mm: the route's most posterior voxel,
    /// the nasopharynx behind the choanae (the start where there is no route).
    pub end_mm: DVec3,
}

/// The endoscope's radius, mm: the route through the passages keeps it clear of the wall.
pub const SCOPE_RADIUS_MM: f64 = 1.0;
/// The shortest route from the start to the nasopharynx taken for the nasal passages, mm
/// (they are 5–7 cm long in adults).
pub const MIN_ROUTE_MM: f64 = 20.0;

/// The share of the passages' front-to-back extent in which the start lies: the nasal cavity
/// proper, before the nasopharynx and the sphenoid sinus behind it, which are wider.
pub const FRONT_SHARE: f64 = 1.0 / 3.0;

/// The nasal cavity below `threshold` (air, −500 HU): the largest 6-connected component of the
/// air holes of the axial slices (air not 4-connected to the slice's border within the slice)
/// whose extent along `i` (left–right) spans the head's middle (the mean `i` of the voxels at
/// or above `threshold`), its passages near that middle, the start in them, the route an
/// endoscope of [`SCOPE_RADIUS_MM`] takes from there and its end at their back. `None` when no
/// such component exists.
pub fn find_nasal_cavity(volume: &Volume, threshold: f64) -> Option<NasalCavity> {
    if !threshold.is_finite() {
        return None;
    }
    let axes = BodyAxes::of(volume);
    let (mut holes, middle) = slice_holes(volume, threshold, axes);
    let middle = middle?;
    let lr = axes.left_right;
    let spans = |lo: [usize; 3], hi: [usize; 3]| (lo[lr]..=hi[lr]).contains(&middle);
    let below = LumenSide::Below;
    let lumen = Lumen::largest_within(volume, threshold, below, &holes, spans).ok()??;
    let spacing = volume.geometry().spacing_mm().to_array();
    let reach = (PASSAGE_HALF_WIDTH_MM / spacing[lr]).round() as usize;
    holes.keep_along(lr, middle.saturating_sub(reach)..=middle + reach);
    let passages = Lumen::largest_within(volume, threshold, below, &holes, spans).ok()??;
    let field = DistanceField::new(&passages, volume.geometry());
    let start = front_centre(volume, &passages, &field);
    let start_mm = field.world_of_voxel(start);
    let route = route_from(volume, &passages, &field, start, threshold);
    let end_mm = route
        .as_ref()
        .and_then(|route| {
            route
                .voxels()
                .map(|v| field.world_of_voxel(v))
                .max_by(|a, b| a.y.total_cmp(&b.y))
        })
        .unwrap_or(start_mm);
    Some(NasalCavity {
        lumen,
        passages,
        start_mm,
        route,
        end_mm,
    })
}

/// The voxels of `passages` (with their distance `field`) at least [`SCOPE_RADIUS_MM`] from
/// the wall's surface (which lies half a voxel before the wall voxels' centres the field
/// measures to) joined to `start`; `None` when `start` is not among them.
fn route_from(
    volume: &Volume,
    passages: &Lumen,
    field: &DistanceField,
    start: [usize; 3],
    threshold: f64,
) -> Option<Lumen> {
    let clearance = SCOPE_RADIUS_MM + 0.5 * field.min_spacing_mm();
    let mut wide = BitGrid::new(volume.dims());
    for v in passages.voxels() {
        if field.distance_at_voxel(v) >= clearance {
            wide.set(v);
        }
    }
    Lumen::within(volume, start, threshold, LumenSide::Below, &wide).ok()
}

/// The most central voxel (largest distance to the wall `field`) of the front [`FRONT_SHARE`]
/// of `passages` along world `y` that lies [`FACE_MARGIN_MM`](super::FACE_MARGIN_MM) from the
/// volume's faces; where none does, of the voxels clear of the faces behind it, else of the
/// front share.
fn front_centre(volume: &Volume, passages: &Lumen, field: &DistanceField) -> [usize; 3] {
    let faces = Faces::of(volume);
    let (front, back) = passages
        .voxels()
        .map(|v| field.world_of_voxel(v).y)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), y| {
            (lo.min(y), hi.max(y))
        });
    let limit = front + FRONT_SHARE * (back - front);
    let rank = |v: &[usize; 3]| {
        (
            faces.clear(*v),
            field.world_of_voxel(*v).y <= limit,
            field.distance_at_voxel(*v),
        )
    };
    passages
        .voxels()
        .max_by(|a, b| {
            let (a, b) = (rank(a), rank(b));
            (a.0, a.1).cmp(&(b.0, b.1)).then(a.2.total_cmp(&b.2))
        })
        .unwrap_or(passages.seed())
}

/// The air holes of every axial slice (across `axes.superior`; one bit per voxel), and the mean
/// index along `axes.left_right` of the voxels at or above `threshold` (`None` when there are
/// none). Slices in parallel.
fn slice_holes(volume: &Volume, threshold: f64, axes: BodyAxes) -> (BitGrid, Option<usize>) {
    let dims = volume.dims();
    let [u, v] = axes.in_slice();
    let (nu, nv) = (dims[u], dims[v]);
    let map = volume.value_map();
    let air: Vec<bool> = (0..=u16::MAX)
        .map(|s| map.physical(s) < threshold)
        .collect();
    let voxel = |m: usize, n: usize| {
        let mut at = [0; 3];
        at[axes.superior] = m;
        at[u] = n % nu;
        at[v] = n / nu;
        at
    };
    let voxels = volume.voxels();
    let linear = |[i, j, k]: [usize; 3]| i + dims[0] * (j + dims[1] * k);
    let per_slice: Vec<(Vec<bool>, f64, usize)> = (0..dims[axes.superior])
        .into_par_iter()
        .map(|m| {
            let open: Vec<bool> = (0..nu * nv)
                .map(|n| air[usize::from(voxels[linear(voxel(m, n))])])
                .collect();
            let (sum, count) = open
                .iter()
                .enumerate()
                .filter(|(_, &a)| !a)
                .fold((0.0, 0), |(s, c), (n, _)| {
                    (s + voxel(m, n)[axes.left_right] as f64, c + 1)
                });
            (holes_of(&open, nu, nv), sum, count)
        })
        .collect();
    let mut holes = BitGrid::new(dims);
    let (mut sum, mut count) = (0.0, 0);
    for (m, (slice, s, c)) in per_slice.into_iter().enumerate() {
        sum += s;
        count += c;
        for (n, _) in slice.iter().enumerate().filter(|(_, &h)| h) {
            holes.set(voxel(m, n));
        }
    }
    let middle = (count > 0).then(|| (sum / count as f64).round() as usize);
    (holes, middle)
}

/// The `open` pixels of an `nx` × `ny` slice that are not 4-connected to its border through
/// open pixels.
fn holes_of(open: &[bool], nx: usize, ny: usize) -> Vec<bool> {
    let mut outside = vec![false; nx * ny];
    let mut stack: Vec<usize> = (0..nx)
        .flat_map(|i| [i, i + nx * (ny - 1)])
        .chain((0..ny).flat_map(|j| [nx * j, nx - 1 + nx * j]))
        .filter(|&n| open[n])
        .collect();
    while let Some(n) = stack.pop() {
        if outside[n] {
            continue;
        }
        outside[n] = true;
        let neighbours = neighbours4(n, nx, ny);
        stack.extend(
            neighbours
                .into_iter()
                .flatten()
                .filter(|&m| open[m] && !outside[m]),
        );
    }
    open.iter()
        .zip(&outside)
        .map(|(&o, &out)| o && !out)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Tissue (40 HU, stored 1040) framed by air at the i and j sides (40 × 40 × 20 voxels of
    /// 1 mm, axis-aligned: `i` left, `j` posterior, `k` superior); a midline cavity opening to
    /// the front air through a nostril in slices 14–15 only; a larger air pocket to the side (a
    /// mastoid's place), enclosed.
    fn head_voxels() -> Vec<u16> {
        let dims = [40, 40, 20];
        let mut voxels = vec![1040u16; dims[0] * dims[1] * dims[2]];
        for k in 0..dims[2] {
            for j in 0..dims[1] {
                for i in 0..dims[0] {
                    let frame = i < 3 || j < 3 || i >= 37 || j >= 37;
                    let cavity =
                        (17..23).contains(&i) && (8..20).contains(&j) && (5..16).contains(&k);
                    let nostril = (19..22).contains(&i) && j < 8 && (14..16).contains(&k);
                    let pocket =
                        (4..12).contains(&i) && (5..30).contains(&j) && (3..17).contains(&k);
                    if frame || cavity || nostril || pocket {
                        voxels[i + dims[0] * (j + dims[1] * k)] = 0;
                    }
                }
            }
        }
        voxels
    }

    fn ct(geometry: crate::Geometry, voxels: Vec<u16>) -> Volume {
        let map = crate::ValueMap::new(1.0, -1000.0).unwrap();
        Volume::new(geometry, voxels, map, crate::Modality::Ct).unwrap()
    }

    #[test]
    fn the_midline_cavity_is_cut_off_at_its_nostril_and_the_side_pocket_passed_over() {
        let g = crate::Geometry::axis_aligned([40, 40, 20], DVec3::ONE, DVec3::ZERO).unwrap();
        let volume = ct(g, head_voxels());
        // Grown on the threshold alone, the largest enclosed air is the pocket.
        let largest = Lumen::largest(&volume, -500.0, LumenSide::Below, true)
            .unwrap()
            .unwrap();
        assert!(largest.contains([8, 10, 10]));
        let nose = find_nasal_cavity(&volume, -500.0).unwrap();
        assert!(nose.lumen.contains([20, 12, 8]) && !nose.lumen.contains([8, 10, 10]));
        // The nostril's slices open to the air in front: cut off there.
        assert!(!nose.lumen.contains([20, 5, 14]) && !nose.lumen.contains([20, 12, 14]));
        assert_eq!(nose.lumen.voxel_count(), 6 * 12 * 9);
        // The start lies in the cavity's front third, in the middle of its section.
        let s = nose.start_mm;
        assert!(
            (8.0..12.0).contains(&s.y) && (18.0..=21.0).contains(&s.x),
            "{s}"
        );
        assert!(find_nasal_cavity(&volume, f64::NAN).is_none());
    }

    #[test]
    fn a_head_stored_in_sagittal_slices_front_to_back_is_read_the_same_way() {
        // The same head stored with `a` superior, `b` left and `c` anterior (world x = b,
        // y = 39 − c, z = a): its axial slices are the planes of constant `a`.
        let axial = head_voxels();
        let dims = [20, 40, 40];
        let mut voxels = vec![0u16; axial.len()];
        for c in 0..40 {
            for b in 0..40 {
                for a in 0..20 {
                    let (i, j, k) = (b, 39 - c, a);
                    voxels[a + 20 * (b + 40 * c)] = axial[i + 40 * (j + 40 * k)];
                }
            }
        }
        let direction = glam::DMat3::from_cols(DVec3::Z, DVec3::X, DVec3::NEG_Y);
        let g =
            crate::Geometry::new(dims, DVec3::ONE, DVec3::new(0.0, 39.0, 0.0), direction).unwrap();
        let volume = ct(g, voxels);
        let nose = find_nasal_cavity(&volume, -500.0).unwrap();
        let at = |[i, j, k]: [usize; 3]| [k, i, 39 - j];
        assert!(nose.lumen.contains(at([20, 12, 8])) && !nose.lumen.contains(at([8, 10, 10])));
        assert!(!nose.lumen.contains(at([20, 5, 14])));
        assert_eq!(nose.lumen.voxel_count(), 6 * 12 * 9);
        let s = nose.start_mm;
        assert!(
            (8.0..12.0).contains(&s.y) && (18.0..=21.0).contains(&s.x),
            "{s}"
        );
    }
}
