//! Case files: annotations and the scan's fingerprint round-trip, bad files are refused with
//! the file and the problem, a kill during a save leaves a whole file, changes made at once
//! are all kept, and a large case opens at once.

use endocast_core::annotate::{Annotation, Annotations, ScanIdentity, Shape};
use endocast_core::phantom::{Phantom, PhantomOptions};
use endocast_io::case::{AnnotationRecord, Case, CaseError, ScanSource};
use glam::DVec3;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn tube() -> (ScanSource, ScanIdentity) {
    let source = ScanSource::Phantom {
        name: "straight-tube".into(),
        size: 16,
    };
    let volume = source.load().unwrap();
    (source, ScanIdentity::of(&volume))
}

/// A case with `n` annotations of every kind.
fn case_with(n: usize) -> Case {
    let (source, identity) = tube();
    let mut marks = Annotations::default();
    for i in 0..n {
        let p = DVec3::new(i as f64, 1.5, -2.25);
        let shape = match i % 3 {
            0 => Shape::Point(p),
            1 => Shape::Stroke(vec![p, p + DVec3::X, p + DVec3::Y]),
            _ => Shape::Distance(p, p + DVec3::new(3.0, 4.0, 0.0)),
        };
        marks
            .add(Annotation::new(shape).labelled(&format!("mark {i}")))
            .unwrap();
    }
    let mut case = Case::new(source, Some(&identity));
    case.set_annotations(&marks);
    case.revision = n as u64;
    case
}

#[test]
fn annotations_and_the_scan_identity_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    let case = case_with(6);
    case.write(&path).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.contains("\"distance_mm\": 5.0") && text.contains("\"stroke\""),
        "{text}"
    );
    let read = Case::read(&path).unwrap();
    assert_eq!(read, Case { ..case.clone() });
    let marks = read.annotations(&path).unwrap();
    assert_eq!(marks, case.annotations(&path).unwrap());
    assert_eq!(marks.items()[2].distance_mm(), Some(5.0));
    let (_, identity) = tube();
    read.check_scan(&identity, &path).unwrap();
}

#[test]
fn a_case_on_another_scan_is_refused_naming_what_differs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tube.case.json");
    let case = case_with(1);
    let other = Phantom::from_name("straight-tube")
        .unwrap()
        .build(&PhantomOptions {
            size: 16,
            noise_hu: 5.0,
            ..PhantomOptions::default()
        });
    let error = case
        .check_scan(&ScanIdentity::of(&other), &path)
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("tube.case.json") && error.contains("voxel values"),
        "{error}"
    );
}

#[test]
fn bad_case_files_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.json");
    case_with(3).write(&good).unwrap();
    let text = std::fs::read_to_string(&good).unwrap();
    for (name, content, expect) in [
        (
            "garbage.json",
            "{not json".to_owned(),
            "key must be a string",
        ),
        (
            "version.json",
            text.replace("\"version\": 3", "\"version\": 9"),
            "version 9",
        ),
        (
            "kind.json",
            text.replace("\"stroke\"", "\"circle\""),
            "circle",
        ),
        (
            "short.json",
            text.replacen("\"measure\"", "\"point\"", 1),
            "needs 1",
        ),
        (
            "key.json",
            text.replace("\"revision\"", "\"surprise\""),
            "surprise",
        ),
    ] {
        let path = dir.path().join(name);
        std::fs::write(&path, content).unwrap();
        let error = Case::read(&path).unwrap_err().to_string();
        assert!(error.contains(name) && error.contains(expect), "{error}");
    }
}

#[test]
fn version_1_cases_of_the_viewer_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.json");
    std::fs::write(
        &path,
        r#"{"format": "endocast-case", "version": 1,
            "scan": {"kind": "phantom", "name": "colon", "size": 64},
            "controls": {"preset": "colonoscopy", "mode": "hybrid", "iso_hu": -500.0,
              "iso_opacity": 1.0, "lens": "pinhole", "fov_deg": 90.0, "stereo": false,
              "collision": true, "speed_mm_s": 20.0, "window_level_hu": -300.0,
              "window_width_hu": 1400.0},
            "camera": {"eye": [1, 2, 3], "forward": [0, 0, 1], "up": [0, -1, 0]},
            "annotations": [{"label": "polyp", "point": [4, 5, 6]}], "revision": 3}"#,
    )
    .unwrap();
    let case = Case::read(&path).unwrap();
    let marks = case.annotations(&path).unwrap();
    assert_eq!(
        marks.items()[0].shape,
        Shape::Point(DVec3::new(4.0, 5.0, 6.0))
    );
    assert_eq!(marks.items()[0].label, "polyp");
    assert!(case.identity.is_none() && case.controls.is_some());
}

