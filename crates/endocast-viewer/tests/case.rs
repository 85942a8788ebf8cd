//! Case files: reopened exactly, strict on reading, never lost to a kill during a save, and
//! never saved over another program's changes.

use crate::common::{settled, tube_session};
use endocast_core::annotate::STROKE_COLOR;
use endocast_core::look::Lighting;
use endocast_core::presets::Preset;
use endocast_core::render::{PeelLayer, TransferFunction, Unpeeled};
use endocast_viewer::case::{Autosave, Case, SessionCase};
use endocast_viewer::controller::LocalMove;
use endocast_viewer::scene::Scene;
use endocast_viewer::session::{Controls, Session};
use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::sync::{mpsc, Arc};
use std::time::Duration;

/// Opens the case at `path` as the application does: its scan, its preset, then its state.
fn reopen(path: &std::path::Path) -> Session {
    let case = Case::read(path).unwrap();
    let volume = case.scan.load().unwrap();
    let scene = Arc::new(Scene::new(case.scan.clone(), volume));
    let preset = Preset::find(&case.controls.as_ref().unwrap().preset);
    let mut session = Session::new(scene, preset, None, || {});
    session.set_view_size([64, 64]);
    case.apply(&mut session, path).unwrap();
    session
}

/// Sets what version 3 added to the case: the transfer function, peel settings, geometry.
fn changed_look(c: &mut Controls) {
    let opacity: Vec<_> =
        c.tf.opacity_points()
            .iter()
            .map(|(v, a)| (*v, a * 0.5))
            .collect();
    c.tf = TransferFunction::from_points(&opacity, c.tf.color_points()).unwrap();
    c.peel.layer = PeelLayer::Last;
    c.peel.threshold_hu = Some(-300.0);
    c.peel.keep = 0.25;
    c.peel.unpeeled = Unpeeled::Context;
    c.geometry.grid = true;
    c.geometry.markers = true;
    c.lighting = Lighting::built_in_ibl();
}

#[test]
fn a_saved_case_reopens_to_the_same_view_with_its_marks_and_key_frames() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tube.endocast-case.json");
    let (mut session, _) = tube_session();
    session.turn(0.4, 0.2);
    session.fly(LocalMove {
        forward_mm: 2.0,
        ..LocalMove::default()
    });
    session.controls.iso_hu = -450.0;
    session.controls.iso_opacity = 0.8;
    session.controls.fov_deg = 70.0;
    changed_look(&mut session.controls);
    session.record_key_frame().unwrap();
    settled(&mut session);
    assert!(session.annotate_pixel(30, 34, "lesion"));
    let shown = settled(&mut session);
    Autosave::new(path.clone(), Duration::ZERO)
        .tick(&session, true)
        .unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("\"lesion\"") && text.contains("endocast-case") && text.contains("\"last\""),
        "{text}"
    );

    let mut reopened = reopen(&path);
    assert_eq!(reopened.controls, session.controls);
    assert_eq!(reopened.annotations(), session.annotations());
    assert_eq!(reopened.key_frames().len(), 1);
    let again = settled(&mut reopened);
    assert_eq!(again.camera, shown.camera);
    assert!(
        again.image.rgb() == shown.image.rgb(),
        "the reopened view differs"
    );
}

