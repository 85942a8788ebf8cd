//! The airway tree with no seed: the trachea found as the round air column in the top axial
//! slices, then grown below a threshold lowered until the tree stops leaking into the lung. A
//! scan stored in sagittal or coronal slices is read in an axial copy.

use super::axial::AxialCopy;
use super::lumen::{Lumen, LumenSide};
use super::section::{sections, top_is_last};
use crate::Volume;

/// Axial slices searched for the trachea, from the top of the scan down.
const TOP_SLICES: usize = 12;
/// The trachea's cross-section, mm² (diameter about 10–30 mm).
const AREA_MM2: (f64, f64) = (75.0, 700.0);
/// Smallest share of its bounding box a round cross-section fills (a disc fills π/4).
const MIN_FILL: f64 = 0.55;
/// Largest airway tree taken, mm³: trachea and bronchi hold some 50–150 ml; more is lung.
const MAX_TREE_MM3: f64 = 300_000.0;
/// Step by which the growing threshold is lowered after a leak, physical units (HU).
const LOWER_STEP: f64 = 20.0;
/// How many times it is lowered.
const LOWER_TRIES: usize = 5;

/// The airway tree below `threshold` (HU): seeded in the most central round air section of the
/// top axial slices (the scan's highest `z`), grown in 3D and, while it holds more than
/// [`MAX_TREE_MM3`] or leaks out of the volume, grown again [`LOWER_STEP`] lower. `None` when
/// no slice holds a round air section of the trachea's size, or every try leaks. A scan stored
/// in other than axial slices is searched in an axial copy ([`AxialCopy`]).
pub fn find_trachea(volume: &Volume, threshold: f64) -> Option<(Lumen, f64)> {
    if !threshold.is_finite() {
        return None;
    }
    match AxialCopy::of(volume) {
        Some(copy) => {
            trachea_in_axial(copy.volume(), threshold).map(|(tree, t)| (copy.lumen_back(&tree), t))
        }
        None => trachea_in_axial(volume, threshold),
    }
}

/// [`find_trachea`] in a scan stored as axial slices.
fn trachea_in_axial(volume: &Volume, threshold: f64) -> Option<(Lumen, f64)> {
    let seed = trachea_seed(volume, threshold)?;
    let spacing = volume.geometry().spacing_mm();
    let voxel_mm3 = spacing.x * spacing.y * spacing.z;
    (0..=LOWER_TRIES)
        .map(|n| threshold - LOWER_STEP * n as f64)
        .filter_map(|t| Some((Lumen::from_seed(volume, seed, t, LumenSide::Below).ok()?, t)))
        .find(|(tree, _)| {
            tree.voxel_count() as f64 * voxel_mm3 <= MAX_TREE_MM3 && tree.leak().is_none()
        })
}

/// The centre voxel of the trachea's section in the first top slice that has one.
fn trachea_seed(volume: &Volume, threshold: f64) -> Option<[usize; 3]> {
    let dims = volume.dims();
    let spacing = volume.geometry().spacing_mm();
    let pixel_mm = [spacing.x, spacing.y];
    let top_last = top_is_last(volume);
    (0..TOP_SLICES.min(dims[2]))
        .map(|n| if top_last { dims[2] - 1 - n } else { n })
        .find_map(|k| {
            let pixel_mm2 = pixel_mm[0] * pixel_mm[1];
            let sized = |n: usize| (AREA_MM2.0..=AREA_MM2.1).contains(&(n as f64 * pixel_mm2));
            sections(volume, k, threshold, LumenSide::Below, sized)
                .into_iter()
                .filter(|s| {
                    (AREA_MM2.0..=AREA_MM2.1).contains(&s.area_mm2(pixel_mm))
                        && s.fill() >= MIN_FILL
                })
                .min_by_key(|s| s.centre[0].abs_diff(dims[0] / 2))
                .map(|s| [s.centre[0], s.centre[1], k])
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn a_vertical_tube_is_found_from_its_top_section() {
        let (volume, tube) = phantom::straight_tube(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        // The phantom's voxels are 1 mm: its tube is a trachea-sized air column along z.
        let area = std::f64::consts::PI * tube.radius_vox * tube.radius_vox;
        assert!((AREA_MM2.0..=AREA_MM2.1).contains(&area), "{area}");
        let (tree, t) = find_trachea(&volume, -900.0).unwrap();
        assert_eq!(t, -900.0);
        assert!(tree.contains([24, 24, 0]) && tree.contains([24, 24, 47]));
        // No air below −2000: nothing is found.
        assert!(find_trachea(&volume, -2000.0).is_none());
        assert!(find_trachea(&volume, f64::NAN).is_none());
    }

    #[test]
    fn a_trachea_stored_in_sagittal_slices_is_the_same_tree() {
        let (volume, _) = phantom::straight_tube(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        let (axial, _) = find_trachea(&volume, -900.0).unwrap();
        // Stored with its superior axis as `i`: every section of the tube lies across `i`.
        let sagittal = volume.with_axes([2, 0, 1]).unwrap();
        let (tree, t) = find_trachea(&sagittal, -900.0).unwrap();
        assert_eq!(t, -900.0);
        let mut back: Vec<[usize; 3]> = tree.voxels().map(|[a, b, c]| [b, c, a]).collect();
        back.sort_by_key(|&[i, j, k]| (k, j, i));
        assert_eq!(back, axial.voxels().collect::<Vec<_>>());
    }
}
