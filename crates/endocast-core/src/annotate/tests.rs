//! Annotations on the sphere shell, whose inner wall is known exactly: drawn from one view,
//! found again from others (every lens), hidden when covered or when the threshold removes the
//! wall.

#![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test

use super::*;
use crate::camera::{Camera, Projection};
use crate::phantom::{self, PhantomOptions, SphereShell};
use crate::render::{Frame, Mode, Prepared, RenderSettings, Renderer};
use crate::views::Image;
use std::sync::Arc;

/// The shell's phantom at 48³ (1 mm voxels) and its iso-surface renderer at `iso_hu`.
fn shell(iso_hu: f64) -> (Prepared, SphereShell, DVec3) {
    let (volume, shell) = phantom::sphere_shell(&PhantomOptions {
        size: 48,
        ..PhantomOptions::default()
    });
    let centre = volume.geometry().world_of(shell.centre_vox);
    let renderer = Arc::new(Renderer::new(volume));
    let settings = RenderSettings {
        mode: Mode::Iso,
        iso_hu,
        ..RenderSettings::default()
    };
    (renderer.prepare(&settings).unwrap(), shell, centre)
}

/// The shell's wall is halfway up its ramp at the tissue/air mid-value.
const WALL_ISO: f64 = -480.0;

fn view<'a>(camera: &'a Camera, frame: &'a Frame) -> SurfaceView<'a> {
    SurfaceView::new(camera, &frame.depth_mm, DVec3::ONE)
}

/// From the centre looking along +z, 64 × 64, 90°.
fn drawing_camera(centre: DVec3) -> Camera {
    Camera::look_at(centre, centre + DVec3::Z, DVec3::Y, 90.0, [64, 64]).unwrap()
}

/// A stroke drawn across the view from the centre: the image positions and the points.
fn drawn_stroke(prepared: &Prepared, camera: &Camera) -> (Vec<(f64, f64)>, Vec<DVec3>) {
    let frame = prepared.render(camera);
    let from = view(camera, &frame);
    let pixels: Vec<(f64, f64)> = (0..12)
        .map(|i| (18.5 + 2.0 * f64::from(i), 24.5 + 1.3 * f64::from(i)))
        .collect();
    let points = pixels
        .iter()
        .map(|&(x, y)| from.pick(x, y).unwrap())
        .collect();
    (pixels, points)
}

#[test]
fn picked_points_lie_on_the_wall_at_the_pixel_picked() {
    let (prepared, shell, centre) = shell(WALL_ISO);
    let camera = drawing_camera(centre);
    let (pixels, points) = drawn_stroke(&prepared, &camera);
    for (&(x, y), p) in pixels.iter().zip(&points) {
        let r = p.distance(centre);
        assert!((r - shell.inner_radius_vox).abs() < 0.05, "radius {r}");
        let (px, py) = camera.project(*p).unwrap();
        assert!((px - x).abs() < 1e-6 && (py - y).abs() < 1e-6);
    }
    // Between pixel centres the depth is interpolated: still on the wall.
    let frame = prepared.render(&camera);
    let between = view(&camera, &frame).pick(30.0, 33.0).unwrap();
    assert!((between.distance(centre) - shell.inner_radius_vox).abs() < 0.05);
}

#[test]
fn a_stroke_drawn_in_one_view_lands_on_the_same_surface_point_in_three_others() {
    let (prepared, _, centre) = shell(WALL_ISO);
    let drawing = drawing_camera(centre);
    let (pixels, points) = drawn_stroke(&prepared, &drawing);
    let middle = points[points.len() / 2];
    let others = [
        (DVec3::new(6.0, -4.0, -3.0), Projection::Pinhole, 70.0),
        (DVec3::new(-7.0, 5.0, 2.0), Projection::Equidistant, 170.0),
        (DVec3::new(2.0, 8.0, -8.0), Projection::Equisolid, 140.0),
    ];
    for (offset, projection, field) in others {
        let eye = centre + offset;
        let camera = Camera::look_at(eye, middle, DVec3::X, 90.0, [96, 96])
            .unwrap()
            .with_projection(projection, field)
            .unwrap();
        let frame = prepared.render(&camera);
        let seen = view(&camera, &frame);
        for (&(x, y), p) in pixels.iter().zip(&points) {
            assert_eq!(seen.visibility(*p), Visibility::Visible, "{projection:?}");
            let (u, v) = camera.project(*p).unwrap();
            let found = seen.pick(u, v).unwrap();
            let (bx, by) = drawing.project(found).unwrap();
            let off = (bx - x).hypot(by - y);
            assert!(
                off < 1.0,
                "{projection:?}: {off} px back in the drawing view"
            );
        }
        // The decal is drawn where the stroke's middle projects.
        let mut image = Image::from_frame(&frame, [0.0; 3]).unwrap();
        let marks =
            Annotations::from_items(vec![Annotation::new(Shape::Stroke(points.clone()))]).unwrap();
        assert_eq!(
            draw(&mut image, &seen, marks.items(), &DrawOptions::default()),
            1
        );
        let (u, v) = camera.project(middle).unwrap();
        assert_eq!(image.pixel(u as usize, v as usize), Some(STROKE_COLOR));
    }
}