#[test]
fn a_stroke_drawn_on_the_tissue_is_in_the_saved_case_and_only_fits_its_scan() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("drawn.endocast-case.json");
    let (mut session, _) = tube_session();
    settled(&mut session);
    // A drag across the view, as the draw tool makes it.
    for x in 16..48 {
        assert!(session.stroke_to_pixel(x, 20 + x / 4));
    }
    let id = session.finish_stroke("resect").unwrap();
    assert!(session.stroke_in_progress().is_empty());
    // The screenshot shows it where the wall is.
    let shot = session.screenshot().unwrap();
    let green = shot.rgb().chunks(3).filter(|p| *p == STROKE_COLOR).count();
    assert!(green > 30, "{green} stroke pixels in the screenshot");
    let mm = session.measure_pixels([20, 40], [44, 40]).unwrap();
    Autosave::new(path.clone(), Duration::ZERO)
        .tick(&session, true)
        .unwrap();

    let case = Case::read(&path).unwrap();
    let marks = case.annotations(&path).unwrap();
    let stroke = marks.get(id).unwrap();
    assert_eq!(stroke.shape.kind(), "stroke");
    assert_eq!(stroke.label, "resect");
    assert_eq!(stroke.shape.points().len(), 32);
    assert_eq!(marks.items()[1].distance_mm(), Some(mm));
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("\"voxel_hash\"") && text.contains("\"measure\""),
        "{text}"
    );
    assert_eq!(reopen(&path).marks(), session.marks());

    // The same case on another scan is refused, saying why.
    let other = endocast_viewer::scene::ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 36,
    };
    let scene = Arc::new(Scene::new(other.clone(), other.load().unwrap()));
    let mut elsewhere = Session::new(scene, Preset::find("colonoscopy"), None, || {});
    let error = case.apply(&mut elsewhere, &path).unwrap_err().to_string();
    assert!(
        error.contains("drawn.endocast-case.json") && error.contains("dimensions"),
        "{error}"
    );
}

#[test]
fn a_version_2_case_reopens_with_the_presets_look() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("v2.endocast-case.json");
    let (mut session, _) = tube_session();
    session.controls.iso_hu = -450.0;
    let mut case = Case::of(&session, 1);
    let controls = case.controls.as_mut().unwrap();
    (controls.tf, controls.peel, controls.geometry) = (None, None, None);
    // Nor the lighting (added later): Phong.
    controls.lighting = None;
    case.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, text.replace("\"version\": 3", "\"version\": 2")).unwrap();
    let reopened = reopen(&path);
    assert_eq!(reopened.controls, session.controls);
    // And the changed look is kept by the current version, but not by that one.
    changed_look(&mut session.controls);
    Case::of(&session, 2).write(&path).unwrap();
    assert_eq!(reopen(&path).controls, session.controls);
    let mut old = Case::read(&path).unwrap();
    old.controls.as_mut().unwrap().tf = None;
    old.write(&path).unwrap();
    assert_ne!(reopen(&path).controls.tf, session.controls.tf);
}

#[test]
fn bad_case_files_are_refused_with_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let (session, _) = tube_session();
    let good = dir.path().join("good.json");
    Case::of(&session, 1).write(&good).unwrap();
    let text = std::fs::read_to_string(&good).unwrap();
    for (name, content, expect) in [
        ("garbage.json", "{not json".to_owned(), "garbage.json"),
        (
            "format.json",
            text.replace("endocast-case", "other"),
            "format",
        ),
        (
            "preset.json",
            text.replace("colonoscopy", "gastroscopy"),
            "gastroscopy",
        ),
        (
            "peel.json",
            text.replace("\"layer\": \"1\"", "\"layer\": \"zero\""),
            "zero",
        ),
        (
            "key.json",
            text.replace("\"revision\"", "\"surprise\""),
            "surprise",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, content).unwrap();
        let error = Case::read(&path)
            .and_then(|case| SessionCase::controls(&case, &path, &session).map(|_| ()))
            .unwrap_err()
            .to_string();
        assert!(error.contains(name) && error.contains(expect), "{error}");
    }
    let missing = Case::read(&dir.path().join("missing.json")).unwrap_err();
    assert!(missing.to_string().contains("missing.json"));
}

/// The child of the kill test: saves a changing case as fast as it can, saying which revision
/// each finished save holds.
fn autosave_forever(path: &std::path::Path) {
    let (mut session, _) = tube_session();
    let mut autosave = Autosave::new(path.to_owned(), Duration::ZERO);
    let mut revision = 0;
    loop {
        session.turn(0.01, 0.0);
        if autosave.tick(&session, true).unwrap() {
            revision += 1;
            println!("saved {revision}");
        }
    }
}

