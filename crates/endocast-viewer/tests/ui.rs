//! The window on a headless egui context: loading, flying with the keys, errors.

use egui::{Event, Key, Modifiers, Pos2, RawInput, Rect, Vec2};
use endocast_core::presets::Preset;
use endocast_viewer::app::{ViewerApp, ViewerOptions};
use endocast_viewer::scene::ScanSource;
use std::time::{Duration, Instant};

fn options(source: ScanSource) -> ViewerOptions {
    ViewerOptions {
        source,
        preset: Preset::find("colonoscopy").unwrap(),
        pose: None,
        case: None,
        screenshot: None,
    }
}

fn input(events: Vec<Event>) -> RawInput {
    RawInput {
        screen_rect: Some(Rect::from_min_size(Pos2::ZERO, Vec2::new(1100.0, 700.0))),
        events,
        ..RawInput::default()
    }
}

fn key(key: Key, pressed: bool) -> Event {
    Event::Key {
        key,
        physical_key: None,
        pressed,
        repeat: false,
        modifiers: Modifiers::NONE,
    }
}

/// Runs UI frames until `done` or the timeout.
fn run_until(ctx: &egui::Context, app: &mut ViewerApp, done: impl Fn(&ViewerApp) -> bool) {
    let start = Instant::now();
    while !done(app) {
        assert!(start.elapsed() < Duration::from_secs(120), "timed out");
        let _ = ctx.run(input(Vec::new()), |ctx| app.frame_ui(ctx));
        std::thread::sleep(Duration::from_millis(10));
    }
}

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
