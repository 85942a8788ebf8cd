//! The renderer through every camera (issue 16): fisheye views of the sphere and tube phantoms
//! against their analytic images, stereo disparity measured on rendered images, and the
//! four-ray set-up against the one-ray trace for every projection, lens and eye.

use super::*;
use crate::camera::{disparity_px, Lens, Projection, StereoRig};
use crate::phantom::profile::{ramp, AIR_HU, TISSUE_HU};
use crate::phantom::{self, PhantomOptions};
use glam::DVec3;

/// The phantoms' air/tissue boundary value.
const WALL_HU: f64 = -480.0;

fn iso() -> RenderSettings {
    RenderSettings {
        mode: Mode::Iso,
        iso_hu: WALL_HU,
        ..Default::default()
    }
}

/// A camera at voxel `eye_vox` of `volume` looking along voxel axis `+k`, up `+j`.
fn along_k(volume: &Volume, eye_vox: DVec3, size: usize) -> Camera {
    let g = volume.geometry();
    let eye = g.world_of(eye_vox);
    let forward = g.world_of(eye_vox + DVec3::Z) - eye;
    let up = g.world_of(eye_vox + DVec3::Y) - eye;
    Camera::look_at(eye, eye + forward, up, 90.0, [size, size]).unwrap()
}

#[test]
fn a_180_degree_fisheye_from_the_sphere_centre_sees_the_shell_at_its_radius() {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    let camera = along_k(&volume, shell.centre_vox, 33)
        .with_projection(Projection::Equidistant, 180.0)
        .unwrap();
    let renderer = Arc::new(Renderer::new(volume));
    let frame = renderer.prepare(&iso()).unwrap().render(&camera);
    let (mut seen, mut worst) = (0, 0.0f64);
    for y in 0..33 {
        for x in 0..33 {
            let depth = f64::from(frame.depth_mm[x + 33 * y]);
            if camera.pixel_ray(x, y).is_none() {
                assert!(depth.is_nan() && frame.color[x + 33 * y].alpha() == 0.0);
                continue;
            }
            worst = worst.max((depth - shell.inner_radius_vox).abs());
            seen += 1;
        }
    }
    assert!(worst < 0.05, "depth off the radius by {worst} voxel");
    // The image circle: π/4 of the square, give or take its edge.
    assert!((f64::from(seen) / (33.0 * 33.0) - std::f64::consts::FRAC_PI_4).abs() < 0.03);
}

/// Whether the ray from `eye_vox` along the fisheye direction of image point `(x, y)` (the
/// equidistant formula, worked out here independently of `Camera::ray`) leaves the straight
/// tube through its far end.
fn through_the_far_end(eye_vox: DVec3, tube: &phantom::Tube, last_k: f64, x: f64, y: f64) -> bool {
    let (w, half) = (65.0, std::f64::consts::FRAC_PI_2);
    let (u, v) = (2.0 * x / w - 1.0, 1.0 - 2.0 * y / w);
    let r = u.hypot(v);
    let theta = r * half;
    // right = forward × up = k × j = −i.
    let (sin, cos) = theta.sin_cos();
    let dir = if r == 0.0 {
        DVec3::Z
    } else {
        DVec3::new(-sin * u / r, sin * v / r, cos)
    };
    if dir.z <= 1e-9 {
        return false;
    }
    let at_face = eye_vox + dir * ((last_k - eye_vox.z) / dir.z);
    let axis = tube.centreline.points()[0];
    (at_face - axis).truncate().length() < tube.radius_vox
}

