//! `endocast annotate` and `--case` on `render` and `fly`, end to end on the sphere shell
//! (centred on the world origin, 1 mm voxels, inner wall 16.8 mm from the centre at 48³).

use crate::common::{count_color, endocast, fails_with};
use std::path::Path;

/// The measurement's default colour (the core's `MEASURE_COLOR`).
const MEASURE_RGB: [u8; 3] = [0, 220, 255];
/// The inner wall's radius of the 48³ shell, mm.
const INNER_MM: f64 = 0.35 * 48.0;

fn run(args: &[&str]) -> String {
    let out = endocast(args);
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

fn phantom(dir: &Path, name: &str, size: &str) -> String {
    let path = dir.join(name);
    let p = path.to_str().unwrap();
    run(&["phantom", "sphere-shell", "-o", p, "--size", size]);
    p.to_owned()
}

/// The view from the centre along +z, 64 × 64, on the wall's isovalue.
const VIEW: [&str; 12] = [
    "--eye",
    "0,0,0",
    "--look-at",
    "0,0,1",
    "--size",
    "64x64",
    "--fov",
    "90",
    "--mode",
    "iso",
    "--iso",
    "-480",
];

#[test]
fn annotations_added_picked_listed_removed_and_drawn() {
    let dir = tempfile::tempdir().unwrap();
    let scan = phantom(dir.path(), "shell.nii.gz", "48");
    let scan = scan.as_str();
    let case = dir.path().join("shell.case.json");
    let c = case.to_str().unwrap();

    let mut add = vec!["annotate", c, "--scan", scan, "add", "measure"];
    add.extend(["--pixel", "16,32", "--pixel", "48,32"]);
    add.extend(VIEW);
    let said = run(&add);
    assert!(
        said.starts_with("added 1 measure") && said.contains(" mm:"),
        "{said}"
    );
    run(&[
        "annotate",
        c,
        "add",
        "label",
        "--at",
        "0,-16.8,0",
        "--label",
        "floor",
    ]);
    run(&[
        "annotate", c, "add", "stroke", "--at", "0,0,16.8", "--at", "1,0,16.7",
    ]);
    run(&[
        "annotate", c, "add", "point", "--at", "3,3,3", "--color", "255,0,0",
    ]);

    let listed: serde_json::Value =
        serde_json::from_str(&run(&["annotate", c, "list", "--json"])).unwrap();
    let records = listed.as_array().unwrap();
    assert_eq!(records.len(), 4);
    assert_eq!(records[0]["kind"], "measure");
    for p in records[0]["points"].as_array().unwrap() {
        let r = p
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap().powi(2))
            .sum::<f64>();
        assert!((r.sqrt() - INNER_MM).abs() < 0.1, "picked {p} off the wall");
    }
    let mm = records[0]["distance_mm"].as_f64().unwrap();
    assert!(mm > 10.0 && mm < 2.0 * INNER_MM, "{mm}");
    assert_eq!(records[1]["label"], "floor");
    assert_eq!(records[3]["color"], serde_json::json!([255, 0, 0]));

    let said = run(&["annotate", c, "remove", "4"]);
    assert!(said.contains("3 left"), "{said}");
    fails_with(&["annotate", c, "remove", "4"], "no annotation 4");
    assert!(run(&["annotate", c, "list"]).lines().count() == 3);

    // Drawn by render --case where the view sees them; the plain view has none of the colour.
    let plain = dir.path().join("plain.png");
    let marked = dir.path().join("marked.png");
    let mut render = vec!["render", scan, "-o", plain.to_str().unwrap()];
    render.extend(VIEW);
    run(&render);
    render[3] = marked.to_str().unwrap();
    render.extend(["--case", c]);
    run(&render);
    assert_eq!(count_color(&plain, MEASURE_RGB), 0);
    assert!(count_color(&marked, MEASURE_RGB) > 40);
}

#[test]
fn fly_draws_a_cases_annotations_on_its_frames() {
    let dir = tempfile::tempdir().unwrap();
    let scan = phantom(dir.path(), "shell.nii.gz", "48");
    let scan = scan.as_str();
    let case = dir.path().join("case.json");
    let c = case.to_str().unwrap();
    run(&[
        "annotate",
        c,
        "--scan",
        scan,
        "add",
        "measure",
        "--at",
        "-6,0,15.6",
        "--at",
        "6,0,15.6",
    ]);
    let route = dir.path().join("route.json");
    std::fs::write(
        &route,
        r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS", "units": "mm", "points": [[0, 0, -4], [0, 0, 4]]}"#,
    )
    .unwrap();
    let frames = dir.path().join("frames");
    run(&[
        "fly",
        scan,
        "--path",
        route.to_str().unwrap(),
        "-o",
        frames.to_str().unwrap(),
        "--size",
        "48x48",
        "--frame-step",
        "4",
        "--mode",
        "iso",
        "--iso",
        "-480",
        "--case",
        c,
    ]);
    let mut pngs: Vec<_> = std::fs::read_dir(&frames)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    pngs.sort();
    assert!(pngs.len() >= 2);
    for png in &pngs {
        assert!(
            count_color(png, MEASURE_RGB) > 10,
            "{} lacks the measurement",
            png.display()
        );
    }
}

