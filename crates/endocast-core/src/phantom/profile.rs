//! Tissue values and the ramp that puts every isosurface exactly on its analytic surface.
//!
//! Every boundary is a linear ramp in signed distance `d` (negative inside, voxels):
//! `value = lerp(inside, outside, clamp(d / RAMP_WIDTH_VOX + 0.5, 0, 1))`. The value halfway
//! between the two materials is therefore crossed exactly at `d = 0`, and because the ramp is
//! linear (and wider than a voxel), trilinear interpolation reproduces that crossing to a small
//! fraction of a voxel. A hard step would put the isosurface anywhere within half a voxel.

/// Air (and gas in a bowel lumen), in HU.
pub const AIR_HU: f64 = -1000.0;
/// Perivascular fat around the vessel phantom, in HU (so that the vessel wall stands out).
pub const FAT_HU: f64 = -100.0;
/// Soft tissue (bowel wall, muscle, vessel wall, mucosa), in HU.
pub const TISSUE_HU: f64 = 40.0;
/// Iodinated contrast in a vessel lumen, in HU.
pub const LUMEN_CONTRAST_HU: f64 = 300.0;
/// Intra-articular contrast in the joint space, in HU (close to bone on purpose: the hard case).
pub const JOINT_CONTRAST_HU: f64 = 600.0;
/// Bone, in HU.
pub const BONE_HU: f64 = 700.0;
/// Calcified plaque, in HU.
pub const CALCIFICATION_HU: f64 = 1000.0;
/// Metal stent struts, in HU (stored exactly: the value map reaches up to +64 511 HU).
pub const STENT_HU: f64 = 2500.0;

/// Width of every boundary ramp, in voxels. Two voxels keep the 8 samples around a surface
/// point mostly on the linear part of the ramp, so the trilinear isosurface error stays far
/// below 0.02 voxel, while septa and struts of one or two voxels still reach most of their value.
pub const RAMP_WIDTH_VOX: f64 = 2.0;

/// How far beyond its surface a shape still changes the value, in voxels.
pub(crate) const REACH_VOX: f64 = RAMP_WIDTH_VOX / 2.0;

/// The value at signed distance `d_vox` (negative inside) from a boundary between `inside` and
/// `outside`; see the module doc.
#[inline]
pub(crate) fn ramp(d_vox: f64, inside: f64, outside: f64) -> f64 {
    let t = (d_vox / RAMP_WIDTH_VOX + 0.5).clamp(0.0, 1.0);
    inside + (outside - inside) * t
}

/// Paints a shape of value `inside` (signed distance `d_vox`) over what lies beneath. Where the
/// shape's ramp meets saturated material beneath, the mid-value between the two is crossed exactly
/// on the shape's surface; so material meant to lie against a shape painted later extends beneath
/// it by [`RAMP_WIDTH_VOX`], which keeps the two ramps apart.
#[inline]
pub(crate) fn paint(beneath: f64, d_vox: f64, inside: f64) -> f64 {
    ramp(d_vox, inside, beneath)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ramp_is_linear_and_crosses_the_mid_value_at_zero() {
        assert_eq!(ramp(0.0, AIR_HU, TISSUE_HU), -480.0);
        assert_eq!(ramp(-5.0, AIR_HU, TISSUE_HU), AIR_HU);
        assert_eq!(ramp(REACH_VOX, AIR_HU, TISSUE_HU), TISSUE_HU);
        let quarter = ramp(-0.5, AIR_HU, TISSUE_HU);
        assert!((quarter - (AIR_HU + 0.25 * (TISSUE_HU - AIR_HU))).abs() < 1e-12);
        assert_eq!(paint(TISSUE_HU, 10.0, BONE_HU), TISSUE_HU);
    }
}
