//! Polyp candidates (computer-aided detection) on a lumen's wall, after Yoshida & Näppi (IEEE
//! TMI 2001): at every wall voxel the volume, smoothed by a Gaussian, gives the principal
//! curvatures of the isosurface through the voxel ([`curvature`]); polyps are caps (shape
//! index near 1) of a curvedness between that of folds' crests and noise. Cap voxels seed
//! regions grown over the wall through looser thresholds (hysteresis); each region is a
//! candidate with its tip on the wall, a score and a size: the largest diameter of what stands
//! out of the local wall around it ([`protrusion`]), as a radiologist measures a polyp.
//!
//! Only the wall of the given lumen is searched (the study's colon, not the outside of the
//! body): non-lumen voxels 6-adjacent to it.

mod cluster;
pub mod curvature;
mod protrusion;
#[cfg(test)]
mod tests;
mod view;

use crate::navigate::Lumen;
use crate::study::{Study, StudyPathError};
use crate::Volume;
use glam::DVec3;
use rayon::prelude::*;
use thiserror::Error;

pub use curvature::SurfaceShape;
pub use view::{annotations, view_pose, CANDIDATE_COLOR, VIEW_DISTANCE_MM, VIEW_FOV_DEG};

/// Thresholds and scales of the detection.
#[derive(Debug, Clone, PartialEq)]
pub struct PolypOptions {
    /// Standard deviation of the Gaussian smoothing before the derivatives, mm (default 1).
    pub sigma_mm: f64,
    /// Shape index a seed voxel reaches (default 0.88: a cap; a flat polyp's dome on the
    /// colon's concave wall peaks at 0.88–0.90 under the default smoothing).
    pub seed_shape_index: f64,
    /// Shape index a region grows through (default 0.8, hysteresis below the seeds').
    pub grow_shape_index: f64,
    /// Curvedness band of seeds and regions, 1/mm: from the inverse radius of the flattest
    /// polyp's dome to that of noise bumps (default 0.05..=1.0: radii 1–20 mm; a 6 mm flat
    /// polyp 1 mm high is a dome of radius 5 mm, flatter still once smoothed).
    pub curvedness_per_mm: (f64, f64),
    /// Candidates whose cap region (the grown region) or whose measured size is narrower than
    /// this across the wall are dropped, so that none is listed smaller, mm (default 4: the cap
    /// region of a 6 mm polyp between folds measures 4.7–5.5 mm, narrowed by the wall's
    /// concavity).
    pub min_size_mm: f64,
}

impl Default for PolypOptions {
    fn default() -> Self {
        Self {
            sigma_mm: 1.0,
            seed_shape_index: 0.88,
            grow_shape_index: 0.8,
            curvedness_per_mm: (0.05, 1.0),
            min_size_mm: 4.0,
        }
    }
}

/// Options that cannot give a detection.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum PolypError {
    /// A parameter is NaN, infinite or out of its range.
    #[error("polyp option {name} must be {range}, not {value}")]
    BadOption {
        /// The option's name.
        name: &'static str,
        /// What it must be.
        range: &'static str,
        /// The value given.
        value: f64,
    },
    /// The lumen was found on another grid.
    #[error("the lumen's grid {lumen:?} is not the volume's {volume:?}")]
    OtherGrid {
        /// The lumen's volume dimensions.
        lumen: [usize; 3],
        /// The volume's dimensions.
        volume: [usize; 3],
    },
}

impl PolypOptions {
    /// Refuses NaN, infinite and out-of-range options, naming them.
    pub fn check(&self) -> Result<(), PolypError> {
        let bad = |name, range, value: f64, ok: bool| {
            if ok && value.is_finite() {
                Ok(())
            } else {
                Err(PolypError::BadOption { name, range, value })
            }
        };
        let (lo, hi) = self.curvedness_per_mm;
        let si = |v: f64| (0.0..=1.0).contains(&v);
        bad(
            "sigma_mm",
            "in (0, 10] mm",
            self.sigma_mm,
            self.sigma_mm > 0.0 && self.sigma_mm <= 10.0,
        )?;
        bad(
            "seed_shape_index",
            "in [0, 1]",
            self.seed_shape_index,
            si(self.seed_shape_index),
        )?;
        bad(
            "grow_shape_index",
            "in [0, seed_shape_index]",
            self.grow_shape_index,
            si(self.grow_shape_index) && self.grow_shape_index <= self.seed_shape_index,
        )?;
        bad("curvedness minimum", "≥ 0 /mm", lo, lo >= 0.0)?;
        bad("curvedness maximum", "above the minimum", hi, hi > lo)?;
        bad(
            "min_size_mm",
            "≥ 0 mm",
            self.min_size_mm,
            self.min_size_mm >= 0.0,
        )
    }
}

