//! Acceptance tests of the look (issue 20) on phantoms with known answers.

use super::*;
use crate::phantom::profile::{paint, ramp, AIR_HU, TISSUE_HU};
use crate::phantom::{layered, rasterize, Layered, PhantomOptions, SECRETION_HU};
use crate::render::quality::reduced_camera;
use crate::render::{Camera, Quality, RenderSettings, Renderer};
use crate::Volume;
use glam::{DVec3, Vec3};
use std::sync::Arc;

fn options(size: usize) -> PhantomOptions {
    PhantomOptions {
        size,
        ..Default::default()
    }
}

/// A camera at voxel position `eye_vox` of `volume` looking along +k (world +z: the phantoms'
/// identity directions), `fov` degrees, `size²` pixels.
fn looking_down_k(volume: &Volume, eye_vox: DVec3, fov: f64, size: usize) -> Camera {
    let eye = volume.geometry().world_of(eye_vox);
    Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, fov, [size, size]).unwrap()
}

/// The ray pass over `volume` with `secretion` and the layered phantom's thresholds.
fn pass(volume: Volume, secretion: SecretionMode, base: &RenderSettings) -> RayPass {
    let settings = RayPassSettings {
        tissue_hu: Layered::tissue_threshold_hu(),
        secretion_hu: Layered::secretion_threshold_hu(),
        secretion,
        ..RayPassSettings::default()
    };
    RayPass::new(&Arc::new(Renderer::new(volume)), base, &settings).unwrap()
}

/// Shading that leaves only the secretion's fog: red tissue, green secretion, no texture,
/// wetness, fall-off or smoothing, and light from everywhere (the tissue and the secretion's
/// own surface, at other angles, lit alike).
fn fog_only() -> Shading {
    Shading {
        tissue_color: [1.0, 0.0, 0.0],
        secretion_color: [0.0, 1.0, 0.0],
        ambient: 1.0,
        diffuse: 0.0,
        attenuation_mm: None,
        smoothing_px: 0,
        fog_mm: 4.0,
        ..Shading::default()
    }
}

#[test]
fn secretion_thickness_matches_the_layered_phantom_and_fog_rises_with_it() {
    let (volume, truth) = layered(&options(40));
    let origin_vox = volume.geometry().voxel_from_world();
    let camera = looking_down_k(&volume, DVec3::new(19.5, 19.5, 2.0), 70.0, 32);
    for mode in [SecretionMode::On, SecretionMode::Accumulate] {
        let gbuffer =
            pass(volume.clone(), mode, &RenderSettings::default()).trace(&camera, Quality::Full);
        let frame = shade(&gbuffer, &camera, &fog_only()).unwrap();
        let (mut worst, mut measured) = (0.0f64, Vec::new());
        for y in 0..32 {
            for x in 0..32 {
                let ray = camera.pixel_ray(x, y).unwrap();
                let o = origin_vox.transform_point3(ray.origin);
                let i = x + 32 * y;
                // Rays whose tissue hit lies two voxels or more inside the phantom's sides.
                let hit = o + ray.dir * f64::from(gbuffer.depth_mm[i]);
                if !(2.0..=37.0).contains(&hit.x) || !(2.0..=37.0).contains(&hit.y) {
                    continue;
                }
                let analytic = truth.secretion_along(o, ray.dir).unwrap();
                let error = f64::from(gbuffer.secretion_mm[i]) - analytic;
                worst = worst.max(error.abs());
                let [r, g, _] = frame.color[i].rgb;
                measured.push((analytic, g / (r + g)));
            }
        }
        assert!(measured.len() > 500, "{mode:?}: {} rays", measured.len());
        assert!(worst < 0.1, "{mode:?}: secretion off by {worst:.3} voxel");
        // Fog strength rises with the thickness and is the shading's fog of it.
        measured.sort_by(|a, b| a.0.total_cmp(&b.0));
        for pair in measured.windows(2) {
            assert!(pair[1].1 >= pair[0].1 - 1e-4, "{mode:?}: {pair:?}");
        }
        for (thickness, fog) in &measured {
            let expected = fog_only().fog(*thickness as f32);
            assert!((fog - expected).abs() < 0.02, "{mode:?}: {thickness} {fog}");
        }
        assert!(measured[measured.len() - 1].1 - measured[0].1 > 0.05);
    }
}

