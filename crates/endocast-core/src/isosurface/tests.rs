//! Tests of the isosurface: watertight, outward, on the isovalue, lean, thread-independent.

use super::*;
use crate::phantom::{self, PhantomOptions};

#[test]
fn the_sphere_phantom_gives_a_closed_surface_on_the_isovalue() {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 32,
        ..Default::default()
    });
    let c = shell.centre_vox.round();
    let seed = [c.x as usize, c.y as usize, c.z as usize];
    let lumen = Lumen::from_seed(&volume, seed, -480.0, LumenSide::Below).unwrap();
    let mesh = lumen_surface(&volume, &lumen).unwrap();
    assert_eq!(mesh.open_edges(), 0);
    let g = volume.geometry();
    for v in mesh.vertices() {
        let p = g.voxel_from_world().transform_point3(*v);
        let value = volume.sample_physical(p).unwrap();
        // The wall's ramp is about 1000 HU per voxel: 0.1 voxel is 100 HU.
        assert!((value + 480.0).abs() < 5.0, "{value} at {p}");
        let r = p.distance(shell.centre_vox);
        assert!((r - shell.inner_radius_vox).abs() < 0.1, "{r}");
    }
    // Facing out of the lumen: the signed volume is positive.
    let volume_mm3: f64 = (0..mesh.triangles().len())
        .map(|i| {
            let [a, b, c] = mesh.corners(i);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    let sphere = 4.0 / 3.0 * std::f64::consts::PI * shell.inner_radius_vox.powi(3);
    assert!(
        (volume_mm3 / sphere - 1.0).abs() < 0.02,
        "{volume_mm3} vs {sphere}"
    );
}

/// The isovalue of [`field_volume`]: stored values are 10 000 + 1000 · d.
const ISO: f64 = 10_000.0;

/// An `n³` volume (1 mm voxels) whose value at voxel `p` is `ISO + 1000 · d(p)`, rounded.
fn field_volume(n: usize, d: impl FnMut(DVec3) -> f64) -> Volume {
    field_box([n; 3], d)
}

/// A volume of `dims` voxels (1 mm) whose value at voxel `p` is `ISO + 1000 · d(p)`, rounded.
fn field_box(dims: [usize; 3], mut d: impl FnMut(DVec3) -> f64) -> Volume {
    let [nx, ny, nz] = dims;
    let voxels = (0..nx * ny * nz)
        .map(|m| {
            let p = DVec3::new(
                (m % nx) as f64,
                (m / nx % ny) as f64,
                (m / (nx * ny)) as f64,
            );
            (ISO + 1000.0 * d(p)).round().clamp(0.0, 65_535.0) as u16
        })
        .collect();
    let geometry = crate::Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
    Volume::new(
        geometry,
        voxels,
        crate::ValueMap::IDENTITY,
        crate::Modality::Unknown,
    )
    .unwrap()
}

/// The volume the mesh encloses (positive when its triangles face out).
fn signed_volume(mesh: &TriangleMesh) -> f64 {
    (0..mesh.triangles().len())
        .map(|i| {
            let [a, b, c] = mesh.corners(i);
            a.dot(b.cross(c)) / 6.0
        })
        .sum()
}

/// The smallest triangle area.
fn smallest_area(mesh: &TriangleMesh) -> f64 {
    (0..mesh.triangles().len())
        .map(|i| {
            let [a, b, c] = mesh.corners(i);
            (b - a).cross(c - a).length() / 2.0
        })
        .fold(f64::INFINITY, f64::min)
}

/// Asserts a closed, consistently oriented surface: every edge in exactly two triangles, once
/// in each direction.
fn assert_watertight(mesh: &TriangleMesh) {
    assert_eq!(mesh.open_edges(), 0);
    let mut directed: Vec<(u32, u32)> = mesh
        .triangles()
        .iter()
        .flat_map(|&[a, b, c]| [(a, b), (b, c), (c, a)])
        .collect();
    directed.sort_unstable();
    assert!(
        directed.windows(2).all(|w| w[0] != w[1]),
        "an edge twice in one direction"
    );
}

#[test]
fn a_distance_sphere_is_closed_outward_on_its_radius_and_lean() {
    let (centre, r) = (DVec3::new(12.3, 11.8, 12.1), 9.0);
    let volume = field_volume(25, |p| r - p.distance(centre));
    let mesh = isosurface(&volume, ISO, LumenSide::Above).unwrap();
    assert_watertight(&mesh);
    for v in mesh.vertices() {
        assert!((v.distance(centre) - r).abs() < 0.03, "{v}");
    }
    let ball = 4.0 / 3.0 * std::f64::consts::PI * r.powi(3);
    assert!((signed_volume(&mesh) / ball - 1.0).abs() < 0.01);
    // A closed surface of genus 0 (Euler): T = 2V − 4, V being the crossed grid edges, about
    // 4πr² · 1.5 (the mean of |nx| + |ny| + |nz| over a sphere).
    let (t, v) = (mesh.triangles().len(), mesh.vertices().len());
    assert_eq!(t, 2 * v - 4);
    assert!(
        (t as f64) < 1.2 * 12.0 * std::f64::consts::PI * r * r,
        "{t} triangles"
    );
    // The lumen around the centre is the whole inside: the same mesh from its bounding box.
    let seed = centre.round().to_array().map(|c| c as usize);
    let lumen = Lumen::from_seed(&volume, seed, ISO, LumenSide::Above).unwrap();
    assert_eq!(lumen_surface(&volume, &lumen).unwrap(), mesh);
}

#[test]
fn a_torus_is_closed_outward_on_its_surface_and_of_genus_one() {
    let (centre, big, small) = (DVec3::new(15.4, 15.2, 8.3), 9.0, 3.5);
    let torus = |p: DVec3| {
        let q = p - centre;
        small - (q.x.hypot(q.y) - big).hypot(q.z)
    };
    let volume = field_volume(31, torus);
    let mesh = isosurface(&volume, ISO, LumenSide::Above).unwrap();
    assert_watertight(&mesh);
    for v in mesh.vertices() {
        assert!(torus(*v).abs() < 0.06, "{v}");
    }
    let solid = 2.0 * std::f64::consts::PI.powi(2) * big * small * small;
    let ratio = signed_volume(&mesh) / solid;
    assert!((ratio - 1.0).abs() < 0.03, "{ratio}");
    assert_eq!(mesh.triangles().len(), 2 * mesh.vertices().len());
}

#[test]
fn random_fields_give_closed_outward_surfaces_without_zero_area_triangles() {
    let mut rng = crate::test_rng::Rng::new(33);
    for values in [
        [-900.0, -300.0, 200.0, 700.0],
        [-1000.0, 0.0, 1000.0, 1000.0],
    ] {
        for _ in 0..4 {
            // Random voxels inside a border of outside ones (values below the isovalue).
            let volume = field_volume(10, |p| {
                let border = p.min_element() == 0.0 || p.max_element() == 9.0;
                let pick = values[(rng.unit() * 4.0) as usize] / 1000.0;
                if border {
                    -1.0
                } else {
                    pick
                }
            });
            let Ok(mesh) = isosurface(&volume, ISO, LumenSide::Above) else {
                continue;
            };
            assert_watertight(&mesh);
            assert!(smallest_area(&mesh) > 1e-7, "{}", smallest_area(&mesh));
            assert!(signed_volume(&mesh) > 0.0);
        }
    }
}

#[test]
fn rows_longer_than_a_word_and_several_slabs_give_a_vertex_a_crossed_edge_and_the_cases_triangles()
{
    // Rows of 131 voxels (three words, crossings at the words' seams) and 21 planes (slabs of
    // 8 planes of cubes, the last one short), random voxels inside a border of outside ones.
    let dims = [131, 6, 21];
    let mut rng = crate::test_rng::Rng::new(7);
    let volume = field_box(dims, |p| {
        let border = p.min_element() == 0.0 || p.x == 130.0 || p.y == 5.0 || p.z == 20.0;
        if border || rng.unit() < 0.5 {
            -0.5
        } else {
            0.5
        }
    });
    let inside = |v: [usize; 3]| volume.voxels()[v[0] + 131 * (v[1] + 6 * v[2])] > ISO as u16;
    let (mut edges, mut triangles) = (0, 0);
    for (i, j, k) in
        (0..131).flat_map(|i| (0..6).flat_map(move |j| (0..21).map(move |k| (i, j, k))))
    {
        for axis in 0..3 {
            let mut u = [i, j, k];
            u[axis] += 1;
            edges += usize::from(u[axis] < dims[axis] && inside([i, j, k]) != inside(u));
        }
        if i + 1 < 131 && j + 1 < 6 && k + 1 < 21 {
            let case = (0..8).fold(0u8, |case, c| {
                let corner = [i + (c & 1), j + (c >> 1 & 1), k + (c >> 2)];
                case | u8::from(inside(corner)) << c
            });
            triangles += usize::from(cases::CASES[usize::from(case)].count);
        }
    }
    let mesh = isosurface(&volume, ISO, LumenSide::Above).unwrap();
    assert_eq!(mesh.vertices().len(), edges);
    assert_eq!(mesh.triangles().len(), triangles);
    assert_watertight(&mesh);
    assert!(signed_volume(&mesh) > 0.0);
}

#[test]
fn voxels_equal_to_the_isovalue_give_no_zero_area_triangles() {
    // A plane of voxels exactly at the isovalue between inside (above) and outside (below),
    // with a dent: one voxel of the plane pushed a voxel into the inside, so that several of
    // its edges end on the same isovalue voxel.
    let volume = field_volume(8, |p| {
        if p == DVec3::new(4.0, 4.0, 4.0) {
            0.0
        } else {
            (p.z - 3.0).clamp(-1.0, 1.0)
        }
    });
    let mesh = isosurface(&volume, ISO, LumenSide::Above).unwrap();
    assert!(smallest_area(&mesh) > 1e-7, "{}", smallest_area(&mesh));
    // Each crossed edge keeps its own vertex, a thousandth of a voxel off the isovalue voxel.
    let dent = DVec3::new(4.0, 4.0, 4.0);
    for v in mesh.vertices() {
        assert!(
            (v.z - 3.001).abs() < 1e-9 || (v.distance(dent) - 0.001).abs() < 1e-9,
            "{v}"
        );
    }
    assert_eq!(mesh.vertices().len(), 63 + 5);
}

#[test]
fn the_mesh_does_not_depend_on_the_thread_count() {
    let volume = phantom::Phantom::Colon.build(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    let mesh_on = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| isosurface(&volume, -500.0, LumenSide::Below).unwrap())
    };
    assert_eq!(mesh_on(1), mesh_on(3));
}