#[test]
fn annotations_are_hidden_behind_tissue_and_where_the_threshold_removes_the_wall() {
    let (prepared, shell, centre) = shell(WALL_ISO);
    let (_, points) = drawn_stroke(&prepared, &drawing_camera(centre));
    let stroke = [Annotation::new(Shape::Stroke(points.clone())).labelled("cut here")];

    // From outside the shell, beyond the stroke: the shell's outer wall covers it.
    let outside = centre + DVec3::Z * (shell.outer_radius_vox + 15.0);
    let camera = Camera::look_at(outside, centre, DVec3::Y, 60.0, [64, 64]).unwrap();
    let frame = prepared.render(&camera);
    let seen = view(&camera, &frame);
    assert!(points
        .iter()
        .all(|p| seen.visibility(*p) == Visibility::Occluded));
    let clean = Image::from_frame(&frame, [0.0; 3]).unwrap();
    let mut image = clean.clone();
    assert_eq!(draw(&mut image, &seen, &stroke, &DrawOptions::default()), 0);
    assert_eq!(
        image, clean,
        "an occluded stroke leaves the image untouched"
    );

    // From inside, looking at it: shown at the wall's threshold and one a little off it...
    let eye = centre + DVec3::new(3.0, -2.0, -4.0);
    let camera = Camera::look_at(eye, points[6], DVec3::X, 80.0, [64, 64]).unwrap();
    for iso in [WALL_ISO, -300.0] {
        let (moved, _, _) = self::shell(iso);
        let frame = moved.render(&camera);
        let seen = view(&camera, &frame);
        assert!(points
            .iter()
            .all(|p| seen.visibility(*p) == Visibility::Visible));
    }
    // ...and gone when the threshold lies above the tissue: no wall is left there.
    let (removed, _, _) = self::shell(200.0);
    let frame = removed.render(&camera);
    let seen = view(&camera, &frame);
    assert!(points
        .iter()
        .all(|p| seen.visibility(*p) == Visibility::Removed));
    let clean = Image::from_frame(&frame, [0.0; 3]).unwrap();
    let mut image = clean.clone();
    assert_eq!(draw(&mut image, &seen, &stroke, &DrawOptions::default()), 0);
    assert_eq!(image, clean);
    // Looking away, it is out of view.
    let away = Camera::look_at(eye, eye - (points[6] - eye), DVec3::X, 80.0, [64, 64]).unwrap();
    let frame = prepared.render(&away);
    assert_eq!(
        view(&away, &frame).visibility(points[6]),
        Visibility::OutOfView
    );
}

#[test]
fn measurements_and_labels_are_drawn_with_their_text() {
    let (prepared, _, centre) = shell(WALL_ISO);
    let camera = drawing_camera(centre);
    let frame = prepared.render(&camera);
    let seen = view(&camera, &frame);
    let (a, b) = (
        seen.pick(20.5, 32.5).unwrap(),
        seen.pick(44.5, 32.5).unwrap(),
    );
    let mut marks = Annotations::default();
    let id = marks.add(Annotation::new(Shape::Distance(a, b))).unwrap();
    marks
        .add(Annotation::new(Shape::Point(seen.pick(32.5, 50.5).unwrap())).labelled("ostium"))
        .unwrap();
    let mut image = Image::new(64, 64, [0; 3]).unwrap();
    assert_eq!(
        draw(&mut image, &seen, marks.items(), &DrawOptions::default()),
        2
    );
    assert_eq!(
        image.pixel(32, 32),
        Some(MEASURE_COLOR),
        "the line between the ends"
    );
    assert_eq!(image.pixel(20, 32), Some(MEASURE_COLOR), "an end's dot");
    assert_eq!(image.pixel(32, 50), Some(POINT_COLOR));
    let caption = marks.get(id).unwrap().caption();
    assert_eq!(caption, format!("{:.1} mm", a.distance(b)));
    let text_pixels = image
        .rgb()
        .chunks(3)
        .filter(|p| *p == MEASURE_COLOR.as_slice())
        .count();
    assert!(
        text_pixels > 60,
        "line, dots and text: {text_pixels} pixels"
    );
}

