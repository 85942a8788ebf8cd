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

/// Issue 32: a 14000² render under a 4 GiB address-space limit is refused before anything is
/// allocated for it (it used to pass the memory check and abort past 9.9 GB): a clean error
/// naming the limit and a non-zero exit, not a signal.
#[test]
#[cfg(target_os = "linux")]
fn a_huge_render_under_an_address_space_limit_is_refused_cleanly() {
    refused_under_4_gib("14000×14000", &["--size", "14000x14000"]);
}

/// Issue 32: the memory a look takes is checked once the look is known, before its buffers
/// are: a 3000² clinical view, whose plain frames would fit in a quarter of 4 GiB, is refused.
#[test]
#[cfg(target_os = "linux")]
fn a_look_too_large_for_the_memory_is_refused_before_rendering() {
    refused_under_4_gib("3000×3000", &["--size", "3000x3000", "--look", "clinical"]);
}

/// Renders an 8³ scan with `options` under a 4 GiB address-space limit and checks that it is
/// refused cleanly, the error naming `size` and the limit, and no image written.
#[cfg(target_os = "linux")]
fn refused_under_4_gib(size: &str, options: &[&str]) {
    if std::process::Command::new("prlimit")
        .arg("--version")
        .output()
        .is_err()
    {
        eprintln!("skipped: no prlimit on this machine");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let raw = dir.path().join("v.raw");
    std::fs::write(&raw, [0u8; 8 * 8 * 8 * 2]).unwrap();
    let png = dir.path().join("view.png");
    let out = std::process::Command::new("prlimit")
        .args(["--as=4294967296", "--", env!("CARGO_BIN_EXE_endocast")])
        .args(["render", raw.to_str().unwrap(), "--raw-dims", "8,8,8"])
        .args(options)
        .args(["-o", png.to_str().unwrap()])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(
        stderr.contains(size) && stderr.contains("limit"),
        "{stderr}"
    );
    assert!(!png.exists());
}

/// `fly --dataset` (issue 37) refuses a file, a folder with files in it, a camera with no
/// COLMAP/nerfstudio model, a stereo flight and the dashboard, each with its reason.
#[test]
fn fly_dataset_refusals() {
    let dir = tempfile::tempdir().unwrap();
    let at = |name: &str| dir.path().join(name).to_str().unwrap().to_owned();
    let scan = at("shell.nii.gz");
    crate::common::endocast(&["phantom", "sphere-shell", "-o", &scan, "--size", "24"]);
    let route = at("route.json");
    let points = r#"{"format": "endocast-path", "version": 1, "coordinate_system": "LPS",
        "units": "mm", "points": [[-2, 0, 0], [2, 0, 0]]}"#;
    std::fs::write(&route, points).unwrap();
    let fly = |dataset: &str, film: &str, extra: &[&str], needle: &str| {
        let mut args = vec!["fly", &scan, "--path", &route, "--size", "16x16"];
        args.extend(["-o", film, "--dataset", dataset, "--preset", "sinus"]);
        args.extend(extra);
        fails_with(&args, needle);
    };
    fly(&scan, &at("a.gif"), &[], "is a file");
    fly(
        dir.path().to_str().unwrap(),
        &at("b.gif"),
        &[],
        "files in it",
    );
    fly(
        &at("c"),
        &at("c.gif"),
        &["--lens", "equisolid"],
        "equisolid camera",
    );
    fly(
        &at("d"),
        &at("d.gif"),
        &["--stereo", "anaglyph"],
        "--stereo",
    );
    fly(
        &at("e"),
        &at("e.gif"),
        &["--layout", "dashboard"],
        "--layout endoscope",
    );
    for name in ["c", "d", "e"] {
        assert!(!dir.path().join(name).exists(), "{name} written");
    }
}
