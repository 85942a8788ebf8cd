//! The central structure (the lateral ventricles) with no seed: the largest lumen component
//! through a box at the object's centre, cut off from the outside at the object's surface.
//!
//! In a skull-stripped brain the background is dark like CSF and touches the CSF of the sulci
//! and cisterns, which the ventricles join through their foramina at any threshold: grown on
//! the threshold alone, the ventricles are part of the background and the search would take
//! the next blob. So where no component of a ventricles' size parts from the outside, the
//! lumen is kept [`CENTRAL_DEPTH_MM`] inside the object (the volume less the dark background
//! joined to its border, holes filled): the CSF at the brain's surface, where the ventricles
//! open to the outside, is cut, the ventricles deep inside are not.

use super::bit_grid::BitGrid;
use super::distance::DistanceField;
use super::lumen::{Lumen, LumenSide};
use super::preset::Central;
use crate::Volume;

/// How deep inside the object the central structure's voxels lie, mm (distance to the
/// background): deeper than the sulci and the basal cisterns, shallower than the ventricles.
pub const CENTRAL_DEPTH_MM: f64 = 9.0;
/// Thresholds tried for a [`Central`] structure, from the given one towards its floor.
const CENTRAL_STEPS: usize = 6;
/// The sizes a central structure is taken at, ml: the lateral ventricles hold 7–30 ml in
/// adults, one of them (the two apart at a low threshold) half that. Smaller is a pocket
/// beside them, larger the CSF around the brain joined to them.
pub const CENTRAL_ML: std::ops::RangeInclusive<f64> = 3.5..=30.0;

/// The [`Central`] structure, the threshold it was found at and whether its size is in
/// [`CENTRAL_ML`]: the central component at the first of [`CENTRAL_STEPS`] thresholds from
/// `threshold` towards the floor where its size is in that range, first among all voxels (the
/// ventricles part from the outside at some threshold where a skull surrounds them), then,
/// where none is, among the voxels [`CENTRAL_DEPTH_MM`] inside the object; where neither is,
/// the one nearest to the range (by the ratio of sizes). `None` when no threshold gives one.
pub(crate) fn find_central(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    central: &Central,
) -> Option<(Lumen, f64, bool)> {
    let search = |allowed| central_search(volume, threshold, side, central, allowed);
    let plain = search(None);
    let best = match plain {
        Some(found) if found.miss == 0.0 => Some(found),
        plain => {
            let deep = deep_inside(volume, central.background, CENTRAL_DEPTH_MM);
            let cut = deep.as_ref().and_then(|deep| search(Some(deep)));
            [plain, cut]
                .into_iter()
                .flatten()
                .min_by(|a, b| a.miss.total_cmp(&b.miss))
        }
    };
    best.map(|found| (found.lumen, found.threshold, found.miss == 0.0))
}

/// A central component found at a threshold, and how far its size lies outside
/// [`CENTRAL_ML`] (the logarithm of the ratio; 0 inside it).
struct Candidate {
    lumen: Lumen,
    threshold: f64,
    miss: f64,
}

/// The central component among the voxels `allowed` holds (all without it) at the first of
/// [`CENTRAL_STEPS`] thresholds whose size is in [`CENTRAL_ML`], else the one nearest to it.
fn central_search(
    volume: &Volume,
    threshold: f64,
    side: LumenSide,
    central: &Central,
    allowed: Option<&BitGrid>,
) -> Option<Candidate> {
    let spacing = volume.geometry().spacing_mm();
    let voxel_ml = spacing.x * spacing.y * spacing.z / 1000.0;
    let (low, high) = (*CENTRAL_ML.start(), *CENTRAL_ML.end());
    let mut best: Option<Candidate> = None;
    for step in 0..CENTRAL_STEPS {
        let t = threshold + (central.floor - threshold) * step as f64 / CENTRAL_STEPS as f64;
        let Ok(Some(lumen)) =
            Lumen::largest_through_box_in(volume, t, side, central.region, allowed)
        else {
            continue;
        };
        let ml = lumen.voxel_count() as f64 * voxel_ml;
        let miss = (low / ml).max(ml / high).max(1.0).ln();
        if best.as_ref().is_none_or(|b| miss < b.miss) {
            best = Some(Candidate {
                lumen,
                threshold: t,
                miss,
            });
        }
        if miss == 0.0 {
            break;
        }
    }
    best
}

/// The voxels of `volume`'s object (see [`Lumen::object`]: the background is what lies below
/// `background` joined to the border) at least `depth_mm` from the background; `None` when
/// the background fills the volume.
fn deep_inside(volume: &Volume, background: f64, depth_mm: f64) -> Option<BitGrid> {
    let object = Lumen::object(volume, background, LumenSide::Below).ok()??;
    let field = DistanceField::new(&object, volume.geometry());
    let mut deep = BitGrid::new(volume.dims());
    for v in object.voxels() {
        if field.distance_at_voxel(v) >= depth_mm {
            deep.set(v);
        }
    }
    Some(deep)
}
