//! The sphere shell: the ray caster's depth test.

use super::profile::{ramp, AIR_HU, TISSUE_HU};
use super::raster::{grid_centre, rasterize};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Truth of the sphere shell: tissue between two concentric spheres, air inside and outside.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereShell {
    /// Common centre, voxel index (the grid's centre).
    pub centre_vox: DVec3,
    /// Radius of the air–tissue surface facing the centre, voxels (0.35 · size).
    pub inner_radius_vox: f64,
    /// Radius of the outer tissue–air surface, voxels (0.45 · size).
    pub outer_radius_vox: f64,
}

/// A `size³` volume holding a tissue shell 0.1 · size thick around air, in air.
pub fn sphere_shell(options: &PhantomOptions) -> (Volume, SphereShell) {
    let dims = options.cube();
    let size = options.size_vox();
    let truth = SphereShell {
        centre_vox: grid_centre(dims),
        inner_radius_vox: 0.35 * size,
        outer_radius_vox: 0.45 * size,
    };
    let volume = rasterize(dims, options, &|p: DVec3| {
        let r = p.distance(truth.centre_vox);
        // The shell's signed distance; the two surfaces are 0.1 · size ≥ 0.8 voxel apart, but
        // each is exact only where the other's ramp does not reach (size ≥ 20).
        let d = (truth.inner_radius_vox - r).max(r - truth.outer_radius_vox);
        ramp(d, TISSUE_HU, AIR_HU)
    });
    (volume, truth)
}
