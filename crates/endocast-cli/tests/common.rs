//! Running the binary and finding the shared data.

use std::path::PathBuf;
use std::process::{Command, Output};

/// Runs `endocast` with `args`.
pub fn endocast(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_endocast"))
        .args(args)
        .output()
        .expect("the endocast binary runs")
}

/// Runs `endocast info --json PATH [extra]` and parses the report; panics with stderr on failure.
pub fn info_json(path: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["info", "--json", path];
    args.extend_from_slice(extra);
    let out = endocast(&args);
    assert!(
        out.status.success(),
        "endocast info {path} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("info --json prints JSON")
}

/// `../shared/data` from the workspace root, or `None` (with a message) when absent.
pub fn shared_data() -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipping: {} is absent", path.display());
        None
    }
}

/// The numbers of a JSON array.
pub fn numbers(value: &serde_json::Value) -> Vec<f64> {
    value
        .as_array()
        .expect("an array")
        .iter()
        .map(|v| v.as_f64().expect("a number"))
        .collect()
}
