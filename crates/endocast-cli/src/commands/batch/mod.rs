//! `endocast batch`: every study of a manifest through the same pipeline (path, flight with
//! coverage and its film, a key view, and for colonoscopy the dissection and polyp
//! candidates), each in its own folder with a report, the run summarised in `summary.csv` and
//! `summary.json`. Resumable (a study whose inputs and settings match a finished report is
//! skipped), isolated (each step is a child process: a failure is recorded and the run goes
//! on), bounded (each worker's study may read at most its share of the memory, and at most
//! `--timeout` seconds).
//!
//! A run can also be split among machines (Python's `endocast.batch` on Dask): `--plan` lists
//! the studies, `--study K` runs one of them exactly as a whole run does, and `--from-records`
//! writes the summary from their records.

mod child;
mod manifest;
mod records;
mod study;
mod summary;

use anyhow::{bail, Result};
use clap::Args;
use endocast_io::Limits;
use manifest::Entry;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};
use study::{Record, Setup, Status};

/// Arguments of `endocast batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// The manifest: CSV with a header, or JSON lines, one study each. Keys: `scan` (required;
    /// relative to the manifest's folder), `preset`, `output` (the study's folder under -o;
    /// default: named after the scan), `dataset` (true: the flight also writes its training
    /// data, `fly --dataset`, into the study's dataset/) and any render/fly option without its
    /// dashes (`iso`, `orientation`, `size`, `bright-lumen` = true, …).
    manifest: PathBuf,
    /// The output folder: one folder a study (path.json, film.mp4 with its coverage,
    /// start.png, flat.png and its map for colonoscopy, report.json), and summary.csv and
    /// summary.json over all.
    #[arg(short, long)]
    output: PathBuf,
    /// Studies run at once; each gets an equal share of the cores and of the memory.
    #[arg(long, default_value_t = 1)]
    workers: usize,
    /// Print the summary as JSON.
    #[arg(long)]
    json: bool,
    /// Exit with an error when any study failed (by default the run succeeds when it
    /// completed, its failures recorded in the summary).
    #[arg(long)]
    fail_on_error: bool,
    /// The most time a study may take, seconds: past it its step is killed and the study
    /// recorded as failed, "timed out after N s" (default: no limit).
    #[arg(long, value_name = "SECONDS", allow_hyphen_values = true)]
    timeout: Option<f64>,
    /// Run only study K (1 is the manifest's first) into its folder, as a whole run would, and
    /// print its record (JSON with --json); no summary is written. One task of a run split
    /// among machines.
    #[arg(long, value_name = "K", group = "part")]
    study: Option<usize>,
    /// Print the studies as JSON (study number, scan, output folder) and run none.
    #[arg(long, group = "part")]
    plan: bool,
    /// Run nothing: write the summary from the records in FILE ('-': standard input), JSON
    /// `{"studies": [...]}` as `--study K --json` printed them, one per study in manifest order.
    #[arg(long, value_name = "FILE", group = "part")]
    from_records: Option<PathBuf>,
}

/// Runs `endocast batch`; `cli` is the program's command line (which options each step takes).
pub fn run(args: &BatchArgs, cli: &clap::Command) -> Result<()> {
    if args.workers == 0 {
        bail!("--workers must be at least 1");
    }
    let timeout = timeout(args.timeout)?;
    let is_option = |name: &str| {
        study::takes_option(cli, "render", name) || study::takes_option(cli, "fly", name)
    };
    let entries = manifest::read(&args.manifest, is_option)?;
    let folders = study_folders(&entries, &args.output)?;
    let clock = Instant::now();
    if args.plan {
        return records::say_plan(&entries, &folders);
    }
    let records = if let Some(file) = &args.from_records {
        records::read(file, &entries, &folders)?
    } else {
        let setup = setup(cli, args.workers, timeout)?;
        if let Some(k) = args.study {
            let n = records::study_index(k, entries.len())?;
            let record = study::run(&entries[n], &folders[n], &setup);
            summary::Progress::new(1, 1).ended(&record);
            return records::say_one(&record, args.json, args.fail_on_error);
        }
        run_all(&entries, &folders, &setup, args.workers)
    };
    summary::write(&args.output, &records)?;
    summary::say(&records, clock.elapsed(), args.json)?;
    let failed = records
        .iter()
        .filter(|r| r.status == Status::Failed)
        .count();
    if args.fail_on_error && failed > 0 {
        bail!(
            "{failed} of {} studies failed (--fail-on-error)",
            records.len()
        );
    }
    Ok(())
}

/// Each study's folder under `out`: its `output`, else the scan's name without extensions; no
/// two studies may share one.
fn study_folders(entries: &[Entry], out: &Path) -> Result<Vec<PathBuf>> {
    let mut seen = BTreeSet::new();
    entries
        .iter()
        .map(|entry| {
            let folder = out.join(
                entry
                    .output
                    .clone()
                    .unwrap_or_else(|| scan_name(&entry.scan)),
            );
            if !seen.insert(folder.clone()) {
                bail!(
                    "line {}: {} is the folder of another study too: give each an output",
                    entry.line,
                    folder.display()
                );
            }
            Ok(folder)
        })
        .collect()
}

/// A scan's name without its extensions (`colon.nii.gz` → `colon`).
fn scan_name(scan: &Path) -> PathBuf {
    let name = scan
        .file_name()
        .map_or_else(|| "scan".into(), |n| n.to_string_lossy().into_owned());
    PathBuf::from(
        name.split('.')
            .next()
            .filter(|s| !s.is_empty())
            .unwrap_or(&name),
    )
}

/// `--timeout`, checked: a positive number of seconds.
fn timeout(seconds: Option<f64>) -> Result<Option<Duration>> {
    let Some(seconds) = seconds else {
        return Ok(None);
    };
    match Duration::try_from_secs_f64(seconds) {
        Ok(timeout) if seconds > 0.0 => Ok(Some(timeout)),
        _ => bail!("--timeout must be a positive number of seconds, not {seconds}"),
    }
}

/// What the studies share: this program, threads and memory per worker, the time a study may
/// take.
fn setup(cli: &clap::Command, workers: usize, timeout: Option<Duration>) -> Result<Setup<'_>> {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    Ok(Setup {
        program: std::env::current_exe()?,
        cli,
        threads: (cores / workers).max(1),
        max_voxels: Limits::default().max_voxels / workers as u64,
        timeout,
    })
}

/// Runs the studies on `workers` threads, in manifest order, reporting each as it ends.
fn run_all(entries: &[Entry], folders: &[PathBuf], setup: &Setup, workers: usize) -> Vec<Record> {
    let next = AtomicUsize::new(0);
    let done: Mutex<Vec<Option<Record>>> = Mutex::new(vec![None; entries.len()]);
    let progress = Mutex::new(summary::Progress::new(entries.len(), workers));
    std::thread::scope(|scope| {
        for _ in 0..workers.min(entries.len()) {
            scope.spawn(|| loop {
                let n = next.fetch_add(1, Ordering::Relaxed);
                let Some(entry) = entries.get(n) else { break };
                let record = study::run(entry, &folders[n], setup);
                if let Ok(mut progress) = progress.lock() {
                    progress.ended(&record);
                }
                if let Ok(mut done) = done.lock() {
                    done[n] = Some(record);
                }
            });
        }
    });
    done.into_inner()
        .unwrap_or_default()
        .into_iter()
        .flatten()
        .collect()
}
