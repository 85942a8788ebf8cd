//! The camera against the VTK peer's convention and the analytic projections.

use super::*;

#[test]
fn follows_the_peer_convention() {
    // The peers' default: eye (128,128,10) looking along +z with up +y, 90° vertical fov.
    let cam = Camera::look_at(
        DVec3::new(128.0, 128.0, 10.0),
        DVec3::new(128.0, 128.0, 11.0),
        DVec3::Y,
        90.0,
        [512, 256],
    )
    .unwrap();
    assert_eq!(cam.right(), DVec3::Z.cross(DVec3::Y)); // −x
                                                       // A point 45° up from the axis lands on the top edge; 45° right (of a 2:1 image whose
                                                       // horizontal half-tangent is 2) lands a quarter of the width from the centre.
    let (x, y) = cam.project(DVec3::new(128.0, 138.0, 20.0)).unwrap();
    assert!((x - 256.0).abs() < 1e-9 && y.abs() < 1e-9);
    let (x, y) = cam.project(DVec3::new(118.0, 128.0, 20.0)).unwrap();
    assert!((x - 384.0).abs() < 1e-9 && (y - 128.0).abs() < 1e-9);
    let ray = cam.ray(100.0, 30.0).unwrap();
    let (x, y) = cam.project(ray.at(7.0)).unwrap();
    assert!((x - 100.0).abs() < 1e-9 && (y - 30.0).abs() < 1e-9);
    assert!(cam.project(DVec3::new(128.0, 128.0, 0.0)).is_none());
    assert!((cam.fov_deg() - 90.0).abs() < 1e-9);
}

#[test]
fn rejects_bad_cameras() {
    let ok = |eye, at, up, fov, size| Camera::look_at(eye, at, up, fov, size);
    let (e, a) = (DVec3::ZERO, DVec3::Z);
    assert!(ok(e, a, DVec3::Y, 90.0, [4, 4]).is_ok());
    assert!(ok(DVec3::NAN, a, DVec3::Y, 90.0, [4, 4]).is_err());
    assert!(ok(e, e, DVec3::Y, 90.0, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::Z, 90.0, [4, 4]).is_err());
    assert!(ok(e, a, -DVec3::Z * 3.0, 90.0, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::ZERO, 90.0, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::Y, 9.0, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::Y, 171.0, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::Y, f64::NAN, [4, 4]).is_err());
    assert!(ok(e, a, DVec3::Y, 90.0, [0, 4]).is_err());
    let cam = ok(e, a, DVec3::Y, 170.0, [4, 4]).unwrap();
    assert!(cam.with_near_mm(-1.0).is_err());
    assert!(cam.with_near_mm(f64::INFINITY).is_err());
    let near = cam.with_near_mm(2.0).unwrap();
    assert!((near.near_distance_along(DVec3::Z) - 2.0).abs() < 1e-12);
}

/// A camera at the origin looking along +z with up +y, `size` pixels.
fn axial(size: [usize; 2]) -> Camera {
    Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0, size).unwrap()
}

/// One of every kind of camera: projections, lenses, stereo eyes, a sub-pixel offset.
fn every_camera() -> Vec<Camera> {
    let base = axial([64, 48]);
    let lens = Lens {
        distortion: [-0.2, 0.03],
        vignetting: 0.4,
    };
    let rig = StereoRig {
        eye_separation_mm: 1.5,
        focus_mm: 12.0,
    };
    let mut cameras = vec![base, base.with_lens(lens).unwrap()];
    for (projection, field) in [
        (Projection::Equidistant, 200.0),
        (Projection::Equidistant, 90.0),
        (Projection::Equisolid, 180.0),
        (Projection::Orthographic, 30.0),
    ] {
        let camera = base.with_projection(projection, field).unwrap();
        cameras.extend([camera, camera.with_lens(lens).unwrap()]);
    }
    for camera in [base, cameras[2]] {
        cameras.extend(rig.eyes(&camera).unwrap());
    }
    cameras.push(base.with_pixel_offset(0.25, -0.375));
    cameras
}

#[test]
fn every_projection_round_trips_pixel_ray_pixel() {
    for camera in every_camera() {
        let [w, h] = camera.size();
        let mut rays = 0;
        for y in 0..=4 * h {
            for x in 0..=4 * w {
                let (x, y) = (x as f64 / 4.0, y as f64 / 4.0);
                let Some(ray) = camera.ray(x, y) else {
                    continue;
                };
                assert!((ray.dir.length() - 1.0).abs() < 1e-12);
                for t in [0.5, 7.0, 300.0] {
                    let (px, py) = camera.project(ray.at(t)).expect("a ray's point is seen");
                    let error = (px - x).hypot(py - y);
                    assert!(error < 1e-4, "{camera:?}: ({x}, {y}) at {t} mm: {error} px");
                }
                rays += 1;
            }
        }
        // A fisheye's circle covers π/4 of the height² square; everything else all.
        assert!(rays > (4 * w * 4 * h) / 3, "{camera:?}: {rays} rays");
    }
}

