//! The review of the wall a flight missed: listed off the UI thread, then "next unseen patch"
//! takes the endoscope to each patch's pose in turn while the coverage grows.

use crate::common::tube_session;
use endocast_viewer::review::ReviewTools;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Polls `tools` until its review has ended; returns what it said.
fn finished(tools: &mut ReviewTools) -> String {
    let deadline = Instant::now() + Duration::from_secs(300);
    loop {
        if let Some(said) = tools.poll() {
            return said;
        }
        assert!(Instant::now() < deadline, "the review did not end");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[test]
fn next_unseen_patch_visits_each_listed_patch_from_its_pose() {
    let (mut session, _) = tube_session();
    // The flight to review: two key frames along the tube (the tube is no colon the preset
    // could find a route in).
    session.record_key_frame().unwrap();
    for _ in 0..40 {
        session.fly(crate::flight::forward(0.5));
    }
    session.record_key_frame().unwrap();
    let mut tools = ReviewTools::default();
    assert!(tools.next(&mut session).contains("no review yet"));
    tools.start(&session, Arc::new(|| {}));
    let said = finished(&mut tools);
    // The forward flight from the tube's end never sees the wall behind its first pose.
    assert!(!tools.views().is_empty(), "{said}");
    let (before, now) = tools.coverage().unwrap();
    assert!(before < 1.0 && now == before, "{before} {now}");
    for n in 0..tools.views().len() {
        let said = tools.next(&mut session);
        let pose = tools.views()[n].pose;
        let camera = session.fly_camera();
        assert!(camera.eye_mm().distance(pose.eye_mm) < 1e-9, "{said}");
        let toward = (pose.look_at_mm - pose.eye_mm).normalize();
        assert!(camera.forward().dot(toward) > 0.999_999, "{said}");
        assert!(tools.visited()[n]);
    }
    let (_, after) = tools.coverage().unwrap();
    assert!(
        after > before,
        "visiting the patches saw nothing: {before} → {after}"
    );
    assert!(tools.next(&mut session).contains("every listed patch"));
}
