//! Scene geometry composited into the look by depth (issue 35, item 5): a sphere through a
//! flat wall at known depths.

use super::geometry::shows_behind;
use super::*;
use crate::camera::Ray;
use crate::phantom::profile::{paint, ramp, AIR_HU, TISSUE_HU};
use crate::phantom::{rasterize, PhantomOptions, SECRETION_HU};
use crate::render::{Camera, Frame, Quality, RenderSettings, Renderer};
use crate::scene::{Marker, Material, Scene, TriangleMesh};
use crate::Volume;
use glam::DVec3;
use std::sync::Arc;

/// The wall's surface (the mid-value of its ramp), `k` index: tissue beyond.
pub(super) const WALL_K: f64 = 20.0;
/// Pixels across the test image.
const SIZE: usize = 48;

/// A 32 × 32 × 40 volume (1 mm voxels) of air with a wall of tissue beyond `k` = [`WALL_K`],
/// and with `secretion` a layer of secretion 6 voxels thick against it.
pub(super) fn wall(secretion: bool) -> Volume {
    let options = PhantomOptions {
        size: 40,
        ..Default::default()
    };
    rasterize([32, 32, 40], &options, &move |p: DVec3| {
        let beneath = match secretion {
            true => ramp(WALL_K - 6.0 - p.z, SECRETION_HU, AIR_HU),
            false => AIR_HU,
        };
        paint(beneath, WALL_K - p.z, TISSUE_HU)
    })
}

/// The G-buffer of `volume` seen from [`camera`], the rays stopping at the air/tissue
/// mid-value (the wall's surface) and finding secretion as `secretion` says.
fn traced(volume: Volume, secretion: SecretionMode) -> (GBuffer, Camera, Volume) {
    let camera = camera(&volume);
    let pass = ray_pass(&volume, secretion);
    (pass.trace(&camera, Quality::Full), camera, volume)
}

/// A camera at voxel (15.5, 15.5, 2) of `volume` looking along +k at the wall.
pub(super) fn camera(volume: &Volume) -> Camera {
    let eye = volume.geometry().world_of(DVec3::new(15.5, 15.5, 2.0));
    Camera::look_at(eye, eye + DVec3::Z, DVec3::Y, 40.0, [SIZE, SIZE]).unwrap()
}

/// The ray pass over `volume` stopping at the wall's surface, with `secretion`.
pub(super) fn ray_pass(volume: &Volume, secretion: SecretionMode) -> RayPass {
    // The mid-values of the wall's edge and of the layer's top.
    let settings = RayPassSettings {
        tissue_hu: match secretion {
            SecretionMode::Off => 0.5 * (AIR_HU + TISSUE_HU),
            _ => 0.5 * (SECRETION_HU + TISSUE_HU),
        },
        secretion_hu: 0.5 * (AIR_HU + SECRETION_HU),
        secretion,
        ..RayPassSettings::default()
    };
    let renderer = Arc::new(Renderer::new(volume.clone()));
    RayPass::new(&renderer, &RenderSettings::default(), &settings).unwrap()
}

/// Red tissue, green secretion (a thin fog: 5 mm veil 63 %), no texture, fall-off or smoothing
/// (depths stay exact).
pub(super) fn red_and_green() -> Shading {
    Shading {
        fog_mm: 5.0,
        tissue_color: [1.0, 0.0, 0.0],
        secretion_color: [0.0, 1.0, 0.0],
        attenuation_mm: None,
        smoothing_px: 0,
        ..Shading::default()
    }
}

/// An opaque blue sphere of `radius` mm centred at voxel `(15.5, 15.5, k)` of `volume`.
pub(super) fn blue_sphere(volume: &Volume, k: f64, radius: f64) -> (Scene, DVec3, f64) {
    let centre = volume.geometry().world_of(DVec3::new(15.5, 15.5, k));
    let mut scene = Scene::new();
    let blue = Material::new([0.0, 0.0, 1.0], 1.0).unwrap();
    scene.add_marker(Marker::new(centre, radius).unwrap(), blue);
    (scene, centre, radius)
}

/// Where `ray` first meets the sphere, mm, and how far it passes inside its rim (mm; negative
/// where it misses).
fn sphere_hit(ray: &Ray, centre: DVec3, radius: f64) -> (f64, f64) {
    let to = centre - ray.origin;
    let along = to.dot(ray.dir);
    let miss2 = to.length_squared() - along * along;
    let inside = radius - miss2.sqrt();
    (along - (radius * radius - miss2).max(0.0).sqrt(), inside)
}

