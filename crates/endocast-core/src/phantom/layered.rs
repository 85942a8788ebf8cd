//! The layered phantom: air over a secretion layer of known, varying thickness over tissue — the
//! secretion test of the realistic look (Krüger et al., "Sinus Endoscopy", §4.3, Figure 3).

use super::profile::{paint, ramp, AIR_HU, TISSUE_HU};
use super::raster::rasterize;
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Secretion (mucus thinned by air, the paper's "viscous material"), in HU: between air and
/// soft tissue, so that two thresholds tell it from both.
pub const SECRETION_HU: f64 = -500.0;

/// Truth of the layered phantom, in voxel index space (1 mm voxels). Air fills `k` below
/// [`Layered::secretion_top_k`]; secretion lies between that plane and the tissue's top
/// surface `k = tissue_k0 + slope · i`, tilted along `i` so that the layer thickens from
/// [`Layered::min_thickness_vox`] at `i = 0` to [`Layered::max_thickness_vox`] at the last
/// column; tissue fills the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Layered {
    /// The air–secretion plane, `k` index.
    pub secretion_top_k: f64,
    /// Thickness of the layer along `k` at `i = 0`, voxels.
    pub min_thickness_vox: f64,
    /// Thickness of the layer along `k` at the last column, voxels.
    pub max_thickness_vox: f64,
    /// The last column's `i` index (size − 1).
    pub last_i: f64,
}

impl Layered {
    /// Thickness of the layer along `k` at column `i` (continuous), voxels.
    pub fn thickness_vox_at(&self, i: f64) -> f64 {
        let f = i / self.last_i;
        self.min_thickness_vox + (self.max_thickness_vox - self.min_thickness_vox) * f
    }

    /// Signed distance from the tissue's top surface, voxels (negative inside tissue).
    fn tissue_distance(&self, p: DVec3) -> f64 {
        let slope = (self.max_thickness_vox - self.min_thickness_vox) / self.last_i;
        let top = self.secretion_top_k + self.min_thickness_vox + slope * p.x;
        (top - p.z) / (1.0 + slope * slope).sqrt()
    }

    /// Length of the ray `origin + t · direction` (voxel space, `t` in voxels when `direction`
    /// is a unit vector) inside the secretion layer: from the air–secretion plane to the
    /// tissue's top surface; `None` when the ray runs parallel to either.
    pub fn secretion_along(&self, origin: DVec3, direction: DVec3) -> Option<f64> {
        let slope = (self.max_thickness_vox - self.min_thickness_vox) / self.last_i;
        let (dz, dtop) = (direction.z, direction.z - slope * direction.x);
        if dz == 0.0 || dtop == 0.0 {
            return None;
        }
        let t_top = (self.secretion_top_k - origin.z) / dz;
        let k0 = self.secretion_top_k + self.min_thickness_vox;
        let t_tissue = (k0 + slope * origin.x - origin.z) / dtop;
        Some((t_tissue - t_top) * direction.length())
    }

    /// The threshold halfway between air and secretion, HU: crossed on the air–secretion plane.
    pub fn secretion_threshold_hu() -> f64 {
        0.5 * (AIR_HU + SECRETION_HU)
    }

    /// The threshold halfway between secretion and tissue, HU: crossed on the tissue's surface.
    pub fn tissue_threshold_hu() -> f64 {
        0.5 * (SECRETION_HU + TISSUE_HU)
    }
}

/// A `size³` volume: air in the top 30 % of `k`, then secretion 3 voxels thick at `i = 0`
/// growing to 0.3 · size at the last column, then tissue.
pub fn layered(options: &PhantomOptions) -> (Volume, Layered) {
    let dims = options.cube();
    let size = options.size_vox();
    let truth = Layered {
        secretion_top_k: (0.3 * size).round(),
        // Three voxels keep the two boundary ramps (two voxels wide each) apart.
        min_thickness_vox: 3.0,
        max_thickness_vox: (0.3 * size).max(4.0),
        last_i: size - 1.0,
    };
    let volume = rasterize(dims, options, &|p: DVec3| {
        let below = ramp(truth.tissue_distance(p), TISSUE_HU, SECRETION_HU);
        paint(below, p.z - truth.secretion_top_k, AIR_HU)
    });
    (volume, truth)
}
