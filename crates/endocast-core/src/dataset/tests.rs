use super::*;
use crate::camera::{EyeShift, Lens, Projection};
use crate::phantom::{self, PhantomOptions};
use crate::render::{Mode, RenderSettings, Renderer};
use glam::DVec3;
use std::sync::Arc;

/// A camera at `eye` looking along +x with up +z (L, S), `w × h` pixels.
fn camera(projection: Projection, field: f64, lens: Lens, [w, h]: [usize; 2]) -> Camera {
    let eye = DVec3::new(3.0, -2.0, 5.0);
    Camera::look_at(
        eye,
        eye + DVec3::new(1.0, 0.2, -0.1),
        DVec3::Z,
        90.0,
        [w, h],
    )
    .unwrap()
    .with_projection(projection, field)
    .unwrap()
    .with_lens(lens)
    .unwrap()
}

/// Points spread through the view of a camera at (3, −2, 5) looking along +x.
fn points() -> impl Iterator<Item = DVec3> {
    (0..200).map(|n| {
        let n = f64::from(n);
        DVec3::new(3.0, -2.0, 5.0)
            + DVec3::new(
                20.0 + (n * 0.37).sin() * 10.0,
                (n * 1.3).sin() * 15.0,
                (n * 0.71).cos() * 12.0,
            )
    })
}

#[test]
fn the_intrinsics_and_extrinsics_project_as_the_camera_does() {
    let barrel = Lens {
        distortion: [-0.166, 0.0246],
        vignetting: 0.0,
    };
    let cases = [
        (Projection::Pinhole, 70.0, Lens::default(), [64, 48]),
        (Projection::Pinhole, 100.0, barrel, [40, 50]),
        (Projection::Equidistant, 170.0, Lens::default(), [64, 64]),
        (Projection::Equidistant, 120.0, barrel, [80, 60]),
    ];
    for (projection, field, lens, size) in cases {
        let camera = camera(projection, field, lens, size);
        let intrinsics = Intrinsics::of(&camera).unwrap();
        let pose = Extrinsics::of(&camera).unwrap();
        assert_eq!(intrinsics.fx, intrinsics.fy);
        assert_eq!(
            [intrinsics.cx, intrinsics.cy],
            [size[0] as f64 / 2.0, size[1] as f64 / 2.0]
        );
        let mut compared = 0;
        for p in points() {
            let Some((x, y)) = camera.project(p) else {
                continue;
            };
            let (u, v) = intrinsics.project(pose.to_camera(p)).unwrap();
            assert!(
                (u - x).abs() < 1e-6 && (v - y).abs() < 1e-6,
                "{projection:?} {lens:?}: ({u}, {v}) against ({x}, {y})"
            );
            compared += 1;
        }
        assert!(compared > 100, "{compared}");
    }
}

#[test]
fn the_pinhole_focal_length_is_half_the_height_over_the_tangent() {
    let camera = camera(Projection::Pinhole, 90.0, Lens::default(), [30, 20]);
    let intrinsics = Intrinsics::of(&camera).unwrap();
    assert!((intrinsics.fx - 10.0).abs() < 1e-12);
    assert_eq!(intrinsics.model.name(), "OPENCV");
    let fisheye = camera
        .with_projection(Projection::Equidistant, 180.0)
        .unwrap();
    let intrinsics = Intrinsics::of(&fisheye).unwrap();
    assert!((intrinsics.fx - 10.0 / std::f64::consts::FRAC_PI_2).abs() < 1e-12);
    assert_eq!(intrinsics.model.name(), "OPENCV_FISHEYE");
}

