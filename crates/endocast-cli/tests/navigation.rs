//! `endocast path` and `endocast fly` end to end on phantoms: the path stays on the tube's axis,
//! flights come out as GIF, PNG frames, dashboards and MP4, coverage grows with a backward pass,
//! and bad requests fail with a clear message.

use crate::common::{endocast, fails_with};
use std::path::Path;

/// A phantom written into `dir`; returns its path.
fn phantom(dir: &Path, name: &str, size: &str) -> String {
    let file = dir.join(format!("{name}.nii.gz"));
    let file = file.to_str().unwrap().to_owned();
    let out = endocast(&["phantom", name, "--size", size, "-o", &file]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    file
}

/// Runs endocast and returns stdout, panicking with stderr on failure.
fn ok(args: &[&str]) -> String {
    let out = endocast(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{args:?} failed: {stderr}");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A path along the 48³ straight tube (axis x = y = 0, radius 9.6 mm) from z = −18 to 18 mm.
fn tube_path(dir: &Path, tube: &str, name: &str) -> String {
    let file = dir.join(name).to_str().unwrap().to_owned();
    let args = [
        "path", tube, "--iso", "-480", "--from", "0,0,-18", "--to", "0,0,18", "-o", &file,
    ];
    let stdout = ok(&args);
    assert!(stdout.contains("mm long"), "{stdout}");
    file
}

#[test]
fn the_tube_path_runs_on_the_axis_and_reads_back_in_both_formats() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let ours = tube_path(dir.path(), &tube, "p.json");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&ours).unwrap()).unwrap();
    assert_eq!(json["format"], "endocast-path");
    let points = json["points"].as_array().unwrap();
    assert!(points.len() >= 18, "{} points", points.len());
    for p in points {
        let [x, y, z] = [0, 1, 2].map(|a| p[a].as_f64().unwrap());
        assert!(x.hypot(y) < 1.0, "({x}, {y}, {z}) is off the axis");
    }
    let slicer = tube_path(dir.path(), &tube, "p.mrk.json");
    let text = std::fs::read_to_string(&slicer).unwrap();
    assert!(text.contains("\"Curve\"") && text.contains("LPS"), "{text}");
    for route in [&ours, &slicer] {
        let gif = dir.path().join("f.gif");
        let gif = gif.to_str().unwrap();
        let args = [
            "fly",
            &tube,
            "--path",
            route,
            "--iso",
            "-480",
            "--size",
            "48x48",
            "--frame-step",
            "4",
            "-o",
            gif,
        ];
        let stdout = ok(&args);
        // 36 mm at 4 mm: frames at 0, 4, ..., 36.
        assert!(stdout.contains("10 frames"), "{stdout}");
        assert_eq!(&std::fs::read(gif).unwrap()[..6], b"GIF89a");
    }
}

#[test]
fn a_dashboard_flight_writes_one_wide_png_per_frame_and_coverage_grows_backward() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let route = tube_path(dir.path(), &tube, "p.json");
    let frames = dir.path().join("frames");
    let frames = frames.to_str().unwrap();
    let args = [
        "fly",
        &tube,
        "--path",
        &route,
        "--iso",
        "-480",
        "--size",
        "60x60",
        "--frame-step",
        "6",
        "--layout",
        "dashboard",
        "--coverage",
        "-o",
        frames,
    ];
    let stdout = ok(&args);
    assert!(stdout.contains("coverage:"), "{stdout}");
    let pngs = std::fs::read_dir(frames).unwrap().count();
    assert_eq!(pngs, 7);
    let png = std::fs::read(Path::new(frames).join("frame_00003.png")).unwrap();
    let width = u32::from_be_bytes([png[16], png[17], png[18], png[19]]);
    assert!(
        width > 60 + 60,
        "a dashboard is wider than the endoscope view: {width}"
    );
    let report = dir.path().join("frames.coverage.json");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(report).unwrap()).unwrap();
    let forward = report["fraction_forward"].as_f64().unwrap();
    let both = report["fraction_forward_backward"].as_f64().unwrap();
    // Looking ahead down a tube hides the wall beside and behind the first camera.
    assert!(forward > 0.3 && forward < 0.99, "forward {forward}");
    assert!(both > forward, "forward {forward}, both {both}");
    assert!(dir.path().join("frames.coverage.png").exists());
    // The mask counts what the summary counts, pass by pass: 1 seen flying forward, 2 seen
    // only flying back, 3 never seen.
    let mask = endocast_io::open(
        &dir.path().join("frames.coverage.nii.gz"),
        &endocast_io::OpenOptions::default(),
    )
    .unwrap()
    .volume;
    let map = mask.value_map();
    let count = |label: f64| {
        let here = |s: &&u16| map.physical(**s) == label;
        mask.voxels().iter().filter(here).count() as u64
    };
    let figure = |key: &str| report[key].as_u64().unwrap();
    let (forward_only, back_only, unseen) = (count(1.0), count(2.0), count(3.0));
    assert_eq!(forward_only, figure("seen_forward"));
    assert_eq!(forward_only + back_only, figure("seen_forward_backward"));
    assert_eq!(forward_only + back_only + unseen, figure("wall_voxels"));
}

