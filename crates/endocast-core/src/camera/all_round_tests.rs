//! The unfolded cube and the panorama (issue 36): each face's centre looks along its axis, the
//! rays run on across every fold, every direction is seen once, pixel → ray → pixel round
//! trips, the panorama's horizon is one row and its seam continuous, and what makes no sense
//! is refused.

use super::*;
use crate::test_rng::Rng;

/// An oblique pose, so that no axis of the camera is a world axis.
fn oblique(projection: Projection, field: f64, size: [usize; 2]) -> Camera {
    Camera::look_at(
        DVec3::new(3.0, -2.0, 5.0),
        DVec3::new(4.0, 1.0, 7.0),
        DVec3::new(0.3, 0.1, 1.0),
        90.0,
        size,
    )
    .unwrap()
    .with_projection(projection, field)
    .unwrap()
}

/// A 4 : 3 cube of 15-pixel faces (odd, so each face has a centre pixel).
fn cube() -> Camera {
    oblique(Projection::Cube, 90.0, [60, 45])
}

fn axes(camera: &Camera) -> [DVec3; 3] {
    [camera.forward(), camera.right(), camera.up()]
}

/// Unit directions spread over the sphere (and some on the cube's edges and corners).
fn directions(n: usize) -> Vec<DVec3> {
    let mut rng = Rng::new(36);
    let mut out: Vec<DVec3> = (0..n).filter_map(|_| rng.vec().try_normalize()).collect();
    out.extend([DVec3::new(1.0, 1.0, 0.3), DVec3::new(1.0, -1.0, -1.0)].map(DVec3::normalize));
    out
}

#[test]
fn each_cube_face_centre_looks_along_its_axis() {
    let camera = cube();
    let layout = CubeLayout::new(camera.size());
    assert_eq!(layout.face_px, 15.0);
    for face in Face::ALL {
        let (x0, y0) = layout.corner(face);
        let ray = camera.pixel_ray(x0 as usize + 7, y0 as usize + 7).unwrap();
        let axis = face.basis(axes(&camera))[0];
        assert!(ray.dir.distance(axis) < 1e-12, "{face:?}: {:?}", ray.dir);
        assert_eq!(ray.origin, camera.eye_mm());
    }
    // The camera's own axes by name: front is forward, up is up, left is −right.
    let c = axes(&camera);
    assert_eq!(Face::Front.basis(c)[0], camera.forward());
    assert_eq!(Face::Up.basis(c)[0], camera.up());
    assert_eq!(Face::Left.basis(c)[0], -camera.right());
}

#[test]
fn cube_rays_agree_across_every_fold() {
    let camera = cube();
    let layout = CubeLayout::new(camera.size());
    let c = axes(&camera);
    // Every edge of the cube (two faces' axes) at points along it, seen on both faces.
    let mut edges = 0;
    for (i, f) in Face::ALL.into_iter().enumerate() {
        for g in Face::ALL.into_iter().skip(i + 1) {
            let (fa, ga) = (f.basis(c)[0], g.basis(c)[0]);
            if fa.dot(ga).abs() > 0.5 {
                continue; // opposite faces share no edge
            }
            edges += 1;
            let along = fa.cross(ga);
            for t in [-0.99, -0.4, 0.0, 0.7] {
                let d = (fa + ga + along * t).normalize();
                for face in [f, g] {
                    let [axis, right, up] = face.basis(c);
                    let (a, b) = (d.dot(right) / d.dot(axis), d.dot(up) / d.dot(axis));
                    let (x0, y0) = layout.corner(face);
                    // Just inside the face, so the point belongs to it and not a neighbour cell.
                    let x = x0 + (a * (1.0 - 1e-12) + 1.0) / 2.0 * layout.face_px;
                    let y = y0 + (1.0 - b * (1.0 - 1e-12)) / 2.0 * layout.face_px;
                    let seen = camera.ray(x, y).unwrap().dir;
                    assert!(
                        seen.distance(d) < 1e-9,
                        "{f:?}/{g:?} on {face:?}: {seen:?} {d:?}"
                    );
                }
            }
        }
    }
    assert_eq!(edges, 12);
    // In the image, the rays run on across every boundary two faces share in the cross.
    let s = layout.face_px;
    let (ox, oy) = layout.origin;
    let close = |p: (f64, f64), q: (f64, f64)| {
        let (a, b) = (camera.ray(p.0, p.1).unwrap(), camera.ray(q.0, q.1).unwrap());
        assert!(a.dir.distance(b.dir) < 1e-6, "{p:?} {q:?}");
    };
    for t in [0.5, 7.25, 14.5] {
        for k in 1..4 {
            let x = ox + f64::from(k) * s;
            close((x - 1e-9, oy + s + t), (x + 1e-9, oy + s + t));
        }
        for k in 1..3 {
            let y = oy + f64::from(k) * s;
            close((ox + s + t, y - 1e-9), (ox + s + t, y + 1e-9));
        }
    }
}

