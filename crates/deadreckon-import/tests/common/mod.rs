//! Shared helpers: where the shared data lives.
#![allow(dead_code)]

use std::path::PathBuf;

/// `shared/data/<rel>` beside the workspace; panics (fails the test) when the
/// data is missing, since CI has it.
pub fn data(rel: &str) -> PathBuf {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/data")
        .join(rel);
    assert!(
        p.exists(),
        "shared data missing: {} (CI has shared/ beside the project)",
        p.display()
    );
    p
}