/// The number of samples in an MP4's `stsz` box.
fn mp4_frames(bytes: &[u8]) -> u32 {
    let at = bytes
        .windows(4)
        .position(|w| w == b"stsz")
        .expect("an stsz box")
        + 12;
    u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap())
}

#[test]
fn mp4_needs_no_ffmpeg_and_holds_every_frame() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let route = tube_path(dir.path(), &tube, "p.json");
    let fly = |out: &str, path_var: &Path| {
        let status = std::process::Command::new(env!("CARGO_BIN_EXE_endocast"))
            .args(["fly", &tube, "--path", &route, "--iso", "-480", "--json"])
            .args(["--size", "48x48", "--frame-step", "6", "-o", out])
            .env("PATH", path_var)
            .output()
            .unwrap();
        assert!(
            status.status.success(),
            "{}",
            String::from_utf8_lossy(&status.stderr)
        );
        let report: serde_json::Value = serde_json::from_slice(&status.stdout).unwrap();
        report["frames"].as_u64().unwrap() as usize
    };
    // PATH holds nothing: no ffmpeg to fall back on.
    let empty = tempfile::tempdir().unwrap();
    let mp4 = dir.path().join("f.mp4");
    let reported = fly(mp4.to_str().unwrap(), empty.path());
    let bytes = std::fs::read(&mp4).unwrap();
    assert_eq!(&bytes[4..8], b"ftyp");
    let frames = dir.path().join("frames");
    assert_eq!(fly(frames.to_str().unwrap(), empty.path()), reported);
    let pngs = std::fs::read_dir(&frames).unwrap().count();
    assert!(pngs > 1);
    assert_eq!(pngs, reported, "--json reports the frames written");
    assert_eq!(
        mp4_frames(&bytes) as usize,
        pngs,
        "one MP4 frame per PNG frame"
    );
}

#[test]
fn bad_navigation_requests_fail_clearly() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let shell = phantom(dir.path(), "sphere-shell", "48");
    let out = dir.path().join("p.json");
    let out = out.to_str().unwrap();
    fails_with(
        &[
            "path", &tube, "--iso", "-480", "--from", "0,15,0", "-o", out,
        ],
        "in the wall",
    );
    fails_with(
        &[
            "path", &shell, "--iso", "-480", "--from", "0,0,0", "--to", "22,22,22", "-o", out,
        ],
        "disconnected",
    );
    fails_with(
        &[
            "path", &tube, "--iso", "-480", "--from", "0,0,500", "-o", out,
        ],
        "outside",
    );
    fails_with(&["path", &tube, "--from", "0,0,0", "-o", out], "--iso");
    let bad = dir.path().join("bad.json");
    let no_points =
        r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm"}"#;
    let nan = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm", "points": [[0,0,"NaN"],[0,0,1]]}"#;
    for text in [no_points, nan, "{", r#"{"format": "endocast-path"}"#] {
        std::fs::write(&bad, text).unwrap();
        let args = [
            "fly",
            &tube,
            "--path",
            bad.to_str().unwrap(),
            "--iso",
            "-480",
            "-o",
            "x.gif",
        ];
        fails_with(&args, "bad.json");
    }
    let route = tube_path(dir.path(), &tube, "p2.json");
    let args = [
        "fly",
        &tube,
        "--path",
        &route,
        "--iso",
        "-480",
        "--frame-step",
        "NaN",
        "-o",
        "x.gif",
    ];
    fails_with(&args, "step");
    // A zero step is the option's fault, not the path file's.
    let mut zero = args;
    zero[7] = "0";
    fails_with(&zero, "--frame-step");
    let args = [
        "fly",
        &tube,
        "--path",
        &route,
        "--iso",
        "-480",
        "-o",
        "frame.png",
    ];
    fails_with(&args, "frame.png");
}

/// Runs `endocast path ... --json` and returns its report.
fn path_json(args: &[&str]) -> serde_json::Value {
    let mut all = vec!["path"];
    all.extend_from_slice(args);
    all.push("--json");
    serde_json::from_str(&ok(&all)).unwrap()
}

