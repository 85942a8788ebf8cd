//! Acceptance tests of the ray caster on phantoms with known answers (issue 3); its
//! release-mode timing runs are in `timing_tests`.

use super::*;
use crate::phantom::{self, PhantomOptions};
use crate::{Geometry, Modality, ValueMap};
use glam::{DMat3, DVec3};
use std::sync::Arc;

fn options(size: usize) -> PhantomOptions {
    PhantomOptions {
        size,
        ..Default::default()
    }
}

/// The phantoms' air/tissue boundary value: the mid-value their ramps put on the surface.
const PHANTOM_WALL_HU: f64 = -480.0;

fn settings(mode: Mode) -> RenderSettings {
    RenderSettings {
        mode,
        iso_hu: PHANTOM_WALL_HU,
        ..Default::default()
    }
}

/// A camera at voxel position `eye_vox` of `volume` looking along world direction `forward`.
fn camera_at(volume: &Volume, eye_vox: DVec3, forward: DVec3, fov: f64, size: usize) -> Camera {
    let eye = volume.geometry().world_of(eye_vox);
    Camera::look_at(
        eye,
        eye + forward,
        forward.any_orthonormal_vector(),
        fov,
        [size, size],
    )
    .unwrap()
}

/// Distance from `eye` along unit `dir` to the sphere of `radius` around `centre`, the eye
/// inside it.
fn sphere_distance(eye: DVec3, dir: DVec3, centre: DVec3, radius: f64) -> f64 {
    let oc = eye - centre;
    let b = dir.dot(oc);
    -b + (b * b - (oc.length_squared() - radius * radius)).sqrt()
}

/// Largest |depth − analytic| over the image of an iso render of the sphere shell.
fn sphere_depth_error(eye_offset: DVec3, refine_steps: u32) -> f64 {
    let (volume, shell) = phantom::sphere_shell(&options(48));
    let eye_vox = shell.centre_vox + eye_offset;
    let renderer = Arc::new(Renderer::new(volume));
    let s = RenderSettings {
        refine_steps,
        ..settings(Mode::Iso)
    };
    let prepared = renderer.prepare(&s).unwrap();
    let mut worst: f64 = 0.0;
    for forward in [DVec3::Z, DVec3::new(1.0, -2.0, 0.5).normalize()] {
        let camera = camera_at(renderer.volume(), eye_vox, forward, 100.0, 24);
        let frame = prepared.render(&camera);
        for y in 0..24 {
            for x in 0..24 {
                let dir = camera.pixel_ray(x, y).unwrap().dir;
                let expected =
                    sphere_distance(eye_vox, dir, shell.centre_vox, shell.inner_radius_vox);
                let depth = f64::from(frame.depth_mm[x + 24 * y]);
                assert!(depth.is_finite(), "no hit at ({x}, {y})");
                worst = worst.max((depth - expected).abs());
            }
        }
    }
    worst
}

#[test]
fn sphere_depth_from_the_centre_is_the_radius() {
    let error = sphere_depth_error(DVec3::ZERO, 4);
    assert!(error < 0.05, "max depth error {error} voxel");
}

#[test]
fn sphere_depth_off_centre_is_the_analytic_distance_and_refinement_matters() {
    let refined = sphere_depth_error(DVec3::new(5.0, -3.0, 2.5), 4);
    assert!(refined < 0.05, "max depth error {refined} voxel");
    let unrefined = sphere_depth_error(DVec3::new(5.0, -3.0, 2.5), 0);
    assert!(
        unrefined > 0.2 && unrefined > 5.0 * refined,
        "without refinement {unrefined}, with {refined}"
    );
}

