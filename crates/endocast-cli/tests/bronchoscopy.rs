//! `endocast path --preset bronchoscopy --target`: the labelled airway tree of the chest CT and
//! routes to targets in it, checked against positions measured from the scan itself.
//!
//! How the positions were measured (independently of endocast, with pydicom and scipy): the
//! airways are the 26-connected component below −900 HU (the preset's lumen threshold) holding
//! the trachea's section in the top slice (z = 75.5); each point below is the mean LPS position
//! (DICOM patient coordinates) of that component's voxels in one axial slice and one region:
//! the trachea's section at z = 39.5; the right and left main bronchi's sections at z = −8.5
//! and −16.5; the two thin branches that leave them upwards (x < −45 mm on the right, x > 33 mm
//! on the left, in the slices above z = −14 and −26), at their widest sections (z = −10.5 and
//! −22.5): the upper lobe bronchi; and the two
//! branches that run on down (z < −38 mm): the lower lobe bronchi. A coronal projection of the
//! component shows the same tree.

use crate::common::{count_color, endocast, fails_with};
use endocast_core::annotate::{HIDDEN_TARGET_COLOR, TARGET_COLOR};
use serde_json::Value;

/// (name the route must pass, a point in that branch's lumen: world mm, LPS).
const MEASURED: [(&str, [f64; 3]); 7] = [
    ("trachea", [-12.6, 70.0, 39.5]),
    ("right main bronchus", [-32.3, 69.5, -8.5]),
    ("left main bronchus", [4.9, 73.6, -16.5]),
    ("right upper lobe bronchus", [-52.5, 65.7, -10.5]),
    ("left upper lobe bronchus", [36.9, 71.0, -22.5]),
    ("right lower lobe bronchus", [-52.3, 71.4, -52.5]),
    ("left lower lobe bronchus", [48.0, 84.6, -44.5]),
];

/// `endocast path CHEST --preset bronchoscopy --target T --scope-diameter D --json`.
fn route(chest: &str, target: [f64; 3], scope_mm: f64) -> Value {
    let out_dir = tempfile::tempdir().unwrap();
    let out = out_dir.path().join("route.json");
    let target = format!("{},{},{}", target[0], target[1], target[2]);
    let scope = scope_mm.to_string();
    let args = [
        "path",
        chest,
        "--preset",
        "bronchoscopy",
        "--target",
        &target,
        "--scope-diameter",
        &scope,
        "-o",
        out.to_str().unwrap(),
        "--json",
    ];
    let run = endocast(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{args:?} failed: {stderr}");
    serde_json::from_slice(&run.stdout).unwrap()
}

/// `endocast path CHEST --preset bronchoscopy --target TARGET -o OUT`.
fn path_to<'a>(chest: &'a str, target: &'a str, out: &'a str) -> [&'a str; 8] {
    [
        "path",
        chest,
        "--preset",
        "bronchoscopy",
        "--target",
        target,
        "-o",
        out,
    ]
}