#[test]
fn accumulated_secretion_skips_the_air_between_a_drop_and_the_wall() {
    // Along k: air, secretion from k = 8 to 14, air again, tissue from k = 22 (its air/tissue
    // mid-value there; the tissue threshold −230 HU lies 0.48 voxel deeper, and the
    // secretion threshold −750 HU one voxel before that, in the wall's own partial volume).
    let volume = rasterize([24, 24, 40], &options(40), &|p: DVec3| {
        let wall = ramp(22.0 - p.z, TISSUE_HU, AIR_HU);
        paint(wall, (p.z - 11.0).abs() - 3.0, SECRETION_HU)
    });
    let camera = looking_down_k(&volume, DVec3::new(11.5, 11.5, 2.0), 20.0, 8);
    let measure = |mode| {
        let gbuffer =
            pass(volume.clone(), mode, &RenderSettings::default()).trace(&camera, Quality::Full);
        let centre = 4 + 8 * 4;
        let cos = camera.pixel_ray(4, 4).unwrap().dir.z as f32;
        (
            gbuffer.secretion_mm[centre] * cos,
            gbuffer.depth_mm[centre] * cos,
        )
    };
    let (on, depth) = measure(SecretionMode::On);
    let (accumulated, same_depth) = measure(SecretionMode::Accumulate);
    let tissue = 22.0
        + (Layered::tissue_threshold_hu() - 0.5 * (AIR_HU + TISSUE_HU)) as f32
            / ((TISSUE_HU - AIR_HU) / 2.0) as f32;
    assert!((depth - (tissue - 2.0)).abs() < 0.05, "tissue at {depth}");
    assert!((same_depth - depth).abs() < 1e-4);
    // The wall's own edge between the two thresholds (1 voxel, from its secretion crossing at
    // 21.48 to the tissue) is not secretion: constant density from the drop to that crossing.
    assert!((on - (tissue - 9.0)).abs() < 0.1, "constant density: {on}");
    // The drop (6 voxels) only.
    assert!(
        (accumulated - 6.0).abs() < 0.1,
        "accumulated: {accumulated}"
    );
}

#[test]
fn a_thin_sheet_of_tissue_in_the_secretion_is_found_not_stepped_over() {
    // Along k: air, then secretion from k = 8, a sheet of tissue in slice 16 whose partial
    // volume (−182 HU) lies just above the tissue threshold (−230 HU), so that the value passes
    // the threshold over only 0.3 voxel along k (the thin edge of a turbinate in a sinus full of
    // secretion), and the wall from k = 30. A continuation stepping half a voxel steps over the
    // sheet on about a third of the rays and shows the wall behind it; every ray must stop at it.
    let sheet_hu = -182.0;
    let volume = rasterize([24, 24, 40], &options(40), &|p: DVec3| match p.z as i64 {
        ..=7 => AIR_HU,
        16 => sheet_hu,
        30.. => TISSUE_HU,
        _ => SECRETION_HU,
    });
    let tissue = Layered::tissue_threshold_hu();
    let sheet = 16.0 - (sheet_hu - tissue) / (sheet_hu - SECRETION_HU);
    let camera = looking_down_k(&volume, DVec3::new(11.5, 11.5, 2.0), 40.0, 16);
    for mode in [SecretionMode::On, SecretionMode::Accumulate] {
        let gbuffer =
            pass(volume.clone(), mode, &RenderSettings::default()).trace(&camera, Quality::Full);
        for i in 0..gbuffer.len() {
            let cos = camera.pixel_ray(i % 16, i / 16).unwrap().dir.z as f32;
            let depth = gbuffer.depth_mm[i] * cos;
            assert!(
                (f64::from(depth) - (sheet - 2.0)).abs() < 0.05,
                "{mode:?}, pixel {i}: tissue at k {} (the sheet at {sheet:.3})",
                depth + 2.0
            );
        }
    }
}

