//! Planned paths as key frames, and the flight exported: the film with progress and cancel,
//! and the path files `endocast fly --path` reads.

use crate::common::{off_axis_mm, settled, tube_session};
use endocast_core::navigate::PathEnd;
use endocast_io::route_file::read_route;
use endocast_viewer::export::{write_flight_path, ExportEnd, FilmExport, FilmOptions};
use endocast_viewer::jobs::Notify;
use endocast_viewer::planner::{start_planning, KEY_STEP_MM};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn quiet() -> Notify {
    Arc::new(|| {})
}

/// Polls `export` until it ends (or fails the test after a minute).
fn finish(export: &FilmExport) -> ExportEnd {
    let start = Instant::now();
    loop {
        if let Some(end) = export.poll() {
            return end;
        }
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the export hangs"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
}

#[test]
fn a_path_to_the_farthest_point_becomes_key_frames_along_the_tube_that_play() {
    let (mut session, truth) = tube_session();
    let start = session.fly_camera().eye_mm();
    let job = start_planning(&session, start, PathEnd::Farthest, quiet()).unwrap();
    let planned = job.wait().unwrap().unwrap();
    // From the middle to an end of the 40 mm tube.
    assert!(
        planned.length_mm > 10.0 && planned.length_mm < 30.0,
        "{} mm",
        planned.length_mm
    );
    let keys = planned.key_frames.len();
    assert!(
        keys as f64 >= planned.length_mm / KEY_STEP_MM,
        "{keys} key frames"
    );
    // Inside the tube (not where its open end meets the volume's face) the key frames lie on
    // the axis and look along it.
    let inner: Vec<_> = planned
        .key_frames
        .iter()
        .filter(|k| (k.eye_mm - truth.centre_mm).dot(truth.axis).abs() < 8.0)
        .collect();
    assert!(inner.len() >= 2, "{} key frames inside", inner.len());
    for key in inner {
        assert!(off_axis_mm(&truth, key.eye_mm) < 1.0, "{:?}", key.eye_mm);
        let along = key.forward().dot(truth.axis).abs();
        assert!(along > 0.9, "{:?}", key.forward());
    }
    session.set_key_frames(planned.key_frames);
    session.play().unwrap();
    let mut steps = 0;
    while session.advance_playback(0.1) {
        steps += 1;
        assert!(off_axis_mm(&truth, session.fly_camera().eye_mm()) < truth.radius_mm);
        assert!(steps < 10_000);
    }
    let end = session.fly_camera().eye_mm();
    assert!(
        (end - start).dot(truth.axis).abs() > 10.0,
        "the flight ended {:?} from its start",
        end - start
    );
    // A start that is no point is refused with the reason.
    let nowhere = glam::DVec3::NAN;
    let outside = start_planning(&session, nowhere, PathEnd::Farthest, quiet()).unwrap();
    let error = outside.wait().unwrap().unwrap_err();
    assert!(error.contains("no path"), "{error}");
}

/// Two key frames along the tube.
fn flight_session() -> endocast_viewer::session::Session {
    let (mut session, _) = tube_session();
    session.turn(0.0, std::f64::consts::FRAC_PI_2 * 0.98);
    session.record_key_frame().unwrap();
    for _ in 0..12 {
        session.fly(endocast_viewer::controller::LocalMove {
            forward_mm: 0.5,
            ..Default::default()
        });
    }
    session.record_key_frame().unwrap();
    session
}

#[test]
fn the_flight_films_to_a_gif_with_progress_and_a_cancelled_film_leaves_nothing() {
    let mut session = flight_session();
    let dir = tempfile::tempdir().unwrap();
    let gif = dir.path().join("flight.gif");
    let film = FilmOptions {
        fps: 10.0,
        ..FilmOptions::default()
    };
    let export = FilmExport::start(&mut session, &gif, &film, quiet()).unwrap();
    let (_, total) = export.progress();
    assert!(total >= 5, "{total} frames for 6 mm");
    assert_eq!(finish(&export), ExportEnd::Written(gif.clone()));
    assert_eq!(export.progress(), (total, total));
    let bytes = std::fs::read(&gif).unwrap();
    assert!(bytes.starts_with(b"GIF89a"), "not a GIF");

    let cancelled = dir.path().join("cancelled.gif");
    let export = FilmExport::start(&mut session, &cancelled, &film, quiet()).unwrap();
    export.cancel();
    assert_eq!(finish(&export), ExportEnd::Cancelled);
    assert!(!cancelled.exists());
    let leftovers = std::fs::read_dir(dir.path()).unwrap().count();
    assert_eq!(leftovers, 1, "a cancelled film left files");

    // Fewer than two key frames: said at once.
    let (mut alone, _) = tube_session();
    let error = FilmExport::start(&mut alone, &gif, &film, quiet()).unwrap_err();
    assert!(error.contains("key frames"), "{error}");
    // A size out of range: named at once.
    let huge = FilmOptions {
        size: [10_000, 64],
        ..film
    };
    let error = FilmExport::start(&mut session, &gif, &huge, quiet()).unwrap_err();
    assert!(error.contains("film size"), "{error}");
}

#[test]
fn films_show_the_marks_and_geometry_the_view_shows_at_the_chosen_size() {
    let mut session = flight_session();
    session.go_to_key_frame(0);
    settled(&mut session);
    let dir = tempfile::tempdir().unwrap();
    let film = FilmOptions {
        size: [48, 40],
        step_mm: 3.0,
        ..FilmOptions::default()
    };
    let first_frame = |session: &mut endocast_viewer::session::Session, name: &str| {
        let folder = dir.path().join(name);
        let export = FilmExport::start(session, &folder, &film, quiet()).unwrap();
        assert_eq!(finish(&export), ExportEnd::Written(folder.clone()));
        let mut frames: Vec<_> = std::fs::read_dir(&folder)
            .unwrap()
            .map(|e| e.unwrap().path())
            .collect();
        frames.sort();
        let png = std::fs::read(&frames[0]).unwrap();
        // The header's width and height (IHDR, big-endian, after the signature).
        let side = |at: usize| u32::from_be_bytes(png[at..at + 4].try_into().unwrap());
        assert_eq!((side(16), side(20)), (48, 40));
        png
    };
    let plain = first_frame(&mut session, "plain");
    // A label on the wall near the view's left edge (the middle looks down the tube): its
    // decal is in the film.
    assert!(session.annotate_pixel(6, 32, "polyp"));
    let marked = first_frame(&mut session, "marked");
    assert!(plain != marked, "the mark is not in the film");
    // The endoscope's instrument toggled on: in the film too.
    session.controls.geometry.endoscope = true;
    let instrument = first_frame(&mut session, "instrument");
    assert!(marked != instrument, "the instrument is not in the film");
}

#[test]
fn the_flight_writes_path_files_that_the_cli_reads_back() {
    let session = flight_session();
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("keys.json");
    write_flight_path(&session, &json).unwrap();
    let keys = read_route(&json).unwrap();
    let markups = dir.path().join("flight.mrk.json");
    write_flight_path(&session, &markups).unwrap();
    let curve = read_route(&markups).unwrap();
    let text = std::fs::read_to_string(&markups).unwrap();
    assert!(text.contains("\"Curve\""), "{text}");
    // Both describe the same 6 mm flight.
    assert!((keys.len_mm() - 6.0).abs() < 0.5, "{}", keys.len_mm());
    assert!(
        (curve.len_mm() - keys.len_mm()).abs() < 0.5,
        "{}",
        curve.len_mm()
    );
}

#[test]
fn path_files_read_back_as_the_key_frames_the_cli_flies() {
    use endocast_viewer::planner::{key_look, read_key_frames};
    let session = flight_session();
    let dir = tempfile::tempdir().unwrap();
    let (json, markups) = (dir.path().join("keys.json"), dir.path().join("c.mrk.json"));
    write_flight_path(&session, &json).unwrap();
    write_flight_path(&session, &markups).unwrap();
    // Our key frames come back as they were.
    let keys = read_key_frames(&json, key_look(&session)).unwrap();
    assert_eq!(keys.len(), session.key_frames().len());
    for (read, recorded) in keys.iter().zip(session.key_frames()) {
        assert!((read.eye_mm - recorded.eye_mm).length() < 1e-6);
    }
    // A Slicer curve becomes key frames along the route the CLI reads, end to end.
    let curve = read_route(&markups).unwrap();
    let along = read_key_frames(&markups, key_look(&session)).unwrap();
    assert!(along.len() >= 2);
    let first = session.key_frames()[0].eye_mm;
    let last = session.key_frames()[1].eye_mm;
    assert!((along[0].eye_mm - first).length() < 0.1);
    assert!((along.last().unwrap().eye_mm - last).length() < 0.1);
    assert!((curve.len_mm() - 6.0).abs() < 0.5);
    // A missing file is named.
    let gone = read_key_frames(&dir.path().join("gone.mrk.json"), key_look(&session));
    assert!(gone.unwrap_err().contains("gone.mrk.json"));
}

#[test]
fn the_window_plans_through_the_stent_as_endocast_path_does() {
    use endocast_core::navigate::PathEnd;
    use endocast_core::path::SmoothOptions;
    use endocast_core::presets::Preset;
    use endocast_viewer::planner::start_planning;
    use endocast_viewer::scene::{ScanSource, Scene};
    use endocast_viewer::session::Session;
    let Some(stent) = endocast_testdata::shared_data("aorta-stent-cta/stent.nrrd") else {
        return;
    };
    let source = ScanSource::File {
        path: stent,
        series: None,
        orientation: None,
    };
    let (volume, facts) = source.load_with_facts(&Default::default()).unwrap();
    let scene = Arc::new(Scene::new(source, volume).with_facts(facts));
    let session = Session::new(scene, Preset::find("angioscopy"), None, || {});
    // The thin contrast-filled tree leaks out at the study's threshold grown from the start;
    // the study's structure (the aorta) does not.
    let eye = session.fly_camera().eye_mm();
    let cli = session.study().plan(
        session.scene().volume(),
        Some(eye),
        None,
        &SmoothOptions::default(),
    );
    let cli_mm = cli.unwrap().planned.path.len_mm();
    let job = start_planning(&session, eye, PathEnd::Farthest, quiet()).unwrap();
    let planned = job.wait().unwrap().unwrap();
    assert!(cli_mm > 150.0, "{cli_mm}");
    assert!(
        (planned.length_mm - cli_mm).abs() < 1e-9,
        "{} vs {cli_mm}",
        planned.length_mm
    );
}