#[test]
fn every_direction_is_seen_by_exactly_one_cube_pixel() {
    let camera = cube();
    let c = axes(&camera);
    let [w, h] = camera.size();
    for d in directions(4000) {
        let inside = Face::ALL
            .into_iter()
            .filter(|face| {
                let [axis, right, up] = face.basis(c);
                let along = d.dot(axis);
                along > 0.0 && (d.dot(right) / along).abs() < 1.0 && (d.dot(up) / along).abs() < 1.0
            })
            .count();
        // On an edge (the two sample directions built on one) no face holds it strictly.
        assert!(inside <= 1, "{d:?} inside {inside} faces");
        let (x, y) = camera.project(camera.eye_mm() + d * 9.0).unwrap();
        assert!((0.0..=w as f64).contains(&x) && (0.0..=h as f64).contains(&y));
        let seen = camera.ray(x, y).unwrap().dir;
        assert!(
            seen.distance(d) < 1e-9,
            "{d:?} projected to ({x}, {y}) sees {seen:?}"
        );
    }
}

#[test]
fn cube_pixels_round_trip_and_empty_cells_have_no_ray() {
    let camera = cube().with_pixel_offset(0.2, -0.3);
    let [w, h] = camera.size();
    let mut with_ray = 0;
    for y in 0..h {
        for x in 0..w {
            let Some(ray) = camera.pixel_ray(x, y) else {
                continue;
            };
            with_ray += 1;
            let (px, py) = camera.project(ray.at(4.0)).unwrap();
            let (ex, ey) = (x as f64 + 0.5, y as f64 + 0.5);
            assert!(
                (px - ex).abs() < 1e-6 && (py - ey).abs() < 1e-6,
                "({x}, {y}) → ({px}, {py})"
            );
        }
    }
    assert_eq!(with_ray, 6 * 15 * 15);
    // The corners of the cross are empty; so are the bands of an image that is not 4 : 3.
    assert!(camera.pixel_ray(0, 0).is_none() && camera.pixel_ray(59, 44).is_none());
    let wide = oblique(Projection::Cube, 90.0, [100, 45]);
    assert_eq!(CubeLayout::new(wide.size()).origin, (20.0, 0.0));
    assert!(wide.pixel_ray(5, 22).is_none() && wide.pixel_ray(25, 22).is_some());
    assert!(camera.project(camera.eye_mm()).is_none());
}

#[test]
fn panorama_horizon_is_one_row_and_its_seam_is_behind() {
    let camera = oblique(Projection::Panorama, 180.0, [72, 36]);
    let [f, r, u] = axes(&camera);
    let at = |d: DVec3| camera.project(camera.eye_mm() + d * 5.0).unwrap();
    for k in 0..36 {
        let longitude = (f64::from(k) * 10.0 - 175.0).to_radians();
        let (x, y) = at(f * longitude.cos() + r * longitude.sin());
        assert!(
            (y - 18.0).abs() < 1e-9,
            "the horizon at {longitude} is row {y}"
        );
        let expected = (longitude / std::f64::consts::TAU + 0.5) * 72.0;
        assert!((x - expected).abs() < 1e-9);
    }
    // Forward in the middle, right a quarter further, up at the top, the seam behind.
    assert!(at(f).0 == 36.0 && at(r).0 == 54.0 && at(u).1.abs() < 1e-9);
    let back = at(-f + r * 1e-12).0;
    assert!((back - 72.0).abs() < 1e-6 || back.abs() < 1e-6);
    for y in [0.5, 10.0, 18.0, 30.5] {
        let (a, b) = (
            camera.ray(1e-9, y).unwrap(),
            camera.ray(72.0 - 1e-9, y).unwrap(),
        );
        assert!(a.dir.distance(b.dir) < 1e-6, "the seam jumps at row {y}");
        assert!(a.dir.dot(f) < 0.0);
    }
}

