//! The sinus: air cavities walled and divided by thin bone, for thin structures that a coarse
//! step or a blurred gradient would miss or punch through.

use super::profile::{paint, AIR_HU, BONE_HU, RAMP_WIDTH_VOX, REACH_VOX, TISSUE_HU};
use super::raster::rasterize;
use super::shape::{rounded_box, slab};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Thickness of every septum, voxels (thin on purpose, whatever the size).
const SEPTUM_VOX: f64 = 1.5;

/// An air cavity: a box with rounded edges.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cavity {
    /// Centre, voxel index.
    pub centre_vox: DVec3,
    /// Half the box's extent along `i`, `j`, `k`, voxels.
    pub half_extent_vox: DVec3,
    /// Radius of the rounded edges and corners, voxels.
    pub corner_radius_vox: f64,
}

impl Cavity {
    /// Signed distance from `p` to the cavity's surface (negative in the air), voxels.
    pub fn signed_distance(&self, p: DVec3) -> f64 {
        rounded_box(
            p,
            self.centre_vox,
            self.half_extent_vox,
            self.corner_radius_vox,
        )
    }
}

/// A bony septum: the slab of `thickness_vox` centred on a plane, spanning one cavity wall to
/// wall so that it splits it into two air cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Septum {
    /// Index into [`Sinus::cavities`] of the cavity it divides.
    pub cavity: usize,
    /// A point of the mid-plane, voxel index.
    pub point_vox: DVec3,
    /// Unit normal of the mid-plane.
    pub normal: DVec3,
    /// Thickness, voxels.
    pub thickness_vox: f64,
}

/// Truth of the sinus phantom: soft tissue holding cavities, each lined by a bony wall of
/// `wall_thickness_vox`, divided by septa.
#[derive(Debug, Clone, PartialEq)]
pub struct Sinus {
    /// Two maxillary-like cavities (right, left) and an ethmoid-like one above between them.
    pub cavities: Vec<Cavity>,
    /// One oblique septum in each maxillary cavity, two parallel ones in the ethmoid.
    pub septa: Vec<Septum>,
    /// Thickness of the bone around each cavity, voxels.
    pub wall_thickness_vox: f64,
}

impl Sinus {
    /// The layout in a `size³` grid.
    fn new(size: f64) -> Self {
        let at = |i: f64, j: f64, k: f64| DVec3::new(i, j, k) * size;
        let cavity = |centre: DVec3, half: DVec3, corner: f64| Cavity {
            centre_vox: centre,
            half_extent_vox: half,
            corner_radius_vox: corner * size,
        };
        let maxillary = at(0.13, 0.20, 0.18);
        let cavities = vec![
            cavity(at(0.30, 0.50, 0.45), maxillary, 0.04),
            cavity(at(0.70, 0.50, 0.45), maxillary, 0.04),
            cavity(at(0.50, 0.45, 0.78), at(0.06, 0.18, 0.08), 0.02),
        ];
        let septum = |cavity: usize, offset: DVec3, normal: DVec3| Septum {
            cavity,
            point_vox: cavities[cavity].centre_vox + offset * size,
            normal: normal.normalize(),
            thickness_vox: SEPTUM_VOX,
        };
        let septa = vec![
            septum(0, DVec3::ZERO, DVec3::new(0.2, 1.0, 0.3)),
            septum(1, DVec3::new(0.0, 0.0, 0.03), DVec3::new(0.0, 0.3, 1.0)),
            septum(2, DVec3::new(0.0, -0.06, 0.0), DVec3::Y),
            septum(2, DVec3::new(0.0, 0.06, 0.0), DVec3::Y),
        ];
        Self {
            cavities,
            septa,
            // At least a ramp's width, so the wall's outer ramp never reaches the cavity's.
            wall_thickness_vox: (0.03 * size).max(RAMP_WIDTH_VOX),
        }
    }

    /// The noiseless value at `p`: bone walls, then air, then septa reaching into the walls.
    fn hu_at(&self, p: DVec3) -> f64 {
        let mut distances = [f64::INFINITY; 3];
        for (d, cavity) in distances.iter_mut().zip(&self.cavities) {
            *d = cavity.signed_distance(p);
        }
        if distances
            .iter()
            .all(|&d| d >= self.wall_thickness_vox + REACH_VOX)
        {
            return TISSUE_HU;
        }
        let mut hu = TISSUE_HU;
        for &d in &distances {
            hu = paint(hu, d - self.wall_thickness_vox, BONE_HU);
        }
        for &d in &distances {
            hu = paint(hu, d, AIR_HU);
        }
        for septum in &self.septa {
            let within = distances[septum.cavity] - RAMP_WIDTH_VOX;
            let d = slab(p, septum.point_vox, septum.normal, septum.thickness_vox);
            hu = paint(hu, d.max(within), BONE_HU);
        }
        hu
    }
}

