//! One study of a batch: its steps, each this program run as a child process (`path`, `fly`
//! with coverage, `render`, and for colonoscopy `dissect` and `polyps`), so that a study that
//! fails, panics, runs out of memory or past its time takes nothing else down; its report,
//! `report.json`; and the fingerprint of its inputs and settings that lets a later run skip it.

use super::child::{run_step, Deadline};
use super::manifest::Entry;
use anyhow::{Context, Result};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant, UNIX_EPOCH};

/// The report of each study, in its output folder.
pub const REPORT: &str = "report.json";

/// What every study of a batch shares.
pub struct Setup<'a> {
    /// This program.
    pub program: PathBuf,
    /// Its command line, to tell which options each step takes.
    pub cli: &'a clap::Command,
    /// Worker threads per study.
    pub threads: usize,
    /// The largest volume a study may read (its share of the memory).
    pub max_voxels: u64,
    /// The most time a study may take (`--timeout`); none by default.
    pub timeout: Option<Duration>,
}

/// How a study ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Every step ran.
    Ok,
    /// A step failed; its message says why.
    Failed,
    /// A finished report with the same inputs and settings was already there.
    Skipped,
}

/// One study's line of the run summary.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Record {
    /// The scan, as the manifest resolved it.
    pub scan: String,
    /// How it ended.
    pub status: Status,
    /// Why it failed (empty otherwise).
    pub message: String,
    /// Its time, seconds (of the run that made the report, when skipped).
    pub seconds: f64,
    /// Its output folder.
    pub output: String,
    /// What it wrote: name → file.
    pub outputs: serde_json::Map<String, Value>,
}

/// Runs the study `entry` into `folder`, or skips it when `folder` already holds a finished
/// report of the same inputs and settings.
pub fn run(entry: &Entry, folder: &Path, setup: &Setup) -> Record {
    let clock = Instant::now();
    let record = |status, message: String, outputs| Record {
        scan: entry.scan.display().to_string(),
        status,
        message,
        seconds: clock.elapsed().as_secs_f64(),
        output: folder.display().to_string(),
        outputs,
    };
    let inputs = match fingerprint(entry) {
        Ok(inputs) => inputs,
        Err(e) => return record(Status::Failed, format!("{e:#}"), Default::default()),
    };
    if let Some(done) = finished(folder, &inputs) {
        return Record {
            status: Status::Skipped,
            ..done
        };
    }
    let mut steps = serde_json::Map::new();
    let deadline = setup.timeout.map(|timeout| Deadline {
        at: clock + timeout,
        timeout,
    });
    let ran = run_steps(entry, folder, setup, deadline, &mut steps);
    let outputs = outputs(folder, &steps);
    let done = match ran {
        Ok(()) => record(Status::Ok, warning(&steps), outputs),
        Err(e) => record(Status::Failed, format!("{e:#}"), outputs),
    };
    let report = json!({"record": &done, "inputs": inputs, "steps": steps});
    if let Err(e) = write_report(folder, &report) {
        return record(Status::Failed, format!("{e:#}"), done.outputs);
    }
    done
}

/// What a reader of the summary must know of a study that ran: its structure found without
/// confidence (the path step's study says why), or nothing.
fn warning(steps: &serde_json::Map<String, Value>) -> String {
    let study = &steps.get("path").unwrap_or(&Value::Null)["study"];
    match (&study["confident"], &study["structure"]) {
        (Value::Bool(false), Value::String(structure)) => format!("warning: {structure}"),
        _ => String::new(),
    }
}

