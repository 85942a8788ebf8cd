use super::*;
use crate::Geometry;
use glam::DMat3;
use std::f64::consts::PI;

/// A grid of `dims` voxels of `spacing` mm, origin at 0.
fn grid(dims: [usize; 3], spacing: [f64; 3]) -> Geometry {
    Geometry::new(dims, DVec3::from(spacing), DVec3::ZERO, DMat3::IDENTITY).unwrap()
}

/// The wall of the lumen `is_lumen` over the whole grid, none of it seen.
fn unseen_wall(geometry: &Geometry, is_lumen: impl Fn(DVec3) -> bool + Sync) -> Coverage {
    let lumen = |v: [i64; 3]| {
        v.iter().all(|&x| x >= 0) && is_lumen(geometry.world_of(DVec3::from(v.map(|x| x as f64))))
    };
    let is_wall = |v: [usize; 3]| {
        let v = v.map(|x| x as i64);
        !lumen(v)
            && (0..3).any(|a| {
                [-1, 1].iter().any(|s| {
                    let mut w = v;
                    w[a] += s;
                    lumen(w)
                })
            })
    };
    Coverage::new(geometry, is_wall, &geometry.dims().map(|n| 0..n)).unwrap()
}

/// The lumen predicate on grid voxels of a world-space test.
fn on_grid(geometry: &Geometry, is_lumen: impl Fn(DVec3) -> bool) -> impl Fn([usize; 3]) -> bool {
    let geometry = *geometry;
    move |v| is_lumen(geometry.world_of(DVec3::from(v.map(|x| x as f64))))
}

#[test]
fn a_sphere_never_seen_is_one_patch_of_its_area_with_its_centroid_on_the_wall() {
    let geometry = grid([40, 40, 40], [1.0; 3]);
    let (centre, radius) = (DVec3::splat(19.3), 11.7);
    let ball = move |p: DVec3| p.distance(centre) <= radius;
    let coverage = unseen_wall(&geometry, ball);
    let patches = coverage.unseen_patches(on_grid(&geometry, ball), f64::INFINITY);
    assert_eq!(patches.len(), 1);
    let patch = &patches[0];
    assert_eq!(patch.voxels.len(), coverage.total());
    let exact = 4.0 * PI * radius * radius;
    let error = patch.area_mm2 / exact - 1.0;
    assert!(error.abs() < 0.05, "area {} vs {exact}", patch.area_mm2);
    // The face count alone overestimates a sphere by about half.
    let faces: f64 = patch
        .voxels
        .iter()
        .map(|v| lumen_faces(*v, &ball, &geometry))
        .sum();
    assert!(faces > 1.3 * exact, "faces {faces} vs {exact}");
    // A sphere's voxels average to its centre: the centroid is the wall voxel nearest it.
    let off_wall = patch.centroid_mm.distance(centre) - radius;
    assert!((0.0..1.5).contains(&off_wall), "{off_wall}");
    // The normal points from the wall into the lumen, towards the centre.
    let inward = (centre - patch.centroid_mm).normalize();
    assert!(patch.normal.dot(inward) > 0.95, "{:?}", patch.normal);
}

/// Lumen-facing faces of a voxel, in voxels (unit spacing).
fn lumen_faces(v: [usize; 3], ball: &impl Fn(DVec3) -> bool, geometry: &Geometry) -> f64 {
    let mut n = 0.0;
    for a in 0..3 {
        for s in [-1.0, 1.0] {
            let mut w = DVec3::from(v.map(|x| x as f64));
            w[a] += s;
            if ball(geometry.world_of(w)) {
                n += 1.0;
            }
        }
    }
    n
}

#[test]
fn a_closed_tube_on_anisotropic_voxels_has_its_analytic_area() {
    // A cylinder along z, radius 9.3 mm, 30 mm long, with flat ends, on 0.8 × 0.8 × 1.5 mm.
    let geometry = grid([34, 34, 30], [0.8, 0.8, 1.5]);
    let (radius, z0, z1) = (9.3, 7.0, 37.0);
    let axis = DVec3::new(13.3, 13.5, 0.0);
    let tube = move |p: DVec3| {
        let r = (p - axis).truncate().length();
        r <= radius && (z0..=z1).contains(&p.z)
    };
    let coverage = unseen_wall(&geometry, tube);
    let patches = coverage.unseen_patches(on_grid(&geometry, tube), f64::INFINITY);
    assert_eq!(patches.len(), 1);
    let exact = 2.0 * PI * radius * (z1 - z0) + 2.0 * PI * radius * radius;
    let error = patches[0].area_mm2 / exact - 1.0;
    assert!(error.abs() < 0.1, "area {} vs {exact}", patches[0].area_mm2);
}

#[test]
fn seen_wall_splits_the_rest_into_patches_largest_first() {
    let geometry = grid([40, 24, 24], [1.0; 3]);
    // Two balls: the larger one's wall is unseen; of the smaller one's, only a cap is seen.
    let (a, b) = (DVec3::new(10.0, 11.5, 11.5), DVec3::new(30.0, 11.5, 11.5));
    let balls = move |p: DVec3| p.distance(a) <= 7.5 || p.distance(b) <= 5.5;
    let mut coverage = unseen_wall(&geometry, balls);
    // Mark the small ball's wall with x beyond its centre + 3.
    for k in 0..24 {
        for j in 0..24 {
            for i in 34..40 {
                if coverage.state([i, j, k]) == Some(false) {
                    coverage.mark_point(DVec3::new(i as f64, j as f64, k as f64));
                }
            }
        }
    }
    let patches = coverage.unseen_patches(on_grid(&geometry, balls), f64::INFINITY);
    assert_eq!(patches.len(), 2);
    assert!(patches[0].area_mm2 > patches[1].area_mm2);
    assert!(patches[0].centroid_mm.distance(a) < 9.0);
    assert!(patches[1].centroid_mm.distance(b) < 7.0);
    assert_eq!(patches[1].seen_in(&coverage), 0);
    let unseen: usize = patches.iter().map(|p| p.voxels.len()).sum();
    assert_eq!(unseen, coverage.total() - coverage.seen_count());
    // Pieces of at most 4 mm from their first voxel split the same wall into more patches.
    let pieces = coverage.unseen_patches(on_grid(&geometry, balls), 4.0);
    assert!(pieces.len() > 4, "{}", pieces.len());
    let voxels: usize = pieces.iter().map(|p| p.voxels.len()).sum();
    assert_eq!(voxels, unseen);
    let area: f64 = pieces.iter().map(|p| p.area_mm2).sum();
    let whole: f64 = patches.iter().map(|p| p.area_mm2).sum();
    assert!((area - whole).abs() < 1e-6 * whole);
}