#[test]
fn panorama_pixels_round_trip_and_sees_every_direction() {
    let camera = oblique(Projection::Panorama, 180.0, [72, 36]).with_pixel_offset(-0.1, 0.4);
    for y in 0..36 {
        for x in 0..72 {
            let ray = camera.pixel_ray(x, y).unwrap();
            let (px, py) = camera.project(ray.at(3.0)).unwrap();
            let (ex, ey) = (x as f64 + 0.5, y as f64 + 0.5);
            assert!(
                (px - ex).abs() < 1e-6 && (py - ey).abs() < 1e-6,
                "({x}, {y}) → ({px}, {py})"
            );
        }
    }
    for d in directions(2000) {
        let (x, y) = camera.project(camera.eye_mm() + d).unwrap();
        assert!(camera.ray(x, y).unwrap().dir.distance(d) < 1e-9);
    }
    // A band of 120° of latitude does not see 80° up.
    let band = oblique(Projection::Panorama, 120.0, [72, 24]);
    let steep = band.forward() * 80f64.to_radians().cos() + band.up() * 80f64.to_radians().sin();
    assert!(band.project(band.eye_mm() + steep).is_none());
    assert!(band.ray(5.0, -0.5).is_none() && band.ray(5.0, 24.5).is_none());
}

#[test]
fn all_round_views_refuse_what_makes_no_sense() {
    let base = Camera::look_at(DVec3::ZERO, DVec3::Z, DVec3::Y, 90.0, [40, 30]).unwrap();
    for (projection, bad_field) in [(Projection::Cube, 100.0), (Projection::Panorama, 200.0)] {
        assert!(base.with_projection(projection, bad_field).is_err());
        assert!(base.with_projection(projection, f64::NAN).is_err());
        let field = projection.default_field().unwrap();
        let camera = base.with_projection(projection, field).unwrap();
        let distorted = Lens {
            distortion: [-0.2, 0.0],
            vignetting: 0.0,
        };
        let dark = Lens {
            distortion: [0.0; 2],
            vignetting: 0.3,
        };
        for lens in [distorted, dark] {
            assert!(matches!(
                camera.with_lens(lens),
                Err(CameraError::AllRoundLens(_))
            ));
            let lensed = base.with_lens(lens).unwrap();
            assert!(lensed.with_projection(projection, field).is_err());
        }
        let shift = EyeShift {
            offset_mm: 1.0,
            focus_mm: 20.0,
        };
        assert!(matches!(
            camera.with_eye_shift(shift),
            Err(CameraError::BadStereo(_))
        ));
        let eye = base.with_eye_shift(shift).unwrap();
        assert!(eye.with_projection(projection, field).is_err());
        // A key frame's field of view leaves the all-round field as it is.
        let optics = Optics {
            projection,
            field,
            ..Optics::default()
        };
        assert_eq!(optics.with_fov(60.0).field, field);
    }
}

#[test]
fn the_cubes_near_surface_is_a_cube() {
    let camera = cube().with_near_mm(2.0).unwrap();
    let [f, r, u] = axes(&camera);
    for axis in [f, -f, r, -r, u, -u] {
        assert!((camera.near_distance_along(axis) - 2.0).abs() < 1e-12);
    }
    let corner = (f + r + u).normalize();
    assert!((camera.near_distance_along(corner) - 2.0 * 3f64.sqrt()).abs() < 1e-9);
    let panorama = oblique(Projection::Panorama, 180.0, [8, 4])
        .with_near_mm(2.0)
        .unwrap();
    assert_eq!(panorama.near_distance_along(corner), 2.0);
}
