//! For endocast's tests only: the real scans in `../shared/data` (beside the repository), and
//! the one rule for a test that needs them and does not find them. Under CI (the environment
//! variable `CI` is `true`) a missing scan fails the test; elsewhere the test is skipped with a
//! line on the terminal, written past the test harness's capture so that a run which checked
//! nothing says so.

pub mod overlays;

use std::io::Write;
use std::path::PathBuf;

/// `../shared/data/NAME` from the workspace root (`""`: the folder itself) when it exists.
/// When it does not: under CI, a panic naming it; elsewhere `None`, after a visible
/// "SKIPPED" line naming it.
///
/// # Panics
///
/// When the path is missing and `CI=true`.
pub fn shared_data(name: &str) -> Option<PathBuf> {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(name);
    if path.exists() {
        return Some(path);
    }
    assert!(
        !under_ci(),
        "{} is missing: under CI (CI=true) the real-scan tests need ../shared/data beside the \
         repository",
        path.display()
    );
    // Straight to the terminal: libtest captures eprintln! of passing tests.
    let _ = writeln!(
        std::io::stderr(),
        "SKIPPED (checked nothing): {} is absent",
        path.display()
    );
    None
}

/// Whether the tests run under CI (`CI=true`).
pub fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| v.eq_ignore_ascii_case("true"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_scan_is_skipped_or_fails_under_ci() {
        let outcome = std::panic::catch_unwind(|| shared_data("no-such-scan-here"));
        match outcome {
            Ok(found) => {
                assert!(!under_ci());
                assert_eq!(found, None);
            }
            Err(_) => assert!(under_ci()),
        }
    }
}
