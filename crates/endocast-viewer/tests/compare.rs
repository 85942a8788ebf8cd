//! Supine/prone side by side (issue 36): the prone phantom opened beside the supine one, its
//! camera following the supine camera through the scans' correspondence; and the route's
//! target ringed in the endoscope view.

use crate::harness::{key, options, Window};
use egui::Key;
use endocast_core::annotate::{HIDDEN_TARGET_COLOR, TARGET_COLOR};
use endocast_core::phantom::{self, PhantomOptions};
use endocast_viewer::app::ViewerOptions;
use endocast_viewer::scene::ScanSource;
use glam::DVec3;
use std::time::Duration;

/// The phantoms' size, voxels (1 mm).
const SIZE: usize = 128;

fn phantom(name: &str) -> ScanSource {
    ScanSource::Phantom {
        name: name.into(),
        size: SIZE,
    }
}

/// Flies forward with W held for `frames` UI frames.
fn fly_forward(window: &mut Window, frames: usize) {
    window.frame(vec![key(Key::W, true)]);
    for _ in 0..frames {
        window.frame(Vec::new());
        std::thread::sleep(Duration::from_millis(15));
    }
    window.frame(vec![key(Key::W, false)]);
}

#[test]
fn the_prone_view_follows_the_supine_camera_within_10_mm_along_the_colon() {
    let mut window = Window::open(ViewerOptions {
        compare: Some(phantom("colon-prone")),
        ..options(phantom("colon"))
    });
    window.run_until(|app| app.compare().is_some_and(|c| c.pose().is_some()));
    let (_, pair) = phantom::colon_prone(&PhantomOptions {
        size: SIZE,
        ..PhantomOptions::default()
    });
    let app = &window.app;
    let dims = app.compare().unwrap().scene().volume().dims();
    // World = voxel index − (dims − 1) / 2 in both phantoms.
    let half = (DVec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) - 1.0) / 2.0;
    let start = app.session().unwrap().fly_camera().eye_mm();
    fly_forward(&mut window, 40);
    let eye = window.app.session().unwrap().fly_camera().eye_mm();
    assert!(
        eye.distance(start) > 5.0,
        "the camera moved {start} → {eye}"
    );
    // The prone camera follows at the next UI frame.
    window.run_until(|app| {
        let followed = app.compare().and_then(|c| c.pose());
        let now = app.session().unwrap().fly_camera().eye_mm();
        followed.is_some() && now == eye
    });
    window.frame(Vec::new());
    let prone_eye = window.app.compare().unwrap().pose().unwrap().eye_mm;
    let (supine_arc, _) = pair.supine.centreline.closest(eye + half);
    let truth = pair.prone_arc_vox(supine_arc);
    let (prone_arc, off) = pair.prone.centreline.closest(prone_eye + half);
    assert!(
        (prone_arc - truth).abs() < 10.0,
        "prone camera at {prone_arc:.1} mm along the colon, its counterpart at {truth:.1} mm"
    );
    assert!(
        off < pair.prone.radius_vox_at(prone_arc),
        "in the lumen: {off} mm off the axis"
    );
    // Its view is drawn: a picture of the prone colon beside the supine one.
    window.run_until(|app| {
        app.compare()
            .is_some_and(|c| c.worker().latest().is_some_and(|f| f.generation > 1))
    });
    let frame = window.app.compare().unwrap().worker().latest().unwrap();
    let lit = frame.image.rgb().iter().filter(|&&v| v > 40).count();
    assert!(lit * 4 > frame.image.rgb().len(), "the prone view is dark");
    assert!(window
        .painted_texts()
        .iter()
        .any(|t| t.contains("follows this camera")));
}

#[test]
fn the_target_is_ringed_in_the_view_solid_ahead_and_dashed_behind_the_wall() {
    let mut window = Window::open(options(phantom("colon")));
    window.settle();
    let frame = window.app.session().unwrap().worker().latest().unwrap();
    let camera = frame.camera;
    let ahead = camera.eye_mm() + camera.forward() * 3.0;
    let [w, h] = camera.size();
    let depth = frame.depth_mm[w / 2 + w * (h / 2)];
    assert!(
        depth.is_finite() && depth > 6.0,
        "the wall ahead at {depth} mm"
    );
    let behind = camera.eye_mm() + camera.forward() * (f64::from(depth) + 20.0);
    for (target, color) in [(ahead, TARGET_COLOR), (behind, HIDDEN_TARGET_COLOR)] {
        window.app.session_mut().unwrap().set_target(Some(target));
        window.frame(Vec::new());
        window.frame(Vec::new());
        let ([w, _], rgba) = window.view.clone().unwrap();
        let (x, y) = camera.project(target).unwrap();
        let i = 4 * (x as usize + w * y as usize);
        assert_eq!(rgba[i..i + 3], color, "the target's pixel");
    }
}
