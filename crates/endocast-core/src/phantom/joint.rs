//! The joint: two bone surfaces around a thin layer of bright contrast (an arthrogram), for
//! two-isosurface rendering where the two materials differ by only 100 HU.

use super::profile::{paint, BONE_HU, JOINT_CONTRAST_HU, RAMP_WIDTH_VOX, TISSUE_HU};
use super::raster::{grid_centre, rasterize};
use super::PhantomOptions;
use crate::Volume;
use glam::DVec3;

/// Truth of the joint phantom. Both articular surfaces are the same paraboloid bowl
/// `k = centre.z + ((i − centre.x)² + (j − centre.y)²) / (2 · curvature radius)` shifted down
/// and up by half the gap; the bones fill everything below and above them within a cylinder of
/// [`Joint::radius_vox`] around `k`, the contrast fills the gap, soft tissue the rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Joint {
    /// Centre of the joint space, voxel index (the grid's centre).
    pub centre_vox: DVec3,
    /// Radius of the bones and of the joint space around the `k` axis, voxels.
    pub radius_vox: f64,
    /// Radius of curvature of the articular surfaces at the axis, voxels.
    pub curvature_radius_vox: f64,
    /// Thickness of the contrast layer along `k`, voxels.
    pub gap_vox: f64,
}

impl Joint {
    /// The bowl both surfaces follow, at column (`i`, `j`).
    fn mid_k(&self, i: f64, j: f64) -> f64 {
        let c = self.centre_vox;
        c.z + ((i - c.x).powi(2) + (j - c.y).powi(2)) / (2.0 * self.curvature_radius_vox)
    }

    /// `k` of the lower bone's articular surface (bone–contrast) at column (`i`, `j`).
    pub fn lower_surface_k(&self, i: f64, j: f64) -> f64 {
        self.mid_k(i, j) - self.gap_vox / 2.0
    }

    /// `k` of the upper bone's articular surface (contrast–bone) at column (`i`, `j`).
    pub fn upper_surface_k(&self, i: f64, j: f64) -> f64 {
        self.mid_k(i, j) + self.gap_vox / 2.0
    }

    /// The noiseless value at `p`. Distances to the surfaces are taken along `k` (exact on the
    /// axis, within 1 % where the bowl is steepest), and the contrast reaches a ramp's width
    /// under the bones so that the bone–contrast mid-value sits exactly on the surfaces.
    fn hu_at(&self, p: DVec3) -> f64 {
        let c = self.centre_vox;
        let outside_cylinder = (p.x - c.x).hypot(p.y - c.y) - self.radius_vox;
        let (lower, upper) = (
            self.lower_surface_k(p.x, p.y),
            self.upper_surface_k(p.x, p.y),
        );
        let gap = (lower - RAMP_WIDTH_VOX - p.z).max(p.z - upper - RAMP_WIDTH_VOX);
        let mut hu = paint(TISSUE_HU, gap.max(outside_cylinder), JOINT_CONTRAST_HU);
        hu = paint(hu, (p.z - lower).max(outside_cylinder), BONE_HU);
        paint(hu, (upper - p.z).max(outside_cylinder), BONE_HU)
    }
}

/// A `size³` volume of soft tissue holding two bones (radius 0.35 · size) that meet at the
/// grid's centre across a contrast-filled gap of 2.5 voxels whose surfaces curve with a radius
/// of 1.5 · size.
pub fn joint(options: &PhantomOptions) -> (Volume, Joint) {
    let dims = options.cube();
    let size = options.size_vox();
    let truth = Joint {
        centre_vox: grid_centre(dims),
        radius_vox: 0.35 * size,
        curvature_radius_vox: 1.5 * size,
        gap_vox: 2.5,
    };
    let volume = rasterize(dims, options, &|p| truth.hu_at(p));
    (volume, truth)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{iso_crossing, small};
    use super::*;

    #[test]
    fn contrast_layer_lies_between_the_bone_surfaces() {
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
                let (lower, upper) = (joint.lower_surface_k(i, j), joint.upper_surface_k(i, j));
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
                worst = worst
                    .max((found_lower - lower).abs())
                    .max((found_upper - upper).abs());
            }
        }
        assert!(worst < 0.02, "worst surface error {worst} voxel");
        // Beyond the bones' radius there is only soft tissue.
        let outside = DVec3::new(c.x + joint.radius_vox + 2.0, c.y, c.z);
        assert_eq!(volume.sample_physical(outside), Some(TISSUE_HU));
    }
}
