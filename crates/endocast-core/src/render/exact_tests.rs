//! The exact isosurface search (`cell_mask`, `cell_walk`, `trilinear_root`) against an
//! independent reference: the first crossing of the trilinear field along each pixel's ray,
//! found by dense stepping and bisection in `f64`.

use super::cell_mask::{is_set, CellMask};
use super::tests::{assert_same_image, colon_view};
use super::*;
use crate::phantom::{self, PhantomOptions};
use crate::{Geometry, Modality, ValueMap};
use glam::DVec3;
use std::sync::Arc;

/// The trilinear field of `volume` at voxel position `p` in `f64` (positions clamped to the
/// voxels' hull, as the sampler clamps them).
fn field(volume: &Volume, p: DVec3) -> f64 {
    let dims = volume.dims();
    let value =
        |i: usize, j: usize, k: usize| f64::from(volume.voxels()[i + dims[0] * (j + dims[1] * k)]);
    let mut base = [0usize; 3];
    let mut frac = [0.0f64; 3];
    for axis in 0..3 {
        let last = (dims[axis] - 1) as f64;
        let x = p[axis].clamp(0.0, last);
        base[axis] = (x.floor() as usize).min(dims[axis].saturating_sub(2));
        frac[axis] = x - base[axis] as f64;
    }
    let next = |axis: usize| (base[axis] + 1).min(dims[axis] - 1);
    let mut sum = 0.0;
    for corner in 0..8 {
        let pick = |axis: usize| corner >> axis & 1 == 1;
        let at = |axis: usize| if pick(axis) { next(axis) } else { base[axis] };
        let weight = (0..3)
            .map(|axis| {
                if pick(axis) {
                    frac[axis]
                } else {
                    1.0 - frac[axis]
                }
            })
            .product::<f64>();
        sum += weight * value(at(0), at(1), at(2));
    }
    sum
}

