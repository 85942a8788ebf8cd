//! The vessel: a contrast-filled lumen with a stent and calcified plaque, for the bright-object
//! render modes (MIP, two isosurfaces) and for values far above the tissue range.

use super::centreline::Centreline;
use super::profile::{
    paint, CALCIFICATION_HU, FAT_HU, LUMEN_CONTRAST_HU, REACH_VOX, STENT_HU, TISSUE_HU,
};
use super::raster::{grid_centre, rasterize};
use super::shape::{cylindrical, Ball};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;
use std::f64::consts::TAU;

/// Helical strands per direction: the two directions cross into a diamond lattice.
const STRANDS: usize = 6;
/// Calcifications: (azimuth, radians; height as a fraction of the grid along `k`).
const CALCIFICATIONS: [(f64, f64); 4] = [(0.3, 0.15), (2.4, 0.35), (4.0, 0.62), (5.3, 0.85)];

/// A stent: two families of [`Stent::strands`] helices each, one left- and one right-handed, on a
/// cylinder around the vessel's axis, between two heights. Each strut is a round wire.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stent {
    /// Radius of the cylinder the wires' centres lie on, voxels (the lumen radius minus the wire
    /// radius: the stent presses against the wall).
    pub radius_vox: f64,
    /// Radius of a wire, voxels.
    pub wire_radius_vox: f64,
    /// Helices per handedness.
    pub strands: usize,
    /// Axial advance of one helix per full turn, voxels (a 45° helix: the cylinder's circumference).
    pub pitch_vox: f64,
    /// The stent's extent along the axis, `k` (voxel index), first and last.
    pub k_range: (f64, f64),
}

/// Truth of the vessel phantom: a straight vessel along `k` through the grid's centre.
#[derive(Debug, Clone, PartialEq)]
pub struct Vessel {
    /// The vessel's axis, first slice to last.
    pub axis: Centreline,
    /// Radius of the contrast-filled lumen (contrast–wall surface), voxels.
    pub lumen_radius_vox: f64,
    /// Outer radius of the wall (wall–fat surface), voxels.
    pub wall_radius_vox: f64,
    /// The stent inside the lumen.
    pub stent: Stent,
    /// Calcified plaques, centred in the wall.
    pub calcifications: Vec<Ball>,
}

impl Vessel {
    /// The noiseless value at `p`; `centre` is a point of the axis. The calcifications and the
    /// stent are only evaluated in the shells of radii where they can reach (the stent's angle is
    /// an `atan2`, which would otherwise dominate).
    fn hu_at(&self, p: DVec3, centre: DVec3) -> f64 {
        let (r, _) = cylindrical(p, centre, DVec3::Z);
        let mut hu = paint(FAT_HU, r - self.wall_radius_vox, TISSUE_HU);
        hu = paint(hu, r - self.lumen_radius_vox, LUMEN_CONTRAST_HU);
        let in_wall = 0.5 * (self.lumen_radius_vox + self.wall_radius_vox);
        for ball in &self.calcifications {
            if (r - in_wall).abs() <= ball.radius_vox + REACH_VOX {
                hu = paint(hu, ball.signed_distance(p), CALCIFICATION_HU);
            }
        }
        if (r - self.stent.radius_vox).abs() <= self.stent.wire_radius_vox + REACH_VOX {
            hu = paint(hu, self.stent_distance(p, centre), STENT_HU);
        }
        hu
    }

    /// Signed distance (approximate away from the wires, exact in the limit of thin wires) from
    /// `p` to the stent, voxels.
    fn stent_distance(&self, p: DVec3, centre: DVec3) -> f64 {
        let s = &self.stent;
        let (r, _) = cylindrical(p, centre, DVec3::Z);
        let theta = (p.y - centre.y).atan2(p.x - centre.x);
        // On the unrolled cylinder (u = radius · angle, z), a helix is the line u = ±slope·z + c,
        // repeated every circumference / strands; slope 1 for a pitch equal to the circumference.
        let period = TAU / s.strands as f64;
        let slope = TAU * s.radius_vox / s.pitch_vox;
        let along_perpendicular = |handedness: f64| {
            let phase = theta - handedness * TAU * p.z / s.pitch_vox;
            let wrapped = phase - (phase / period).round() * period;
            (s.radius_vox * wrapped).abs() / slope.hypot(1.0)
        };
        let across = along_perpendicular(1.0).min(along_perpendicular(-1.0));
        let wire = (r - s.radius_vox).hypot(across) - s.wire_radius_vox;
        let (k0, k1) = s.k_range;
        let ends = (k0 - p.z).max(p.z - k1);
        wire.max(ends)
    }
}

