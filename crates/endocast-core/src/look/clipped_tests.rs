//! The colour overlay where the view starts inside the tissue (issue 35, item 5; Krüger et al.
//! §4.4): a flat wall, the eye in front of it with a near sphere reaching into it, and the eye
//! inside it.

use super::clipped::{CLIPPED_COLOR, CLIPPED_SHARE};
use super::geometry_tests::wall;
use super::*;
use crate::camera::Projection;
use crate::phantom::profile::{AIR_HU, TISSUE_HU};
use crate::render::{Camera, Quality, RenderSettings, Renderer};
use crate::Volume;
use glam::DVec3;
use std::sync::Arc;

/// The wall's surface, `k` index (tissue beyond), as `wall` paints it.
const SURFACE_K: f64 = 20.0;
/// Pixels across the test image.
const SIZE: usize = 48;

/// A 180° equidistant fisheye at voxel `(15.5, 15.5, k)` looking along +k at the wall, rays
/// starting on a sphere of `near_mm` around the eye.
fn fisheye(volume: &Volume, k: f64, near_mm: f64) -> Camera {
    let eye = volume.geometry().world_of(DVec3::new(15.5, 15.5, k));
    Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, 90.0, [SIZE, SIZE])
        .unwrap()
        .with_projection(Projection::Equidistant, 180.0)
        .unwrap()
        .with_near_mm(near_mm)
        .unwrap()
}

/// The G-buffer of `camera` over `volume`, the rays stopping at the wall's mid-value.
fn traced(volume: &Volume, camera: &Camera) -> GBuffer {
    let settings = RayPassSettings {
        tissue_hu: 0.5 * (AIR_HU + TISSUE_HU),
        secretion_hu: 0.75 * AIR_HU + 0.25 * TISSUE_HU,
        ..RayPassSettings::default()
    };
    let renderer = Arc::new(Renderer::new(volume.clone()));
    let pass = RayPass::new(&renderer, &RenderSettings::default(), &settings).unwrap();
    pass.trace(camera, Quality::Full)
}

#[test]
fn a_near_sphere_reaching_into_the_wall_clips_exactly_the_rays_that_start_beyond_it() {
    let volume = wall(false);
    // The eye 6 mm in front of the surface, the near sphere 12 mm around it: a ray at angle θ
    // to the view axis starts in the tissue where 12 cos θ > 6, inside a cone of 60°.
    let camera = fisheye(&volume, SURFACE_K - 6.0, 12.0);
    let gbuffer = traced(&volume, &camera);
    assert_eq!(gbuffer.clipped.len(), SIZE * SIZE);
    let (mut clipped, mut checked) = (0u32, 0u32);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let Some(ray) = camera.pixel_ray(x, y) else {
                assert!(!gbuffer.clipped[x + SIZE * y], "({x}, {y}) has no ray");
                continue;
            };
            let beyond = 12.0 * ray.dir.z - 6.0;
            if beyond.abs() < 0.05 {
                continue; // on the cone itself
            }
            checked += 1;
            assert_eq!(gbuffer.clipped[x + SIZE * y], beyond > 0.0, "({x}, {y})");
            clipped += u32::from(beyond > 0.0);
        }
    }
    // The cone holds (60 / 90)² of the image circle's pixels.
    let share = f64::from(clipped) / f64::from(checked);
    assert!((share - 4.0 / 9.0).abs() < 0.05, "{share}");
}

#[test]
fn the_eye_in_the_air_clips_nothing_and_the_eye_in_the_tissue_clips_every_ray() {
    let volume = wall(false);
    let open = traced(&volume, &fisheye(&volume, SURFACE_K - 6.0, 0.0));
    assert!(open.clipped.is_empty());
    let buried = fisheye(&volume, SURFACE_K + 4.0, 0.0);
    let gbuffer = traced(&volume, &buried);
    let rays = (0..SIZE * SIZE).filter(|i| buried.pixel_ray(i % SIZE, i / SIZE).is_some());
    assert!(rays.clone().count() > SIZE * SIZE / 2);
    assert!(rays.clone().all(|i| gbuffer.clipped[i]));
}

#[test]
fn the_overlay_tints_the_clipped_pixels_and_leaves_the_others_as_they_were() {
    let volume = wall(false);
    let camera = fisheye(&volume, SURFACE_K - 6.0, 12.0);
    let gbuffer = traced(&volume, &camera);
    let shading = Shading::default();
    let tinted = shade(&gbuffer, &camera, &shading).unwrap();
    let plain = shade(
        &GBuffer {
            clipped: Vec::new(),
            ..gbuffer.clone()
        },
        &camera,
        &shading,
    )
    .unwrap();
    for (i, (t, p)) in tinted.color.iter().zip(&plain.color).enumerate() {
        if gbuffer.clipped[i] {
            for ((t, p), overlay) in t.rgb.iter().zip(p.rgb).zip(CLIPPED_COLOR) {
                let expected = p + CLIPPED_SHARE * (overlay - p);
                assert!((t - expected).abs() < 1e-6, "pixel {i}");
            }
            assert_eq!(t.transmittance, 0.0);
        } else {
            assert_eq!(t, p, "pixel {i}");
        }
    }
}
