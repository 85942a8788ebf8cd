//! `--cleanse on|off` on the four commands issue 36 names (`render`, `path`, `fly`, `polyps`):
//! each cleanses the tagged colon phantom before it reads it, saying what it removed, and the
//! path planned in the cleansed colon runs through the air where the pools were.

use crate::common::{endocast, fails_with};

/// Runs `endocast` with `args` and returns its JSON report and error output, failing on error.
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
    let scan = file("tagged.nii.gz");
    let phantom = ["phantom", "colon", "--tagged-fluid", "--size", "96"];
    run(&[&phantom[..], &["-o", &scan]].concat());
    let preset = ["--preset", "colonoscopy"];

    let (path_off, said) = run(&[
        &["path", &scan],
        &preset[..],
        &["-o", &file("off.json"), "--json"],
    ]
    .concat());
    assert!(!said.contains(REMOVED), "{said}");
    let on = ["--cleanse", "on"];
    let path_args = [
        &["path", &scan],
        &preset[..],
        &on[..],
        &["-o", &file("on.json"), "--json"],
    ]
    .concat();
    let (path_on, said) = run(&path_args);
    assert!(said.contains(REMOVED), "{said}");
    // The pools' voxels are air once cleansed: the colon planned in holds more.
    let voxels =
        |report: Option<serde_json::Value>| report.unwrap()["lumen_voxels"].as_u64().unwrap();
    assert!(voxels(path_on) > voxels(path_off));

    let render = [
        &["render", &scan],
        &preset[..],
        &on[..],
        &["--size", "32x32", "-o", &file("r.png")],
    ]
    .concat();
    assert!(run(&render).1.contains(REMOVED));
    let fly = [
        &["fly", &scan, "--path", &file("on.json")],
        &preset[..],
        &on[..],
        &[
            "--size",
            "32x32",
            "--frame-step",
            "40",
            "-o",
            &file("frames"),
        ],
    ]
    .concat();
    assert!(run(&fly).1.contains(REMOVED));
    let polyps = [&["polyps", &scan], &preset[..], &on[..], &["--json"]].concat();
    let (report, said) = run(&polyps);
    assert!(said.contains(REMOVED), "{said}");
    assert!(report.unwrap()["candidates"].is_array());

    fails_with(
        &["render", &scan, "--cleanse", "maybe", "-o", &file("x.png")],
        "expected on or off",
    );
}
