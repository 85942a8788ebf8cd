//! The straight tube: the simplest lumen, for centreline and fly-through tests.

use super::centreline::Centreline;
use super::profile::{ramp, AIR_HU, TISSUE_HU};
use super::raster::{grid_centre, rasterize};
use super::shape::cylindrical;
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Truth of a tube of constant radius.
#[derive(Debug, Clone, PartialEq)]
pub struct Tube {
    /// The axis, from one face of the volume to the opposite one.
    pub centreline: Centreline,
    /// Radius of the air–tissue surface, voxels.
    pub radius_vox: f64,
}

/// A `size³` volume of tissue pierced along `k`, through the centre of the `i`–`j` plane, by an
/// air cylinder of radius 0.2 · size that runs from the first slice to the last.
pub fn straight_tube(options: &PhantomOptions) -> (Volume, Tube) {
    let dims = options.cube();
    let centre = grid_centre(dims);
    let last_k = dims[2] as f64 - 1.0;
    let truth = Tube {
        centreline: Centreline::new(vec![
            DVec3::new(centre.x, centre.y, 0.0),
            DVec3::new(centre.x, centre.y, last_k),
        ]),
        radius_vox: 0.2 * options.size_vox(),
    };
    let volume = rasterize(dims, options, &|p: DVec3| {
        let (r, _) = cylindrical(p, centre, DVec3::Z);
        ramp(r - truth.radius_vox, AIR_HU, TISSUE_HU)
    });
    (volume, truth)
}
