//! `endocast batch` (issue 37, item 1): a manifest of studies run to their folders, a corrupt
//! scan and a scan without the structure recorded as failures while the rest go on, the run
//! summarised, and a second run skipping every finished study.

use crate::common::{endocast, fails_with};
use serde_json::Value;
use std::path::Path;
use std::time::Instant;

/// Runs `endocast batch MANIFEST -o OUT --json ...` and returns its studies by scan name.
fn batch(manifest: &Path, out: &Path, extra: &[&str]) -> Vec<Value> {
    let mut args = vec![
        "batch",
        manifest.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--json",
    ];
    args.extend_from_slice(extra);
    let run = endocast(&args);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let summary: Value = serde_json::from_slice(&run.stdout).unwrap();
    let written: Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary, written);
    assert!(out.join("summary.csv").is_file());
    summary["studies"].as_array().unwrap().clone()
}

fn phantom(dir: &Path, kind: &str, size: &str) -> String {
    let file = dir.join(format!("{kind}.nii.gz"));
    let made = endocast(&[
        "phantom",
        kind,
        "--size",
        size,
        "-o",
        file.to_str().unwrap(),
    ]);
    assert!(made.status.success());
    file.file_name().unwrap().to_str().unwrap().to_owned()
}

#[test]
fn a_manifest_runs_each_study_records_failures_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let colon = phantom(dir.path(), "colon", "48");
    let joint = phantom(dir.path(), "joint", "32");
    let bytes = std::fs::read(dir.path().join(&colon)).unwrap();
    std::fs::write(dir.path().join("corrupt.nii.gz"), &bytes[..bytes.len() / 3]).unwrap();
    let manifest = dir.path().join("studies.csv");
    std::fs::write(
        &manifest,
        format!(
            "scan,preset,size,output\n{colon},colonoscopy,48x48,\ncorrupt.nii.gz,colonoscopy,,\n\
             {joint},colonoscopy,,\n{colon},colonoscopy,32x32,colon-small\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let first = batch(&manifest, &out, &["--workers", "2"]);
    let status: Vec<&str> = first
        .iter()
        .map(|s| s["status"].as_str().unwrap())
        .collect();
    assert_eq!(status, ["ok", "failed", "failed", "ok"], "{first:#?}");
    let message = |n: usize| first[n]["message"].as_str().unwrap();
    assert!(message(1).contains("corrupt.nii.gz"), "{}", message(1));
    assert!(
        message(2).contains("no colonoscopy structure"),
        "{}",
        message(2)
    );
    for file in [
        "film.mp4",
        "path.json",
        "start.png",
        "flat.png",
        "report.json",
    ] {
        assert!(out.join("colon").join(file).is_file(), "{file}");
    }
    let report: Value = serde_json::from_str(
        &std::fs::read_to_string(out.join("colon-small/report.json")).unwrap(),
    )
    .unwrap();
    assert!(
        report["steps"]["fly"]["coverage"]["fraction_forward"]
            .as_f64()
            .unwrap()
            > 0.5
    );
    assert_eq!(
        report["steps"]["polyps"]["candidates"]
            .as_array()
            .map(Vec::len),
        Some(0)
    );

    let clock = Instant::now();
    let second = batch(&manifest, &out, &[]);
    assert!(clock.elapsed().as_secs_f64() < 5.0);
    let status: Vec<&str> = second
        .iter()
        .map(|s| s["status"].as_str().unwrap())
        .collect();
    assert_eq!(status, ["skipped", "failed", "failed", "skipped"]);

    // A changed scan is a new study: it runs again.
    std::fs::write(dir.path().join(&colon), &bytes).unwrap();
    let third = batch(&manifest, &out, &[]);
    assert_eq!(third[0]["status"], "ok");
}

#[test]
fn a_bad_manifest_or_failures_with_fail_on_error_fail_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let manifest = dir.path().join("m.csv");
    std::fs::write(&manifest, "scan,colour\na.nii,red\n").unwrap();
    let out = dir.path().join("out");
    let (m, o) = (manifest.to_str().unwrap(), out.to_str().unwrap());
    fails_with(&["batch", m, "-o", o], "\"colour\" is not a column");
    std::fs::write(&manifest, "scan\nmissing.nii\n").unwrap();
    fails_with(
        &["batch", m, "-o", o, "--fail-on-error"],
        "1 of 1 studies failed",
    );
    assert!(out.join("summary.csv").is_file());
    fails_with(&["batch", m, "-o", o, "--workers", "0"], "--workers");
}