#[test]
fn real_scans_trachea_into_a_bronchus_and_down_the_aorta() {
    let Some(data) = endocast_testdata::shared_data("") else {
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let chest = data.join("chest-ct-airways-dicom");
    let airway = dir.path().join("airway.json");
    let report = path_json(&[
        chest.to_str().unwrap(),
        "--preset",
        "bronchoscopy",
        "--from",
        "-9.84,66.32,51.5",
        "-o",
        airway.to_str().unwrap(),
    ]);
    // From the upper trachea past the carina (about 60 mm down) into a main bronchus.
    let length = report["length_mm"].as_f64().unwrap();
    assert!((100.0..250.0).contains(&length), "{report}");
    assert!(report["min_radius_mm"].as_f64().unwrap() > 0.5, "{report}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&airway).unwrap()).unwrap();
    let last = json["points"].as_array().unwrap().last().unwrap().clone();
    let [x, _, z] = [0, 1, 2].map(|a| last[a].as_f64().unwrap());
    assert!(
        x.abs() > 20.0 && z < 0.0,
        "ends at x {x}, z {z}: not in a bronchus"
    );

    let abdomen = data.join("abdomen-ct-pancreas-dicom");
    let aorta = dir.path().join("aorta.json");
    let report = path_json(&[
        abdomen.to_str().unwrap(),
        "--preset",
        "angioscopy",
        "--from",
        "27.55,113.71,355.91",
        "--to",
        "11.8,76.5,205.9",
        "-o",
        aorta.to_str().unwrap(),
    ]);
    // The end points are 155 mm apart along a nearly straight aorta about 20 mm wide.
    let length = report["length_mm"].as_f64().unwrap();
    assert!((150.0..175.0).contains(&length), "{report}");
    let mean = report["mean_radius_mm"].as_f64().unwrap();
    assert!((5.0..12.0).contains(&mean), "{report}");
    let gif = dir.path().join("aorta.gif");
    let args = [
        "fly",
        abdomen.to_str().unwrap(),
        "--path",
        aorta.to_str().unwrap(),
        "--preset",
        "angioscopy",
        "--layout",
        "dashboard",
        "--size",
        "64x64",
        "--frame-step",
        "40",
        "-o",
        gif.to_str().unwrap(),
    ];
    assert!(ok(&args).contains("5 frames"));
}

#[test]
fn key_frames_fly_at_constant_speed_with_their_own_look() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let keys = dir.path().join("keys.json");
    std::fs::write(
        &keys,
        r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm",
            "key_frames": [
              {"eye": [0, 0, -15], "forward": [0, 0, 1], "up": [0, -1, 0], "fov_deg": 90,
               "iso_hu": -480, "iso_opacity": 1.0, "tf": "colonoscopy"},
              {"eye": [0, 0, 15], "forward": [0, 0.3, 1], "up": [0, -1, 0], "fov_deg": 60,
               "iso_hu": -300, "iso_opacity": 0.5}]}"#,
    )
    .unwrap();
    let frames = dir.path().join("frames");
    let args = [
        "fly",
        &tube,
        "--path",
        keys.to_str().unwrap(),
        "--mode",
        "hybrid",
        "--size",
        "32x32",
        "--frame-step",
        "5",
        "-o",
        frames.to_str().unwrap(),
    ];
    let stdout = ok(&args);
    // 30 mm of eye path at 5 mm: 7 frames.
    assert!(stdout.contains("7 frames"), "{stdout}");
    assert_eq!(std::fs::read_dir(&frames).unwrap().count(), 7);
}

#[test]
fn coverage_lists_the_patches_a_forward_flight_missed_and_views_that_see_them() {
    let dir = tempfile::tempdir().unwrap();
    let tube = phantom(dir.path(), "straight-tube", "48");
    let route = tube_path(dir.path(), &tube, "p.json");
    let views = dir.path().join("views");
    let views = views.to_str().unwrap();
    let base = [
        "coverage",
        &tube,
        "--path",
        &route,
        "--iso",
        "-480",
        "--size",
        "48x48",
        "--frame-step",
        "4",
        "--forward-only",
        "--min-area",
        "1",
    ];
    let json = [&base[..], &["--json", "--views", views]].concat();
    let report: serde_json::Value = serde_json::from_str(&ok(&json)).unwrap();
    let patches = report["patches"].as_array().unwrap();
    assert!(!patches.is_empty(), "{report}");
    let areas: Vec<f64> = patches
        .iter()
        .map(|p| p["area_mm2"].as_f64().unwrap())
        .collect();
    assert!(areas.windows(2).all(|w| w[0] >= w[1]), "{areas:?}");
    assert!(areas.iter().all(|&a| a >= 1.0));
    for patch in patches {
        for key in ["centroid", "eye", "look_at"] {
            let point = patch[key].as_array().unwrap();
            assert_eq!(point.len(), 3, "{key}");
            assert!(point.iter().all(|x| x.as_f64().unwrap().is_finite()));
        }
        assert_eq!(patch["look_at"], patch["centroid"]);
        assert!(
            patch["voxels_seen_by_view"].as_u64().unwrap() > 0,
            "{patch}"
        );
        assert!(Path::new(patch["view"].as_str().unwrap()).exists());
    }
    // Looking ahead from the path's start, the wall behind the first camera (z < −18) is the
    // largest patch missed.
    let centroid = |n: usize| patches[n]["centroid"][2].as_f64().unwrap();
    assert!(centroid(0) < -14.0, "largest patch at z {}", centroid(0));
    let (before, after) = (
        report["coverage_before"].as_f64().unwrap(),
        report["coverage_after"].as_f64().unwrap(),
    );
    assert!(before < 0.99 && after > before, "{before} → {after}");
    assert_eq!(report["coverage_forward"], report["coverage_before"]);
    // The words say the same.
    let said = ok(&base);
    assert!(
        said.contains(&format!("{} unseen patches", report["patches_total"])),
        "{said}"
    );
    let mut bad = base.to_vec();
    let last = bad.len() - 1;
    bad[last] = "NaN";
    fails_with(&bad, "--min-area");
}