#[test]
fn tube_depth_from_inside_matches_the_cylinder() {
    let (volume, tube) = phantom::straight_tube(&options(48));
    let eye_vox = tube.centreline.point_at(4.0) + DVec3::new(2.0, -1.0, 0.0);
    let axis = tube.centreline.points()[0];
    let last_k = (volume.dims()[2] - 1) as f64;
    let renderer = Arc::new(Renderer::new(volume));
    let prepared = renderer.prepare(&settings(Mode::Iso)).unwrap();
    let forward = DVec3::new(0.1, 0.05, 1.0).normalize();
    let camera = camera_at(renderer.volume(), eye_vox, forward, 90.0, 32);
    let frame = prepared.render(&camera);
    let mut checked = 0;
    for y in 0..32 {
        for x in 0..32 {
            let d = camera.pixel_ray(x, y).unwrap().dir;
            // |(e + t d − a)⊥| = R in the i–j plane.
            let (e, dp) = ((eye_vox - axis).truncate(), d.truncate());
            let (a, b, c) = (
                dp.length_squared(),
                e.dot(dp),
                e.length_squared() - tube.radius_vox.powi(2),
            );
            let t = (-b + (b * b - a * c).sqrt()) / a;
            if eye_vox.z + t * d.z > last_k - 2.0 {
                continue; // leaves through the end face before reaching the wall
            }
            let depth = f64::from(frame.depth_mm[x + 32 * y]);
            // The hit lies on the analytic cylinder within 0.05 voxel; along the ray that is
            // 0.05 voxel too except at grazing incidence, where any error along the normal is
            // stretched by 1 / sin(incidence).
            let hit = eye_vox + d * depth - axis;
            let off_surface = hit.truncate().length() - tube.radius_vox;
            assert!(
                off_surface.abs() < 0.05,
                "({x}, {y}): {off_surface} voxel off the wall"
            );
            let sin_incidence = (e + dp * t).normalize().dot(dp).abs();
            if sin_incidence > 0.5 {
                assert!((depth - t).abs() < 0.05, "({x}, {y}): {depth} vs {t}");
            }
            checked += 1;
        }
    }
    assert!(checked > 500, "{checked} pixels checked");
}

/// A homogeneous `12 × 12 × 41` block of 100 HU seen along `k` from outside.
fn homogeneous_block() -> Volume {
    let g = Geometry::axis_aligned([12, 12, 41], DVec3::ONE, DVec3::ZERO).unwrap();
    Volume::new(g, vec![100; 12 * 12 * 41], ValueMap::IDENTITY, Modality::Ct).unwrap()
}

#[test]
fn dvr_of_a_homogeneous_slab_follows_beer_lambert_at_any_step() {
    let renderer = Arc::new(Renderer::new(homogeneous_block()));
    let alpha_per_mm = 0.05f32;
    let tf = TransferFunction::from_points(&[(0.0, alpha_per_mm)], &[(0.0, [1.0; 3])]).unwrap();
    let camera = Camera::look_at(
        DVec3::new(5.5, 5.5, -10.0),
        DVec3::new(5.5, 5.5, 0.0),
        DVec3::Y,
        20.0,
        [5, 5],
    )
    .unwrap();
    let mut images = Vec::new();
    for step_vox in [0.25, 0.5, 1.0] {
        let s = RenderSettings {
            tf: tf.clone(),
            step_vox,
            ..settings(Mode::Dvr)
        };
        let prepared = renderer.prepare(&s).unwrap();
        let frame = prepared.render(&camera);
        for y in 0..5 {
            for x in 0..5 {
                let trace = prepared.trace_pixel(&camera, x, y);
                let (t0, t1) = trace.range_mm.unwrap();
                let expected = 1.0 - (1.0 - f64::from(alpha_per_mm)).powf(t1 - t0);
                let alpha = f64::from(frame.alpha(x, y));
                assert!(
                    (alpha / expected - 1.0).abs() < 0.01,
                    "step {step_vox}: {alpha} vs {expected}"
                );
            }
        }
        images.push(
            frame
                .color
                .iter()
                .map(Premultiplied::alpha)
                .collect::<Vec<_>>(),
        );
    }
    for image in &images[1..] {
        for (a, b) in image.iter().zip(&images[0]) {
            assert!((a - b).abs() < 0.01, "{a} vs {b}");
        }
    }
}