#[test]
fn ids_stay_unique_and_shapes_check_their_points() {
    let mut marks = Annotations::default();
    let p = Annotation::new(Shape::Point(DVec3::ZERO));
    let [one, two] = [marks.add(p.clone()).unwrap(), marks.add(p.clone()).unwrap()];
    assert_eq!((one, two), (1, 2));
    assert!(marks.remove(one).is_some());
    assert_eq!(marks.add(p.clone()), Ok(3));
    assert!(marks.remove(9).is_none());
    let kept = Annotations::from_items(vec![
        Annotation { id: 5, ..p.clone() },
        Annotation { id: 5, ..p.clone() },
    ])
    .unwrap();
    assert_eq!(
        kept.items().iter().map(|a| a.id).collect::<Vec<_>>(),
        [5, 6]
    );
    assert!(Shape::from_points("measure", &[DVec3::ZERO])
        .unwrap_err()
        .contains("2"));
    assert!(Shape::from_points("circle", &[DVec3::ZERO]).is_err());
    assert!(Shape::from_points("point", &[DVec3::NAN]).is_err());
    let stroke = Shape::from_points("stroke", &[DVec3::ZERO, DVec3::X]).unwrap();
    assert_eq!(stroke.kind(), "stroke");
    assert_eq!(stroke.points().len(), 2);
}

#[test]
fn ids_past_the_largest_u32_are_refused_not_wrapped() {
    let p = Annotation::new(Shape::Point(DVec3::ZERO));
    let last = Annotation {
        id: u32::MAX,
        ..p.clone()
    };
    let mut marks = Annotations::from_items(vec![last.clone()]).unwrap();
    assert_eq!(marks.add(p.clone()), Err(IdsExhausted));
    assert_eq!(marks.len(), 1);
    assert!(IdsExhausted.to_string().contains("4294967295"));
    // A duplicate id after the largest possible one cannot be renumbered either.
    assert_eq!(
        Annotations::from_items(vec![last.clone(), last]),
        Err(IdsExhausted)
    );
}

#[test]
fn a_scan_is_recognised_and_any_change_is_named() {
    let options = PhantomOptions {
        size: 16,
        ..PhantomOptions::default()
    };
    let (volume, _) = phantom::sphere_shell(&options);
    let identity = ScanIdentity::of(&volume);
    assert_eq!(identity, ScanIdentity::of(&volume.clone()));
    assert!(identity.check(&ScanIdentity::of(&volume)).is_ok());
    let mut voxels = volume.voxels().to_vec();
    voxels[100] ^= 1;
    let changed = crate::Volume::new(
        *volume.geometry(),
        voxels,
        volume.value_map(),
        volume.modality().clone(),
    )
    .unwrap();
    let error = identity.check(&ScanIdentity::of(&changed)).unwrap_err();
    assert_eq!(error.what, "voxel values");
    let (bigger, _) = phantom::sphere_shell(&PhantomOptions {
        size: 18,
        ..options
    });
    let error = identity.check(&ScanIdentity::of(&bigger)).unwrap_err();
    assert!(error.to_string().contains("dimensions"), "{error}");
    // The same voxels read with another orientation (e.g. a wrong --orientation) are refused:
    // the annotations' world points would land elsewhere.
    let flipped = volume
        .geometry()
        .with_direction(glam::DMat3::from_diagonal(DVec3::new(1.0, 1.0, -1.0)))
        .unwrap();
    let turned = crate::Volume::new(
        flipped,
        volume.voxels().to_vec(),
        volume.value_map(),
        volume.modality().clone(),
    )
    .unwrap();
    let error = identity.check(&ScanIdentity::of(&turned)).unwrap_err();
    assert_eq!(error.what, "axes");
    // A fingerprint recorded without axes (older cases) still matches.
    let older = ScanIdentity {
        axes: None,
        ..identity.clone()
    };
    assert!(older.check(&ScanIdentity::of(&volume)).is_ok());
}
