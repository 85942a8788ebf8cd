//! Flying: collision, the frame following the camera and the controls, key frames.

use crate::common::{mean_difference, off_axis_mm, settled, tube_session};
use endocast_core::render::progressive::Stage;
use endocast_viewer::controller::LocalMove;
use std::time::Duration;

/// A step of `mm` straight ahead.
pub(crate) fn forward(mm: f64) -> LocalMove {
    LocalMove {
        forward_mm: mm,
        ..LocalMove::default()
    }
}

#[test]
fn flying_into_the_wall_stops_outside_it_and_the_frame_changes() {
    let (mut session, truth) = tube_session();
    let before = settled(&mut session);
    let radius = session
        .navigation()
        .expect("the eye is in the lumen")
        .radius_mm();
    // Into the wall, in small steps as the keys fly.
    for _ in 0..100 {
        session.fly(forward(1.0));
    }
    let eye = session.fly_camera().eye_mm();
    let off = off_axis_mm(&truth, eye);
    // Stopped short of the wall by about the camera's radius (the field's bound is on voxel
    // centres, so within a voxel of it), yet well on its way.
    assert!(
        off <= truth.radius_mm - radius + 1.0,
        "{off} mm off axis, wall at {}",
        truth.radius_mm
    );
    assert!(
        off >= truth.radius_mm - radius - 1.5,
        "stopped early: {off} mm"
    );
    let after = settled(&mut session);
    assert!(
        mean_difference(&before, &after) > 5.0,
        "the frame did not change"
    );
    // Without collision the same flight goes through the wall.
    session.controls.collision = false;
    session.fly(forward(10.0));
    assert!(off_axis_mm(&truth, session.fly_camera().eye_mm()) > truth.radius_mm + 5.0);
}

#[test]
fn flying_along_the_tube_slides_along_the_wall() {
    let (mut session, truth) = tube_session();
    // Aim 45° between the wall and the axis: the camera slides along the tube.
    session.turn(0.0, std::f64::consts::FRAC_PI_4);
    for _ in 0..40 {
        session.fly(forward(0.5));
    }
    let d = session.fly_camera().eye_mm() - truth.centre_mm;
    assert!(
        d.dot(truth.axis) > 10.0,
        "only {} mm along the tube",
        d.dot(truth.axis)
    );
    assert!(off_axis_mm(&truth, session.fly_camera().eye_mm()) < truth.radius_mm);
}

#[test]
fn changing_the_isovalue_changes_the_next_frame() {
    let (mut session, _) = tube_session();
    let before = settled(&mut session);
    session.controls.iso_hu = 100.0;
    let after = settled(&mut session);
    assert!(
        mean_difference(&before, &after) > 1.0,
        "the isovalue did nothing"
    );
    // A setting out of range is reported and the view stays.
    session.controls.iso_opacity = 2.0;
    session.sync(false);
    let deadline = std::time::Instant::now() + Duration::from_secs(10);
    while session.worker().error().is_none() && std::time::Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(
        session
            .worker()
            .error()
            .is_some_and(|e| e.contains("opacity")),
        "{:?}",
        session.worker().error()
    );
}

#[test]
fn moving_views_show_a_preview_first_and_new_input_supersedes_the_frame() {
    let (mut session, _) = tube_session();
    session.set_view_size([256, 256]);
    let first = session.sync(true).unwrap();
    session.turn(0.2, 0.0);
    // The first view has shown nothing yet: the new one waits for it.
    let waiting = session.sync(true);
    let preview = session
        .worker()
        .wait_for(first, Duration::from_secs(30), |_| true)
        .unwrap();
    assert!(
        matches!(preview.stage, Stage::Preview(_)),
        "{:?}",
        preview.stage
    );
    if waiting.is_none() {
        session.sync(true);
    }
    let turned = session.worker().generation();
    assert!(turned > first);
    let shown = session
        .worker()
        .wait_for(turned, Duration::from_secs(30), |f| f.stage == Stage::Full)
        .unwrap();
    assert_eq!(shown.generation, turned);
    assert_eq!(shown.camera, session.camera().unwrap());
}

