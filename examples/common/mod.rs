//! What the examples share besides `retract::plot` (the figures): where they write them.

use std::path::{Path, PathBuf};

/// The path of a figure under the repository's `docs/`: the first `docs/` directory at or
/// above the crate of the example (the root's, also for `validation/examples`).
pub fn docs_path(name: &str) -> PathBuf {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    manifest
        .ancestors()
        .find(|dir| dir.join("docs").is_dir())
        .unwrap_or(manifest)
        .join("docs")
        .join(name)
}
