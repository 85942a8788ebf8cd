//! The curved tube: an air tube bent along a circular arc, for centreline tests where the path
//! must follow a bend rather than a straight line.

use super::centreline::Centreline;
use super::profile::{ramp, AIR_HU, TISSUE_HU};
use super::raster::{grid_centre, rasterize};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;
use std::f64::consts::TAU;

/// How much of a full circle the arc sweeps: three quarters, so the bend turns through 270° and
/// its two ends stay apart.
const SWEEP_RAD: f64 = 0.75 * TAU;
/// Arc and tube radius as fractions of the size.
const ARC_RADIUS: f64 = 0.3;
const TUBE_RADIUS: f64 = 0.1;
/// Spacing of the truth polyline's vertices, voxels (its chords then stray from the arc by less
/// than a thousandth of a voxel).
const POLYLINE_STEP_VOX: f64 = 0.5;

/// Truth of a tube of constant radius around a circular arc in the `i`–`k` plane. The axis is
/// `arc_centre_vox + arc_radius_vox · (cos θ, 0, sin θ)` for `θ` from 0 to `sweep_rad`; the ends
/// are rounded (half balls), since the tube is the set of points within `radius_vox` of the arc.
#[derive(Debug, Clone, PartialEq)]
pub struct CurvedTube {
    /// The axis as a fine polyline, from `θ = 0` to `θ = sweep_rad`.
    pub centreline: Centreline,
    /// Centre of the arc's circle, continuous voxel index.
    pub arc_centre_vox: DVec3,
    /// Radius of the arc (of the axis), voxels.
    pub arc_radius_vox: f64,
    /// Angle swept by the arc, radians.
    pub sweep_rad: f64,
    /// Radius of the air–tissue surface around the axis, voxels.
    pub radius_vox: f64,
}

impl CurvedTube {
    /// The axis point at angle `theta` (radians) along the arc, voxel index.
    pub fn axis_point(&self, theta: f64) -> DVec3 {
        self.arc_centre_vox + self.arc_radius_vox * DVec3::new(theta.cos(), 0.0, theta.sin())
    }

    /// Exact distance from `p` (voxel index) to the axis arc, voxels.
    pub fn distance_to_axis_vox(&self, p: DVec3) -> f64 {
        let q = p - self.arc_centre_vox;
        let theta = q.z.atan2(q.x).rem_euclid(TAU);
        if theta <= self.sweep_rad {
            (q.x.hypot(q.z) - self.arc_radius_vox).hypot(q.y)
        } else {
            let start = self.axis_point(0.0).distance(p);
            start.min(self.axis_point(self.sweep_rad).distance(p))
        }
    }
}

/// A `size³` volume of tissue holding an air tube of radius 0.1 · size bent around a circle of
/// radius 0.3 · size centred in the grid, in the `i`–`k` plane, through 270°.
pub fn curved_tube(options: &PhantomOptions) -> (Volume, CurvedTube) {
    let dims = options.cube();
    let size = options.size_vox();
    let mut truth = CurvedTube {
        centreline: Centreline::new(vec![DVec3::ZERO, DVec3::X]),
        arc_centre_vox: grid_centre(dims),
        arc_radius_vox: ARC_RADIUS * size,
        sweep_rad: SWEEP_RAD,
        radius_vox: TUBE_RADIUS * size,
    };
    let segments = (SWEEP_RAD * truth.arc_radius_vox / POLYLINE_STEP_VOX).ceil() as usize;
    truth.centreline = Centreline::new(
        (0..=segments)
            .map(|n| truth.axis_point(SWEEP_RAD * n as f64 / segments as f64))
            .collect(),
    );
    let volume = rasterize(dims, options, &|p: DVec3| {
        ramp(
            truth.distance_to_axis_vox(p) - truth.radius_vox,
            AIR_HU,
            TISSUE_HU,
        )
    });
    (volume, truth)
}

#[cfg(test)]
mod tests {
    use super::super::tests::small;
    use super::*;

    #[test]
    fn axis_is_air_and_the_surface_sits_on_the_radius() {
        let (volume, tube) = curved_tube(&small(64));
        for &p in tube.centreline.points() {
            assert!(tube.distance_to_axis_vox(p) < 1e-9);
            assert_eq!(volume.sample_physical(p), Some(AIR_HU));
        }
        // Along the arc's normal (in its plane) the wall's mid value lies at the radius: the ramp
        // rises 520 HU per two voxels, so 20 HU is 0.08 voxel (trilinear
        // interpolation of the curved surface costs a few hundredths).
        let theta: f64 = 1.0;
        let outward = DVec3::new(theta.cos(), 0.0, theta.sin());
        let on_surface = tube.axis_point(theta) + outward * tube.radius_vox;
        let mid = volume.sample_physical(on_surface).unwrap();
        assert!((mid - 0.5 * (AIR_HU + TISSUE_HU)).abs() < 20.0, "{mid}");
        // Beyond the open quarter (between the ends) and at the circle's centre: tissue.
        let gap = tube.arc_centre_vox + tube.arc_radius_vox * DVec3::new(0.7, 0.0, -0.7);
        assert_eq!(volume.sample_physical(gap), Some(TISSUE_HU));
        assert_eq!(volume.sample_physical(tube.arc_centre_vox), Some(TISSUE_HU));
        let polyline = tube.centreline.length_vox();
        assert!(
            (polyline - SWEEP_RAD * tube.arc_radius_vox).abs() < 0.01,
            "{polyline}"
        );
    }
}
