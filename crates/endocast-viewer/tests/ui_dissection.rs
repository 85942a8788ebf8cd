//! The virtual dissection in the window: made off the UI thread for the study's path, shown
//! as a flat view, and a click on a flat pixel taking the endoscope to look at its wall point.

use crate::harness::{options, Window};
use egui::{Pos2, Vec2};
use endocast_viewer::scene::ScanSource;

/// The screen position of the middle of flat pixel `(x, y)` in an image drawn in `rect` of
/// an image `height` pixels high.
fn on_screen(rect: egui::Rect, height: usize, (x, y): (usize, usize)) -> Pos2 {
    let scale = rect.height() / height as f32;
    rect.min + Vec2::new(x as f32 + 0.5, y as f32 + 0.5) * scale
}

#[test]
fn a_click_on_the_flat_view_looks_at_the_wall_point_its_map_gives() {
    let source = ScanSource::Phantom {
        name: "colon".into(),
        size: 96,
    };
    let mut window = Window::open(options(source));
    window.run_until(|app| app.session().is_some());
    window.frame(Vec::new());
    window.click_text("Virtual dissection");
    window.click_text("Dissect");
    window.run_until(|app| app.dissection().is_some_and(|d| d.flat().is_some()));
    window.frame(Vec::new());
    let (rect, visible) = window
        .image_rect("virtual dissection")
        .expect("the flat view is drawn");
    let flat = window.app.dissection().unwrap().flat().unwrap();
    let d = &flat.dissection;
    assert!(d.hit_fraction > 0.5, "{}", d.hit_fraction);
    // A pixel 30 columns (15 mm) along the path, the first with a wall point from 90° down.
    let x = d.plot.x + 30;
    let y = (d.plot.y + d.plot.rows / 4..d.plot.y + d.plot.rows)
        .find(|&y| d.map.at(x, y).is_some())
        .unwrap();
    let wall = d.map.at(x, y).unwrap();
    let expected = d.pose_of_pixel(&flat.path, x, y).unwrap();
    let click = on_screen(rect, d.image.height(), (x, y));
    assert!(visible.contains(click), "{click:?} not in {visible:?}");
    let margin = on_screen(rect, d.image.height(), (2, 2));
    let path = flat.path.clone();
    window.click(click);

    let session = window.app.session().unwrap();
    let eye = session.fly_camera().eye_mm();
    assert!(eye.distance(expected.eye_mm) < 1e-9, "{eye} {expected:?}");
    assert!(path.nearest_sample(eye).1 < 0.5, "the eye is on the path");
    let camera = session.camera().unwrap();
    assert!((wall - eye).dot(session.fly_camera().forward()) > 0.0);
    let (u, v) = camera.project(wall).expect("the wall point is in view");
    let [w, h] = session.view_size();
    assert!(
        (u - w as f64 / 2.0).abs() < 1.0 && (v - h as f64 / 2.0).abs() < 1.0,
        "the wall point at ({u}, {v}) is not at the centre of {w} × {h}"
    );
    assert!(
        window.app.message().contains("looking at the wall point"),
        "{}",
        window.app.message()
    );

    // A pixel without a wall point (the labelled margin) says so and leaves the endoscope.
    window.click(margin);
    assert_eq!(window.app.session().unwrap().fly_camera().eye_mm(), eye);
    let said = window.app.message();
    assert!(
        said.contains("outside the flat wall") && said.contains("stays"),
        "{said}"
    );
}