#[test]
fn stereo_shows_an_anaglyph_of_two_shifted_eyes() {
    let (mut session, _) = tube_session();
    session.turn(0.0, 0.6);
    let mono = settled(&mut session);
    session.controls.stereo = true;
    session.sync(false);
    let g = session.worker().generation();
    let stereo = session
        .worker()
        .wait_for(g, Duration::from_secs(30), |f| f.stage == Stage::Full)
        .unwrap();
    assert_eq!([stereo.image.width(), stereo.image.height()], [64, 64]);
    assert!(two_shifted_eyes(&mono, &stereo), "not two shifted eyes");
    // The focus stays with the pose: once the pair is at full quality no new view follows.
    session.sync(false);
    let g = session.worker().generation();
    let full = |f: &endocast_viewer::worker::Delivered| f.stage == Stage::Full;
    session
        .worker()
        .wait_for(g, Duration::from_secs(30), full)
        .unwrap();
    for _ in 0..3 {
        assert_eq!(
            session.sync(false),
            None,
            "a delivered frame moved the focus"
        );
    }
    assert_eq!(session.worker().generation(), g);
}

/// Whether `stereo` is an anaglyph of eyes on either side of `mono`'s: red from the left eye,
/// green and blue from the right, each channel differing from the centre eye's somewhere.
fn two_shifted_eyes(
    mono: &endocast_viewer::worker::Delivered,
    stereo: &endocast_viewer::worker::Delivered,
) -> bool {
    let channel_differs = |c: usize| {
        mono.image
            .rgb()
            .chunks(3)
            .zip(stereo.image.rgb().chunks(3))
            .any(|(m, s)| m[c].abs_diff(s[c]) > 8)
    };
    channel_differs(0) && channel_differs(1)
}

#[test]
fn the_realistic_look_in_stereo_shows_an_anaglyph_of_two_shifted_eyes() {
    use endocast_core::look::LookKind;
    let (mut session, _) = tube_session();
    // The rig focuses on the wall 10 mm ahead with the 1/30 rule's 0.34 mm between the eyes:
    // at 64 pixels the farthest surface's disparity is about one pixel, which the look's soft
    // shading hides; at 128 it is two.
    session.set_view_size([128, 128]);
    session.turn(0.0, 0.6);
    session.controls.look = LookKind::Realistic;
    let mono = settled(&mut session);
    session.controls.stereo = true;
    let stereo = settled(&mut session);
    assert_eq!([stereo.image.width(), stereo.image.height()], [128, 128]);
    assert!(two_shifted_eyes(&mono, &stereo), "not two shifted eyes");
}

#[test]
fn two_key_frames_play_from_the_first_to_the_second() {
    let (mut session, truth) = tube_session();
    session.turn(0.0, std::f64::consts::FRAC_PI_2 * 0.98);
    session.record_key_frame().unwrap();
    let start = session.fly_camera().eye_mm();
    for _ in 0..20 {
        session.fly(forward(0.5));
    }
    session.turn(0.8, 0.0);
    session.record_key_frame().unwrap();
    let end = *session.fly_camera();
    assert_eq!(session.key_frames().len(), 2);
    session.reset();
    session.play().unwrap();
    assert!((session.fly_camera().eye_mm() - start).length() < 1e-6);
    let first = settled(&mut session);
    let mut steps = 0;
    let mut along = Vec::new();
    while session.advance_playback(0.05) {
        steps += 1;
        along.push((session.fly_camera().eye_mm() - start).dot(truth.axis));
        assert!(steps < 1000);
    }
    let last = settled(&mut session);
    assert!(steps > 5, "played in {steps} steps");
    assert!((session.fly_camera().eye_mm() - end.eye_mm()).length() < 1e-6);
    assert!((session.fly_camera().forward() - end.forward()).length() < 1e-6);
    assert!(session.playback().unwrap().finished());
    // The finished flight releases the camera: looking around and going home stay done.
    session.turn(0.3, 0.0);
    let looked = *session.fly_camera();
    assert!(!session.advance_playback(0.05));
    assert_eq!(*session.fly_camera(), looked);
    session.reset();
    assert!(!session.advance_playback(0.05));
    assert_ne!(*session.fly_camera(), looked);
    assert!(
        mean_difference(&first, &last) > 1.0,
        "the flight shows the same picture"
    );
    // Forward along the tube all the way, never back.
    assert!(along.windows(2).all(|w| w[1] >= w[0] - 1e-9), "{along:?}");
    // Along the tube the whole way.
    assert!(off_axis_mm(&truth, session.fly_camera().eye_mm()) < truth.radius_mm);
    session.delete_key_frame(0);
    assert_eq!(session.key_frames().len(), 1);
}