#[test]
fn a_sphere_through_the_wall_is_solid_in_front_and_stippled_behind() {
    let (gbuffer, camera, volume) = traced(wall(false), SecretionMode::Off);
    // Centre 4 mm behind the wall, radius 5 mm: a cap in front (9.5° around the view's
    // axis), a ring of it behind (out to 13.1°).
    let (scene, centre, radius) = blue_sphere(&volume, WALL_K + 4.0, 5.0);
    let shading = red_and_green();
    let plain = shade(&gbuffer, &camera, &shading).unwrap();
    let with = shade_with_scene(&gbuffer, &camera, &shading, Some(&scene)).unwrap();
    let counts = sphere_through_wall(&camera, [&plain, &with], &volume, (centre, radius));
    assert!(counts.iter().all(|&n| n > 40), "{counts:?}");
}

/// Checks `with`, the look's frame `plain` of [`wall`]`(false)` in `volume` seen by `camera`
/// with a sphere (`centre`, `radius`) composited, pixel by pixel against the depths along
/// `camera`'s rays: solid where the sphere lies in front of the wall, on the stipple where it
/// lies behind, the look's own pixel elsewhere. Returns how many pixels show it in front,
/// behind, hide it behind, and miss it.
pub(super) fn sphere_through_wall(
    camera: &Camera,
    [plain, with]: [&Frame; 2],
    volume: &Volume,
    (centre, radius): (DVec3, f64),
) -> [usize; 4] {
    let wall_z = volume.geometry().world_of(DVec3::new(0.0, 0.0, WALL_K)).z;
    let mut counts = [0; 4]; // in front, behind shown, behind hidden, elsewhere
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = x + SIZE * y;
            let ray = camera.pixel_ray(x, y).unwrap();
            let wall_mm = (wall_z - ray.origin.z) / ray.dir.z;
            assert!(
                (f64::from(plain.depth_mm[i]) - wall_mm).abs() < 0.02,
                "wall at {x},{y}"
            );
            let (sphere_mm, inside_mm) = sphere_hit(&ray, centre, radius);
            let (c, base) = (with.color[i], plain.color[i]);
            if inside_mm < -0.05 {
                // No sphere: the look's pixel, bit for bit.
                assert_eq!((c, with.depth_mm[i]), (base, plain.depth_mm[i]), "{x},{y}");
                counts[3] += 1;
            } else if inside_mm > 0.05 && sphere_mm < wall_mm - 0.1 {
                // In front: the sphere alone, opaque, at its depth.
                let depth = f64::from(with.depth_mm[i]);
                assert!(
                    (depth - sphere_mm).abs() < 1e-3,
                    "{x},{y}: {depth} ≠ {sphere_mm}"
                );
                assert!(c.rgb[0] == 0.0 && c.rgb[2] > 0.1, "{x},{y}: {c:?}");
                assert_eq!(c.transmittance, 0.0);
                counts[0] += 1;
            } else if inside_mm > 0.05 && sphere_mm > wall_mm + 0.1 {
                // Behind: the wall's depth; the sphere on the stipple's pixels, the wall's
                // colour on the others.
                assert_eq!(with.depth_mm[i], plain.depth_mm[i]);
                if shows_behind(x, y) {
                    assert!(c.rgb[0] < base.rgb[0] && c.rgb[2] > 0.1, "{x},{y}: {c:?}");
                    counts[1] += 1;
                } else {
                    assert_eq!(c, base, "{x},{y}");
                    counts[2] += 1;
                }
            }
        }
    }
    counts
}

#[test]
fn secretion_in_front_of_the_wall_veils_a_nearer_sphere_less() {
    let (gbuffer, camera, volume) = traced(wall(true), SecretionMode::On);
    // A sphere whose front lies 1.5–3.5 mm into the 6 mm layer.
    let (scene, centre, radius) = blue_sphere(&volume, WALL_K - 2.5, 2.0);
    let shading = red_and_green();
    let plain = shade(&gbuffer, &camera, &shading).unwrap();
    let with = shade_with_scene(&gbuffer, &camera, &shading, Some(&scene)).unwrap();
    let top_z = volume
        .geometry()
        .world_of(DVec3::new(0.0, 0.0, WALL_K - 6.0))
        .z;
    let mut checked = 0;
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = x + SIZE * y;
            let ray = camera.pixel_ray(x, y).unwrap();
            let (sphere_mm, inside_mm) = sphere_hit(&ray, centre, radius);
            if inside_mm < 0.05 {
                continue;
            }
            // The secretion between the layer's top and the sphere.
            let front_mm = sphere_mm - (top_z - ray.origin.z) / ray.dir.z;
            let [_, g, b] = with.color[i].rgb;
            let veil = g / (g + b);
            let expected = shading.fog(front_mm as f32);
            assert!(
                (veil - expected).abs() < 0.03,
                "{x},{y}: {veil} ≠ {expected}"
            );
            // The wall behind it lies under the whole layer: more veiled.
            let [r, g_wall, _] = plain.color[i].rgb;
            assert!(veil + 0.1 < g_wall / (r + g_wall), "{x},{y}");
            checked += 1;
        }
    }
    assert!(checked > 40, "{checked} pixels");
}

