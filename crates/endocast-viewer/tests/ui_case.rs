//! The window's marking tools and its case, driven by clicks: a point labelled and a stroke
//! drawn with the panel's tools are in the saved case, and the case reopens to the same picture.

use crate::common::tube;
use crate::harness::{key, options, Window, SCREEN};
use egui::{Event, Key, Pos2, Vec2};
use endocast_core::annotate::Shape;
use endocast_viewer::app::ViewerOptions;
use endocast_viewer::case::Case;
use endocast_viewer::scene::ScanSource;

/// The middle of the endoscopic view (between the 290-point panel and the 250-point column,
/// above the status line).
fn view_centre() -> Pos2 {
    Pos2::new((290.0 + SCREEN.x - 250.0) / 2.0, SCREEN.y / 2.0 - 12.0)
}

/// Replaces the text of the field showing `old` by `new`.
fn retype(window: &mut Window, old: &str, new: &str) {
    window.click_text(old);
    let mut events = vec![key(Key::End, true), key(Key::End, false)];
    for _ in 0..old.len() {
        events.extend([key(Key::Backspace, true), key(Key::Backspace, false)]);
    }
    events.push(Event::Text(new.into()));
    window.frame(events);
}

/// The window on the tube phantom written as a scan in `dir`, at its known pose, settled.
fn tube_window(dir: &std::path::Path) -> (Window, ScanSource) {
    let scan = dir.join("tube.nii.gz");
    let (volume, pose, _) = tube();
    endocast_io::write(&scan, &volume).unwrap();
    let source = ScanSource::File {
        path: scan,
        series: None,
        orientation: None,
    };
    let mut window = Window::open(ViewerOptions {
        pose: Some(pose),
        ..options(source.clone())
    });
    window.settle();
    (window, source)
}

#[test]
fn marks_made_with_the_tools_are_in_the_saved_case_which_reopens_to_the_same_picture() {
    let dir = tempfile::tempdir().unwrap();
    let (mut window, source) = tube_window(dir.path());
    let unmarked = window.view.clone().expect("the view's picture");

    // Label the wall in the middle of the view.
    retype(&mut window, "mark", "polyp");
    window.click_text("label");
    window.click(view_centre());
    // Draw across it, below the point.
    window.click_text("draw");
    let below = view_centre() + Vec2::new(0.0, 40.0);
    window.drag(below - Vec2::X * 90.0, below + Vec2::X * 90.0, 12);
    let session = window.app.session().unwrap();
    let kinds: Vec<_> = session
        .annotations()
        .iter()
        .map(|a| (a.shape.kind(), a.label.as_str(), a.shape.points().len()))
        .collect();
    assert!(
        matches!(kinds[..], [("point", "polyp", 1), ("stroke", "polyp", n)] if n >= 8),
        "{kinds:?}"
    );

    // The marks' list draws with the font's glyphs.
    window.assert_glyphs();
    window.click_text("Save case");
    let path = window.app.case_path().unwrap();
    assert!(
        window.app.message().starts_with("saved"),
        "{}",
        window.app.message()
    );
    let case = Case::read(&path).unwrap();
    let saved = case.annotations(&path).unwrap();
    assert_eq!(&saved, window.app.session().unwrap().marks());
    assert!(matches!(saved.items()[0].shape, Shape::Point(_)));
    window.settle();
    let (size, marked) = window.view.clone().unwrap();
    assert_ne!(unmarked.1, marked, "the marks are not drawn on the view");

    // Reopening the case (its scan, controls, camera and marks) shows the same picture.
    let mut reopened = Window::open(ViewerOptions {
        case: Some(path.clone()),
        ..options(ScanSource::Phantom {
            name: "colon".into(),
            size: 16,
        })
    });
    reopened.settle();
    let before = window.app.session().unwrap();
    let after = reopened.app.session().unwrap();
    assert_eq!(after.fly_camera(), before.fly_camera());
    assert_eq!(after.controls, before.controls);
    assert_eq!(after.marks(), before.marks());
    let (size_again, again) = reopened.view.clone().unwrap();
    assert_eq!(size_again, size);
    assert!(again == marked, "the reopened case shows another picture");

    // Opening the scan again without --case reopens its case and leaves the file as it is.
    let bytes = std::fs::read(&path).unwrap();
    let mut relaunched = Window::open(options(source));
    relaunched.settle();
    assert_eq!(relaunched.app.case_path().unwrap(), path);
    assert_eq!(relaunched.app.session().unwrap().marks(), before.marks());
    let message = relaunched.app.message();
    assert!(message.contains("reopened the saved case"), "{message}");
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
}

#[test]
fn a_measurement_shows_its_line_and_depth_while_placed() {
    let dir = tempfile::tempdir().unwrap();
    let (mut window, _) = tube_window(dir.path());
    window.click_text("measure");
    window.click(view_centre() + Vec2::new(0.0, 60.0));
    window.frame(vec![Event::PointerMoved(
        view_centre() + Vec2::new(80.0, 60.0),
    )]);
    let texts = window.painted_texts();
    assert!(texts.iter().any(|t| t.ends_with("mm deeper")), "{texts:?}");
    // Nothing measured yet: the second click makes it.
    assert!(window.app.session().unwrap().annotations().is_empty());
}
