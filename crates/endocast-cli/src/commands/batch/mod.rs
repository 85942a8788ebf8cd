//! `endocast batch`: every study of a manifest through the same pipeline (path, flight with
//! coverage and its film, a key view, and for colonoscopy the dissection and polyp
//! candidates), each in its own folder with a report, the run summarised in `summary.csv` and
//! `summary.json`. Resumable (a study whose inputs and settings match a finished report is
//! skipped), isolated (each step is a child process: a failure is recorded and the run goes
//! on), bounded (each worker's study may read at most its share of the memory).

mod manifest;
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
use std::time::Instant;
use study::{Record, Setup, Status};

/// Arguments of `endocast batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// The manifest: CSV with a header, or JSON lines, one study each. Keys: `scan` (required;
    /// relative to the manifest's folder), `preset`, `output` (the study's folder under -o;
    /// default: named after the scan) and any render/fly option without its dashes (`iso`,
    /// `orientation`, `size`, `bright-lumen` = true, …).
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
}

/// Runs `endocast batch`; `cli` is the program's command line (which options each step takes).
pub fn run(args: &BatchArgs, cli: &clap::Command) -> Result<()> {
    if args.workers == 0 {
        bail!("--workers must be at least 1");
    }
    let is_option = |name: &str| {
        study::takes_option(cli, "render", name) || study::takes_option(cli, "fly", name)
    };
    let entries = manifest::read(&args.manifest, is_option)?;
    let folders = study_folders(&entries, &args.output)?;
    let setup = setup(cli, args.workers)?;
    let clock = Instant::now();
    let records = run_all(&entries, &folders, &setup, args.workers);
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

/// What the studies share: this program, threads and memory per worker.
fn setup(cli: &clap::Command, workers: usize) -> Result<Setup<'_>> {
    let cores = std::thread::available_parallelism().map_or(1, usize::from);
    Ok(Setup {
        program: std::env::current_exe()?,
        cli,
        threads: (cores / workers).max(1),
        max_voxels: Limits::default().max_voxels / workers as u64,
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
