//! The airway tree with no seed: the trachea found as the round air column in the top axial
//! slices, then grown below a threshold lowered until the tree stops leaking into the lung.

use super::lumen::{Lumen, LumenSide};
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
/// no slice holds a round air section of the trachea's size, or every try leaks.
pub fn find_trachea(volume: &Volume, threshold: f64) -> Option<(Lumen, f64)> {
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
    let g = volume.geometry();
    let z_of = |k: usize| g.world_of(glam::DVec3::new(0.0, 0.0, k as f64)).z;
    let top_first = z_of(dims[2] - 1) > z_of(0);
    let spacing = g.spacing_mm();
    let pixel_mm2 = spacing.x * spacing.y;
    (0..TOP_SLICES.min(dims[2]))
        .map(|n| if top_first { dims[2] - 1 - n } else { n })
        .find_map(|k| {
            let sections = air_sections(volume, k, threshold);
            sections
                .into_iter()
                .filter(|s| {
                    let area = s.pixels as f64 * pixel_mm2;
                    let box_pixels = (s.hi[0] - s.lo[0] + 1) * (s.hi[1] - s.lo[1] + 1);
                    (AREA_MM2.0..=AREA_MM2.1).contains(&area)
                        && s.pixels as f64 >= MIN_FILL * box_pixels as f64
                })
                .min_by_key(|s| s.centre[0].abs_diff(dims[0] / 2))
                .map(|s| [s.centre[0], s.centre[1], k])
        })
}

/// One 4-connected air section of an axial slice that does not touch the slice's border.
struct Section {
    pixels: usize,
    lo: [usize; 2],
    hi: [usize; 2],
    /// A pixel of the section nearest its centroid.
    centre: [usize; 2],
}

/// The air sections (values below `threshold`) of slice `k` not touching its border.
fn air_sections(volume: &Volume, k: usize, threshold: f64) -> Vec<Section> {
    let [nx, ny, _] = volume.dims();
    let map = volume.value_map();
    let slice = &volume.voxels()[k * nx * ny..(k + 1) * nx * ny];
    let air: Vec<bool> = slice.iter().map(|&s| map.physical(s) < threshold).collect();
    let mut seen = vec![false; nx * ny];
    let mut sections = Vec::new();
    for start in 0..nx * ny {
        if !air[start] || seen[start] {
            continue;
        }
        seen[start] = true;
        let mut stack = vec![start];
        let mut pixels = Vec::new();
        while let Some(n) = stack.pop() {
            pixels.push(n);
            let (i, j) = (n % nx, n / nx);
            let neighbours = [
                (i > 0).then(|| n - 1),
                (i + 1 < nx).then_some(n + 1),
                (j > 0).then(|| n - nx),
                (j + 1 < ny).then_some(n + nx),
            ];
            for m in neighbours.into_iter().flatten() {
                if air[m] && !seen[m] {
                    seen[m] = true;
                    stack.push(m);
                }
            }
        }
        if let Some(section) = section_of(&pixels, nx, ny) {
            sections.push(section);
        }
    }
    sections
}

/// The section of `pixels` (linear indices in an `nx` × `ny` slice), or `None` when it touches
/// the slice's border.
fn section_of(pixels: &[usize], nx: usize, ny: usize) -> Option<Section> {
    let ij = |n: usize| [n % nx, n / nx];
    let (mut lo, mut hi) = ([usize::MAX; 2], [0; 2]);
    let mut sum = [0.0; 2];
    for &n in pixels {
        let p = ij(n);
        for a in 0..2 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
            sum[a] += p[a] as f64;
        }
    }
    if lo[0] == 0 || lo[1] == 0 || hi[0] + 1 == nx || hi[1] + 1 == ny {
        return None;
    }
    let mean = sum.map(|s| s / pixels.len() as f64);
    let centre = pixels.iter().map(|&n| ij(n)).min_by(|a, b| {
        let d = |p: &[usize; 2]| (p[0] as f64 - mean[0]).powi(2) + (p[1] as f64 - mean[1]).powi(2);
        d(a).total_cmp(&d(b))
    })?;
    Some(Section {
        pixels: pixels.len(),
        lo,
        hi,
        centre,
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
    }
}