#[test]
fn a_straight_tube_through_the_fisheye_is_a_circle_on_axis_and_bends_off_axis() {
    let (volume, tube) = phantom::straight_tube(&PhantomOptions {
        size: 64,
        ..Default::default()
    });
    let last_k = (volume.dims()[2] - 1) as f64;
    let axis = tube.centreline.points()[0];
    let renderer = Arc::new(Renderer::new(volume));
    let prepared = renderer.prepare(&iso()).unwrap();
    for offset in [DVec3::ZERO, DVec3::new(6.0, 3.0, 0.0)] {
        let eye_vox = DVec3::new(axis.x, axis.y, last_k - 20.0) + offset;
        let camera = along_k(renderer.volume(), eye_vox, 65)
            .with_projection(Projection::Equidistant, 180.0)
            .unwrap();
        let frame = prepared.render(&camera);
        let (mut open, mut wrong) = (0, 0);
        for y in 0..65 {
            for x in 0..65 {
                let (cx, cy) = (x as f64 + 0.5, y as f64 + 0.5);
                if camera.ray(cx, cy).is_none() {
                    continue;
                }
                let expected = through_the_far_end(eye_vox, &tube, last_k, cx, cy);
                let missed = frame.depth_mm[x + 65 * y].is_nan();
                open += usize::from(expected);
                // Pixels the analytic edge passes within 0.75 px of may go either way.
                let near_edge = [(-0.75, 0.0), (0.75, 0.0), (0.0, -0.75), (0.0, 0.75)]
                    .iter()
                    .any(|(dx, dy)| {
                        through_the_far_end(eye_vox, &tube, last_k, cx + dx, cy + dy) != expected
                    });
                if missed != expected && !near_edge {
                    wrong += 1;
                }
            }
        }
        assert_eq!(wrong, 0, "offset {offset}: pixels off the analytic image");
        assert!(open > 200, "offset {offset}: {open} pixels see the far end");
        if offset == DVec3::ZERO {
            // On the axis the far end is a disc around the centre: its edge radius is
            // θ/φ · 32.5 px with tan θ = R / 20.
            let edge = (tube.radius_vox / 20.0).atan() / std::f64::consts::FRAC_PI_2 * 32.5;
            let disc = std::f64::consts::PI * edge * edge;
            assert!((open as f64 - disc).abs() < 2.0 * std::f64::consts::PI * edge);
        }
    }
}

#[test]
fn stereo_disparity_on_rendered_images_follows_the_off_axis_formula() {
    // Three balls of 2.5 voxels (1 mm) at depths 20 (the focus), 35 and 55 mm ahead of the eye.
    let balls = [
        DVec3::new(24.0, 32.0, 22.0),
        DVec3::new(33.0, 32.0, 37.0),
        DVec3::new(40.0, 36.0, 57.0),
    ];
    let eye_vox = DVec3::new(32.0, 32.0, 2.0);
    let options = PhantomOptions {
        size: 64,
        ..Default::default()
    };
    let volume = phantom::rasterize([64, 64, 64], &options, &|p: DVec3| {
        let d = balls
            .iter()
            .map(|c| p.distance(*c) - 2.5)
            .fold(f64::INFINITY, f64::min);
        ramp(d, TISSUE_HU, AIR_HU)
    });
    let centre = along_k(&volume, eye_vox, 128)
        .with_projection(Projection::Pinhole, 60.0)
        .unwrap();
    let rig = StereoRig {
        eye_separation_mm: 2.0,
        focus_mm: 20.0,
    };
    let renderer = Arc::new(Renderer::new(volume));
    let prepared = renderer.prepare(&iso()).unwrap();
    let [left, right] = rig.eyes(&centre).unwrap().map(|eye| prepared.render(&eye));
    for ball in balls {
        let z = ball.z - eye_vox.z;
        let centroid = |frame: &Frame| {
            let (mut sum, mut n) = (0.0, 0.0);
            for (i, d) in frame.depth_mm.iter().enumerate() {
                if (f64::from(*d) - z).abs() < 6.0 {
                    sum += (i % 128) as f64 + 0.5;
                    n += 1.0;
                }
            }
            assert!(n > 20.0, "ball at {z} mm: {n} pixels");
            sum / n
        };
        let measured = centroid(&right) - centroid(&left);
        // The outline is the ball's silhouette circle, r²/z nearer than its centre.
        let expected = disparity_px(&centre, &rig, z - 2.5 * 2.5 / z);
        assert!(
            (measured - expected).abs() < 0.15,
            "ball at {z} mm: disparity {measured} px, formula {expected} px"
        );
        if z == rig.focus_mm {
            assert!(measured.abs() < 0.4, "near zero on the focus plane");
        } else {
            assert!(measured > 3.0, "behind the focus plane: uncrossed");
        }
    }
}