/// Variance of the 4×4 block means of `error` (a `size²` image): the low-frequency energy in
/// which sampling bands live (fine per-pixel patterns average out in a block).
fn banding(error: &[f64], size: usize) -> f64 {
    let mut means = Vec::new();
    for by in (0..size).step_by(4) {
        for bx in (0..size).step_by(4) {
            let block = (0..16).map(|k| error[bx + k % 4 + size * (by + k / 4)]);
            means.push(block.sum::<f64>() / 16.0);
        }
    }
    let mean = means.iter().sum::<f64>() / means.len() as f64;
    means.iter().map(|m| (m - mean).powi(2)).sum::<f64>() / means.len() as f64
}

#[test]
fn interleaved_sampling_removes_the_bands_of_the_sample_grid() {
    // A tissue slab whose face is tilted 30° to the view, seen without refinement: each hit
    // lies up to a step behind the face, in bands where the face crosses a sample plane.
    let normal = DVec3::new(0.5, 0.0, -(0.75f64.sqrt()));
    let point = DVec3::new(32.0, 32.0, 30.0);
    let volume = rasterize([64, 64, 64], &options(64), &|p: DVec3| {
        ramp((p - point).dot(normal), TISSUE_HU, AIR_HU)
    });
    let camera = looking_down_k(&volume, DVec3::new(31.5, 31.5, 4.0), 40.0, 64);
    let world_point = volume.geometry().world_of(point);
    let coarse = RenderSettings {
        refine_steps: 0,
        step_vox: 1.0,
        ..RenderSettings::default()
    };
    let statistic = |interleave| {
        let settings = RayPassSettings {
            tissue_hu: 0.5 * (AIR_HU + TISSUE_HU),
            interleave,
            ..RayPassSettings::default()
        };
        let renderer = Arc::new(Renderer::new(volume.clone()));
        let gbuffer = RayPass::new(&renderer, &coarse, &settings)
            .unwrap()
            .trace(&camera, Quality::Full);
        let error: Vec<f64> = (0..64 * 64)
            .map(|i| {
                let ray = camera.pixel_ray(i % 64, i / 64).unwrap();
                let t = (world_point - ray.origin).dot(normal) / ray.dir.dot(normal);
                f64::from(gbuffer.depth_mm[i]) - t
            })
            .collect();
        assert!(
            error.iter().all(|e| (-0.05..1.6).contains(e)),
            "a hit off the face"
        );
        banding(&error, 64)
    };
    let (plain, interleaved) = (statistic(false), statistic(true));
    assert!(plain > 0.01, "no bands to remove: {plain}");
    assert!(interleaved < 0.25 * plain, "{interleaved} vs {plain}");
}

/// A far wall (tissue from k = 40) and a fold in front of it (tissue from k = 14 to 20) over
/// the half `i < 24`, with `noise_hu` of noise.
fn fold_and_wall(noise_hu: f64) -> Volume {
    let options = PhantomOptions {
        size: 48,
        noise_hu,
        seed: 3,
        ..Default::default()
    };
    rasterize([48, 48, 48], &options, &|p: DVec3| {
        let wall = ramp(40.0 - p.z, TISSUE_HU, AIR_HU);
        let fold = ((p.z - 17.0).abs() - 3.0).max(p.x - 24.0);
        paint(wall, fold, TISSUE_HU)
    })
}