/// A `size³` volume of fat holding a vessel along `k`: a lumen of contrast (radius 0.25 · size)
/// in a soft-tissue wall (0.05 · size, at least 1.5 voxels thick), a stent over the middle 60 %
/// of its length and four calcified plaques in the wall.
pub fn vessel(options: &PhantomOptions) -> (Volume, Vessel) {
    let dims = options.cube();
    let size = options.size_vox();
    let centre = grid_centre(dims);
    let last_k = dims[2] as f64 - 1.0;
    let lumen = 0.25 * size;
    let wall = lumen + (0.05 * size).max(1.5);
    let wire = (0.01 * size).max(0.6);
    let stent_radius = lumen - wire;
    let calcification = 0.6 * (wall - lumen);
    let truth = Vessel {
        axis: Centreline::new(vec![
            DVec3::new(centre.x, centre.y, 0.0),
            DVec3::new(centre.x, centre.y, last_k),
        ]),
        lumen_radius_vox: lumen,
        wall_radius_vox: wall,
        stent: Stent {
            radius_vox: stent_radius,
            wire_radius_vox: wire,
            strands: STRANDS,
            pitch_vox: TAU * stent_radius,
            k_range: (0.2 * last_k, 0.8 * last_k),
        },
        calcifications: CALCIFICATIONS
            .iter()
            .map(|&(azimuth, height)| Ball {
                centre_vox: DVec3::new(
                    centre.x + 0.5 * (lumen + wall) * azimuth.cos(),
                    centre.y + 0.5 * (lumen + wall) * azimuth.sin(),
                    height * last_k,
                ),
                radius_vox: calcification,
            })
            .collect(),
    };
    let volume = rasterize(dims, options, &|p| truth.hu_at(p, centre));
    (volume, truth)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{iso_crossing, small};
    use super::*;

    #[test]
    fn materials_sit_at_their_radii() {
        let (volume, vessel) = vessel(&small(64));
        let axis = vessel.axis.point_at(5.0);
        assert_eq!(volume.sample_physical(axis), Some(LUMEN_CONTRAST_HU));
        assert_eq!(volume.physical(0, 0, 0), Some(FAT_HU));
        // Below the stent and away from plaque, the lumen–wall and wall–fat surfaces are exact.
        for angle in [0.0, 1.0, 2.0] {
            let dir = DVec3::new(f64::cos(angle), f64::sin(angle), 0.0);
            let lumen = vessel.lumen_radius_vox;
            let wall = vessel.wall_radius_vox;
            let mid = 0.5 * (LUMEN_CONTRAST_HU + TISSUE_HU);
            let r = iso_crossing(&volume, axis, dir, (lumen - 1.2, lumen + 1.2), mid);
            assert!(
                (r - lumen).abs() < 0.02,
                "lumen radius {r}, expected {lumen}"
            );
            let mid = 0.5 * (TISSUE_HU + FAT_HU);
            let r = iso_crossing(&volume, axis, dir, (wall - 1.2, wall + 1.2), mid);
            assert!((r - wall).abs() < 0.02, "wall radius {r}, expected {wall}");
        }
    }

    #[test]
    fn stent_voxels_lie_on_the_stent_and_its_wires_are_bright() {
        let (volume, vessel) = vessel(&small(96));
        let stent = vessel.stent;
        let centre = vessel.axis.point_at(0.0);
        let [nx, ny, nz] = volume.dims();
        let mut bright = 0;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    if volume.physical(i, j, k).unwrap() < 0.5 * (STENT_HU + CALCIFICATION_HU) {
                        continue;
                    }
                    bright += 1;
                    let p = DVec3::new(i as f64, j as f64, k as f64);
                    let (r, _) = cylindrical(p, centre, DVec3::Z);
                    assert!((r - stent.radius_vox).abs() <= stent.wire_radius_vox + 1.0);
                    let (k0, k1) = stent.k_range;
                    assert!(p.z >= k0 - 1.0 && p.z <= k1 + 1.0, "metal at k = {k}");
                }
            }
        }
        assert!(bright > 1000, "{bright} metal voxels");
        // Along one right-handed wire, every point is metal.
        let (k0, k1) = stent.k_range;
        for n in 0..200 {
            let z = k0 + 1.0 + (k1 - k0 - 2.0) * f64::from(n) / 200.0;
            let angle = TAU * z / stent.pitch_vox;
            let p = centre + DVec3::new(angle.cos(), angle.sin(), 0.0) * stent.radius_vox;
            let hu = volume.sample_physical(DVec3::new(p.x, p.y, z)).unwrap();
            assert!(
                hu > 0.5 * (STENT_HU + LUMEN_CONTRAST_HU),
                "{hu} HU on a wire at k = {z}"
            );
        }
    }

    #[test]
    fn calcifications_are_bright_at_their_centres() {
        let (volume, vessel) = vessel(&small(64));
        assert_eq!(vessel.calcifications.len(), 4);
        for ball in &vessel.calcifications {
            let hu = volume.sample_physical(ball.centre_vox).unwrap();
            assert!(
                hu > 0.5 * (CALCIFICATION_HU + TISSUE_HU),
                "{hu} HU at {ball:?}"
            );
            let (r, _) = cylindrical(ball.centre_vox, vessel.axis.point_at(0.0), DVec3::Z);
            assert!(r > vessel.lumen_radius_vox && r < vessel.wall_radius_vox);
        }
    }
}