/// The steps of a study, each adding its JSON (or `null`) to `steps`; stops at the first
/// that fails or runs past `deadline`.
fn run_steps(
    entry: &Entry,
    folder: &Path,
    setup: &Setup,
    deadline: Option<Deadline>,
    steps: &mut serde_json::Map<String, Value>,
) -> Result<()> {
    std::fs::create_dir_all(folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let path_file = folder.join("path.json");
    let path_arg = path_file.display().to_string();
    let mut fly = vec!["--path", &path_arg, "--coverage", "--json"];
    let dataset = folder.join(DATASET);
    let dataset_arg = dataset.display().to_string();
    clear_dataset(&dataset)?;
    if entry.dataset {
        fly.extend(["--dataset", &dataset_arg]);
    }
    // Each step: its command, its output file in `folder` (if any) and its own options.
    let mut plan = vec![
        ("path", Some("path.json"), vec!["--json"]),
        ("fly", Some("film.mp4"), fly),
        ("render", Some("start.png"), vec![]),
    ];
    if entry.preset.as_deref() == Some("colonoscopy") {
        plan.push((
            "dissect",
            Some("flat.png"),
            vec!["--path", &path_arg, "--json"],
        ));
        plan.push(("polyps", None, vec!["--path", &path_arg, "--json"]));
    }
    for (command, output, own) in plan {
        let output = output.map(|file| folder.join(file));
        let args = step_args(command, output.as_deref(), &own, entry, setup);
        let said = run_step(&setup.program, command, &args, deadline)?;
        steps.insert(command.into(), said);
    }
    Ok(())
}

/// The study's training-data folder (manifest column `dataset`), written by its flight.
const DATASET: &str = "dataset";

/// Removes the training data of an earlier run of the study, which this run replaces or no
/// longer makes (`fly --dataset` writes only into a new or empty folder); the folder is the
/// batch's own, inside the study's.
fn clear_dataset(dataset: &Path) -> Result<()> {
    if dataset.is_dir() {
        std::fs::remove_dir_all(dataset)
            .with_context(|| format!("cannot clear {}", dataset.display()))?;
    }
    Ok(())
}

/// The arguments of step `command`: the scan, the preset, the options of the manifest it
/// takes, its output file and own options, and the batch's threads and memory share.
fn step_args(
    command: &str,
    output: Option<&Path>,
    own: &[&str],
    entry: &Entry,
    setup: &Setup,
) -> Vec<String> {
    let takes = |name: &str| takes_option(setup.cli, command, name);
    let mut args = vec![command.to_owned(), entry.scan.display().to_string()];
    if let Some(preset) = &entry.preset {
        args.extend(["--preset".to_owned(), preset.clone()]);
    }
    for (name, value) in entry.options.iter().filter(|(name, _)| takes(name)) {
        match value.as_str() {
            "true" => args.push(format!("--{name}")),
            "false" => {}
            _ => args.extend([format!("--{name}"), value.clone()]),
        }
    }
    if let Some(file) = output {
        args.extend(["-o".to_owned(), file.display().to_string()]);
    }
    args.extend(own.iter().map(|arg| arg.to_string()));
    if takes("threads") {
        args.extend(["--threads".to_owned(), setup.threads.to_string()]);
    }
    args.extend(["--max-voxels".to_owned(), setup.max_voxels.to_string()]);
    args
}

/// Whether subcommand `command` of `cli` has the option `--name`.
pub fn takes_option(cli: &clap::Command, command: &str, name: &str) -> bool {
    cli.find_subcommand(command)
        .is_some_and(|sub| sub.get_arguments().any(|arg| arg.get_long() == Some(name)))
}

/// The files the steps wrote that exist, by name.
fn outputs(
    folder: &Path,
    steps: &serde_json::Map<String, Value>,
) -> serde_json::Map<String, Value> {
    let files = [
        ("path", "path.json"),
        ("film", "film.mp4"),
        ("coverage", "film.coverage.json"),
        ("start", "start.png"),
        ("dissection", "flat.png"),
        ("dissection_map", "flat.map.npy"),
    ];
    let mut found: serde_json::Map<String, Value> = files
        .iter()
        .map(|(name, file)| (*name, folder.join(file)))
        .filter(|(_, file)| file.is_file())
        .map(|(name, file)| (name.to_owned(), json!(file.display().to_string())))
        .collect();
    let dataset = folder.join(DATASET);
    if dataset.join("transforms.json").is_file() {
        found.insert("dataset".into(), json!(dataset.display().to_string()));
    }
    if let Some(candidates) = steps.get("polyps").and_then(|p| p.get("candidates")) {
        found.insert(
            "polyp_candidates".into(),
            json!(candidates.as_array().map_or(0, Vec::len)),
        );
    }
    found
}

/// What decides a study's results: the scan's files (name, size, time of change), its preset
/// and options, and this program's version. A report with the same fingerprint is current.
fn fingerprint(entry: &Entry) -> Result<Value> {
    let scan = &entry.scan;
    let meta = std::fs::metadata(scan)
        .with_context(|| format!("cannot read the scan {}", scan.display()))?;
    let mut files = vec![scan.clone()];
    if meta.is_dir() {
        files = list_files(scan)?;
    }
    let files: Vec<Value> = files
        .iter()
        .map(|file| {
            let meta = std::fs::metadata(file)
                .with_context(|| format!("cannot read {}", file.display()))?;
            let changed = meta
                .modified()
                .ok()
                .and_then(|t| t.duration_since(UNIX_EPOCH).ok())
                .map_or(0, |d| d.as_nanos());
            Ok(json!([
                file.display().to_string(),
                meta.len(),
                changed.to_string()
            ]))
        })
        .collect::<Result<_>>()?;
    let mut inputs = json!({
        "files": files,
        "preset": entry.preset,
        "options": entry.options,
        "version": env!("CARGO_PKG_VERSION"),
    });
    // Only when asked, so that the reports of studies without it stay current.
    if entry.dataset {
        inputs["dataset"] = json!(true);
    }
    Ok(inputs)
}

/// Every file under `folder`, sorted (a DICOM series' folder).
fn list_files(folder: &Path) -> Result<Vec<PathBuf>> {
    let mut files = Vec::new();
    let mut pending = vec![folder.to_path_buf()];
    while let Some(dir) = pending.pop() {
        let read =
            std::fs::read_dir(&dir).with_context(|| format!("cannot list {}", dir.display()))?;
        for item in read {
            let path = item?.path();
            if path.is_dir() {
                pending.push(path);
            } else {
                files.push(path);
            }
        }
    }
    files.sort();
    Ok(files)
}

/// The record of a finished (ok) report in `folder` made from `inputs`, if there is one.
fn finished(folder: &Path, inputs: &Value) -> Option<Record> {
    let text = std::fs::read_to_string(folder.join(REPORT)).ok()?;
    let report: Value = serde_json::from_str(&text).ok()?;
    let record = report.get("record")?;
    if report.get("inputs")? != inputs || record.get("status")? != "ok" {
        return None;
    }
    Some(Record {
        scan: record.get("scan")?.as_str()?.to_owned(),
        status: Status::Ok,
        message: String::new(),
        seconds: record.get("seconds")?.as_f64()?,
        output: record.get("output")?.as_str()?.to_owned(),
        outputs: record.get("outputs")?.as_object()?.clone(),
    })
}

/// Writes `report` into `folder` atomically (a study killed while writing leaves the old one).
fn write_report(folder: &Path, report: &Value) -> Result<()> {
    let file = folder.join(REPORT);
    let text = serde_json::to_string_pretty(report)?;
    endocast_io::atomic::write_file(&file, |out| out.write_all(text.as_bytes()))
        .with_context(|| format!("cannot write {}", file.display()))
}

#[cfg(test)]
mod tests {
    #![allow(clippy::unwrap_used)] // a failed unwrap in a test is a failed test
    use super::*;

    /// A structure found without confidence is said in the record; a confident one says
    /// nothing.
    #[test]
    fn a_structure_found_without_confidence_is_a_warning() {
        let steps = |confident: bool| {
            let path = json!({"study": {"confident": confident, "structure": "not confident: x"}});
            json!({ "path": path }).as_object().unwrap().clone()
        };
        assert_eq!(warning(&steps(false)), "warning: not confident: x");
        assert_eq!(warning(&steps(true)), "");
        assert_eq!(warning(&serde_json::Map::new()), "");
    }
}