#[test]
fn cameras_without_a_model_are_refused() {
    let base = camera(Projection::Pinhole, 90.0, Lens::default(), [16, 16]);
    for (projection, field) in [
        (Projection::Equisolid, 180.0),
        (Projection::Orthographic, 50.0),
        (Projection::Cube, 90.0),
        (Projection::Panorama, 180.0),
    ] {
        let camera = base.with_projection(projection, field).unwrap();
        let error = Intrinsics::of(&camera).unwrap_err();
        assert_eq!(error, DatasetError::Projection(projection.name()));
        assert!(error.to_string().contains(projection.name()));
    }
    let shift = EyeShift {
        offset_mm: 1.0,
        focus_mm: 30.0,
    };
    let eye = base.with_eye_shift(shift).unwrap();
    assert_eq!(Intrinsics::of(&eye), Err(DatasetError::Stereo));
    assert_eq!(Extrinsics::of(&eye), Err(DatasetError::Stereo));
}

#[test]
fn the_colmap_rotation_is_the_inverse_of_the_nerfstudio_one() {
    let camera = camera(Projection::Pinhole, 60.0, Lens::default(), [8, 8]);
    let pose = Extrinsics::of(&camera).unwrap();
    let ([w, x, y, z], t) = pose.world_to_camera_opencv();
    let q = glam::DQuat::from_xyzw(x, y, z, w);
    let m = pose.camera_to_world_opengl();
    for p in points().take(10) {
        let colmap = q * p + DVec3::from(t);
        // OpenGL camera → world by the rows of `m`, then GL → CV (flip y and z).
        let gl = DVec3::new(colmap.x, -colmap.y, -colmap.z);
        let row = |r: [f64; 4]| r[0] * gl.x + r[1] * gl.y + r[2] * gl.z + r[3];
        let back = DVec3::new(row(m[0]), row(m[1]), row(m[2]));
        assert!(back.distance(p) < 1e-9, "{back} {p}");
        assert!(colmap.distance(pose.to_camera(p)) < 1e-9);
    }
    assert!(w >= 0.0);
}

#[test]
fn depth_codes_have_a_round_scale_and_keep_no_wall_apart() {
    assert!((depth_scale_mm(655.0) - 0.01).abs() < 1e-15);
    assert!((depth_scale_mm(656.0) - 0.02).abs() < 1e-15);
    assert!((depth_scale_mm(100.0) - 0.002).abs() < 1e-15);
    let codes = depth_to_u16(&[f32::NAN, 0.0, 1.234, 1e9], 0.01);
    assert_eq!(codes, [0, 1, 123, DEPTH_CODES]);
}

#[test]
fn on_the_sphere_shell_the_normals_face_the_eye_at_its_centre() {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 40,
        ..Default::default()
    });
    let centre = volume.geometry().world_of(shell.centre_vox);
    let camera = Camera::look_at(
        centre,
        centre + DVec3::new(1.0, 0.3, 0.2),
        DVec3::Z,
        100.0,
        [24, 18],
    )
    .unwrap();
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu: -480.0,
        ..Default::default()
    };
    let renderer = Arc::new(Renderer::new(volume));
    let frame = renderer.prepare(&settings).unwrap().render(&camera);
    let layers = FrameLayers::new(&camera, &frame.depth_mm, renderer.volume());
    assert!(layers.mask().iter().all(|&m| m == 255));
    let pose = Extrinsics::of(&camera).unwrap();
    for (i, n) in layers.normal_camera.iter().enumerate() {
        let ray = camera.pixel_ray(i % 24, i / 24).unwrap();
        let toward_eye = pose.to_camera(camera.eye_mm() - ray.dir);
        let n = DVec3::new(f64::from(n[0]), f64::from(n[1]), f64::from(n[2]));
        // Central differences on a 14-voxel sphere: within 5° of the radius.
        assert!(
            n.dot(toward_eye) > 0.996,
            "pixel {i}: {n} against {toward_eye}"
        );
        let along = ray.dir.dot(camera.forward()) * f64::from(layers.depth_ray_mm[i]);
        assert!((f64::from(layers.depth_z_mm[i]) - along).abs() < 1e-4);
        assert!(f64::from(layers.depth_z_mm[i]) < f64::from(layers.depth_ray_mm[i]) + 1e-4);
    }
}
