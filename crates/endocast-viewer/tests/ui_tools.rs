//! The window's tools driven as a radiologist drives them: the large slice beside the endoscope
//! (the wheel pages, Ctrl+wheel zooms, a drag sets the window, a double click frames the volume
//! again, a click jumps the camera, the key frames' path is drawn on it), the keys help inside
//! the panel, and the transfer function's colour strip.

use crate::harness::{key, options, Window};
use egui::{Key, Modifiers, Pos2, Vec2};
use endocast_core::views::slices::Plane;
use endocast_viewer::app::ViewerOptions;
use endocast_viewer::scene::ScanSource;

/// The colour the key frames' path is drawn in.
const PATH: [u8; 3] = [80, 200, 255];

/// The large slice's caption ("axial · through the camera · ×1.0 · W 1500 L −500"), once its
/// image is shown.
fn caption(window: &Window) -> Option<String> {
    window
        .painted_texts()
        .into_iter()
        .find(|t| t.contains(" · ×") && t.contains(" · W "))
}

/// Runs frames until the caption satisfies `ok`; returns it.
fn caption_until(window: &mut Window, ok: impl Fn(&str) -> bool) -> String {
    for _ in 0..3000 {
        if let Some(text) = caption(window).filter(|t| ok(t)) {
            return text;
        }
        window.frame(Vec::new());
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    panic!(
        "the large slice never showed the caption wanted: {:?}",
        caption(window)
    );
}

/// The number after `key` in the caption ("W 1500" → 1500).
fn number_after(text: &str, key: &str) -> f64 {
    let rest = &text[text.find(key).unwrap() + key.len()..];
    let end = rest.find([' ', '·']).unwrap_or(rest.len());
    rest[..end].trim().parse().unwrap()
}

#[test]
fn the_large_slice_pages_zooms_sets_its_window_jumps_and_shows_the_path() {
    let source = ScanSource::Phantom {
        name: "colon".into(),
        size: 64,
    };
    let mut window = Window::open(ViewerOptions {
        layout: Some(Plane::Axial),
        ..options(source)
    });
    window.settle();
    let first = caption_until(&mut window, |t| t.starts_with("axial · through the camera"));
    let top = window.text_rect(&first).unwrap();
    // A point inside the image, below the caption.
    let inside = Pos2::new(top.min.x + 80.0, top.max.y + 80.0);

    window.wheel(inside, 40.0, Modifiers::NONE);
    let paged = caption_until(&mut window, |t| t.contains("mm from the camera"));
    assert!(paged.contains(" +"), "{paged}");

    window.wheel(inside, 200.0, Modifiers::CTRL);
    let zoomed = caption_until(&mut window, |t| number_after(t, "×") > 1.05);
    assert!(
        zoomed.contains("mm from the camera"),
        "Ctrl+wheel paged: {zoomed}"
    );

    window.double_click(inside);
    let home = caption_until(&mut window, |t| t.contains("through the camera · ×1.0"));
    let width = number_after(&home, "W ");
    window.drag(inside, inside + Vec2::new(100.0, 0.0), 5);
    let widened = caption_until(&mut window, |t| number_after(t, "W ") > width);
    assert_eq!(number_after(&widened, "L "), number_after(&home, "L "));

    // Key frames recorded along the way appear on the slice as a path.
    assert_eq!(window.segments_coloured(PATH), 0);
    window.frame(vec![key(Key::K, true), key(Key::K, false)]);
    window.frame(vec![key(Key::W, true)]);
    for _ in 0..30 {
        window.frame(Vec::new());
    }
    window.frame(vec![
        key(Key::W, false),
        key(Key::K, true),
        key(Key::K, false),
    ]);
    assert_eq!(window.app.session().unwrap().key_frames().len(), 2);
    // The slice is drawn before the view takes the keys: the next frame draws the second.
    window.frame(Vec::new());
    assert!(
        window.segments_coloured(PATH) > 0,
        "no path drawn on the slice"
    );

    // A click jumps the camera into the slice's plane.
    let eye = window.app.session().unwrap().fly_camera().eye_mm();
    window.click(inside + Vec2::new(30.0, 20.0));
    let moved = window.app.session().unwrap().fly_camera().eye_mm();
    assert_ne!(moved, eye, "the click did not jump");

    window.click_text("coronal");
    caption_until(&mut window, |t| t.starts_with("coronal ·"));
}

/// The window on a small straight tube, its session open and drawn once.
fn open_tube() -> Window {
    let source = ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 48,
    };
    let mut window = Window::open(options(source));
    window.run_until(|app| app.session().is_some());
    window.frame(Vec::new());
    window
}

#[test]
fn the_keys_help_fits_the_panel_and_leaves_the_view_its_width() {
    let mut window = open_tube();
    let view = window.app.session().unwrap().view_size();
    window.click_text("Keys");
    window.wheel(Pos2::new(100.0, 300.0), -2000.0, Modifiers::NONE);
    assert_eq!(window.app.session().unwrap().view_size(), view);
    // Every key and what it does that is drawn lies inside the 290-point panel, none over
    // the view (a table of two columns was wider).
    let help: Vec<&str> = endocast_viewer::keys::HELP
        .iter()
        .flat_map(|(key, what)| [*key, *what])
        .collect();
    let drawn: Vec<_> = window
        .painted_text_rects()
        .into_iter()
        .filter(|(text, _)| help.contains(&text.as_str()))
        .collect();
    assert!(drawn.len() >= 6, "{drawn:?}");
    for (text, rect) in drawn {
        assert!(rect.max.x <= 290.0, "{text:?} reaches {}", rect.max.x);
    }
}

#[test]
fn a_colour_point_is_added_on_the_strip_under_the_histogram_and_offered_for_editing() {
    let mut window = open_tube();
    let colours = |w: &Window| w.app.session().unwrap().controls.tf.color_points().len();
    let before = colours(&window);
    // The strip lies just above the isovalue slider.
    let slider = window.text_rect("isovalue").unwrap();
    window.double_click(Pos2::new(145.0, slider.top() - 12.0));
    assert_eq!(colours(&window), before + 1);
    assert!(
        window
            .painted_texts()
            .iter()
            .any(|t| t.starts_with("colour at ")),
        "no colour editor for the new point"
    );
}
