//! What the command-line tests share: running the binary.
#![allow(dead_code)] // each test file uses some of these

use std::io::Write;
use std::process::{Command, Stdio};

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

/// What one run of `deadreckon` did: whether it succeeded, its standard
/// output and its standard error.
#[derive(Debug)]
pub struct Ran {
    /// The exit status was success.
    pub ok: bool,
    /// Standard output.
    pub stdout: String,
    /// Standard error.
    pub stderr: String,
}

/// Runs `deadreckon` with `args` and `stdin` (empty if `None`), whatever its
/// exit status.
pub fn run(args: &[&str], stdin: Option<&[u8]>) -> Ran {
    let mut child = Command::new(env!("CARGO_BIN_EXE_deadreckon"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("deadreckon runs");
    let mut input = child.stdin.take().expect("stdin piped");
    let data = stdin.unwrap_or_default().to_vec();
    let writer = std::thread::spawn(move || {
        // A command that stops reading early closes the pipe: not an error here.
        let _ = input.write_all(&data);
    });
    let out = child.wait_with_output().expect("deadreckon ends");
    writer.join().expect("stdin writer");
    Ran {
        ok: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// Runs `deadreckon` with `args`; panics unless it fails; returns its
/// standard error.
pub fn run_err(args: &[&str]) -> String {
    let r = run(args, None);
    assert!(!r.ok, "deadreckon {args:?} succeeded:\n{}", r.stdout);
    r.stderr
}

/// Simulates `duration_s` of the built-in calibration scenario (its default
/// seed) into `dir/name`; returns the drive's path.
pub fn simulated(dir: &std::path::Path, name: &str, duration_s: &str) -> String {
    let out = dir.join(name).to_str().unwrap().to_string();
    run_ok(&[
        "simulate",
        "--scenario",
        "calibration",
        "--duration",
        duration_s,
        "--out",
        &out,
    ]);
    out
}