/// The colon phantom and a camera on its centreline at arc-length fraction `at`, looking along
/// it.
pub(super) fn colon_view(size: usize, at: f64, image: usize) -> (Arc<Renderer>, Camera) {
    let (volume, colon) = phantom::colon(&options(size));
    let s = colon.centreline.length_vox() * at;
    let eye = colon.centreline.point_at(s);
    let ahead = colon.centreline.point_at(s + 8.0);
    let g = volume.geometry();
    let camera = Camera::look_at(
        g.world_of(eye),
        g.world_of(ahead),
        (ahead - eye).any_orthonormal_vector(),
        90.0,
        [image, image],
    )
    .unwrap();
    (Arc::new(Renderer::new(volume)), camera)
}

/// Asserts two lists are equal, naming the first differing element (not printing megabytes).
fn assert_same<T: PartialEq + std::fmt::Debug>(a: &[T], b: &[T], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: lengths differ");
    if let Some(i) = (0..a.len()).find(|&i| a[i] != b[i]) {
        panic!("{what}: element {i} differs: {:?} vs {:?}", a[i], b[i]);
    }
}

pub(super) fn assert_same_image(a: &Frame, b: &Frame, what: &str) {
    let bits = |v: &[Premultiplied]| {
        let bits = |c: &Premultiplied| c.rgb.map(f32::to_bits).to_vec();
        v.iter()
            .map(|c| (bits(c), c.transmittance.to_bits()))
            .collect::<Vec<_>>()
    };
    assert_same(
        &bits(&a.color),
        &bits(&b.color),
        &format!("{what}: colours"),
    );
    let bits = |v: &[f32]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(a.layers(), b.layers(), "{what}: layers");
    assert_same(
        &bits(&a.depth_mm),
        &bits(&b.depth_mm),
        &format!("{what}: depths"),
    );
    assert_same(&bits(&a.value), &bits(&b.value), &format!("{what}: values"));
}

#[test]
fn skipping_gives_the_same_image_with_several_times_fewer_samples() {
    let (renderer, camera) = colon_view(160, 0.3, 48);
    for (mode, tf, jitter) in [
        (Mode::Iso, "ramp", false),
        (Mode::Hybrid, "complex", true),
        (Mode::Dvr, "colonoscopy", false),
        (Mode::Mip, "ramp", false),
        (Mode::Minip, "ramp", true),
    ] {
        let mut s = RenderSettings {
            mode,
            iso_opacity: 0.5,
            tf: TransferFunction::preset(tf).unwrap(),
            jitter,
            ..Default::default()
        };
        let on = renderer.prepare(&s).unwrap().render(&camera);
        s.skip_empty = false;
        let off = renderer.prepare(&s).unwrap().render(&camera);
        assert_same_image(&on, &off, mode.name());
        assert!(on.stats.samples <= off.stats.samples);
    }
}

/// Rays set up four at a time and rendered a row at a time (the eight-ray search and
/// compositing, bisection across rays, gradients in batches) give every pixel exactly what the one-ray path (the
/// `--debug-pixel` trace) gives: from inside, past a near plane, and from outside the volume
/// on an image whose width is no multiple of four.
#[test]
fn grouped_rays_give_the_one_ray_pixels() {
    let (renderer, inside) = colon_view(120, 0.45, 40);
    let bricked = Arc::new(Renderer::for_many_frames(renderer.volume().clone()));
    let g = renderer.volume().geometry();
    let outside = Camera::look_at(
        g.world_of(DVec3::new(-40.0, 50.0, 70.0)),
        g.world_of(DVec3::splat(60.0)),
        DVec3::Z,
        70.0,
        [37, 23],
    )
    .unwrap();
    let cameras = [inside, inside.with_near_mm(4.0).unwrap(), outside];
    for (mode, crossing, jitter, skip_empty) in [
        (Mode::Iso, Crossing::Auto, false, true),
        (Mode::Iso, Crossing::Falling, true, true),
        (Mode::Iso, Crossing::Auto, true, false),
        (Mode::Hybrid, Crossing::Auto, true, true),
        (Mode::Hybrid, Crossing::Rising, false, false),
        (Mode::Dvr, Crossing::Auto, true, true),
        (Mode::Dvr, Crossing::Auto, false, false),
    ] {
        let s = RenderSettings {
            mode,
            crossing,
            jitter,
            skip_empty,
            iso_opacity: 0.6,
            tf: TransferFunction::preset("complex").unwrap(),
            ..settings(mode)
        };
        let views = cameras.iter().flat_map(|c| [(&renderer, c), (&bricked, c)]);
        for (renderer, camera) in views {
            let prepared = renderer.prepare(&s).unwrap();
            let frame = prepared.render(camera);
            let [w, h] = camera.size();
            let mut hits = 0;
            for (y, x) in (0..h).flat_map(|y| (0..w).map(move |x| (y, x))) {
                let trace = prepared.trace_pixel(camera, x, y);
                let what =
                    format!("{mode:?} {crossing:?} jitter {jitter} skip {skip_empty} ({x}, {y})");
                let i = x + w * y;
                assert_eq!(trace.rgb, frame.pixel(x, y, s.background), "{what}");
                assert_eq!(trace.alpha, frame.color[i].alpha(), "{what}");
                let depth = frame.depth_mm[i];
                assert_eq!(trace.depth_mm.to_bits(), depth.to_bits(), "{what}");
                hits += usize::from(depth.is_finite());
            }
            // A falling crossing is met only by rays that leave the wall into another cavity.
            let surface = mode != Mode::Dvr;
            assert!(
                !surface || hits > w * h / 20,
                "{mode:?} {crossing:?}: {hits} hits"
            );
        }
    }
}

