//! Which case file a viewer session opens and saves to, so that opening a scan again never
//! replaces the work saved for it: a case already beside the scan is reopened; one that is
//! unreadable or belongs to another scan is left alone and the session saves under a new name.

use crate::case::Case;
use endocast_io::case::ScanSource;
use std::path::{Path, PathBuf};

/// The case file of a session about to open.
#[derive(Debug, Clone, PartialEq)]
pub struct CaseChoice {
    /// The case to reopen (its scan, view, key frames and marks), if any.
    pub open: Option<PathBuf>,
    /// Where the session saves.
    pub save_to: PathBuf,
    /// What the user should be told about the choice (a case reopened, or one left alone).
    pub note: Option<String>,
}

/// The case for a session on `source`: `given` (`--case`) when there is one; else the scan's
/// default case ([`default_case_path`]) reopened when it is this scan's; else, when that file
/// cannot be read or belongs to another scan (or the scan is a phantom), a new file beside it:
/// an existing one is never written over.
pub fn choose_case(source: &ScanSource, given: Option<PathBuf>) -> CaseChoice {
    if let Some(path) = given {
        return CaseChoice {
            open: Some(path.clone()),
            save_to: path,
            note: None,
        };
    }
    let default = default_case_path(source);
    if !default.exists() {
        return CaseChoice {
            open: None,
            save_to: default,
            note: None,
        };
    }
    // A phantom is made anew, not a study with saved work: its case in the temporary folder
    // (perhaps another session's) is not reopened, nor written over.
    if matches!(source, ScanSource::Phantom { .. }) {
        return CaseChoice {
            open: None,
            save_to: free_name(&default),
            note: None,
        };
    }
    let why = match Case::read(&default) {
        Ok(case) if same_scan(&case.scan, source) => {
            return CaseChoice {
                note: Some(format!("reopened the saved case {}", default.display())),
                open: Some(default.clone()),
                save_to: default,
            };
        }
        Ok(_) => "is the case of another scan".to_string(),
        Err(e) => format!("cannot be read ({e})"),
    };
    let save_to = free_name(&default);
    CaseChoice {
        open: None,
        note: Some(format!(
            "{} {why}: left as it is; this session saves to {}",
            default.display(),
            save_to.display()
        )),
        save_to,
    }
}

/// Where a scan's case is saved until the user saves elsewhere: beside the scan for a file
/// (in the working directory when the scan's folder is read-only), in the temporary folder for
/// a phantom.
pub fn default_case_path(source: &ScanSource) -> PathBuf {
    match source {
        ScanSource::File { path, .. } => {
            let name = path
                .file_name()
                .map_or_else(|| "scan".into(), |n| n.to_string_lossy().into_owned());
            let dir = path.parent().map(PathBuf::from).unwrap_or_default();
            let candidate = dir.join(format!("{name}.endocast-case.json"));
            if dir.as_os_str().is_empty() || writable(&dir) {
                candidate
            } else {
                PathBuf::from(format!("{name}.endocast-case.json"))
            }
        }
        ScanSource::Phantom { name, .. } => {
            std::env::temp_dir().join(format!("endocast-{name}.endocast-case.json"))
        }
    }
}

fn writable(dir: &Path) -> bool {
    std::fs::metadata(dir).is_ok_and(|m| !m.permissions().readonly())
        && tempfile::tempfile_in(dir).is_ok()
}

/// Whether two sources name the same scan (files compared by their canonical paths).
fn same_scan(a: &ScanSource, b: &ScanSource) -> bool {
    match (a, b) {
        (
            ScanSource::File {
                path: pa,
                series: sa,
                ..
            },
            ScanSource::File {
                path: pb,
                series: sb,
                ..
            },
        ) => {
            let canonical = |p: &Path| p.canonicalize().unwrap_or_else(|_| p.to_path_buf());
            sa == sb && canonical(pa) == canonical(pb)
        }
        _ => a == b,
    }
}

/// The first of `NAME-2.endocast-case.json`, `NAME-3…` beside `default` that does not exist.
fn free_name(default: &Path) -> PathBuf {
    let file = default.file_name().unwrap_or_default().to_string_lossy();
    let stem = file.strip_suffix(".endocast-case.json").unwrap_or(&file);
    (2..)
        .map(|n| default.with_file_name(format!("{stem}-{n}.endocast-case.json")))
        .find(|p| !p.exists())
        .expect("an unbounded range has a free name")
}
