//! A batch split among machines: its plan (`--plan`), one study's record (`--study K`) and the
//! summary written from the records the machines sent back (`--from-records`), checked
//! against the manifest.

use super::manifest::Entry;
use super::study::{Record, Status};
use anyhow::{bail, Context, Result};
use serde_json::json;
use std::io::Read;
use std::path::{Path, PathBuf};

/// Prints the plan: `{"studies": [{"study": K, "scan": …, "output": …}, …]}`, K from 1.
pub fn say_plan(entries: &[Entry], folders: &[PathBuf]) -> Result<()> {
    let studies: Vec<_> = entries
        .iter()
        .zip(folders)
        .enumerate()
        .map(|(n, (entry, folder))| {
            json!({
                "study": n + 1,
                "scan": entry.scan.display().to_string(),
                "output": folder.display().to_string(),
            })
        })
        .collect();
    let plan = json!({ "studies": studies });
    println!("{}", serde_json::to_string_pretty(&plan)?);
    Ok(())
}

/// The index of `--study K` among `count` studies.
pub fn study_index(k: usize, count: usize) -> Result<usize> {
    if !(1..=count).contains(&k) {
        bail!("--study {k}: the manifest has studies 1 to {count}");
    }
    Ok(k - 1)
}

/// Prints one study's record (as JSON, or a line); an error when it failed and `fail_on_error`.
pub fn say_one(record: &Record, json: bool, fail_on_error: bool) -> Result<()> {
    if json {
        println!("{}", serde_json::to_string_pretty(record)?);
    } else {
        let status = serde_json::to_value(record.status)?;
        println!("{}: {} {}", record.scan, status, record.message);
    }
    if fail_on_error && record.status == Status::Failed {
        bail!("the study failed (--fail-on-error): {}", record.message);
    }
    Ok(())
}

/// The records in `file` ('-': standard input), one per study of the manifest in its order,
/// each of its study's scan and folder.
pub fn read(file: &Path, entries: &[Entry], folders: &[PathBuf]) -> Result<Vec<Record>> {
    let text = if file == Path::new("-") {
        let mut text = String::new();
        std::io::stdin().read_to_string(&mut text)?;
        text
    } else {
        std::fs::read_to_string(file)
            .with_context(|| format!("cannot read the records {}", file.display()))?
    };
    #[derive(serde::Deserialize)]
    struct Records {
        studies: Vec<Record>,
    }
    let records: Records =
        serde_json::from_str(&text).with_context(|| format!("the records {}", file.display()))?;
    let records = records.studies;
    if records.len() != entries.len() {
        bail!(
            "{} records for the manifest's {} studies",
            records.len(),
            entries.len()
        );
    }
    for (n, (record, (entry, folder))) in
        records.iter().zip(entries.iter().zip(folders)).enumerate()
    {
        let (scan, output) = (
            entry.scan.display().to_string(),
            folder.display().to_string(),
        );
        if record.scan != scan || record.output != output {
            bail!(
                "record {} is of {} into {}, the manifest's study {} is {scan} into {output}",
                n + 1,
                record.scan,
                record.output,
                n + 1
            );
        }
    }
    Ok(records)
}