#[test]
fn a_label_one_voxel_thin_keeps_a_closed_surface_around_its_voxels_and_a_block_its_volume() {
    let geometry = crate::Geometry::axis_aligned([12, 12, 12], DVec3::ONE, DVec3::ZERO).unwrap();
    let mut voxels = vec![0u16; 12 * 12 * 12];
    let at = |i: usize, j: usize, k: usize| i + 12 * (j + 12 * k);
    // Label 1: a line one voxel thin along k; label 2: a 4 × 4 × 4 block.
    for k in 2..9 {
        voxels[at(3, 3, k)] = 1;
    }
    for (i, j, k) in
        (6..10).flat_map(|i| (6..10).flat_map(move |j| (6..10).map(move |k| (i, j, k))))
    {
        voxels[at(i, j, k)] = 2;
    }
    let map = crate::ValueMap::IDENTITY;
    let volume = Volume::new(geometry, voxels, map, crate::Modality::Unknown).unwrap();
    let signed_volume = |mesh: &TriangleMesh| -> f64 {
        (0..mesh.triangles().len())
            .map(|i| {
                let [a, b, c] = mesh.corners(i);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    };
    let line = label_surface(&volume, 1).unwrap();
    assert_eq!(line.open_edges(), 0);
    for v in line.vertices() {
        let off_axis = (v.x - 3.0).hypot(v.y - 3.0);
        assert!(off_axis < 0.6, "{v}");
    }
    assert!(signed_volume(&line) > 0.5, "{}", signed_volume(&line));
    let block = label_surface(&volume, 2).unwrap();
    assert_eq!(block.open_edges(), 0);
    // Rounded at its edges and corners by the blur: a little under its 64 voxels.
    let v = signed_volume(&block);
    assert!((0.8..1.05).contains(&(v / 64.0)), "{v} against 64");
}