#[test]
fn killing_during_autosave_loses_nothing_saved_before() {
    if let Some(path) = std::env::var_os("ENDOCAST_AUTOSAVE_CHILD") {
        autosave_forever(std::path::Path::new(&path));
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    // Killed after a few saves, at different moments of the next one (the child may get little
    // CPU on a loaded machine: it is waited for by its saves, not by the clock).
    for (saves, delay_ms) in [(3, 0), (5, 3), (8, 11)] {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "case::killing_during_autosave_loses_nothing_saved_before",
                "--nocapture",
                "--test-threads=1",
            ])
            .env("ENDOCAST_AUTOSAVE_CHILD", &path)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let (send, saved) = mpsc::channel();
        let reader = std::thread::spawn(move || {
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if let Some(n) = line.strip_prefix("saved ") {
                    let _ = send.send(n.parse::<u64>().unwrap());
                }
            }
        });
        let mut confirmed = Vec::new();
        while confirmed.len() < saves {
            match saved.recv_timeout(Duration::from_secs(120)) {
                Ok(n) => confirmed.push(n),
                Err(e) => panic!("the child saved {} times, then {e}", confirmed.len()),
            }
        }
        std::thread::sleep(Duration::from_millis(delay_ms));
        child.kill().unwrap();
        child.wait().unwrap();
        reader.join().unwrap();
        confirmed.extend(saved.try_iter());
        let last = *confirmed.last().unwrap();
        let case = Case::read(&path).expect("the case file is whole after the kill");
        assert!(
            case.revision >= last,
            "saved {last}, the file holds {}",
            case.revision
        );
    }
}

#[test]
fn a_case_reads_its_meshes_again_and_opens_without_one_that_is_gone() {
    use endocast_core::scene::TriangleMesh;
    use endocast_viewer::case::read_case_meshes;
    use endocast_viewer::geometry::with_mesh;
    let dir = tempfile::tempdir().unwrap();
    let (path, stl) = (
        dir.path().join("mesh.endocast-case.json"),
        dir.path().join("t.stl"),
    );
    let (mut session, _) = tube_session();
    // A triangle across the view, 3 mm ahead of the eye.
    let camera = session.fly_camera();
    let (eye, f, u) = (camera.eye_mm(), camera.forward(), camera.up());
    let r = f.cross(u);
    let ahead = eye + f * 3.0;
    let corners = vec![ahead - r - u, ahead + r - u, ahead + u];
    let mesh = TriangleMesh::new(corners, vec![[0, 1, 2]]).unwrap();
    endocast_io::mesh::write_mesh(&stl, &mesh).unwrap();
    let without = settled(&mut session);
    let meshes = with_mesh(session.geometry_mut().meshes().clone(), &stl).unwrap();
    session.geometry_mut().set_meshes(meshes, stl.clone());
    session.controls.geometry.meshes = true;
    let shown = settled(&mut session);
    assert!(
        shown.image.rgb() != without.image.rgb(),
        "the mesh is not in view"
    );
    Autosave::new(path.clone(), Duration::ZERO)
        .tick(&session, true)
        .unwrap();

    let case = Case::read(&path).unwrap();
    let mut reopened = reopen(&path);
    assert!(read_case_meshes(&case, &mut reopened).is_empty());
    assert_eq!(reopened.geometry().mesh_files(), std::slice::from_ref(&stl));
    let again = settled(&mut reopened);
    assert!(
        again.image.rgb() == shown.image.rgb(),
        "the reopened view lost its mesh"
    );

    // The mesh file gone: the case opens all the same, and the problem names the file.
    std::fs::remove_file(&stl).unwrap();
    let mut reopened = reopen(&path);
    let problems = read_case_meshes(&case, &mut reopened);
    assert_eq!(problems.len(), 1);
    assert!(problems[0].contains("t.stl"), "{problems:?}");
    assert!(reopened.geometry().mesh_files().is_empty());
    assert_eq!(reopened.controls, session.controls);
}