/// The paths CPUs without AVX2 take (one-ray searches, bisection a step at a time across the
/// rays, scalar samples) give the AVX2 paths' images and counters.
#[test]
fn scalar_paths_give_the_simd_images() {
    let (renderer, camera) = colon_view(100, 0.6, 40);
    let scalar = Arc::new(Renderer::new(renderer.volume().clone()).without_simd());
    for mode in [
        Mode::Iso,
        Mode::Hybrid,
        Mode::Dvr,
        Mode::TwoIso,
        Mode::Mip,
        Mode::Minip,
    ] {
        let s = RenderSettings {
            mode,
            iso_opacity: 0.5,
            tf: TransferFunction::preset("complex").unwrap(),
            ..settings(mode)
        };
        let simd = renderer.prepare(&s).unwrap().render(&camera);
        let other = scalar.prepare(&s).unwrap().render(&camera);
        assert_same_image(&simd, &other, mode.name());
        assert_eq!(simd.stats.samples, other.stats.samples, "{}", mode.name());
    }
}

#[test]
fn bricked_voxels_give_the_same_image() {
    let (renderer, camera) = colon_view(100, 0.6, 40);
    let bricked = Arc::new(Renderer::for_many_frames(renderer.volume().clone()));
    for mode in [Mode::Iso, Mode::Hybrid, Mode::Dvr, Mode::TwoIso, Mode::Mip] {
        let s = RenderSettings {
            mode,
            iso_opacity: 0.5,
            tf: TransferFunction::preset("complex").unwrap(),
            ..Default::default()
        };
        let plain = renderer.prepare(&s).unwrap().render(&camera);
        let other = bricked.prepare(&s).unwrap().render(&camera);
        assert_same_image(&plain, &other, mode.name());
        assert!(plain.stats.samples > 0, "{}", mode.name());
    }
}

#[test]
fn skipping_takes_several_times_fewer_samples_inside_a_cavity() {
    let (volume, shell) = phantom::sphere_shell(&options(128));
    let renderer = Arc::new(Renderer::new(volume));
    let camera = camera_at(
        renderer.volume(),
        shell.centre_vox + DVec3::new(6.0, -4.0, 3.0),
        DVec3::new(1.0, 0.4, 0.2).normalize(),
        90.0,
        48,
    );
    let mut s = settings(Mode::Iso);
    let on = renderer.prepare(&s).unwrap().render(&camera);
    s.skip_empty = false;
    let off = renderer.prepare(&s).unwrap().render(&camera);
    assert_same_image(&on, &off, "sphere");
    assert_eq!(on.stats.iso_hits, 48 * 48);
    let factor = off.stats.samples as f64 / on.stats.samples as f64;
    assert!(factor > 3.0, "only {factor:.2}× fewer samples");
}

