//! What the command-line tests share: running the binary.

use std::process::Command;

/// Runs `deadreckon` with `args`; panics with its standard error unless it
/// succeeds; returns its standard output.
pub fn run_ok(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_deadreckon"))
        .args(args)
        .output()
        .expect("deadreckon runs");
    assert!(
        out.status.success(),
        "deadreckon {args:?} failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).expect("utf-8 output")
}
