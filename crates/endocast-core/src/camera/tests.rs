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