#[test]
fn smoothing_keeps_silhouettes_and_removes_noise() {
    let camera_for = |v: &Volume| looking_down_k(v, DVec3::new(23.5, 23.5, 2.0), 60.0, 48);
    let trace = |volume: Volume| {
        let camera = camera_for(&volume);
        let settings = RayPassSettings {
            tissue_hu: 0.5 * (AIR_HU + TISSUE_HU),
            ..RayPassSettings::default()
        };
        let renderer = Arc::new(Renderer::new(volume));
        RayPass::new(&renderer, &RenderSettings::default(), &settings)
            .unwrap()
            .trace(&camera, Quality::Full)
    };
    let raw = trace(fold_and_wall(0.0));
    let smoothed = smooth::smooth(&raw, 2);
    let on_fold = |d: f32| d < 25.0;
    let fold_far = raw.depth_mm.iter().copied().filter(|&d| on_fold(d));
    let fold_far = fold_far.fold(0.0f32, f32::max);
    let wall_near = raw.depth_mm.iter().copied().filter(|&d| !on_fold(d));
    let wall_near = wall_near.fold(f32::INFINITY, f32::min);
    assert!(
        fold_far < 20.0 && wall_near > 36.0,
        "{fold_far} {wall_near}"
    );
    let mut fold_pixels = 0;
    for (i, (&before, &after)) in raw.depth_mm.iter().zip(&smoothed.depth_mm).enumerate() {
        assert!(!before.is_nan() && !after.is_nan(), "pixel {i}");
        // Nothing lands in the gap, and nothing moves more than a few per cent.
        assert!(
            after <= fold_far + 0.2 || after >= wall_near - 0.2,
            "pixel {i}: {after}"
        );
        assert!(
            (after - before).abs() < 0.04 * before,
            "pixel {i}: {before} → {after}"
        );
        fold_pixels += usize::from(on_fold(before));
    }
    assert!((500..48 * 48 - 500).contains(&fold_pixels));
    // On a noisy scan the normals of the far wall turn toward the true normal (−z, into the
    // tissue is +z).
    let noisy = trace(fold_and_wall(60.0));
    let spread = |g: &GBuffer| {
        let wall = (0..g.len()).filter(|&i| g.depth_mm[i] > 36.0);
        let angles: Vec<f32> = wall
            .map(|i| Vec3::from(g.normal[i]).dot(Vec3::Z).clamp(-1.0, 1.0).acos())
            .collect();
        angles.iter().sum::<f32>() / angles.len() as f32
    };
    let (before, after) = (spread(&noisy), spread(&smooth::smooth(&noisy, 2)));
    assert!(after < 0.7 * before, "normals {before} → {after} rad");
}

#[test]
fn a_new_shading_needs_no_new_ray_pass_and_bad_looks_are_refused() {
    let (volume, _) = layered(&options(24));
    let camera = looking_down_k(&volume, DVec3::new(11.5, 11.5, 1.0), 60.0, 16);
    let pass = pass(volume, SecretionMode::On, &RenderSettings::default());
    let gbuffer = pass.trace(&camera, Quality::Full);
    let realistic = Look::of_kind(LookKind::Realistic, &PresetLook::CT).unwrap();
    let wet = shade(&gbuffer, &camera, &realistic.shading).unwrap();
    let dry = Shading {
        wetness: 0.0,
        texture: None,
        ..realistic.shading.clone()
    };
    let dry = shade(&gbuffer, &camera, &dry).unwrap();
    assert_ne!(wet.color, dry.color);
    assert!(wet.color.iter().all(|c| c.transmittance == 0.0));
    let bad = [
        Shading {
            wetness: f32::NAN,
            ..Shading::default()
        },
        Shading {
            wetness: 1.5,
            ..Shading::default()
        },
        Shading {
            attenuation_mm: Some(0.0),
            ..Shading::default()
        },
        Shading {
            texture_mm: -1.0,
            ..Shading::default()
        },
    ];
    for shading in bad {
        assert!(
            matches!(
                shade(&gbuffer, &camera, &shading),
                Err(LookError::OutOfRange { .. })
            ),
            "{shading:?}"
        );
    }
    let other = camera.with_size([8, 8]).unwrap();
    assert!(matches!(
        shade(&gbuffer, &other, &Shading::default()),
        Err(LookError::SizeMismatch { .. })
    ));
    let same = RayPassSettings {
        tissue_hu: -500.0,
        secretion_hu: -500.0,
        secretion: SecretionMode::On,
        ..RayPassSettings::default()
    };
    assert!(same.validate().is_err());
    let nan = RayPassSettings {
        tissue_hu: f64::NAN,
        ..RayPassSettings::default()
    };
    assert!(nan.validate().is_err());
    assert_eq!(LookKind::from_name(" Realistic"), Some(LookKind::Realistic));
    assert_eq!(
        SecretionMode::from_name("accumulate"),
        Some(SecretionMode::Accumulate)
    );
    assert_eq!(LookKind::from_name("photo"), None);
    assert!(Look::of_kind(LookKind::Plain, &PresetLook::CT).is_none());
}