/// The names of the branches a route passes.
fn passed(report: &Value) -> Vec<String> {
    report["branches"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["name"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn the_chest_ct_tree_is_labelled_and_routes_reach_targets_beside_it() {
    let Some(chest) = endocast_testdata::shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let chest = chest.to_str().unwrap();
    // A thin scope to a point in each branch's lumen passes that branch, and ends beside it.
    for (name, point) in MEASURED {
        let report = route(chest, point, 1.0);
        let names = passed(&report);
        assert!(
            names.iter().any(|n| n == name),
            "{name} at {point:?}: {names:?}"
        );
        let remaining = report["remaining_mm"].as_f64().unwrap();
        assert!(
            remaining < 5.0,
            "{name}: ends {remaining} mm from {point:?}"
        );
    }
    // A target in the lung (−410 HU) 8 mm anterior to the left lower lobe bronchus's last
    // section (52.0, 87.2, −50.5): a thinner scope ends as near or nearer.
    let nodule = [52.0, 79.2, -50.5];
    let reports: Vec<Value> = [1.0, 4.9, 7.0].map(|d| route(chest, nodule, d)).into();
    let remaining: Vec<f64> = reports
        .iter()
        .map(|r| r["remaining_mm"].as_f64().unwrap())
        .collect();
    assert!(
        remaining.windows(2).all(|w| w[0] <= w[1] + 1e-9),
        "{remaining:?}"
    );
    assert!(remaining[0] < 10.0, "{remaining:?}");
    assert!(passed(&reports[0]).contains(&"left lower lobe bronchus".to_owned()));
    for report in &reports {
        let narrowest = report["narrowest_diameter_mm"].as_f64();
        let scope = report["scope_diameter_mm"].as_f64().unwrap();
        assert!(narrowest.is_none_or(|n| n >= scope), "{report}");
    }
    // The whole tree: trachea, both main bronchi and four lobar bronchi, by generation.
    let tree = reports[0]["airway_tree"].as_array().unwrap();
    for (name, generation) in [
        ("trachea", 0),
        ("right main bronchus", 1),
        ("left main bronchus", 1),
        ("right upper lobe bronchus", 2),
        ("left upper lobe bronchus", 2),
        ("right lower lobe bronchus", 2),
        ("left lower lobe bronchus", 2),
    ] {
        assert!(
            tree.iter()
                .any(|b| b["name"] == name && b["generation"] == generation),
            "no {name} of generation {generation}"
        );
    }
}

/// The carina, measured on the chest CT (issue 36 item 7; pydicom and scipy, independently of
/// endocast): the airway component below −900 HU (as above) cut into axial slices, each
/// slice's section split into 8-connected parts: the trachea's section is one part down to
/// z = −2.5 (371 voxels around (−21.0, 72.7)) and two from z = −4.5 (the main bronchi, 232
/// voxels around (−29.3, 70.5) and 134 around (−7.6, 75.3)): the split lies at z = −3.5 ± 1.
/// The spur between them, where the line between those two sections is most dense at
/// z = −4.5, lies at (−17.6, 73.1); the −500 HU wall surface, interpolated along z through
/// the points within 2 mm of it, tops at z = −3.3 at (−16.6, 71.1). The tree's branch point
/// (the trachea's last centreline point) lay 11 mm higher.
const CARINA: [f64; 3] = [-17.0, 72.0, -3.5];
/// The middle of the trachea's section in the scan's top slice (z = 75.5): the mean position
/// of its 142 voxels below −900 HU.
const TRACHEA_TOP: [f64; 3] = [-2.2, 55.1, 75.5];

fn distance(a: [f64; 3], b: &Value) -> f64 {
    let b: Vec<f64> = b
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_f64().unwrap())
        .collect();
    (0..3).map(|i| (a[i] - b[i]).powi(2)).sum::<f64>().sqrt()
}

/// Issue 36 item 7: the carina where the trachea splits, and the route from the trachea's top.
#[test]
fn the_carina_is_where_the_chest_cts_trachea_splits_and_routes_start_at_its_top() {
    let Some(chest) = endocast_testdata::shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let report = route(chest.to_str().unwrap(), MEASURED[1].1, 4.9);
    let carina = &report["carina"];
    assert!(distance(CARINA, carina) <= 3.0, "carina {carina}");
    assert!(
        (carina[2].as_f64().unwrap() - CARINA[2]).abs() <= 2.0,
        "{carina}"
    );
    let trachea = &report["airway_tree"][0];
    assert_eq!(trachea["name"], "trachea");
    assert_eq!(trachea["split"], *carina);
    assert!(distance(TRACHEA_TOP, &trachea["start"]) <= 2.0, "{trachea}");
    // The trachea's centrelines fork above the spur: the scope passes it centred.
    assert!(
        trachea["end"][2].as_f64().unwrap() > CARINA[2] + 4.0,
        "{trachea}"
    );
}

/// The target drawn in the endoscope view (issue 36): the route to the left lower lobe nodule
/// keeps its target, and the last frame of the flight along it rings the target.
#[test]
fn the_last_frame_of_the_route_to_the_nodule_rings_the_target() {
    let Some(chest) = endocast_testdata::shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let chest = chest.to_str().unwrap();
    let dir = tempfile::tempdir().unwrap();
    let (route, frames) = (dir.path().join("route.json"), dir.path().join("frames"));
    let (route, frames) = (route.to_str().unwrap(), frames.to_str().unwrap());
    let target = "52.0,79.2,-50.5";
    assert!(endocast(&path_to(chest, target, route)).status.success());
    let file: Value = serde_json::from_str(&std::fs::read_to_string(route).unwrap()).unwrap();
    assert_eq!(file["target"], serde_json::json!([52.0, 79.2, -50.5]));
    // Two frames: the route's start and its end.
    let flown = [
        "fly",
        chest,
        "--path",
        route,
        "--preset",
        "bronchoscopy",
        "--frame-step",
        "1000",
        "--size",
        "192x192",
        "-o",
        frames,
    ];
    let run = endocast(&flown);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut pngs: Vec<_> = std::fs::read_dir(frames)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    pngs.sort();
    let last = pngs.last().unwrap();
    let ringed = count_color(last, TARGET_COLOR) + count_color(last, HIDDEN_TARGET_COLOR);
    assert!(
        ringed > 30,
        "{} pixels of the target's ring in {}",
        ringed,
        last.display()
    );
}

#[test]
fn targets_outside_the_body_or_not_numbers_are_errors() {
    let Some(chest) = endocast_testdata::shared_data("chest-ct-airways-dicom") else {
        return;
    };
    let chest = chest.to_str().unwrap();
    let run =
        |target: &str, needle: &str| fails_with(&path_to(chest, target, "/tmp/x.json"), needle);
    // The air in front of the chest, inside the scan.
    run("0,-150,0", "outside the body");
    run("0,0,500", "outside");
    run("nan,0,0", "--target");
    fails_with(
        &[
            "path",
            chest,
            "--preset",
            "bronchoscopy",
            "--target",
            "0,70,0",
            "--scope-diameter",
            "nan",
            "-o",
            "/tmp/x.json",
        ],
        "scope diameter",
    );
}
