//! Shared by the integration tests: the real measurements beside the repository.

use std::path::{Path, PathBuf};

/// `../shared/data/real/<path>`, or None (with a message) when the folder is absent.
pub fn real(path: &str) -> Option<PathBuf> {
    let p = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/real"
    ))
    .join(path);
    if p.exists() {
        Some(p)
    } else {
        eprintln!("skipped: {} is absent", p.display());
        None
    }
}