#[test]
fn hybrid_at_full_opacity_is_iso_and_at_zero_is_dvr_from_the_hit() {
    let (renderer, camera) = colon_view(128, 0.6, 32);
    let iso = renderer
        .prepare(&settings(Mode::Iso))
        .unwrap()
        .render(&camera);
    let hybrid_full = renderer
        .prepare(&settings(Mode::Hybrid))
        .unwrap()
        .render(&camera);
    assert_same_image(&iso, &hybrid_full, "hybrid 100 %");
    // A transfer function transparent up to the isovalue: DVR from the eye then starts
    // contributing exactly at the first sample past the isosurface.
    let tf = TransferFunction::from_points(
        &[(-500.0, 0.0), (-498.0, 0.0), (-300.0, 0.3), (3000.0, 0.3)],
        &[(-500.0, [0.2, 0.4, 0.8]), (100.0, [1.0, 0.9, 0.8])],
    )
    .unwrap();
    let hybrid_zero = RenderSettings {
        iso_hu: -500.0,
        iso_opacity: 0.0,
        tf: tf.clone(),
        ..settings(Mode::Hybrid)
    };
    let dvr = RenderSettings {
        tf,
        ..settings(Mode::Dvr)
    };
    let a = renderer.prepare(&hybrid_zero).unwrap().render(&camera);
    let b = renderer.prepare(&dvr).unwrap().render(&camera);
    assert_same(&a.color, &b.color, "hybrid 0 % vs dvr: colours");
    assert!(a.color.iter().filter(|c| c.alpha() > 0.5).count() > 32 * 32 / 2);
}

/// Also checks that compositing a batch at a time (the frame) gives exactly what one sample at
/// a time gives (the trace).
#[test]
fn early_termination_stops_at_the_first_sample_past_the_threshold() {
    let (renderer, camera) = colon_view(128, 0.45, 12);
    let s = RenderSettings {
        iso_opacity: 0.3,
        early_termination: 0.9,
        ..settings(Mode::Hybrid)
    };
    let prepared = renderer.prepare(&s).unwrap();
    let frame = prepared.render(&camera);
    assert!(frame.stats.terminated_early > 100);
    for y in 0..12 {
        for x in 0..12 {
            let trace = prepared.trace_pixel(&camera, x, y);
            let over = trace.samples.iter().position(|s| s.alpha >= 0.9);
            if let Some(first) = over {
                assert_eq!(first + 1, trace.samples.len(), "samples after termination");
                let before = trace.samples[..first].last().map_or(0.0, |s| s.alpha);
                assert!(before < 0.9);
            }
            let i = x + 12 * y;
            assert_eq!(trace.alpha, frame.color[i].alpha());
            assert_eq!(trace.rgb, frame.pixel(x, y, s.background));
        }
    }
}

#[test]
fn two_iso_shows_the_stent_in_front_of_the_wall() {
    let (volume, vessel) = phantom::vessel(&options(64));
    let middle = vessel.axis.point_at(0.5 * vessel.axis.length_vox());
    let renderer = Arc::new(Renderer::new(volume));
    let s = RenderSettings::preset("angioscopy").unwrap();
    assert_eq!(s.mode, Mode::TwoIso);
    let prepared = renderer.prepare(&s).unwrap();
    let camera = camera_at(renderer.volume(), middle, DVec3::X, 60.0, 32);
    let frame = prepared.render(&camera);
    let (mut stent, mut wall) = (Vec::new(), Vec::new());
    for y in 0..32 {
        for x in 0..32 {
            let depth = f64::from(frame.depth_mm[x + 32 * y]);
            assert!(depth.is_finite(), "({x}, {y}) sees nothing");
            let dir = camera.pixel_ray(x, y).unwrap().dir;
            // Metal within a voxel behind the hit (a strut is thin; rays may graze it).
            let metal = (0..10).any(|n| {
                let p = middle + dir * (depth + 0.1 * f64::from(n));
                renderer
                    .volume()
                    .sample_physical(p)
                    .is_some_and(|hu| hu > 700.0)
            });
            let radial = (dir * depth).truncate().length();
            if metal {
                // Metal first: a strut, inside the lumen, in front of the wall.
                assert!(
                    radial < vessel.lumen_radius_vox,
                    "({x}, {y}): strut at {radial}"
                );
                stent.push(frame.pixel(x, y, s.background));
            } else {
                // The wall, not in front of the lumen's edge (next to a strut or a plaque the
                // 130 HU surface is pushed into the wall by their boundary ramps).
                let (r, outer) = (vessel.lumen_radius_vox, vessel.wall_radius_vox);
                assert!(
                    radial > r - 0.3 && radial < outer,
                    "({x}, {y}): wall at {radial}"
                );
                wall.push(frame.pixel(x, y, s.background));
            }
        }
    }
    assert!(
        stent.len() > 50 && wall.len() > 50,
        "stent {}, wall {} pixels",
        stent.len(),
        wall.len()
    );
    // Each surface wears its own colour: bluish-white metal, red wall.
    let mean = |pixels: &[[u8; 3]], c: usize| {
        pixels.iter().map(|p| f64::from(p[c])).sum::<f64>() / pixels.len() as f64
    };
    assert!(mean(&stent, 2) > mean(&stent, 0) && mean(&wall, 0) > mean(&wall, 2));
}

