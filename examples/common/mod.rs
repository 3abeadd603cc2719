//! What the examples share besides `retract::plot` (the figures): where they write them.

use std::path::{Path, PathBuf};

/// The path of a figure under the repository's `docs/`.
pub fn docs_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("docs")
        .join(name)
}
