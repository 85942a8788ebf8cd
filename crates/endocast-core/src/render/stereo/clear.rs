//! The ball around an eye in which every sample lies on the eye's side of the isovalue, from
//! the voxels themselves: a trilinear sample is a convex combination of the eight corners of
//! its cell, all within a cell's diagonal (√3 voxels) of it, so where every voxel within
//! `r + √3` of the eye lies on one side, so does every sample within `r`.

use crate::Volume;
use glam::Vec3;

/// How far (voxels) around the eye the voxels are looked at.
const REACH: i32 = 16;

/// A cell's diagonal, voxels, and a hair more for the samples' `f32` positions.
const DIAGONAL: f32 = 1.733;

/// The radius (voxels) of a ball around `eye` (voxel space, inside the volume) in which every
/// trilinear sample of `volume` lies below `iso` (`below`), else at or above it: the distance
/// to the nearest voxel within [`REACH`] not clearly on that side, less a cell's diagonal;
/// 0 where there is no such ball.
pub(super) fn clear_radius(volume: &Volume, eye: Vec3, iso: f32, below: bool) -> f32 {
    let dims = volume.dims().map(|n| n as i32);
    let voxels = volume.voxels();
    let range = |axis: usize| {
        let lo = (eye[axis] - REACH as f32).ceil().max(0.0) as i32;
        let hi = (eye[axis] + REACH as f32)
            .floor()
            .min((dims[axis] - 1) as f32) as i32;
        lo..=hi
    };
    // The rounding of a trilinear value stays far inside this tolerance.
    let clearly_on_side = |v: f32| {
        let tolerance = 1e-4 * (1.0 + iso.abs() + v);
        if below {
            v < iso - tolerance
        } else {
            v >= iso + tolerance
        }
    };
    let mut nearest2 = (REACH * REACH) as f32;
    for k in range(2) {
        let dz = k as f32 - eye.z;
        for j in range(1) {
            let dy = j as f32 - eye.y;
            let row = (j + dims[1] * k) as usize * dims[0] as usize;
            for i in range(0) {
                let v = f32::from(voxels[row + i as usize]);
                if !clearly_on_side(v) {
                    let dx = i as f32 - eye.x;
                    nearest2 = nearest2.min(dx * dx + dy * dy + dz * dz);
                }
            }
        }
    }
    (nearest2.sqrt() - DIAGONAL).max(0.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};
    use crate::render::Sampler;
    use crate::test_rng::Rng;

    /// Every sample in the ball lies on the eye's side, and the ball reaches close to the
    /// nearest voxel on the other side.
    #[test]
    fn samples_in_the_clear_ball_lie_on_the_eyes_side() {
        let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
            size: 48,
            ..Default::default()
        });
        let sampler = Sampler::new(&volume);
        // The air/tissue mid-value lies on the shell's wall.
        let iso = volume.value_map().stored_from_physical(-480.0) as f32;
        let centre = shell.centre_vox.as_vec3();
        let mut rng = Rng::new(7);
        for eye in [centre, centre + Vec3::new(3.3, -2.1, 1.7)] {
            let below = sampler.value(eye) < iso;
            let r = clear_radius(&volume, eye, iso, below);
            assert!(r > 2.0, "radius {r}");
            for _ in 0..20_000 {
                let u = rng.vec().as_vec3();
                if u.length() <= 1.0 {
                    let p = eye + u * r;
                    assert_eq!(sampler.value(p) < iso, below, "at {p}");
                }
            }
            // A little past the ball (a cell's diagonal and a voxel) the other side shows.
            let reach = r + DIAGONAL + 1.0;
            let crossed = (0..20_000).any(|_| {
                let u = rng.vec().as_vec3().normalize_or_zero();
                (sampler.value(eye + u * reach) < iso) != below
            });
            assert!(crossed || r >= REACH as f32 - DIAGONAL, "radius {r}");
        }
    }
}
