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

/// The `deadreckon` binary as a command, for tests that set it up further
/// (standard input, environment, signals).
pub fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_deadreckon"))
}

/// Parses a command's JSON output; panics showing the text otherwise.
pub fn json(s: &str) -> serde_json::Value {
    serde_json::from_str(s).unwrap_or_else(|e| panic!("not JSON ({e}):\n{s}"))
}

/// A real log under `../shared/data` (read only; never copied into the
/// repository), e.g. `data("comma2k19-rav4")`.
pub fn data(rel: &str) -> String {
    format!("{}/../shared/data/{rel}", env!("CARGO_MANIFEST_DIR"))
}

/// Simulates the built-in `scenario` with `seed` into `dir` through the
/// binary.
pub fn simulate_into(dir: &std::path::Path, scenario: &str, seed: &str) {
    run_ok(&[
        "simulate",
        "--scenario",
        scenario,
        "--seed",
        seed,
        "--out",
        dir.to_str().unwrap(),
    ]);
}

/// The built-in evaluation scenario's TOML with its receiver 0.1 s late
/// (as `tests/golden/scenario.toml`'s): a drive on which the default
/// corrections apply the GNSS delay.
pub fn evaluation_with_late_receiver() -> String {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("crates/deadreckon-sim/scenarios/evaluation.toml");
    let text = std::fs::read_to_string(path).unwrap();
    let gnss = "[sensors.gnss]\n";
    assert!(text.contains(gnss) && !text.contains("latency_s"));
    text.replace(gnss, &format!("{gnss}latency_s = 0.1\n"))
}

/// The built-in `scenario` simulated in-process with `seed` (the drive and
/// its true parameters).
pub fn sim(scenario: &str, seed: u64) -> deadreckon_sim::SimOutput {
    deadreckon_sim::simulate(&deadreckon_sim::Scenario::builtin(scenario).unwrap(), seed).unwrap()
}

/// The built-in `scenario` simulated in-process with `seed`, cut to
/// `duration_s` when given.
pub fn sim_drive(scenario: &str, seed: u64, duration_s: Option<f64>) -> deadreckon_core::Drive {
    let mut sc = deadreckon_sim::Scenario::builtin(scenario).unwrap();
    if let Some(d) = duration_s {
        sc = sc.with_duration_s(d);
    }
    deadreckon_sim::simulate(&sc, seed).unwrap().drive
}

/// The comma2k19 segment (`../shared/data/comma2k19-rav4`).
pub const COMMA2K19: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/comma2k19-rav4");
/// The Husky's ROS bag with GNSS.
pub const HUSKY_BAG: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../shared/data/husky-gps-bag/husky_gps.bag"
);
/// The tricycle's log with its tracker.
pub const TRICYCLE_LOG: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../shared/data/tricycle-tracker/dataset.txt"
);

/// A path inside the repository (`tests/golden`).
pub fn repo_path(rel: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}
