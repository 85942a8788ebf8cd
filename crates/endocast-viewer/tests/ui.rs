//! The window on a headless egui context: loading, flying with the keys, errors.

use crate::harness::{input, key, options, run_until, Window};
use egui::Key;
use endocast_core::render::progressive::Stage;
use endocast_viewer::app::ViewerApp;
use endocast_viewer::scene::ScanSource;
use std::time::{Duration, Instant};

#[test]
fn the_window_opens_a_phantom_shows_frames_and_flies_with_the_keys() {
    let ctx = egui::Context::default();
    let source = ScanSource::Phantom {
        name: "colon".into(),
        size: 64,
    };
    let mut app = ViewerApp::new(ctx.clone(), options(source));
    assert!(app.is_loading());
    run_until(&ctx, &mut app, |a| a.session().is_some());
    assert!(app.message().contains("colon"), "{}", app.message());
    run_until(&ctx, &mut app, |a| {
        a.session().unwrap().worker().latest().is_some()
    });
    let start = app.session().unwrap().fly_camera().eye_mm();
    let forward = app.session().unwrap().fly_camera().forward();
    let _ = ctx.run(input(vec![key(Key::W, true)]), |ctx| app.frame_ui(ctx));
    for _ in 0..30 {
        let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
    }
    let _ = ctx.run(input(vec![key(Key::W, false)]), |ctx| app.frame_ui(ctx));
    let moved = app.session().unwrap().fly_camera().eye_mm() - start;
    assert!(moved.dot(forward) > 1.0, "W flew {moved:?}");
    // K records a key frame, H goes back to the start.
    let _ = ctx.run(input(vec![key(Key::K, true), key(Key::K, false)]), |ctx| {
        app.frame_ui(ctx)
    });
    assert_eq!(app.session().unwrap().key_frames().len(), 1);
    let _ = ctx.run(input(vec![key(Key::H, true), key(Key::H, false)]), |ctx| {
        app.frame_ui(ctx)
    });
    assert_eq!(app.session().unwrap().fly_camera().eye_mm(), start);
    // The frame shown follows: a frame of the current view arrives.
    let generation = app.session().unwrap().worker().generation();
    run_until(&ctx, &mut app, |a| {
        a.session()
            .unwrap()
            .worker()
            .latest()
            .is_some_and(|f| f.generation >= generation)
    });
}

#[test]
fn a_scan_that_cannot_be_read_says_why_and_the_app_stays_usable() {
    let ctx = egui::Context::default();
    let source = ScanSource::File {
        path: "/nonexistent/chest.nii.gz".into(),
        series: None,
        orientation: None,
    };
    let mut app = ViewerApp::new(ctx.clone(), options(source));
    run_until(&ctx, &mut app, |a| !a.is_loading());
    assert!(app.session().is_none());
    assert!(
        app.message().contains("/nonexistent/chest.nii.gz"),
        "{}",
        app.message()
    );
    // Another frame draws without a session.
    let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
}

#[test]
fn a_change_of_control_renders_at_moving_quality_first_then_refines() {
    let ctx = egui::Context::default();
    let source = ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 48,
    };
    let mut app = ViewerApp::new(ctx.clone(), options(source));
    run_until(&ctx, &mut app, |a| {
        a.session()
            .and_then(|s| s.worker().latest())
            .is_some_and(|f| matches!(f.stage, Stage::Still(_)))
    });
    // The isovalue changes between two UI frames, as a dragged slider does.
    app.session_mut().unwrap().controls.iso_hu += 150.0;
    let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
    let changed = app.session().unwrap().worker().generation();
    // Without another UI frame the worker stays at moving quality: never a still.
    let moving = app
        .session()
        .unwrap()
        .worker()
        .wait_for(changed, Duration::from_secs(60), |f| f.stage == Stage::Full)
        .expect("the moving view's full frame");
    std::thread::sleep(Duration::from_millis(300));
    let latest = app.session().unwrap().worker().latest().unwrap();
    assert_eq!(latest.generation, moving.generation);
    assert_eq!(
        latest.stage,
        Stage::Full,
        "a moving view accumulated a still"
    );
    // The next UI frame (no change) sends the same view to refine into the still.
    run_until(&ctx, &mut app, |a| {
        let f = a.session().unwrap().worker().latest().unwrap();
        f.generation > changed && matches!(f.stage, Stage::Still(_))
    });
}

#[test]
fn the_slices_and_the_overview_arrive_from_their_threads() {
    let ctx = egui::Context::default();
    let source = ScanSource::Phantom {
        name: "colon".into(),
        size: 64,
    };
    let mut app = ViewerApp::new(ctx.clone(), options(source));
    run_until(&ctx, &mut app, |a| a.session().is_some());
    // The overview and the three slices are textures once their jobs are done.
    let start = Instant::now();
    loop {
        let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
        let names = ctx
            .tex_manager()
            .read()
            .allocated()
            .map(|(_, m)| m.name.clone())
            .collect::<Vec<_>>();
        let all = ["axial", "coronal", "sagittal", "overview"]
            .iter()
            .all(|n| names.iter().any(|m| m == n));
        if all {
            break;
        }
        assert!(start.elapsed() < Duration::from_secs(120), "only {names:?}");
        std::thread::sleep(Duration::from_millis(10));
    }
}

#[test]
fn every_text_of_the_window_has_its_glyphs_in_the_font() {
    let mut window = Window::open(options(ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 32,
    }));
    window.run_until(|a| a.session().is_some());
    window.frame(Vec::new());
    // A key frame, listed with its buttons.
    window.frame(vec![key(Key::K, true), key(Key::K, false)]);
    window.frame(Vec::new());
    assert_eq!(window.app.session().unwrap().key_frames().len(), 1);
    window.assert_glyphs();
    // The folded parts of the panel too, each checked once it is in view.
    for header in ["Geometry", "Export the flight", "Keys"] {
        window.click_text(header);
        window.assert_glyphs();
    }
    // The keys, one a line, run below the panel's fold: scrolled to.
    window.wheel(
        egui::Pos2::new(100.0, 300.0),
        -2000.0,
        egui::Modifiers::NONE,
    );
    window.assert_glyphs();
    let texts = window.painted_texts();
    assert!(texts.iter().any(|t| t.contains("slide left")), "{texts:?}");
}
