//! Helpers shared by the integration tests.

use std::path::PathBuf;

/// `../shared/data/NAME` from the workspace root, or `None` (with a message) when absent.
pub fn shared_data(name: &str) -> Option<PathBuf> {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data");
    let path = root.join(name);
    if path.exists() {
        Some(path)
    } else {
        eprintln!("skipping: {} is absent", path.display());
        None
    }
}