/// One polyp candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// The candidate's tip on the wall (its wall voxel farthest into the lumen), world (LPS) mm.
    pub centre_mm: DVec3,
    /// Unit normal into the lumen: the mean of the region's normals, world axes.
    pub normal: DVec3,
    /// Size: the largest diameter, across its normal, of what stands out of the local wall
    /// around it ([`protrusion`]), mm; the cap region's extent where the wall cannot be fitted.
    pub size_mm: f64,
    /// Ranking in [0, 1]: how cap-like the region is (its mean shape index from 0.5 to 1)
    /// times how much of it is cap ([`cluster`]'s seed area against that of a 5 mm cap).
    pub score: f64,
    /// Wall voxels in the region.
    pub voxels: usize,
}

/// A wall voxel and its surface shape.
#[derive(Debug, Clone, Copy)]
pub(crate) struct WallPoint {
    /// Linear index in the volume.
    pub(crate) index: usize,
    /// Voxel index.
    pub(crate) voxel: [usize; 3],
    /// The shape there.
    pub(crate) shape: SurfaceShape,
    /// The (unsmoothed) isosurface's point next to the voxel on the lumen's side, world (LPS) mm.
    pub(crate) surface_mm: DVec3,
    /// The unsmoothed isosurface's unit normal there, into the lumen, world axes.
    pub(crate) surface_normal: DVec3,
}

/// The polyp candidates on the wall of `lumen` in `volume`, best score first.
pub fn find_candidates(
    volume: &Volume,
    lumen: &Lumen,
    options: &PolypOptions,
) -> Result<Vec<Candidate>, PolypError> {
    options.check()?;
    if lumen.volume_dims() != volume.dims() {
        return Err(PolypError::OtherGrid {
            lumen: lumen.volume_dims(),
            volume: volume.dims(),
        });
    }
    let wall = wall_shapes(volume, lumen, options.sigma_mm);
    let mut candidates = cluster::candidates(volume.geometry(), &wall, options);
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    Ok(candidates)
}

/// The lumen whose wall the front ends search: the one a route starting at `start_mm` flies
/// through (see [`Study::lumen_from`]), else the structure the study found (the colon with the
/// colonoscopy preset).
pub fn searched_lumen(
    study: &Study,
    volume: &Volume,
    start_mm: Option<DVec3>,
) -> Result<Lumen, StudyPathError> {
    match (start_mm, study.structure()) {
        (Some(start), _) => Ok(study.lumen_from(volume, start)?.0),
        (None, Some(structure)) => Ok(structure.clone()),
        (None, None) => Err(StudyPathError::NoStart(
            "the study found no structure to search: give a path, or a preset whose structure is \
             found (colonoscopy)"
                .to_owned(),
        )),
    }
}

/// The 26 neighbours of `v` inside the grid.
fn neighbours(dims: [usize; 3], v: [usize; 3]) -> impl Iterator<Item = [usize; 3]> {
    (0..27).filter(|&n| n != 13).filter_map(move |n| {
        let offset = [n % 3, n / 3 % 3, n / 9];
        let shifted = |a: usize| (v[a] + offset[a]).checked_sub(1).filter(|&c| c < dims[a]);
        Some([shifted(0)?, shifted(1)?, shifted(2)?])
    })
}

/// Every wall voxel of `lumen` (sorted by linear index) with its surface shape at `sigma_mm`.
fn wall_shapes(volume: &Volume, lumen: &Lumen, sigma_mm: f64) -> Vec<WallPoint> {
    let geometry = volume.geometry();
    let dims = geometry.dims();
    let kernels = curvature::Kernels::new(sigma_mm, geometry.spacing_mm());
    let direction = geometry.direction();
    let spacing = geometry.spacing_mm();
    let threshold = lumen.threshold();
    let away = curvature::rising_away(lumen.side());
    let (lo, hi) = lumen.bounds();
    let range = |a: usize| lo[a].saturating_sub(1)..(hi[a] + 2).min(dims[a]);
    let (xs, ys) = (range(0), range(1));
    range(2)
        .into_par_iter()
        .flat_map_iter(|k| {
            let (xs, ys) = (xs.clone(), ys.clone());
            ys.flat_map(move |j| xs.clone().map(move |i| [i, j, k]))
                .filter(|&v| lumen.is_wall(v))
                .map(|v| {
                    let (g, h) = curvature::derivatives(volume, &kernels, v);
                    let toward_lumen = -g * away / spacing;
                    let surface = curvature::surface_vox(volume, v, threshold, toward_lumen);
                    WallPoint {
                        index: v[0] + dims[0] * (v[1] + dims[1] * v[2]),
                        voxel: v,
                        shape: curvature::shape(g, h, lumen.side(), direction),
                        surface_mm: geometry.world_of(surface),
                        surface_normal: curvature::raw_normal(volume, surface, lumen.side()),
                    }
                })
                .collect::<Vec<_>>()
        })
        .collect()
}