#[test]
fn a_case_of_another_scan_and_bad_annotations_are_clear_errors() {
    let dir = tempfile::tempdir().unwrap();
    let scan = phantom(dir.path(), "shell.nii.gz", "48");
    let scan = scan.as_str();
    let other = phantom(dir.path(), "other.nii.gz", "40");
    let other = other.as_str();
    let case = dir.path().join("case.json");
    let c = case.to_str().unwrap();
    fails_with(&["annotate", c, "list"], "give --scan");
    run(&[
        "annotate", c, "--scan", scan, "add", "point", "--at", "0,0,16.8",
    ]);
    fails_with(&["annotate", c, "--scan", other, "list"], "dimensions");
    let png = dir.path().join("view.png");
    let mut render = vec!["render", other, "-o", png.to_str().unwrap(), "--case", c];
    render.extend(VIEW);
    fails_with(&render, "made on another scan");
    fails_with(
        &["annotate", c, "add", "label", "--at", "0,0,1"],
        "needs --label",
    );
    fails_with(
        &["annotate", c, "add", "measure", "--at", "0,0,1"],
        "needs 2",
    );
    fails_with(
        &["annotate", c, "add", "point", "--pixel", "3,3"],
        "--eye and --look-at",
    );
    // Above the tissue's value no wall is left to pick.
    let mut miss = vec!["annotate", c, "add", "point", "--pixel", "32,32"];
    miss.extend(&VIEW[..10]);
    miss.extend(["--iso", "900"]);
    fails_with(&miss, "shows no surface");
    std::fs::write(&case, "{broken").unwrap();
    fails_with(&["annotate", c, "list"], "case.json");
}

#[test]
fn a_case_keeps_the_orientation_given_for_a_scan_that_declares_none() {
    let dir = tempfile::tempdir().unwrap();
    // A NRRD without an anatomical space: its orientation must be given (`--orientation`).
    let scan = dir.path().join("bare.nrrd");
    let mut bytes = b"NRRD0004\ntype: uint8\ndimension: 3\nsizes: 8 8 8\nspacings: 1 1 1\n\
encoding: raw\n\n"
        .to_vec();
    bytes.extend((0..512u32).map(|i| (i % 251) as u8));
    std::fs::write(&scan, bytes).unwrap();
    let s = scan.to_str().unwrap();
    let case = dir.path().join("case.json");
    let c = case.to_str().unwrap();
    run(&[
        "annotate",
        c,
        "--scan",
        s,
        "--orientation",
        "LPI",
        "add",
        "point",
        "--at",
        "1,1,-1",
    ]);
    let saved = std::fs::read_to_string(&case).unwrap();
    assert!(saved.contains("\"orientation\": \"LPI\""), "{saved}");
    run(&["annotate", c, "--scan", s, "--orientation", "LPI", "list"]);
    // Read the other way up, the same voxels are another scan: the points would land elsewhere.
    fails_with(&["annotate", c, "--scan", s, "list"], "axes");
    let png = dir.path().join("view.png");
    let p = png.to_str().unwrap();
    let view = ["--eye", "3,3,-10", "--look-at", "3,3,0", "--size", "16x16"];
    let mut render = vec!["render", s, "-o", p, "--case", c, "--orientation", "LPS"];
    render.extend(view);
    fails_with(&render, "axes");
    render[7] = "LPI";
    run(&render);
}

#[test]
fn annotations_added_at_once_by_many_processes_are_all_kept() {
    let dir = tempfile::tempdir().unwrap();
    let scan = phantom(dir.path(), "shell.nii.gz", "24");
    let case = dir.path().join("case.json");
    let c = case.to_str().unwrap();
    run(&[
        "annotate", c, "--scan", &scan, "add", "point", "--at", "0,0,0",
    ]);
    // Eight writers, ten annotations each, one process an annotation.
    std::thread::scope(|scope| {
        for writer in 0..8 {
            scope.spawn(move || {
                for k in 0..10 {
                    let at = format!("{writer},{k},1");
                    let said = run(&["annotate", c, "add", "point", "--at", &at]);
                    assert!(said.starts_with("added "), "{said}");
                }
            });
        }
    });
    let listed: serde_json::Value =
        serde_json::from_str(&run(&["annotate", c, "list", "--json"])).unwrap();
    let records = listed.as_array().unwrap();
    assert_eq!(records.len(), 81, "the first and 8 × 10 more");
    let mut ids: Vec<u64> = records.iter().map(|r| r["id"].as_u64().unwrap()).collect();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), 81);
}
