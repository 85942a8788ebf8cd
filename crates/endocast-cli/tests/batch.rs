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
    assert_eq!(message(0), "", "the colon is found with confidence");
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

#[test]
fn a_study_past_its_timeout_is_killed_and_recorded_failed() {
    let dir = tempfile::tempdir().unwrap();
    let colon = phantom(dir.path(), "colon", "48");
    let manifest = dir.path().join("m.csv");
    std::fs::write(&manifest, format!("scan,preset\n{colon},colonoscopy\n")).unwrap();
    let out = dir.path().join("out");
    let clock = Instant::now();
    let studies = batch(&manifest, &out, &["--timeout", "0.2"]);
    assert!(clock.elapsed().as_secs_f64() < 5.0);
    assert_eq!(studies[0]["status"], "failed");
    let message = studies[0]["message"].as_str().unwrap();
    assert!(message.contains("timed out after 0.2 s"), "{message}");
    let (m, o) = (manifest.to_str().unwrap(), out.to_str().unwrap());
    for bad in ["0", "-1", "NaN", "inf"] {
        fails_with(&["batch", m, "-o", o, "--timeout", bad], "--timeout");
    }
}

#[test]
fn a_dataset_column_makes_the_flight_write_its_training_data() {
    let dir = tempfile::tempdir().unwrap();
    let colon = phantom(dir.path(), "colon", "48");
    let manifest = dir.path().join("m.jsonl");
    std::fs::write(
        &manifest,
        format!(
            "{{\"scan\": \"{colon}\", \"preset\": \"colonoscopy\", \"size\": \"24x24\", \
             \"frame-step\": 4, \"dataset\": true}}\n"
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    let studies = batch(&manifest, &out, &[]);
    assert_eq!(studies[0]["status"], "ok", "{studies:#?}");
    let dataset = out.join("colon/dataset");
    assert_eq!(studies[0]["outputs"]["dataset"], dataset.to_str().unwrap());
    let transforms: Value =
        serde_json::from_str(&std::fs::read_to_string(dataset.join("transforms.json")).unwrap())
            .unwrap();
    let frames = transforms["frames"].as_array().unwrap().len();
    assert!(frames > 2, "{frames} frames");
    assert!(dataset.join("images/00000.png").is_file());
    // A changed dataset column is a new study; running it again replaces the old data.
    std::fs::write(
        &manifest,
        std::fs::read_to_string(&manifest)
            .unwrap()
            .replace("true", "false"),
    )
    .unwrap();
    let again = batch(&manifest, &out, &[]);
    assert_eq!(again[0]["status"], "ok");
    assert!(again[0]["outputs"].get("dataset").is_none());
}

#[test]
fn a_run_split_into_studies_writes_the_summary_of_a_whole_run() {
    let dir = tempfile::tempdir().unwrap();
    let colon = phantom(dir.path(), "colon", "48");
    let manifest = dir.path().join("m.csv");
    std::fs::write(
        &manifest,
        format!("scan,preset,size\n{colon},colonoscopy,24x24\nmissing.nii,,\n"),
    )
    .unwrap();
    let out = dir.path().join("out");
    let (m, o) = (manifest.to_str().unwrap(), out.to_str().unwrap());
    let plan = endocast(&["batch", m, "-o", o, "--plan"]);
    let plan: Value = serde_json::from_slice(&plan.stdout).unwrap();
    assert_eq!(plan["studies"][1]["study"], 2);
    assert_eq!(
        plan["studies"][0]["output"],
        out.join("colon").to_str().unwrap()
    );
    assert!(!out.exists(), "--plan runs nothing");
    let records: Vec<Value> = (1..=2)
        .map(|k| {
            let run = endocast(&["batch", m, "-o", o, "--study", &k.to_string(), "--json"]);
            assert!(run.status.success());
            serde_json::from_slice(&run.stdout).unwrap()
        })
        .collect();
    assert_eq!(records[0]["status"], "ok");
    assert_eq!(records[1]["status"], "failed");
    assert!(!out.join("summary.json").exists());
    let file = dir.path().join("records.json");
    std::fs::write(&file, serde_json::json!({ "studies": records }).to_string()).unwrap();
    let summary = batch(&manifest, &out, &["--from-records", file.to_str().unwrap()]);
    assert_eq!(summary, records);
    // A whole run finds the study a split run finished.
    assert_eq!(batch(&manifest, &out, &[])[0]["status"], "skipped");
    let f = file.to_str().unwrap();
    fails_with(&["batch", m, "-o", o, "--study", "3"], "studies 1 to 2");
    std::fs::write(
        &file,
        serde_json::json!({ "studies": [records[1], records[0]] }).to_string(),
    )
    .unwrap();
    fails_with(
        &["batch", m, "-o", o, "--from-records", f],
        "record 1 is of",
    );
    fails_with(
        &["batch", m, "-o", o, "--plan", "--study", "1"],
        "cannot be used",
    );
}

#[test]
fn a_flight_flown_in_parts_joins_into_the_whole_flights_film() {
    let dir = tempfile::tempdir().unwrap();
    let colon = dir.path().join(phantom(dir.path(), "colon", "48"));
    let path = dir.path().join("path.json");
    let (scan, route) = (colon.to_str().unwrap(), path.to_str().unwrap());
    let made = endocast(&["path", scan, "--preset", "colonoscopy", "-o", route]);
    assert!(made.status.success());
    let fly = |output: &Path, extra: &[&str]| {
        let mut args = vec!["fly", scan, "--path", route, "--preset", "colonoscopy"];
        args.extend(["--size", "24x20", "--frame-step", "3", "-o"]);
        args.push(output.to_str().unwrap());
        args.extend_from_slice(extra);
        let run = endocast(&args);
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
    };
    let whole = dir.path().join("whole");
    fly(&whole, &[]);
    let parts: Vec<_> = ["1/2", "2/2"]
        .iter()
        .enumerate()
        .map(|(n, part)| {
            let folder = dir.path().join(format!("part{n}"));
            fly(&folder, &["--frames", part]);
            folder
        })
        .collect();
    let frames = |folder: &Path| {
        let mut names: Vec<_> = std::fs::read_dir(folder)
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        names.sort();
        names
    };
    let all = frames(&whole);
    assert!(all.len() > 3, "{all:?}");
    let split = [frames(&parts[0]), frames(&parts[1])].concat();
    assert_eq!(split, all);
    for (n, name) in all.iter().enumerate() {
        let part = &parts[usize::from(n >= frames(&parts[0]).len())];
        let same =
            std::fs::read(whole.join(name)).unwrap() == std::fs::read(part.join(name)).unwrap();
        assert!(same, "{name}");
    }
    let range = dir.path().join("range");
    fly(&range, &["--frames", "1:3"]);
    assert_eq!(frames(&range), all[1..3]);

    let (whole_mp4, joined) = (dir.path().join("whole.mp4"), dir.path().join("joined.mp4"));
    fly(&whole_mp4, &[]);
    let mut args = vec![
        "film",
        parts[1].to_str().unwrap(),
        parts[0].to_str().unwrap(),
        "-o",
    ];
    args.push(joined.to_str().unwrap());
    assert!(endocast(&args).status.success());
    assert!(std::fs::read(&whole_mp4).unwrap() == std::fs::read(&joined).unwrap());
    let j = joined.to_str().unwrap();
    fails_with(
        &["film", parts[1].to_str().unwrap(), "-o", j],
        "frame 0 is missing",
    );
    fails_with(
        &["fly", scan, "--path", route, "-o", j, "--frames", "1/2"],
        "--frames writes a folder of PNGs",
    );
    fails_with(
        &["fly", scan, "--path", route, "-o", j, "--frames", "4:2"],
        "END must be past START",
    );
}