#[test]
fn an_autosave_never_overwrites_what_another_program_saved_meanwhile() {
    use endocast_core::annotate::{Annotation, Shape};
    use endocast_viewer::case::CaseError;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("shared.json");
    let (mut session, _) = tube_session();
    let mut autosave = Autosave::new(path.clone(), Duration::ZERO);
    assert!(autosave.tick(&session, true).unwrap());
    // `endocast annotate` adds a mark to the same case.
    Case::update(
        &path,
        || unreachable!(),
        |case| {
            let mut marks = case.annotations(&path)?;
            marks
                .add(Annotation::new(Shape::Point(glam::DVec3::ZERO)))
                .map_err(|e| CaseError::new(&path, e))?;
            case.set_annotations(&marks);
            Ok::<_, CaseError>(())
        },
    )
    .unwrap();
    session.turn(0.01, 0.0);
    let refused = autosave.tick(&session, true).unwrap_err().to_string();
    assert!(
        refused.contains("shared.json") && refused.contains("another program"),
        "{refused}"
    );
    assert_eq!(Case::read(&path).unwrap().annotations.len(), 1);
    // Opened again, it saves over the file as it is now.
    let mut reopened = Autosave::new(path.clone(), Duration::ZERO);
    assert!(reopened.tick(&session, true).unwrap());
    assert_eq!(Case::read(&path).unwrap().revision, 3);
}

#[test]
fn opening_a_scan_again_reopens_its_case_and_never_replaces_one_it_cannot_use() {
    use endocast_io::case::ScanSource;
    use endocast_viewer::case_choice::{choose_case, default_case_path};
    let dir = tempfile::tempdir().unwrap();
    let scan = dir.path().join("chest.nii.gz");
    std::fs::write(&scan, b"voxels").unwrap();
    let source = ScanSource::File {
        path: scan.clone(),
        series: None,
        orientation: None,
    };
    let default = default_case_path(&source);
    assert_eq!(default, dir.path().join("chest.nii.gz.endocast-case.json"));
    // None yet: the session will save to the default.
    let first = choose_case(&source, None);
    assert_eq!((first.open, &first.save_to), (None, &default));
    // This scan's case is reopened.
    Case::new(source.clone(), None).write(&default).unwrap();
    let again = choose_case(&source, None);
    assert_eq!(again.open.as_ref(), Some(&default));
    assert_eq!(again.save_to, default);
    // Another scan's case, or a damaged file, is left alone byte for byte.
    let other = ScanSource::Phantom {
        name: "colon".into(),
        size: 64,
    };
    Case::new(other, None).write(&default).unwrap();
    let others = std::fs::read(&default).unwrap();
    for content in [others, b"{ not a case".to_vec()] {
        std::fs::write(&default, &content).unwrap();
        let choice = choose_case(&source, None);
        assert_eq!(choice.open, None);
        assert_eq!(
            choice.save_to,
            dir.path().join("chest.nii.gz-2.endocast-case.json")
        );
        let note = choice.note.unwrap();
        assert!(note.contains("left as it is"), "{note}");
        assert_eq!(std::fs::read(&default).unwrap(), content);
    }
}

#[test]
fn a_reopened_case_is_not_rewritten_until_the_session_changes_and_keeps_its_last_version() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tube.endocast-case.json");
    let (mut session, _) = tube_session();
    session.record_key_frame().unwrap();
    Autosave::new(path.clone(), Duration::ZERO)
        .tick(&session, true)
        .unwrap();
    let saved = std::fs::read(&path).unwrap();
    // Relaunched on its case: nothing written, however often it ticks.
    let mut reopened = reopen(&path);
    let mut autosave = Autosave::opened(path.clone(), Duration::ZERO, &reopened);
    assert!(!autosave.tick(&reopened, true).unwrap());
    assert_eq!(std::fs::read(&path).unwrap(), saved);
    // A --screenshot run never writes.
    reopened.turn(0.3, 0.0);
    assert!(!Autosave::never(path.clone()).tick(&reopened, true).unwrap());
    assert_eq!(std::fs::read(&path).unwrap(), saved);
    // A change is saved, and the version it replaced is kept beside it.
    assert!(autosave.tick(&reopened, true).unwrap());
    assert_ne!(std::fs::read(&path).unwrap(), saved);
    assert_eq!(std::fs::read(Case::previous_path(&path)).unwrap(), saved);
}
