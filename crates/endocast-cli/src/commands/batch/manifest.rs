//! The batch manifest: one study a row of a CSV file with a header, or a line of JSON lines,
//! with the same keys: `scan` (required; relative to the manifest's folder), `preset`,
//! `output` (relative to the batch's output folder), `dataset` (true: the flight also writes
//! its training data) and any `render`/`fly` option without its dashes (`iso`, `orientation`,
//! `bright-lumen`, …).

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Keys the batch sets itself for every study: a manifest may not give them.
const RESERVED: [&str; 5] = ["path", "json", "coverage", "max-voxels", "threads"];

/// A row of the manifest as read: its line and its `(key, value)` pairs.
type Row = (usize, Vec<(String, String)>);

/// One study of the manifest.
#[derive(Debug, Clone, PartialEq)]
pub struct Entry {
    /// Its line in the manifest (1 is the first line), for messages.
    pub line: usize,
    /// The scan, as given (relative paths resolved against the manifest's folder).
    pub scan: PathBuf,
    /// The clinical preset, if any.
    pub preset: Option<String>,
    /// Its output folder, relative to the batch's (default: named after the scan).
    pub output: Option<PathBuf>,
    /// Whether its flight also writes its training data (`fly --dataset`). Default false.
    pub dataset: bool,
    /// Further options, `(name, value)`: name without dashes; a value `true` is a flag.
    pub options: Vec<(String, String)>,
}

/// Reads the manifest at `path`; `is_option` says whether a name is a `render` or `fly` option.
/// Errors name the manifest, the line and what is wrong.
pub fn read(path: &Path, is_option: impl Fn(&str) -> bool) -> Result<Vec<Entry>> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("cannot read the manifest {}", path.display()))?;
    let base = path.parent().unwrap_or(Path::new("."));
    let rows = if text.trim_start().starts_with('{') {
        json_lines(&text)
    } else {
        csv_rows(&text)
    }
    .with_context(|| format!("the manifest {}", path.display()))?;
    let entries = rows
        .into_iter()
        .map(|(line, keys)| entry(line, keys, base, &is_option))
        .collect::<Result<Vec<_>>>()
        .with_context(|| format!("the manifest {}", path.display()))?;
    if entries.is_empty() {
        bail!("the manifest {} lists no study", path.display());
    }
    Ok(entries)
}

/// The rows of a CSV manifest with a header: `(line, [(key, value)])`, empty values left out.
fn csv_rows(text: &str) -> Result<Vec<Row>> {
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .comment(Some(b'#'))
        .from_reader(text.as_bytes());
    let header: Vec<String> = reader.headers()?.iter().map(str::to_owned).collect();
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        let keys = header
            .iter()
            .zip(record.iter())
            .filter(|(_, value)| !value.is_empty())
            .map(|(key, value)| (key.clone(), value.to_owned()))
            .collect();
        rows.push((line, keys));
    }
    Ok(rows)
}

/// The lines of a JSON-lines manifest, each an object of strings, numbers or booleans (`null`
/// leaves a key out); blank lines are skipped.
fn json_lines(text: &str) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    for (n, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let object: serde_json::Map<String, Value> = serde_json::from_str(line)
            .with_context(|| format!("line {}: not a JSON object", n + 1))?;
        let mut keys = Vec::new();
        for (key, value) in object {
            let value = match value {
                Value::Null => continue,
                Value::String(s) => s,
                Value::Bool(_) | Value::Number(_) => value.to_string(),
                other => bail!(
                    "line {}: {key} is {other}, not a string, number or boolean",
                    n + 1
                ),
            };
            keys.push((key, value));
        }
        rows.push((n + 1, keys));
    }
    Ok(rows)
}