#[test]
fn marks_lie_on_the_wall_and_measure_between_them() {
    let (mut session, truth) = tube_session();
    settled(&mut session);
    assert!(session.annotate_pixel(32, 32, "polyp"));
    assert!(!session.annotate_pixel(640, 32, "outside"));
    let mm = session.measure_pixels([12, 32], [52, 32]).unwrap();
    session.turn(std::f64::consts::PI, 0.0);
    settled(&mut session);
    assert!(session.annotate_pixel(32, 32, "opposite"));
    let marks = session.annotations();
    assert_eq!(marks.len(), 3);
    let points: Vec<_> = marks.iter().flat_map(|a| a.shape.points()).collect();
    for p in &points {
        let off = off_axis_mm(&truth, *p);
        assert!(
            (off - truth.radius_mm).abs() < 1.0,
            "mark {off} mm off axis"
        );
    }
    assert_eq!(marks[1].distance_mm(), Some(mm));
    assert!(mm > 5.0 && mm < 2.0 * truth.radius_mm, "{mm} mm");
    let across = points[0].distance(points[3]);
    assert!(
        (across - 2.0 * truth.radius_mm).abs() < 2.0,
        "{across} mm across the tube"
    );
}

#[test]
fn centring_moves_the_eye_to_the_tube_axis_across_the_view() {
    let (mut session, truth) = tube_session();
    // Look along the tube, then slide 5 mm off the axis.
    session.turn(0.0, std::f64::consts::FRAC_PI_2);
    session.fly(LocalMove {
        right_mm: 5.0,
        ..LocalMove::default()
    });
    let before = *session.fly_camera();
    assert!(off_axis_mm(&truth, before.eye_mm()) > 4.0);
    assert!(session.centre_in_lumen());
    let after = *session.fly_camera();
    assert!(
        off_axis_mm(&truth, after.eye_mm()) < 1.0,
        "{}",
        off_axis_mm(&truth, after.eye_mm())
    );
    // Only across the view: not along it, and the view direction stays.
    let moved = after.eye_mm() - before.eye_mm();
    assert!(moved.dot(before.forward()).abs() < 0.3, "{moved:?}");
    assert_eq!(after.forward(), before.forward());
}

#[test]
fn a_click_beside_the_lumen_jumps_into_it_and_one_far_from_any_says_so() {
    let (mut session, truth) = tube_session();
    let across = truth.axis.any_orthonormal_vector();
    let beside = truth.centre_mm + across * (truth.radius_mm + 1.5);
    let said = session.jump_to(beside).unwrap();
    assert!(said.starts_with("moved"), "{said}");
    let eye = session.fly_camera().eye_mm();
    assert!(off_axis_mm(&truth, eye) < truth.radius_mm, "{eye}");
    let far = truth.centre_mm + across * (truth.radius_mm + 40.0);
    let said = session.jump_to(far).unwrap();
    assert!(said.starts_with("not in a lumen"), "{said}");
    assert!(session.jump_to(truth.centre_mm).is_none());
}

#[test]
fn the_realistic_look_refines_to_its_still_and_then_rests() {
    use endocast_core::look::LookKind;
    let (mut session, _) = tube_session();
    session.turn(0.0, 0.6);
    let plain = settled(&mut session);
    session.controls.look = LookKind::Realistic;
    let look = settled(&mut session);
    assert!(
        mean_difference(&plain, &look) > 2.0,
        "the look shows the plain picture"
    );
    let g = session.worker().generation();
    assert_eq!(session.sync(false), None);
    assert_eq!(session.worker().generation(), g);
}

#[test]
fn key_frames_insert_move_delete_and_undo() {
    let (mut session, _) = tube_session();
    let eye = |s: &endocast_viewer::session::Session| -> Vec<f64> {
        s.key_frames().iter().map(|k| k.eye_mm.z).collect()
    };
    session.record_key_frame().unwrap();
    session.fly(forward(2.0));
    session.record_key_frame().unwrap();
    session.fly(forward(2.0));
    // The view now goes between the two.
    session.insert_key_frame(1).unwrap();
    let [a, b, c] = eye(&session)[..] else {
        panic!("{:?}", eye(&session));
    };
    session.move_key_frame(2, 0);
    assert_eq!(eye(&session), [c, a, b]);
    session.delete_key_frame(1);
    assert_eq!(eye(&session), [c, b]);
    // Each change taken back in turn, to none recorded.
    assert!(session.undo_key_frames());
    assert_eq!(eye(&session), [c, a, b]);
    assert!(session.undo_key_frames());
    assert_eq!(eye(&session), [a, b, c]);
    for _ in 0..3 {
        assert!(session.undo_key_frames());
    }
    assert!(session.key_frames().is_empty());
    assert!(!session.undo_key_frames());
}