#[test]
fn mip_and_minip_match_a_brute_force_reference() {
    let (volume, vessel) = phantom::vessel(&options(32));
    let centre = vessel.axis.point_at(0.5 * vessel.axis.length_vox());
    let renderer = Arc::new(Renderer::new(volume));
    let volume = renderer.volume();
    let extent = DVec3::from(volume.dims().map(|n| (n - 1) as f64));
    let camera = camera_at(
        volume,
        centre + DVec3::new(-30.0, 4.0, 3.0),
        DVec3::X,
        60.0,
        12,
    );
    for mode in [Mode::Mip, Mode::Minip] {
        let prepared = renderer.prepare(&settings(mode)).unwrap();
        let frame = prepared.render(&camera);
        for y in 0..12 {
            for x in 0..12 {
                let trace = prepared.trace_pixel(&camera, x, y);
                let Some((t0, t1)) = trace.range_mm else {
                    assert!(frame.value[x + 12 * y].is_nan());
                    continue;
                };
                let mut best: Option<f64> = None;
                let mut n = 0.0;
                loop {
                    let t = t0 + (n + 0.5) * trace.step_mm;
                    if t >= t1 {
                        break;
                    }
                    let p = trace.ray.unwrap().at(t).clamp(DVec3::ZERO, extent);
                    let v = volume.sample_physical(p).unwrap();
                    best = Some(match (best, mode) {
                        (None, _) => v,
                        (Some(b), Mode::Mip) => b.max(v),
                        (Some(b), _) => b.min(v),
                    });
                    n += 1.0;
                }
                let got = f64::from(frame.value[x + 12 * y]);
                let expected = best.unwrap_or(f64::NAN);
                assert!(
                    (got - expected).abs() < 0.5 || (got.is_nan() && expected.is_nan()),
                    "{} ({x}, {y}): {got} vs {expected}",
                    mode.name()
                );
            }
        }
    }
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let (renderer, camera) = colon_view(96, 0.5, 40);
    let s = RenderSettings {
        iso_opacity: 0.5,
        jitter: true,
        tf: TransferFunction::preset("complex").unwrap(),
        ..settings(Mode::Hybrid)
    };
    let prepared = renderer.prepare(&s).unwrap();
    let render_with = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| prepared.render(&camera))
    };
    let (one, two) = (render_with(1), render_with(2));
    assert_same_image(&one, &two, "1 vs 2 threads");
    let counts = |f: &Frame| RenderStats {
        time: Default::default(),
        ..f.stats
    };
    assert_eq!(counts(&one), counts(&two));
}