/// The child of the kill test: writes ever-growing cases as fast as it can, saying which
/// revision each finished write holds.
fn save_forever(path: &Path) {
    for n in 1.. {
        // Large enough that a write takes a while: thousands of stroke points.
        let mut case = case_with(300);
        case.revision = n;
        case.write(path).unwrap();
        println!("saved {n}");
    }
}

#[test]
fn a_kill_during_a_save_leaves_the_old_or_the_new_case_whole() {
    if let Some(path) = std::env::var_os("ENDOCAST_CASE_CHILD") {
        save_forever(Path::new(&path));
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    for delay_ms in [50, 170, 400] {
        let mut child = Command::new(std::env::current_exe().unwrap())
            .args([
                "--exact",
                "case::a_kill_during_a_save_leaves_the_old_or_the_new_case_whole",
                "--nocapture",
                "--test-threads=1",
            ])
            .env("ENDOCAST_CASE_CHILD", &path)
            .stdout(Stdio::piped())
            .spawn()
            .unwrap();
        let stdout = child.stdout.take().unwrap();
        let (saved, confirmations) = std::sync::mpsc::channel();
        let lines = std::thread::spawn(move || {
            let mut confirmed = Vec::new();
            for line in BufReader::new(stdout).lines() {
                let Ok(line) = line else { break };
                if let Some(n) = line.strip_prefix("saved ") {
                    confirmed.push(n.parse::<u64>().unwrap());
                    let _ = saved.send(());
                }
            }
            confirmed
        });
        // Killed in the middle of later saves once three are confirmed: on a busy machine a
        // save can take longer than any fixed delay.
        for _ in 0..3 {
            confirmations
                .recv_timeout(Duration::from_secs(60))
                .expect("the child saves");
        }
        std::thread::sleep(Duration::from_millis(delay_ms));
        child.kill().unwrap();
        child.wait().unwrap();
        let confirmed = lines.join().unwrap();
        let last = *confirmed.last().expect("the child saved");
        let case = Case::read(&path).expect("the case file is whole after the kill");
        assert!(
            case.revision == last || case.revision == last + 1,
            "saved {last}, the file holds {}",
            case.revision
        );
        assert_eq!(case.annotations.len(), 300);
    }
}

#[test]
fn changes_made_at_once_are_all_kept() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("case.json");
    let (source, identity) = tube();
    let add = |n: usize| {
        Case::update(
            &path,
            || Ok::<_, CaseError>(Case::new(source.clone(), Some(&identity))),
            |case| {
                let mut marks = case.annotations(&path)?;
                marks
                    .add(Annotation::new(Shape::Point(DVec3::splat(n as f64))))
                    .map_err(|e| CaseError::new(&path, e))?;
                case.set_annotations(&marks);
                Ok(())
            },
        )
    };
    std::thread::scope(|scope| {
        for writer in 0..8 {
            scope.spawn(move || (0..10).for_each(|k| add(writer * 10 + k).unwrap()));
        }
    });
    let case = Case::read(&path).unwrap();
    assert_eq!(case.annotations.len(), 80);
    assert_eq!(case.revision, 80);
    // A failed change writes nothing.
    let failed: Result<(), _> = Case::update(
        &path,
        || unreachable!(),
        |_| Err(CaseError::new(&path, "no")),
    );
    assert!(failed.is_err());
    assert_eq!(Case::read(&path).unwrap(), case);
}

#[test]
fn a_case_of_300_000_annotations_opens_in_linear_time() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("big.json");
    let (source, identity) = tube();
    let mut case = Case::new(source, Some(&identity));
    case.annotations = (1..=300_000)
        .map(|id| AnnotationRecord {
            id,
            kind: "point".into(),
            label: String::new(),
            points: vec![[f64::from(id % 97), 1.0, 2.0]],
            point: None,
            color: None,
            distance_mm: None,
        })
        .collect();
    // Compact, as the size limit of case files allows.
    std::fs::write(&path, serde_json::to_vec(&case).unwrap()).unwrap();
    let start = std::time::Instant::now();
    let read = Case::read(&path).unwrap();
    let marks = read.annotations(&path).unwrap();
    let seconds = start.elapsed().as_secs_f64();
    assert_eq!(marks.len(), 300_000);
    assert_eq!(marks.items()[299_999].id, 300_000);
    assert!(seconds <= 2.0, "{seconds:.1} s to open 300 000 annotations");
}