#[test]
fn fisheye_angles_follow_their_formulas() {
    for (projection, field) in [
        (Projection::Equidistant, 200.0),
        (Projection::Equisolid, 200.0),
    ] {
        let camera = axial([101, 101])
            .with_projection(projection, field)
            .unwrap();
        let half = f64::to_radians(field / 2.0);
        for r in [0.0, 0.25, 0.5, 0.9, 1.0] {
            let ray = camera.ray(50.5 + 50.5 * r, 50.5).unwrap();
            let theta = ray.dir.angle_between(DVec3::Z);
            let expected = match projection {
                Projection::Equidistant => r * half,
                _ => 2.0 * (r * (half / 2.0).sin()).asin(),
            };
            assert!((theta - expected).abs() < 1e-12, "{projection:?} r {r}");
            // Toward the image's right: −x here (right = forward × up).
            assert!(r == 0.0 || ray.dir.x < 0.0);
        }
        assert!(
            camera.ray(101.0, 101.0).is_none(),
            "a corner lies outside the circle"
        );
        assert!(camera.project(DVec3::new(0.0, 0.0, -1.0)).is_none());
        assert!(
            camera.project(DVec3::new(0.0, 1.0, -0.1)).is_some(),
            "behind 90° is seen"
        );
    }
    let bad = axial([8, 8]).with_projection(Projection::Equidistant, 400.0);
    assert!(bad.is_err());
    assert!(axial([8, 8])
        .with_projection(Projection::Pinhole, 180.0)
        .is_err());
    assert!(axial([8, 8])
        .with_projection(Projection::Orthographic, f64::NAN)
        .is_err());
    let nan_lens = Lens {
        distortion: [f64::NAN, 0.0],
        vignetting: 0.0,
    };
    assert!(axial([8, 8]).with_lens(nan_lens).is_err());
}

#[test]
fn stereo_eyes_are_off_axis_with_zero_parallax_on_the_focus_plane() {
    let centre = axial([80, 60]);
    let rig = StereoRig {
        eye_separation_mm: 2.0,
        focus_mm: 20.0,
    };
    let [left, right] = rig.eyes(&centre).unwrap();
    // Off-axis, not toe-in: both eyes look along the centre's axis, from ±e/2 along right.
    assert_eq!(left.forward(), centre.forward());
    let left_eye = left.ray(40.0, 30.0).unwrap().origin;
    assert!((left_eye - centre.eye_mm() + centre.right()).length() < 1e-12);
    // Each eye's ray passes through the centre ray's point on the focus plane.
    for &(x, y) in &[(3.5, 7.5), (40.0, 30.0), (71.25, 55.0)] {
        let c = centre.ray(x, y).unwrap();
        let on_plane = c.at(rig.focus_mm / c.dir.dot(centre.forward()));
        for eye in [left, right] {
            let r = eye.ray(x, y).unwrap();
            let off_ray = (on_plane - r.origin).cross(r.dir).length();
            assert!(off_ray < 1e-9, "({x}, {y}): {off_ray} mm off the ray");
        }
    }
    // Disparity: zero on the focus plane, uncrossed and growing behind it, as the formula.
    for depth in [20.0, 30.0, 60.0, 500.0] {
        let p = DVec3::new(3.0, -2.0, depth);
        let (xl, yl) = left.project(p).unwrap();
        let (xr, yr) = right.project(p).unwrap();
        assert!((yl - yr).abs() < 1e-9, "rows stay rows");
        let expected = disparity_px(&centre, &rig, depth);
        assert!(
            (xr - xl - expected).abs() < 1e-9,
            "{depth}: {} vs {expected}",
            xr - xl
        );
        assert!(depth == 20.0 && expected.abs() < 1e-9 || depth > 20.0 && expected > 0.0);
    }
    let ortho = centre
        .with_projection(Projection::Orthographic, 10.0)
        .unwrap();
    assert!(rig.eyes(&ortho).is_err());
    assert!(StereoRig::focused_at(0.0).eyes(&centre).is_err());
}

#[test]
fn vignetting_darkens_the_corners_only_as_asked() {
    let camera = axial([40, 40]);
    assert_eq!(camera.vignetting(0.0, 0.0), 1.0);
    let lens = Lens {
        distortion: [0.0; 2],
        vignetting: 0.5,
    };
    let dark = camera.with_lens(lens).unwrap();
    assert_eq!(dark.vignetting(20.0, 20.0), 1.0);
    assert!((dark.vignetting(0.0, 0.0) - 0.5).abs() < 1e-12);
}

#[test]
fn optics_make_the_camera_look_at_makes() {
    let (eye, at) = (DVec3::new(1.0, 2.0, 3.0), DVec3::new(4.0, -1.0, 9.0));
    let plain = Camera::look_at(eye, at, DVec3::Z, 70.0, [33, 21]).unwrap();
    let optics = Optics {
        field: 70.0,
        ..Optics::default()
    };
    assert_eq!(optics.camera(eye, at, DVec3::Z, [33, 21]).unwrap(), plain);
    let fisheye = Optics {
        projection: Projection::Equisolid,
        field: 220.0,
        near_mm: 1.0,
        ..Optics::default()
    };
    let camera = fisheye.camera(eye, at, DVec3::Z, [33, 21]).unwrap();
    assert_eq!((camera.field(), camera.near_mm()), (220.0, 1.0));
}