/// Tile-rendered frames (rays set up four at a time) equal the one-ray trace, pixel for pixel,
/// for every projection, lens, stereo eye and sub-pixel offset.
#[test]
fn every_camera_gives_the_one_ray_pixels() {
    let (volume, tube) = phantom::straight_tube(&PhantomOptions {
        size: 48,
        ..Default::default()
    });
    let eye_vox = tube.centreline.point_at(6.0) + DVec3::new(2.0, -1.0, 0.0);
    let base = along_k(&volume, eye_vox, 8).with_size([37, 23]).unwrap();
    let lens = Lens {
        distortion: [-0.25, 0.05],
        vignetting: 0.5,
    };
    let fisheye = base
        .with_projection(Projection::Equidistant, 200.0)
        .unwrap();
    let rig = StereoRig {
        eye_separation_mm: 1.0,
        focus_mm: 8.0,
    };
    let mut cameras = vec![
        base.with_lens(lens).unwrap(),
        fisheye.with_lens(lens).unwrap().with_near_mm(1.5).unwrap(),
        base.with_projection(Projection::Equisolid, 170.0).unwrap(),
        base.with_projection(Projection::Orthographic, 18.0)
            .unwrap()
            .with_near_mm(0.5)
            .unwrap(),
        base.with_pixel_offset(0.3, -0.2),
    ];
    cameras.extend(rig.eyes(&base).unwrap());
    cameras.extend(rig.eyes(&fisheye).unwrap());
    let renderer = Arc::new(Renderer::new(volume));
    for (mode, jitter) in [(Mode::Iso, false), (Mode::Hybrid, true), (Mode::Dvr, false)] {
        let settings = RenderSettings {
            mode,
            jitter,
            iso_opacity: 0.6,
            tf: TransferFunction::preset("complex").unwrap(),
            ..iso()
        };
        let prepared = renderer.prepare(&settings).unwrap();
        for camera in &cameras {
            let frame = prepared.render(camera);
            let [w, h] = camera.size();
            for (y, x) in (0..h).flat_map(|y| (0..w).map(move |x| (y, x))) {
                let trace = prepared.trace_pixel(camera, x, y);
                let (i, what) = (x + w * y, format!("{mode:?} {camera:?} ({x}, {y})"));
                assert_eq!(trace.rgb, frame.pixel(x, y, settings.background), "{what}");
                assert_eq!(trace.alpha, frame.color[i].alpha(), "{what}");
                assert_eq!(
                    trace.depth_mm.to_bits(),
                    frame.depth_mm[i].to_bits(),
                    "{what}"
                );
            }
        }
    }
}

/// The right eye rendered with the searches the left eye's emptiness allows is the right eye
/// rendered alone, bit for bit, with far fewer samples; modes that composite in front of the
/// surface, and eyes the sharing does not cover, fall back to plain renders.
#[test]
fn the_second_eye_starts_late_and_gives_the_same_image() {
    use super::tests::{assert_same_image, colon_view};
    let (renderer, camera) = colon_view(160, 0.3, 96);
    let rig = StereoRig {
        eye_separation_mm: 1.0,
        focus_mm: 12.0,
    };
    let [left, right] = rig.eyes(&camera).unwrap();
    for (mode, opacity, jitter) in [
        (Mode::Iso, 1.0, false),
        (Mode::Hybrid, 0.6, true),
        (Mode::Hybrid, 0.3, false),
        (Mode::Dvr, 1.0, false),
    ] {
        let settings = RenderSettings {
            mode,
            iso_opacity: opacity,
            jitter,
            tf: TransferFunction::preset("complex").unwrap(),
            ..iso()
        };
        let prepared = renderer.prepare(&settings).unwrap();
        let [l, r] = prepared.render_stereo(&camera, &rig).unwrap();
        let (alone_l, alone_r) = (prepared.render(&left), prepared.render(&right));
        assert_same_image(&l, &alone_l, &format!("{mode:?} left"));
        assert_same_image(&r, &alone_r, &format!("{mode:?} right"));
        if mode == Mode::Iso {
            let (shared, own) = (r.stats.samples, alone_r.stats.samples);
            assert!(2 * shared < own, "{shared} samples against {own}");
        }
    }
    // A fisheye pair and a pair with a near plane render as two plain eyes.
    let prepared = renderer.prepare(&iso()).unwrap();
    for camera in [
        camera
            .with_projection(Projection::Equidistant, 170.0)
            .unwrap(),
        camera.with_near_mm(2.0).unwrap(),
    ] {
        let [l, r] = prepared.render_stereo(&camera, &rig).unwrap();
        let [left, right] = rig.eyes(&camera).unwrap();
        assert_same_image(&l, &prepared.render(&left), "left");
        assert_same_image(&r, &prepared.render(&right), "right");
    }
}