#[test]
fn half_quality_and_stills_give_the_camera_s_size() {
    let (volume, _) = layered(&options(24));
    let camera = looking_down_k(&volume, DVec3::new(11.5, 11.5, 1.0), 60.0, 20);
    let pass = pass(volume, SecretionMode::On, &RenderSettings::default());
    let full = pass.trace(&camera, Quality::Full);
    let half = pass.trace(&camera, Quality::Half);
    assert_eq!([half.width, half.height], [20, 20]);
    let centre = 10 + 20 * 10;
    assert!((half.secretion_mm[centre] - full.secretion_mm[centre]).abs() < 0.5);
    let shading = Look::of_kind(LookKind::Realistic, &PresetLook::CT)
        .unwrap()
        .shading;
    let converged = still(&pass, &camera, &shading, None, 4).unwrap();
    let single = shade(&full, &camera, &shading).unwrap();
    assert_eq!([converged.width, converged.height], [20, 20]);
    assert_ne!(converged.color, single.color);
    // Both stages at half size, the shaded frame upsampled: the camera's size, the same
    // surface at the centre; a G-buffer larger than the camera is refused.
    let small = reduced_camera(&camera, Quality::Half.reduced_size(camera.size()));
    let low = pass.trace(&small, Quality::Full);
    assert_eq!([low.width, low.height], [10, 10]);
    let reduced = shade_reduced(&low, &camera, &shading).unwrap();
    assert_eq!([reduced.width, reduced.height], [20, 20]);
    assert!((reduced.depth_mm[centre] - full.depth_mm[centre]).abs() < 0.5);
    let (a, b) = (reduced.color[centre].rgb, single.color[centre].rgb);
    assert!(
        a.iter().zip(b).all(|(a, b)| (a - b).abs() < 0.1),
        "{a:?} {b:?}"
    );
    assert_eq!(
        shade_reduced(&full, &camera, &shading).unwrap().color,
        single.color
    );
    assert!(matches!(
        shade_reduced(&full, &small, &shading),
        Err(LookError::SizeMismatch { .. })
    ));
}

#[test]
fn a_bare_blurred_wall_has_no_secretion_film_and_a_layer_on_it_keeps_its_thickness() {
    // A wall tilted against k, its air–tissue edge blurred like a scan's (a logistic profile
    // close to a Gaussian of σ = 1.5 voxels): the value passes both thresholds on the way in,
    // over about two voxels along k, yet there is no secretion. The same wall under a
    // secretion layer 8 voxels thick keeps the layer (one under about 1.5 times the bare edge's
    // crossing of the band, 5 voxels at this blur, cannot be told from the edge and fades).
    let blurred = |d: f64, inside: f64, outside: f64| {
        outside + (inside - outside) / (1.0 + (-1.7 * d / 1.5).exp())
    };
    let wall = |layer: f64| {
        rasterize([32, 32, 48], &options(48), &move |p: DVec3| {
            let depth = (p.z - 26.0 - 0.25 * p.x) / 1.0625f64.sqrt();
            let tissue = blurred(depth, TISSUE_HU, SECRETION_HU);
            if layer > 0.0 {
                blurred(depth + layer, tissue, AIR_HU)
            } else {
                blurred(depth, TISSUE_HU, AIR_HU)
            }
        })
    };
    for mode in [SecretionMode::On, SecretionMode::Accumulate] {
        for (layer, expected) in [(0.0, 0.0), (8.0, 8.0)] {
            let volume = wall(layer);
            let camera = looking_down_k(&volume, DVec3::new(15.5, 15.5, 2.0), 40.0, 16);
            let gbuffer =
                pass(volume, mode, &RenderSettings::default()).trace(&camera, Quality::Full);
            let hits: Vec<f32> = (0..gbuffer.len())
                .filter(|i| gbuffer.hit(*i))
                .map(|i| {
                    // Along the wall's normal (the layer's thickness), not along the ray.
                    let normal = Vec3::from(gbuffer.normal[i]);
                    let dir = camera.pixel_ray(i % 16, i / 16).unwrap().dir.as_vec3();
                    gbuffer.secretion_mm[i] * normal.dot(dir).abs()
                })
                .collect();
            assert!(hits.len() > 200, "{mode:?} {layer}: {} hits", hits.len());
            let worst = hits
                .iter()
                .map(|s| (s - expected).abs())
                .fold(0.0, f32::max);
            assert!(worst < 0.5, "{mode:?}, layer {layer}: off by {worst:.2}");
        }
    }
}

