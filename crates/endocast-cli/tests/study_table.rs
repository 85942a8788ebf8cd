//! Issue 31: one study, the same in every front end. For every shared scan with no preset and
//! with each preset that applies to it, `render --json`, the viewer's session (headless) and
//! `fly`'s first frame start from the same pose with the same values; the start looks along the
//! automatic path; and without a preset the object fills at least a third of the image.
//! (Python's `default_view` is compared with `render --json` in the Python suite.)

use crate::common::{endocast, hit_share, numbers};
use endocast_core::presets::Preset;
use endocast_testdata::shared_data;
use endocast_viewer::scene::{ScanSource, Scene};
use endocast_viewer::session::Session;
use glam::DVec3;
use serde_json::Value;
use std::path::Path;
use std::sync::Arc;

/// Every shared scan that holds a volume, with the presets that apply to it.
const TABLE: [(&str, &[&str]); 11] = [
    ("abdomen-ct-pancreas-dicom", &["colonoscopy"]),
    ("aorta-stent-cta/stent.nrrd", &["angioscopy"]),
    ("brain-mri-flair-nrrd/FLAIR.nrrd", &["ventricles"]),
    ("brain-mri-t1/chris_t1.nii.gz", &["ventricles"]),
    ("chest-ct-airways-dicom", &["bronchoscopy"]),
    ("classic-engine-ct/engine.nii.gz", &[]),
    ("classic-vtk-headsq/quarter.nhdr", &["sinus"]),
    ("head-ct-ge-gantry-tilt/GE", &["sinus"]),
    ("head-ct-stanford-cthead/CThead.nhdr", &["sinus"]),
    ("knee-mri/knee3D_dataR.mha", &["arthroscopy"]),
    ("knee-mri/knee3D_dataT.mha", &["arthroscopy"]),
];

/// A point of a JSON pose (`"eye"`, `"look_direction"`, ...) as a vector.
fn vector(pose: &Value, key: &str) -> DVec3 {
    let v = numbers(&pose[key]);
    DVec3::new(v[0], v[1], v[2])
}

/// Angle between two directions, degrees.
fn degrees(a: DVec3, b: DVec3) -> f64 {
    a.normalize()
        .dot(b.normalize())
        .clamp(-1.0, 1.0)
        .acos()
        .to_degrees()
}

/// Runs `endocast ARGS` and returns its JSON on stdout; panics with stderr on failure.
fn json_of(args: &[&str]) -> (Value, String) {
    let out = endocast(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {stderr}");
    let json = serde_json::from_slice(&out.stdout)
        .unwrap_or_else(|e| panic!("{args:?} printed no JSON ({e}): {stderr}"));
    (json, stderr)
}

/// `render SCAN [--preset P] --json` at 64²: the study it reports, the share of rays that met
/// the wall, and stderr.
fn render(scan: &Path, preset: Option<&str>, dir: &Path) -> (Value, f64, String) {
    let (png, depth) = (dir.join("v.png"), dir.join("d.npy"));
    let mut args = vec![
        "render",
        scan.to_str().unwrap(),
        "-o",
        png.to_str().unwrap(),
        "--size",
        "64x64",
        "--depth-out",
        depth.to_str().unwrap(),
        "--json",
    ];
    args.extend(preset.iter().flat_map(|p| ["--preset", p]));
    let (json, stderr) = json_of(&args);
    (json["study"].clone(), hit_share(&depth), stderr)
}

/// The viewer's session on `scan` for `preset`, as `endocast view` opens it (no window): its
/// camera's eye and view direction.
fn session_start(scan: &Path, preset: Option<&str>) -> (DVec3, DVec3) {
    let loaded = endocast_io::open(scan, &endocast_io::OpenOptions::default()).unwrap();
    let source = ScanSource::File {
        path: scan.to_path_buf(),
        series: None,
        orientation: None,
    };
    let scene = Arc::new(Scene::new(source, loaded.volume));
    let preset = preset.map(|p| Preset::find(p).unwrap());
    let session = Session::new(scene, preset, None, || {});
    let camera = session.fly_camera();
    (camera.eye_mm(), camera.forward())
}

/// `path SCAN --preset P`, then `fly` along it (one frame): the first frame's camera.
fn fly_start(scan: &Path, preset: &str, dir: &Path) -> Value {
    let (route, frames) = (dir.join("p.json"), dir.join("frames"));
    let scan = scan.to_str().unwrap();
    let args = [
        "path",
        scan,
        "--preset",
        preset,
        "-o",
        route.to_str().unwrap(),
    ];
    json_of(&[&args[..], &["--json"]].concat());
    let (fly, _) = json_of(&[
        "fly",
        scan,
        "--path",
        route.to_str().unwrap(),
        "--preset",
        preset,
        "--size",
        "32x32",
        "--frame-step",
        "1000",
        "-o",
        frames.to_str().unwrap(),
        "--json",
    ]);
    fly["first_camera"].clone()
}

/// One row of the table: `scan` with `preset` (or none).
fn check_row(scan: &Path, preset: Option<&str>, dir: &Path) {
    let row = format!("{} {preset:?}", scan.display());
    let (study, share, stderr) = render(scan, preset, dir);
    let start = &study["start"];
    let (eye, forward) = (vector(start, "eye"), vector(start, "look_direction"));
    let (session_eye, session_forward) = session_start(scan, preset);
    assert!(
        eye.distance(session_eye) < 1e-6,
        "{row}: viewer eye {session_eye} against {eye}"
    );
    assert!(
        degrees(forward, session_forward) < 1e-3,
        "{row}: viewer looks along {session_forward} against {forward}"
    );
    let Some(preset) = preset else {
        // The CTA crop is soft tissue to its border: its object at the background/object
        // boundary is the contrast-filled vessels and the bone, a sparse tree.
        let least = if scan.ends_with("stent.nrrd") {
            0.15
        } else {
            1.0 / 3.0
        };
        assert!(
            share >= least,
            "{row}: the object fills {share:.3}; {stderr}"
        );
        return;
    };
    if study["structure"].is_null() {
        // No structure: the run must have said why, in one line.
        assert!(
            stderr.contains("warning:"),
            "{row}: no structure and no word: {stderr}"
        );
        return;
    }
    assert!(
        study["path_mm"].as_f64().is_some(),
        "{row}: no automatic path: {stderr}"
    );
    let first = fly_start(scan, preset, dir);
    let fly_eye = vector(&first, "eye");
    let fly_forward = vector(&first, "look_direction");
    assert!(
        eye.distance(fly_eye) < 1.0,
        "{row}: fly starts at {fly_eye}, not {eye}"
    );
    // The start looks along the automatic path (the flight's first view direction).
    let off = degrees(forward, fly_forward);
    assert!(off < 30.0, "{row}: the start looks {off:.1}° off the path");
}

#[test]
fn every_front_end_starts_every_scan_at_the_same_pose_looking_along_the_path() {
    let dir = tempfile::tempdir().unwrap();
    for (name, presets) in TABLE {
        let Some(scan) = shared_data(name) else {
            continue;
        };
        check_row(&scan, None, dir.path());
        for preset in presets {
            check_row(&scan, Some(preset), dir.path());
        }
    }
}
