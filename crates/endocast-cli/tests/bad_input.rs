//! Bad input gives one readable line naming the problem and a non-zero exit, never a panic.

use crate::common::fails_with;

#[test]
fn missing_and_unknown_files() {
    fails_with(&["info", "/no/such/scan.nii.gz"], "/no/such/scan.nii.gz");
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("notes.txt");
    std::fs::write(&junk, "not a scan").unwrap();
    fails_with(&["info", junk.to_str().unwrap()], "notes.txt");
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    fails_with(&["info", empty.to_str().unwrap()], "empty");
}

#[test]
fn absurd_parameters() {
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("v.raw");
    std::fs::write(&raw, [0u8; 16]).unwrap();
    let raw = raw.to_str().unwrap();
    fails_with(
        &[
            "info",
            raw,
            "--raw-dims",
            "2,2,2",
            "--raw-spacing",
            "1,NaN,1",
        ],
        "spacing",
    );
    fails_with(&["info", raw, "--raw-dims", "4,4,4"], "v.raw");
    fails_with(
        &["info", raw, "--raw-dims", "100000,100000,100000"],
        "limit",
    );
    fails_with(
        &["info", raw, "--raw-dims", "2,2,2", "--raw-type", "complex"],
        "raw-type",
    );
    let out = dir.path().join("p.nii");
    fails_with(
        &[
            "phantom",
            "sphere-shell",
            "-o",
            out.to_str().unwrap(),
            "--size",
            "5000",
        ],
        "size",
    );
    fails_with(
        &[
            "phantom",
            "sphere-shell",
            "-o",
            out.to_str().unwrap(),
            "--noise",
            "NaN",
        ],
        "noise",
    );
    fails_with(
        &["phantom", "teapot", "-o", out.to_str().unwrap()],
        "teapot",
    );
    fails_with(
        &["phantom", "sphere-shell", "-o", "/no/such/dir/p.nii"],
        "/no/such/dir/p.nii",
    );
}