/// Near-white: every channel at least this (a highlight saturating the mucosa's colour).
const NEAR_WHITE: f32 = 0.85;

/// Pixels of `frame` that are near-white, and pixels with a hit, among those `counted` picks.
fn highlights(frame: &crate::render::Frame, counted: impl Fn(usize) -> bool) -> (usize, usize) {
    let hit = |i: usize| frame.color[i].transmittance == 0.0 && counted(i);
    let white = |i: usize| hit(i) && frame.color[i].rgb.iter().all(|&c| c >= NEAR_WHITE);
    let n = frame.color.len();
    (
        (0..n).filter(|&i| white(i)).count(),
        (0..n).filter(|&i| hit(i)).count(),
    )
}

/// The realistic look of the CT preset at `wetness` (the default where `None`).
fn realistic(wetness: Option<f32>) -> Shading {
    let mut shading = Look::of_kind(LookKind::Realistic, &PresetLook::CT)
        .unwrap()
        .shading;
    shading.wetness = wetness.unwrap_or(shading.wetness);
    shading
}

#[test]
fn the_default_look_glistens_and_a_dry_one_does_not() {
    // The sinus phantom (bone-walled air cells, no secretion) from inside its right cell, and
    // the layered phantom (air over a secretion layer over tissue) from above.
    let (sinus, _) = crate::phantom::sinus(&options(48));
    let sinus_camera = looking_down_k(&sinus, DVec3::new(14.4, 19.0, 21.6), 90.0, 64);
    let (layers, _) = layered(&options(40));
    let layers_camera = looking_down_k(&layers, DVec3::new(19.5, 19.5, 2.0), 90.0, 64);
    let scenes = [
        (sinus, sinus_camera, SecretionMode::Off),
        (layers, layers_camera, SecretionMode::On),
    ];
    for (volume, camera, secretion) in scenes {
        let mut settings = Look::of_kind(LookKind::Realistic, &PresetLook::CT)
            .unwrap()
            .ray;
        settings.secretion = secretion;
        if secretion != SecretionMode::Off {
            (settings.tissue_hu, settings.secretion_hu) = (
                Layered::tissue_threshold_hu(),
                Layered::secretion_threshold_hu(),
            );
        }
        let renderer = Arc::new(Renderer::new(volume));
        let gbuffer = RayPass::new(&renderer, &RenderSettings::default(), &settings)
            .unwrap()
            .trace(&camera, Quality::Full);
        let wet = shade(&gbuffer, &camera, &realistic(None)).unwrap();
        let (white, tissue) = highlights(&wet, |_| true);
        assert!(tissue > 1000, "{secretion:?}: {tissue} tissue pixels");
        assert!(
            white * 100 >= tissue,
            "{secretion:?}: {white} highlight pixels of {tissue}"
        );
        let dry = shade(&gbuffer, &camera, &realistic(Some(0.0))).unwrap();
        assert_eq!(highlights(&dry, |_| true).0, 0, "{secretion:?}: dry");
        if secretion != SecretionMode::Off {
            // The mucus film glistens: highlights where the layer is thick, none when dry.
            let layer = |i: usize| gbuffer.secretion_mm[i] > 3.0;
            let (white, pixels) = highlights(&wet, layer);
            assert!(
                pixels > 1000 && white * 100 >= pixels,
                "{white} of {pixels}"
            );
            assert_eq!(highlights(&dry, layer).0, 0);
        }
    }
}