/// The first rising crossing of `iso` along the voxel-space ray `origin + t direction` over
/// `(t0, t1)`: steps of 0.005 mm to the first bracket, then bisection to 1e-10 mm.
fn reference_crossing(
    volume: &Volume,
    ray: &VoxelRay,
    (t0, t1): (f64, f64),
    iso: f64,
) -> Option<f64> {
    let f = |t: f64| field(volume, ray.at(t)) - iso;
    let step = 0.005;
    let mut a = t0;
    while a < t1 {
        let b = (a + step).min(t1);
        if f(a) < 0.0 && f(b) >= 0.0 {
            let (mut lo, mut hi) = (a, b);
            while hi - lo > 1e-10 {
                let mid = 0.5 * (lo + hi);
                if f(mid) >= 0.0 {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
            return Some(hi);
        }
        a = b;
    }
    None
}

/// Renders an iso frame of `volume` at `iso_hu` from voxel position `eye_vox` looking along
/// `forward` and checks every pixel's depth against [`reference_crossing`] to 1e-3 voxel (1 mm
/// voxels); returns the number of pixels that hit.
fn check_depths(
    volume: Volume,
    iso_hu: f64,
    eye_vox: DVec3,
    forward: DVec3,
    step_vox: f64,
) -> usize {
    let size = 12;
    let eye = volume.geometry().world_of(eye_vox);
    let camera = Camera::look_at(
        eye,
        eye + forward,
        forward.any_orthonormal_vector(),
        100.0,
        [size, size],
    )
    .unwrap();
    let renderer = Arc::new(Renderer::new(volume));
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu,
        step_vox,
        exact_hits: true,
        ..Default::default()
    };
    let frame = renderer.prepare(&settings).unwrap().render(&camera);
    let volume = renderer.volume();
    let extent = DVec3::from(volume.dims().map(|n| (n - 1) as f64));
    let voxel_from_world = volume.geometry().voxel_from_world();
    let stored = volume.value_map().stored_from_physical(iso_hu);
    let mut hits = 0;
    for y in 0..size {
        for x in 0..size {
            let world = camera.pixel_ray(x, y).unwrap();
            let ray = VoxelRay::new(&voxel_from_world, world.origin, world.dir);
            let range = ray
                .clip(extent, camera.near_distance_along(world.dir))
                .unwrap();
            let expected = reference_crossing(volume, &ray, range, stored);
            let depth = frame.depth_mm[x + size * y];
            match expected {
                Some(t) => {
                    let error = (f64::from(depth) - t).abs();
                    assert!(error < 1e-3, "({x}, {y}): depth {depth}, exact {t}");
                    hits += 1;
                }
                None => assert!(depth.is_nan(), "({x}, {y}): depth {depth}, no crossing"),
            }
        }
    }
    hits
}

#[test]
fn depths_are_the_trilinear_crossings_on_the_noisy_sphere_shell() {
    let options = PhantomOptions {
        size: 24,
        noise_hu: 40.0,
        ..Default::default()
    };
    let (volume, shell) = phantom::sphere_shell(&options);
    let eye = shell.centre_vox + DVec3::new(1.5, -2.0, 0.7);
    let forward = DVec3::new(0.3, 0.2, 1.0).normalize();
    // The noise's own crossings in the air are the trilinear field's too.
    assert!(check_depths(volume, -480.0, eye, forward, 0.5) > 100);
}

#[test]
fn depths_are_the_trilinear_crossings_in_the_curved_tube_at_any_step() {
    let options = PhantomOptions {
        size: 24,
        ..Default::default()
    };
    let (volume, tube) = phantom::curved_tube(&options);
    let eye = tube.axis_point(0.3);
    let forward = (tube.axis_point(0.5) - eye).normalize();
    for step_vox in [0.5, 4.0] {
        assert!(check_depths(volume.clone(), -480.0, eye, forward, step_vox) > 100);
    }
}

/// A 16³ volume of zeros with a one-voxel sheet of `1000` at `k = 8`.
fn sheet() -> Volume {
    let dims = [16, 16, 16];
    let g = Geometry::axis_aligned(dims, DVec3::ONE, DVec3::ZERO).unwrap();
    let voxels = (0..16 * 16 * 16)
        .map(|n| if n / 256 == 8 { 1000 } else { 0 })
        .collect();
    Volume::new(g, voxels, ValueMap::IDENTITY, Modality::Unknown).unwrap()
}

#[test]
fn a_sheet_thinner_than_a_step_is_hit_exactly() {
    // Above 950 only over k in [7.95, 8.05]: a step of one voxel from k = 2.3 samples 7.8 and
    // 8.8 and misses it.
    let (eye, forward) = (DVec3::new(7.2, 8.1, 2.3), DVec3::Z);
    let hits = check_depths(sheet(), 950.0, eye, forward, 1.0);
    assert_eq!(hits, 144);
    let sampled = RenderSettings {
        mode: Mode::Iso,
        iso_hu: 950.0,
        step_vox: 1.0,
        ..Default::default()
    };
    let renderer = Arc::new(Renderer::new(sheet()));
    let camera = Camera::look_at(eye, eye + forward, DVec3::Y, 10.0, [1, 1]).unwrap();
    let frame = renderer.prepare(&sampled).unwrap().render(&camera);
    assert!(frame.depth_mm[0].is_nan(), "the samples' search found it");
}

#[test]
fn cell_bits_are_the_corner_ranges() {
    let options = PhantomOptions {
        size: 21,
        noise_hu: 200.0,
        ..Default::default()
    };
    let (volume, _) = phantom::straight_tube(&options);
    let dims = volume.dims();
    let grid = BrickGrid::new(&volume);
    let map = volume.value_map();
    let iso = map.stored_from_physical(-480.0) as f32;
    let table = TfTable::new(
        &TransferFunction::ramp(0.0, 1.0),
        map,
        volume.stored_range(),
        1.0,
    );
    let activity = Activity::classify(&grid, &[iso], &table);
    let cells = CellMask::new(&volume, &grid, &activity, iso);
    let value =
        |i: usize, j: usize, k: usize| f32::from(volume.voxels()[i + dims[0] * (j + dims[1] * k)]);
    let mut set = 0;
    for k in 0..dims[2] - 1 {
        for j in 0..dims[1] - 1 {
            for i in 0..dims[0] - 1 {
                let corners = (0..8).map(|c| value(i + (c & 1), j + (c >> 1 & 1), k + (c >> 2)));
                let (lo, hi) =
                    corners.fold((f32::MAX, f32::MIN), |(lo, hi), v| (lo.min(v), hi.max(v)));
                let straddles = lo < iso && hi >= iso;
                let b = BRICK_VOX;
                let brick = grid.index([i / b, j / b, k / b]) as u32;
                let place = i % b + b * (j % b) + b * b * (k % b);
                let bit = cells.of(brick).is_some_and(|c| is_set(c, place));
                assert_eq!(bit, straddles, "cell ({i}, {j}, {k})");
                set += usize::from(bit);
            }
        }
    }
    assert!(set > 100);
}

/// Exact iso and hybrid settings on the colon phantom at `opacity`.
fn exact(mode: Mode, opacity: f32) -> RenderSettings {
    RenderSettings {
        mode,
        iso_hu: -480.0,
        iso_opacity: opacity,
        exact_hits: true,
        ..Default::default()
    }
}

#[test]
fn exact_hybrid_at_full_opacity_is_exact_iso_and_close_to_the_samples() {
    let (renderer, camera) = colon_view(96, 0.6, 24);
    let iso = renderer
        .prepare(&exact(Mode::Iso, 1.0))
        .unwrap()
        .render(&camera);
    let hybrid = renderer
        .prepare(&exact(Mode::Hybrid, 1.0))
        .unwrap()
        .render(&camera);
    assert_same_image(&iso, &hybrid, "exact hybrid 100 %");
    let sampled = RenderSettings {
        exact_hits: false,
        ..exact(Mode::Hybrid, 0.6)
    };
    let a = renderer
        .prepare(&exact(Mode::Hybrid, 0.6))
        .unwrap()
        .render(&camera);
    let b = renderer.prepare(&sampled).unwrap().render(&camera);
    // The same surfaces, a bisection's error apart, and the same volume behind them.
    for (da, db) in a.depth_mm.iter().zip(&b.depth_mm) {
        assert!(
            (da - db).abs() < 0.05 || (da.is_nan() && db.is_nan()),
            "{da} vs {db}"
        );
    }
    assert!(a.stats.samples > 0);
}

#[test]
fn exact_depth_layers_start_at_the_frame_depth() {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 32,
        ..Default::default()
    });
    let eye = volume.geometry().world_of(shell.centre_vox);
    let camera = Camera::look_at(eye, eye + DVec3::X, DVec3::Z, 60.0, [8, 8]).unwrap();
    let renderer = Arc::new(Renderer::new(volume));
    let prepared = renderer.prepare(&exact(Mode::Iso, 1.0)).unwrap();
    let mut frame = Frame::default();
    let options = RenderOptions::new().layers(Layers::ALL);
    prepared.render_with(&camera, &options, &mut frame).unwrap();
    for (i, [first, second, third, _]) in frame.layer_depths_mm.iter().enumerate() {
        assert_eq!(first.to_bits(), frame.depth_mm[i].to_bits());
        // Out of the shell into the air outside, then nothing.
        assert!(
            (f64::from(*second) - shell.outer_radius_vox).abs() < 0.6,
            "{second}"
        );
        assert!(third.is_nan());
    }
}

