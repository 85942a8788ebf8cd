//! Camera poses in the patient frame, and fly-throughs along a centreline.

use crate::Geometry;
use glam::DVec3;

/// Where a camera is and where it looks, in world millimetres (LPS).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// Eye position, mm.
    pub eye_mm: DVec3,
    /// Point looked at, mm.
    pub look_at_mm: DVec3,
    /// Up direction (unit, perpendicular to the view direction).
    pub up: DVec3,
}

/// `frames` poses evenly spaced in arc length along the curve `point_vox(s)` (voxel indices,
/// `s` in mm of arc from 0 to `length_mm`), from `ahead_mm` after its start to `2·ahead_mm`
/// before its end, each looking at the curve point `ahead_mm` further on. The up vector is
/// carried along the curve in 0.5 mm steps by projecting it onto the plane normal to the new view
/// direction (a discrete rotation-minimising frame): it never spins about the view axis needlessly
/// and never becomes parallel to the view. `None` when the curve is too short or `frames < 2`.
pub fn fly_through(
    geometry: &Geometry,
    point_vox: impl Fn(f64) -> DVec3,
    length_mm: f64,
    frames: usize,
    ahead_mm: f64,
) -> Option<Vec<Pose>> {
    let (first, last) = (ahead_mm, length_mm - 2.0 * ahead_mm);
    // Written so that NaN lengths fail too.
    let usable = ahead_mm > 0.0 && last > first;
    if frames < 2 || !usable {
        return None;
    }
    let world = |s: f64| geometry.world_of(point_vox(s));
    let view = |s: f64| (world(s + ahead_mm) - world(s)).normalize_or_zero();
    let d0 = view(first);
    // Start from the world axis least aligned with the first view direction, made orthogonal.
    let seed = [DVec3::X, DVec3::Y, DVec3::Z]
        .into_iter()
        .min_by(|a, b| a.dot(d0).abs().total_cmp(&b.dot(d0).abs()))
        .unwrap_or(DVec3::Z);
    let mut up = (seed - d0 * seed.dot(d0)).normalize();
    let step = (last - first) / (frames - 1) as f64;
    let mut s = first;
    let mut poses = Vec::with_capacity(frames);
    for n in 0..frames {
        let target = first + step * n as f64;
        while s < target {
            s = (s + 0.5).min(target);
            let d = view(s);
            up = (up - d * up.dot(d)).try_normalize().unwrap_or(up);
        }
        poses.push(Pose {
            eye_mm: world(target),
            look_at_mm: world(target + ahead_mm),
            up,
        });
    }
    Some(poses)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phantom::{self, PhantomOptions};

    #[test]
    fn poses_follow_the_colon_without_twisting() {
        let (volume, colon) = phantom::colon(&PhantomOptions {
            size: 96,
            ..Default::default()
        });
        let line = &colon.centreline;
        let g = volume.geometry();
        let poses = fly_through(g, |s| line.point_at(s), line.length_vox(), 40, 5.0).unwrap();
        assert_eq!(poses.len(), 40);
        for pair in poses.windows(2) {
            let forward = (pair[0].look_at_mm - pair[0].eye_mm).normalize();
            assert!(pair[0].up.dot(forward).abs() < 1e-6);
            assert!((pair[0].up.length() - 1.0).abs() < 1e-9);
            // Consecutive up vectors turn by less than 30° on this tightly sampled path.
            assert!(pair[0].up.dot(pair[1].up) > 0.86, "{:?}", pair);
        }
        // Every eye is in the air of the lumen.
        let to_vox = g.voxel_from_world();
        for p in &poses {
            let v = volume
                .sample_physical(to_vox.transform_point3(p.eye_mm))
                .unwrap();
            assert!(v < -500.0, "eye in tissue: {v}");
        }
        assert!(fly_through(g, |s| line.point_at(s), 10.0, 40, 5.0).is_none());
        assert!(fly_through(g, |s| line.point_at(s), line.length_vox(), 1, 5.0).is_none());
    }
}
