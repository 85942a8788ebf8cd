//! The joint: a wrist-like stack of three bones around two thin layers of contrast (an
//! arthrogram), for two-isosurface rendering where the two materials differ by only 100 HU and
//! for depth peeling, whose n-th and last surfaces lie on the analytic surfaces of the layers.

use super::profile::{paint, BONE_HU, JOINT_CONTRAST_HU, RAMP_WIDTH_VOX, TISSUE_HU};
use super::raster::{grid_centre, rasterize};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Truth of the joint phantom. Every articular surface is the same paraboloid bowl
/// `k = centre.z + ((i − centre.x)² + (j − centre.y)²) / (2 · curvature radius)`, shifted:
/// the first joint space lies half the gap below and above it, the second the same way
/// [`Joint::second_joint_offset_vox`] higher. The lower bone fills everything below the first
/// joint space, a plate of bone lies between the two, the upper bone fills everything above the
/// second, all within a cylinder of [`Joint::radius_vox`] around `k`; contrast fills the gaps,
/// soft tissue the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    /// Centre of the first joint space, voxel index (the grid's centre).
    pub centre_vox: DVec3,
    /// Radius of the bones and of the joint spaces around the `k` axis, voxels.
    pub radius_vox: f64,
    /// Radius of curvature of the articular surfaces at the axis, voxels.
    pub curvature_radius_vox: f64,
    /// Thickness of each contrast layer along `k`, voxels.
    pub gap_vox: f64,
    /// How far above the first joint space (along `k`) the second one lies, voxels.
    pub second_joint_offset_vox: f64,
}

impl Joint {
    /// The bowl the first joint space follows, at column (`i`, `j`).
    fn mid_k(&self, i: f64, j: f64) -> f64 {
        let c = self.centre_vox;
        c.z + ((i - c.x).powi(2) + (j - c.y).powi(2)) / (2.0 * self.curvature_radius_vox)
    }

    /// `k` of the lower bone's articular surface (bone–contrast) at column (`i`, `j`).
    pub fn lower_surface_k(&self, i: f64, j: f64) -> f64 {
        self.mid_k(i, j) - self.gap_vox / 2.0
    }

    /// `k` of the plate's lower articular surface (contrast–bone) at column (`i`, `j`).
    pub fn upper_surface_k(&self, i: f64, j: f64) -> f64 {
        self.mid_k(i, j) + self.gap_vox / 2.0
    }

    /// `k` of the four articular surfaces at column (`i`, `j`), bottom to top: the first joint
    /// space's lower and upper surface, then the second's.
    pub fn surfaces_k(&self, i: f64, j: f64) -> [f64; 4] {
        let (lower, upper) = (self.lower_surface_k(i, j), self.upper_surface_k(i, j));
        let up = self.second_joint_offset_vox;
        [lower, upper, lower + up, upper + up]
    }

    /// The noiseless value at `p`. Distances to the surfaces are taken along `k` (exact on the
    /// axis, within 1 % where the bowl is steepest), and the contrast reaches a ramp's width
    /// under the bones so that the bone–contrast mid-value sits exactly on the surfaces.
    fn hu_at(&self, p: DVec3) -> f64 {
        let c = self.centre_vox;
        let outside_cylinder = (p.x - c.x).hypot(p.y - c.y) - self.radius_vox;
        let [a, b, c2, d] = self.surfaces_k(p.x, p.y);
        let r = RAMP_WIDTH_VOX;
        let gaps = ((a - r - p.z).max(p.z - b - r)).min((c2 - r - p.z).max(p.z - d - r));
        let mut hu = paint(TISSUE_HU, gaps.max(outside_cylinder), JOINT_CONTRAST_HU);
        hu = paint(hu, (p.z - a).max(outside_cylinder), BONE_HU);
        hu = paint(hu, (b - p.z).max(p.z - c2).max(outside_cylinder), BONE_HU);
        paint(hu, (d - p.z).max(outside_cylinder), BONE_HU)
    }
}

/// A `size³` volume of soft tissue holding three bones (radius 0.35 · size) that meet across
/// two contrast-filled gaps of 2.5 voxels, the first at the grid's centre, the second
/// 0.2 · size (at least 7.5 voxels) above it; their surfaces curve with a radius of
/// 1.5 · size.
pub fn joint(options: &PhantomOptions) -> (Volume, Joint) {
    let dims = options.cube();
    let size = options.size_vox();
    let gap_vox = 2.5;
    let truth = Joint {
        centre_vox: grid_centre(dims),
        radius_vox: 0.35 * size,
        curvature_radius_vox: 1.5 * size,
        gap_vox,
        // The plate between the gaps keeps at least one voxel of plain bone between its ramps.
        second_joint_offset_vox: (0.2 * size).max(gap_vox + 2.0 * RAMP_WIDTH_VOX + 1.0),
    };
    let volume = rasterize(dims, options, &|p| truth.hu_at(p));
    (volume, truth)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{iso_crossing, small};
    use super::*;

    #[test]
    fn contrast_layers_lie_between_the_bone_surfaces() {
        let (volume, joint) = joint(&small(64));
        let c = joint.centre_vox;
        let bone_contrast = 0.5 * (BONE_HU + JOINT_CONTRAST_HU);
        let mut worst: f64 = 0.0;
        for dj in -4..=4 {
            for di in -4..=4 {
                let i = (c.x + 5.0 * f64::from(di)).round();
                let j = (c.y + 5.0 * f64::from(dj)).round();
                if (i - c.x).hypot(j - c.y) > 0.8 * joint.radius_vox {
                    continue;
                }
                let [lower, upper, second_lower, second_upper] = joint.surfaces_k(i, j);
                let mid = 0.5 * (lower + upper);
                let at = |k: f64| volume.sample_physical(DVec3::new(i, j, k)).unwrap();
                // The layer's plateau is only half a voxel wide, so trilinear samples between
                // voxel centres mix in some bone; the voxels themselves hold the contrast.
                let nearest = volume.physical(i as usize, j as usize, mid.round() as usize);
                assert!(at(mid) < bone_contrast - 25.0, "{} HU mid-gap", at(mid));
                assert!(nearest.unwrap() < bone_contrast - 25.0);
                assert_eq!(at(lower - 2.0), BONE_HU);
                assert_eq!(at(upper + 2.0), BONE_HU);
                let column = DVec3::new(i, j, 0.0);
                let found_lower =
                    iso_crossing(&volume, column, DVec3::Z, (lower - 2.0, mid), bone_contrast);
                let found_upper =
                    iso_crossing(&volume, column, DVec3::Z, (mid, upper + 2.0), bone_contrast);
                let second_mid = 0.5 * (second_lower + second_upper);
                let found_second = [
                    iso_crossing(
                        &volume,
                        column,
                        DVec3::Z,
                        (upper + 2.0, second_mid),
                        bone_contrast,
                    ),
                    iso_crossing(
                        &volume,
                        column,
                        DVec3::Z,
                        (second_mid, second_upper + 2.0),
                        bone_contrast,
                    ),
                ];
                assert_eq!(at(second_upper + 2.0), BONE_HU);
                worst = worst
                    .max((found_lower - lower).abs())
                    .max((found_upper - upper).abs())
                    .max((found_second[0] - second_lower).abs())
                    .max((found_second[1] - second_upper).abs());
            }
        }
        assert!(worst < 0.02, "worst surface error {worst} voxel");
        // Beyond the bones' radius there is only soft tissue.
        let outside = DVec3::new(c.x + joint.radius_vox + 2.0, c.y, c.z);
        assert_eq!(volume.sample_physical(outside), Some(TISSUE_HU));
    }
}