#[test]
fn awkward_cameras_give_no_nan_and_no_panic() {
    let (volume, _) = phantom::sphere_shell(&options(33));
    let renderer = Arc::new(Renderer::new(volume));
    let v = renderer.volume();
    let cameras = [
        // Exactly on a brick corner, looking along an axis (odd size: the centre ray is exact).
        camera_at(v, DVec3::splat(8.0), DVec3::X, 90.0, 9),
        camera_at(v, DVec3::splat(16.0), -DVec3::Z, 170.0, 9),
        // On the volume's corner and faces.
        camera_at(v, DVec3::ZERO, DVec3::ONE.normalize(), 10.0, 5),
        camera_at(v, DVec3::new(32.0, 16.0, 16.0), DVec3::X, 90.0, 7),
        // Outside, looking away; and outside looking in.
        camera_at(v, DVec3::splat(-5.0), -DVec3::ONE.normalize(), 90.0, 7),
        camera_at(v, DVec3::new(-40.0, 16.0, 16.0), DVec3::X, 30.0, 7),
    ];
    for camera in &cameras {
        for mode in Mode::ALL {
            let s = RenderSettings {
                iso2_hu: 1000.0,
                ..settings(mode)
            };
            let prepared = renderer.prepare(&s).unwrap();
            for near in [0.0, 3.0] {
                let camera = camera.with_near_mm(near).unwrap();
                let frame = prepared.render(&camera);
                assert!(frame
                    .color
                    .iter()
                    .all(|c| c.alpha().is_finite() && (0.0..=1.0001).contains(&c.alpha())));
                assert!(frame.depth_mm.iter().all(|d| d.is_nan() || *d >= 0.0));
            }
        }
    }
    let away = renderer.prepare(&settings(Mode::Dvr)).unwrap();
    let frame = away.render(&cameras[4]);
    assert_eq!(frame.stats.rays, 0);
    assert!(frame.to_rgb8([0.0; 3]).iter().all(|&c| c == 0));
}

#[test]
fn sheared_anisotropic_grids_shade_and_measure_in_millimetres() {
    // A ball of radius 9 mm (air inside, tissue outside) on a grid with 18.5° shear and
    // 0.8 × 1 × 1.5 mm voxels; depth from the centre is the radius in mm.
    let tilt = 18.5_f64.to_radians();
    let direction = DMat3::from_cols(DVec3::X, DVec3::new(0.0, tilt.cos(), -tilt.sin()), DVec3::Z);
    let dims = [40, 36, 26];
    let g = Geometry::new(dims, DVec3::new(0.8, 1.0, 1.5), DVec3::ZERO, direction).unwrap();
    let centre = g.world_of(DVec3::new(19.5, 17.5, 12.5));
    let mut voxels = Vec::with_capacity(dims.iter().product());
    for k in 0..dims[2] {
        for j in 0..dims[1] {
            for i in 0..dims[0] {
                let r = g
                    .world_of(DVec3::new(i as f64, j as f64, k as f64))
                    .distance(centre);
                // Linear ramp (in mm) from −1000 to +40 HU over 4 mm around r = 9 mm.
                let hu = (-480.0 + (r - 9.0) * 260.0).clamp(-1000.0, 40.0);
                voxels.push((hu + 1024.0).round() as u16);
            }
        }
    }
    let map = ValueMap::new(1.0, -1024.0).unwrap();
    let renderer = Arc::new(Renderer::new(
        Volume::new(g, voxels, map, Modality::Ct).unwrap(),
    ));
    let prepared = renderer.prepare(&settings(Mode::Iso)).unwrap();
    let camera = Camera::look_at(
        centre,
        centre + DVec3::new(0.3, 1.0, 0.2),
        DVec3::Z,
        120.0,
        [16, 16],
    )
    .unwrap();
    let frame = prepared.render(&camera);
    for (n, depth) in frame.depth_mm.iter().enumerate() {
        // Rounding the ramp to integers moves the surface by at most 0.5 / 260 mm.
        assert!((depth - 9.0).abs() < 0.05, "pixel {n}: {depth} mm");
    }
    // A headlight on a sphere seen from its centre: every normal faces the eye, so every pixel
    // is lit fully (ambient + diffuse + specular, clamped).
    let background = settings(Mode::Iso).background;
    let lit = frame.pixel(8, 8, background);
    for p in frame.to_rgb8(background).chunks(3) {
        assert!(
            p.iter().zip(lit).all(|(a, b)| a.abs_diff(b) <= 2),
            "{p:?} vs {lit:?}"
        );
    }
}