/// One study from its keys, checked: a scan, no key twice, every other key an option.
fn entry(
    line: usize,
    keys: Vec<(String, String)>,
    base: &Path,
    is_option: impl Fn(&str) -> bool,
) -> Result<Entry> {
    let mut seen = BTreeSet::new();
    let mut entry = Entry {
        line,
        scan: PathBuf::new(),
        preset: None,
        output: None,
        dataset: false,
        options: Vec::new(),
    };
    for (key, value) in keys {
        let key = key.trim_start_matches('-').to_owned();
        if !seen.insert(key.clone()) {
            bail!("line {line}: {key} is given twice");
        }
        match key.as_str() {
            "scan" => entry.scan = base.join(value),
            "preset" => entry.preset = Some(value),
            "output" => entry.output = Some(PathBuf::from(value)),
            "dataset" => entry.dataset = yes_or_no(line, &key, &value)?,
            name if RESERVED.contains(&name) => {
                bail!("line {line}: {name} is set by the batch itself and cannot be given")
            }
            name if is_option(name) => entry.options.push((key, value)),
            name => bail!(
                "line {line}: {name:?} is not a column of a manifest (scan, preset, output, \
                 dataset) nor an option of render or fly"
            ),
        }
    }
    if entry.scan.as_os_str().is_empty() {
        bail!("line {line}: no scan");
    }
    Ok(entry)
}

/// A yes/no column: `true`/`false` (any case), `1`/`0`, `yes`/`no`.
fn yes_or_no(line: usize, key: &str, value: &str) -> Result<bool> {
    match value.to_ascii_lowercase().as_str() {
        "true" | "1" | "yes" => Ok(true),
        "false" | "0" | "no" => Ok(false),
        _ => bail!("line {line}: {key} is {value:?}, not true or false"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(name: &str, text: &str) -> Result<Vec<Entry>> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(name);
        std::fs::write(&path, text).unwrap();
        read(&path, |name| {
            ["iso", "bright-lumen", "size"].contains(&name)
        })
        .map(|entries| {
            entries
                .into_iter()
                .map(|e| Entry {
                    scan: e.scan.strip_prefix(dir.path()).unwrap().to_path_buf(),
                    ..e
                })
                .collect()
        })
    }

    #[test]
    fn csv_and_json_lines_give_the_same_studies() {
        let csv = "scan,preset,iso,output\na.nii.gz,colonoscopy,-600,\n\"b, c.nrrd\",,,b\n";
        let json = "{\"scan\": \"a.nii.gz\", \"preset\": \"colonoscopy\", \"iso\": -600}\n\n\
                    {\"scan\": \"b, c.nrrd\", \"output\": \"b\", \"preset\": null}\n";
        let from_csv = parse("m.csv", csv).unwrap();
        let from_json = parse("m.jsonl", json).unwrap();
        assert_eq!(from_csv.len(), 2);
        assert_eq!(from_csv[0].scan, PathBuf::from("a.nii.gz"));
        assert_eq!(from_csv[0].preset.as_deref(), Some("colonoscopy"));
        assert_eq!(from_csv[0].options, vec![("iso".into(), "-600".into())]);
        assert_eq!(from_csv[1].scan, PathBuf::from("b, c.nrrd"));
        assert_eq!(from_csv[1].output, Some(PathBuf::from("b")));
        let strip = |e: &[Entry]| {
            e.iter()
                .map(|e| {
                    (
                        e.scan.clone(),
                        e.preset.clone(),
                        e.output.clone(),
                        e.options.clone(),
                    )
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(strip(&from_csv), strip(&from_json));
    }

    #[test]
    fn bad_manifests_name_the_line_and_the_problem() {
        let said = |name: &str, text: &str| format!("{:#}", parse(name, text).unwrap_err());
        assert!(said("m.csv", "scan,colour\na.nii,red\n").contains("line 2: \"colour\""));
        assert!(said("m.csv", "scan,path\na.nii,p.json\n").contains("path is set by the batch"));
        assert!(said("m.csv", "preset\ncolonoscopy\n").contains("line 2: no scan"));
        assert!(said("m.csv", "scan\n").contains("lists no study"));
        assert!(said("m.jsonl", "{\"scan\": \"a\"}\n{\"scan\": [1]}\n").contains("line 2"));
        assert!(said("m.jsonl", "{\"scan\": \"a\", \"--scan\": \"b\"}\n").contains("twice"));
        assert!(said("m.csv", "scan,dataset\na.nii,maybe\n").contains("dataset is \"maybe\""));
    }
}