/// A `size³` volume of soft tissue holding three bone-walled air cavities divided by septa
/// 1.5 voxels thick.
pub fn sinus(options: &PhantomOptions) -> (Volume, Sinus) {
    let truth = Sinus::new(options.size_vox());
    let volume = rasterize(options.cube(), options, &|p| truth.hu_at(p));
    (volume, truth)
}

#[cfg(test)]
mod tests {
    use super::super::tests::small;
    use super::*;
    use std::collections::VecDeque;

    /// Voxels 6-connected to `seed` whose value is below `threshold_hu`.
    fn flood(volume: &Volume, seed: DVec3, threshold_hu: f64) -> Vec<bool> {
        let [nx, ny, nz] = volume.dims();
        let mut inside = vec![false; nx * ny * nz];
        let start = seed.round();
        let start = [start.x as usize, start.y as usize, start.z as usize];
        let mut queue = VecDeque::from([start]);
        inside[volume.index(start[0], start[1], start[2])] = true;
        while let Some([i, j, k]) = queue.pop_front() {
            let neighbours = [
                [i.wrapping_sub(1), j, k],
                [i + 1, j, k],
                [i, j.wrapping_sub(1), k],
                [i, j + 1, k],
                [i, j, k.wrapping_sub(1)],
                [i, j, k + 1],
            ];
            for [a, b, c] in neighbours {
                if volume.physical(a, b, c).is_some_and(|hu| hu < threshold_hu) {
                    let index = volume.index(a, b, c);
                    if !inside[index] {
                        inside[index] = true;
                        queue.push_back([a, b, c]);
                    }
                }
            }
        }
        inside
    }

    #[test]
    fn septa_split_each_cavity_into_separate_air_cells() {
        let (volume, sinus) = sinus(&small(64));
        // The most permissive threshold a user would pick for this air–bone boundary.
        let threshold = 0.5 * (AIR_HU + BONE_HU);
        let voxel = |p: DVec3| {
            volume.index(
                p.x.round() as usize,
                p.y.round() as usize,
                p.z.round() as usize,
            )
        };
        for septum in &sinus.septa {
            let cavity = sinus.cavities[septum.cavity];
            let (a, b) = (
                septum.point_vox + septum.normal * 2.5,
                septum.point_vox - septum.normal * 2.5,
            );
            for p in [a, b] {
                assert!(cavity.signed_distance(p) < -1.0);
                assert_eq!(volume.sample_physical(p.round()), Some(AIR_HU));
            }
            let cell = flood(&volume, a, threshold);
            assert!(cell.iter().filter(|&&v| v).count() > 50);
            assert!(!cell[voxel(b)], "septum in cavity {} leaks", septum.cavity);
        }
        // The ethmoid's middle cell reaches neither outer cell; the cavities are apart.
        let ethmoid = sinus.cavities[2];
        let middle = flood(&volume, ethmoid.centre_vox, threshold);
        let offset = DVec3::Y * (0.5 * ethmoid.half_extent_vox.y + 2.0);
        assert!(!middle[voxel(ethmoid.centre_vox + offset)]);
        assert!(!middle[voxel(ethmoid.centre_vox - offset)]);
        assert!(!middle[voxel(sinus.cavities[0].centre_vox)]);
    }

    #[test]
    fn cavity_walls_are_bone_and_exact() {
        let (volume, sinus) = sinus(&small(64));
        let cavity = sinus.cavities[1];
        // Straight down from the centre of the left maxillary cavity, below its septum.
        let face = cavity.centre_vox.z - cavity.half_extent_vox.z;
        let from = DVec3::new(cavity.centre_vox.x, cavity.centre_vox.y, face + 4.0);
        let r = super::super::tests::iso_crossing(
            &volume,
            from,
            -DVec3::Z,
            (0.0, 5.5),
            0.5 * (AIR_HU + BONE_HU),
        );
        assert!(
            (from.z - r - face).abs() < 0.02,
            "air–bone surface at {}",
            from.z - r
        );
        let in_wall = DVec3::new(from.x, from.y, face - 0.5 * sinus.wall_thickness_vox - 0.5);
        assert!(volume.sample_physical(in_wall).unwrap() > 0.5 * (BONE_HU + TISSUE_HU));
        assert_eq!(volume.physical(0, 0, 0), Some(TISSUE_HU));
    }
}
