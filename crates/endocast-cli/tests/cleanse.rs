//! `--cleanse on|off` on the four commands issue 36 names (`render`, `path`, `fly`, `polyps`):
//! each cleanses the tagged colon phantom before it reads it, saying what it removed, and the
//! colon the path is planned in holds the air where the pools were.

use crate::common::{endocast, fails_with};

/// Runs `endocast` with `args` and returns its JSON report (if it printed one) and its error
/// output, failing on error.
fn run(args: &[&str]) -> (Option<serde_json::Value>, String) {
    let out = endocast(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{args:?}: {stderr}");
    (serde_json::from_slice(&out.stdout).ok(), stderr)
}

/// The cleansing's summary line, on stderr.
const REMOVED: &str = "pool(s) of tagged fluid";

#[test]
fn render_path_fly_and_polyps_take_cleanse_on_and_say_what_it_removed() {
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let (scan, off, on, png, frames) = (
        file("tagged.nii.gz"),
        file("off.json"),
        file("on.json"),
        file("r.png"),
        file("frames"),
    );
    run(&[
        "phantom",
        "colon",
        "--tagged-fluid",
        "--size",
        "96",
        "-o",
        &scan,
    ]);
    let study = [scan.as_str(), "--preset", "colonoscopy"];
    let cleansed = [scan.as_str(), "--preset", "colonoscopy", "--cleanse", "on"];

    let (path_off, said) = run(&[&["path"], &study[..], &["-o", &off, "--json"]].concat());
    assert!(!said.contains(REMOVED), "{said}");
    let (path_on, said) = run(&[&["path"], &cleansed[..], &["-o", &on, "--json"]].concat());
    assert!(said.contains(REMOVED), "{said}");
    // The pools are air once cleansed: the colon the path is planned in holds more voxels.
    let voxels = |report: Option<serde_json::Value>| report.unwrap()["lumen_voxels"].as_u64();
    assert!(voxels(path_on) > voxels(path_off));

    let render = [&["render"], &cleansed[..], &["--size", "32x32", "-o", &png]].concat();
    assert!(run(&render).1.contains(REMOVED));
    let flight = [
        "--path",
        &on,
        "--size",
        "32x32",
        "--frame-step",
        "40",
        "-o",
        &frames,
    ];
    let fly = [&["fly"], &cleansed[..], &flight[..]].concat();
    assert!(run(&fly).1.contains(REMOVED));
    let (report, said) = run(&[&["polyps"], &cleansed[..], &["--json"]].concat());
    assert!(said.contains(REMOVED), "{said}");
    assert!(report.unwrap()["candidates"].is_array());

    let maybe = ["render", &scan, "--cleanse", "maybe", "-o", &png];
    fails_with(&maybe, "expected on or off");
}