#[test]
fn geometry_where_no_ray_meets_tissue_is_drawn_solid_and_sets_the_depth() {
    let (gbuffer, camera, volume) = traced(wall(false), SecretionMode::Off);
    let empty = GBuffer {
        depth_mm: vec![f32::NAN; gbuffer.len()],
        ..gbuffer
    };
    let (scene, centre, radius) = blue_sphere(&volume, 10.0, 3.0);
    let frame = shade_with_scene(&empty, &camera, &red_and_green(), Some(&scene)).unwrap();
    let (ray, i) = (
        camera.pixel_ray(SIZE / 2, SIZE / 2).unwrap(),
        SIZE / 2 * (SIZE + 1),
    );
    let (sphere_mm, _) = sphere_hit(&ray, centre, radius);
    assert!((f64::from(frame.depth_mm[i]) - sphere_mm).abs() < 1e-3);
    assert_eq!(frame.color[i].transmittance, 0.0);
    assert!(frame.depth_mm[0].is_nan() && frame.color[0].transmittance == 1.0);
    // Half opaque: both of its surfaces composited, and no opaque surface to give a depth.
    let mut glass = Scene::new();
    let half = Material::new([0.0, 0.0, 1.0], 0.5).unwrap();
    glass.add_marker(Marker::new(centre, radius).unwrap(), half);
    let frame = shade_with_scene(&empty, &camera, &red_and_green(), Some(&glass)).unwrap();
    assert_eq!(frame.color[i].transmittance, 0.25);
    assert!(frame.depth_mm[i].is_nan());
}

/// A closed octahedron of half-diagonal `r` mm around `centre` (its triangles wound either way).
fn octahedron(centre: DVec3, r: f64) -> TriangleMesh {
    let corners = [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let vertices = corners.iter().map(|c| centre + *c * r).collect();
    let mut triangles = Vec::new();
    for (a, b) in [(0, 2), (2, 1), (1, 3), (3, 0)] {
        triangles.extend([[a, b, 4], [a, b, 5]]);
    }
    TriangleMesh::new(vertices, triangles).unwrap()
}

#[test]
fn a_mesh_around_the_eye_tints_the_view_instead_of_hiding_it() {
    let (gbuffer, camera, _) = traced(wall(false), SecretionMode::Off);
    let shading = red_and_green();
    let plain = shade(&gbuffer, &camera, &shading).unwrap();
    let blue = Material::new([0.0, 0.0, 1.0], 1.0).unwrap();
    let mut scene = Scene::new();
    // Around the eye (the wall 18 mm ahead lies outside it), and one behind the eye.
    scene.add_mesh(&octahedron(camera.eye_mm(), 6.0), blue);
    scene.add_mesh(
        &octahedron(camera.eye_mm() - DVec3::new(0.0, 0.0, 30.0), 1.5),
        blue,
    );
    let (outside, around) = scene.without_enclosing(camera.eye_mm());
    assert_eq!(around, [blue]);
    assert!(!outside.is_empty());
    let tinted = shade_with_scene(&gbuffer, &camera, &shading, Some(&scene)).unwrap();
    assert_eq!(tinted.depth_mm, plain.depth_mm);
    for (t, p) in tinted.color.iter().zip(&plain.color) {
        let expected = [0.7 * p.rgb[0], 0.0, 0.3 * (1.0 - p.transmittance)];
        for (t, e) in t.rgb.iter().zip(expected) {
            assert!((t - e).abs() < 1e-6, "{t} ≠ {e}");
        }
    }
}

#[test]
fn the_reduced_preview_composites_the_scene_too() {
    let (_, camera, volume) = traced(wall(false), SecretionMode::Off);
    // A sphere well in front of the wall, about the view's axis.
    let (scene, _, _) = blue_sphere(&volume, WALL_K - 8.0, 3.0);
    let shading = red_and_green();
    let small = crate::render::quality::reduced_camera(&camera, [SIZE / 2, SIZE / 2]);
    let settings = RayPassSettings {
        tissue_hu: 0.5 * (AIR_HU + TISSUE_HU),
        ..RayPassSettings::default()
    };
    let renderer = Arc::new(Renderer::new(volume));
    let pass = RayPass::new(&renderer, &RenderSettings::default(), &settings).unwrap();
    let half = pass.trace(&small, Quality::Full);
    let without = shade_reduced(&half, &camera, &shading).unwrap();
    let with = shade_reduced_with_scene(&half, &camera, &shading, Some(&scene)).unwrap();
    assert_eq!([with.width, with.height], [SIZE, SIZE]);
    let centre = SIZE / 2 + SIZE * (SIZE / 2);
    assert!(
        without.color[centre].rgb[2] < 0.01,
        "{:?}",
        without.color[centre]
    );
    let c = with.color[centre];
    assert!(c.rgb[2] > 0.1, "no sphere in the preview: {c:?}");
    assert!(with.depth_mm[centre] < without.depth_mm[centre] - 5.0);
    // Beside the sphere, the preview is the look's own.
    assert_eq!(with.color[0], without.color[0]);
}