/// The one-ray cell walk (CPUs without AVX2) gives the eight-lane walk's images bit for bit,
/// the volume behind the hybrid's surface included: in the colon, and in a noisy shell seen
/// from outside (rays that leave bricks empty of the isovalue and cross noise cells).
#[test]
fn the_scalar_cell_walk_gives_the_simd_images() {
    let (renderer, camera) = colon_view(64, 0.6, 40);
    let (shell, sphere) = phantom::sphere_shell(&PhantomOptions {
        size: 40,
        noise_hu: 60.0,
        ..Default::default()
    });
    let centre = shell.geometry().world_of(sphere.centre_vox);
    let eye = centre + DVec3::new(70.0, 20.0, -30.0);
    let outside = Camera::look_at(eye, centre, DVec3::Z, 50.0, [40, 40]).unwrap();
    for (renderer, camera, what) in [
        (renderer, camera, "colon"),
        (Arc::new(Renderer::new(shell)), outside, "shell"),
    ] {
        let scalar = Arc::new(Renderer::new(renderer.volume().clone()).without_simd());
        let mut hits = 0;
        for mode in [Mode::Iso, Mode::Hybrid] {
            let s = RenderSettings {
                tf: TransferFunction::preset("complex").unwrap(),
                ..exact(mode, 0.5)
            };
            let simd = renderer.prepare(&s).unwrap().render(&camera);
            let other = scalar.prepare(&s).unwrap().render(&camera);
            assert_same_image(&simd, &other, &format!("{what} {}", mode.name()));
            assert_eq!(simd.stats.samples, other.stats.samples, "{what}");
            hits += simd.depth_mm.iter().filter(|d| !d.is_nan()).count();
        }
        assert!(hits > 40 * 40 / 4, "{what}: {hits} hits");
    }
}
