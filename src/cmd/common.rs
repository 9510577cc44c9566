//! Shared pieces of the commands: loading drives and parameters, printing tables.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::{Drive, Params};

pub use crate::args::*;

/// How the commands read drives: the global options `--mapping` and
/// `--skip-checks`, passed to each command explicitly.
#[derive(Debug, Default)]
pub struct Loader {
    /// The `--mapping` file for ROS recordings (`None`: the built-in mapping).
    pub mapping: Option<std::path::PathBuf>,
    /// `--skip-checks`: read drives without the cross-stream plausibility checks.
    pub skip_checks: bool,
    /// `--wheels`: the wheel file to read when a drive directory has both.
    pub wheels: Option<deadreckon_io::WheelFile>,
    /// What the plausibility checks said of the last drive read, for
    /// `"checks"` in `--json`.
    pub checks: std::sync::Mutex<deadreckon_api::checks::Checks>,
}

impl Loader {
    /// Reads a drive from a drive directory or, directly, from a recording that a
    /// reader understands: a comma2k19 segment directory, a ROS1 `.bag`, a ROS2
    /// `.mcap` (with the `--mapping` file or the built-in mapping) or a rosbag2
    /// directory holding one, or a tricycle `dataset.txt`
    /// ([`deadreckon_api::read_drive`]).
    pub fn drive(&self, path: &Path) -> Result<Drive> {
        self.drive_with(path, &deadreckon_io::ReadOptions::default())
    }

    /// [`Loader::drive`] with reading options for drive directories (recordings
    /// are read whole); `--wheels` fills the wheel-file choice they leave open.
    pub fn drive_with(&self, path: &Path, options: &deadreckon_io::ReadOptions) -> Result<Drive> {
        let mut options = options.clone();
        if options.prefer_wheels.is_none() {
            options.prefer_wheels = self.wheels;
        }
        let drive = deadreckon_api::read_drive_with(path, &options, self.mapping.as_deref())?;
        let checks = deadreckon_api::checks::check(path, &drive, self.skip_checks)?;
        for f in &checks.warnings {
            eprintln!("warning: {}: {} ({})", path.display(), f.message, f.check);
        }
        // A poisoned lock holds a whole `Checks` still: take it.
        *self.checks.lock().unwrap_or_else(|p| p.into_inner()) = checks;
        Ok(drive)
    }

    /// The plausibility checks' verdict on the last drive read, and its time
    /// span.
    pub fn checks(&self) -> deadreckon_api::checks::Checks {
        self.checks
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }
}

/// Refuses an output path that is one of the command's inputs (the drive, a
/// params.toml, a model, a configuration): writing it would destroy what it
/// was computed from. `nominal` and other non-paths among `inputs` are
/// skipped by [`deadreckon_io::check_not_an_input`] (they do not exist).
pub fn check_output(out: &Path, inputs: &[&Path]) -> Result<()> {
    for input in inputs {
        deadreckon_io::check_not_an_input(out, input)?;
    }
    Ok(())
}

/// Prints a `--json` object with `"checks"` (what the plausibility checks
/// said of the drive `load` read last) and `"time_span_s"`.
pub fn print_json(load: &Loader, mut v: serde_json::Value) -> Result<()> {
    load.checks().annotate(&mut v);
    outln!("{}", serde_json::to_string_pretty(&v)?);
    Ok(())
}

/// Prints a `--json` object as it is.
pub fn print_pretty(v: &serde_json::Value) -> Result<()> {
    outln!("{}", serde_json::to_string_pretty(v)?);
    Ok(())
}

/// Prints lines of text.
pub fn print_lines(lines: impl IntoIterator<Item = String>) -> Result<()> {
    for l in lines {
        outln!("{l}");
    }
    Ok(())
}

/// `--params nominal` or a `params.toml` path.
pub fn load_params(spec: &str, drive: &Drive) -> Result<Params> {
    if spec == "nominal" {
        return Ok(Params::nominal(&drive.vehicle));
    }
    Ok(read_params_file(spec)?.params)
}

/// `--params nominal` or a `params.toml` path, and the drive with the
/// corrections that file stores applied (its delays, IMU tilt and gyro
/// scale): the parameters were calibrated on the corrected streams, and on
/// the raw ones they are wrong (a tilted, scaled gyro turns the track).
pub fn load_params_corrected(spec: &str, drive: Drive) -> Result<(Params, Drive)> {
    let params = load_params(spec, &drive)?;
    if spec == "nominal" {
        return Ok((params, drive));
    }
    Ok((params, apply_stored(spec, drive)?))
}

/// The drive with the corrections stored in the params.toml `spec` applied
/// (none for `nominal` or a file without them).
pub fn apply_stored(spec: &str, drive: Drive) -> Result<Drive> {
    let stored =
        deadreckon_api::corrections::stored_in_file(Path::new(spec)).map_err(anyhow::Error::msg)?;
    Ok(stored.apply(&drive))
}

/// Reads a params.toml with its standard errors, validated.
pub fn read_params_file(spec: &str) -> Result<deadreckon_core::ParamsWithStd> {
    let p = deadreckon_io::read_params(Path::new(spec))
        .with_context(|| format!("reading parameters {spec}"))?;
    p.params
        .validate()
        .with_context(|| format!("parameters in {spec}"))?;
    Ok(p)
}

/// Ends quietly when the reader of standard output went away (a closed pipe,
/// as `| head` does); any other write error is an error.
pub fn quiet_on_broken_pipe(r: std::io::Result<()>) -> Result<()> {
    match r {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r.context("writing to standard output")?),
    }
}

/// Every track of a drive: the estimated ones
/// ([`deadreckon_core::track::drive_tracks`]) and, with truth, `truth`.
pub fn all_tracks(
    drive: &deadreckon_core::Drive,
    params: &deadreckon_core::Params,
    opts: &deadreckon_core::ekf::FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<Vec<deadreckon_core::Track>> {
    let mut t = deadreckon_core::track::drive_tracks(drive, params, opts, init_pose)?;
    t.extend(deadreckon_core::Track::from_truth(drive));
    Ok(t)
}

/// The footer: version and command line.
pub fn footer() -> deadreckon_report::Footer {
    deadreckon_report::Footer {
        version: env!("CARGO_PKG_VERSION").into(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    }
}

/// Resolves a scenario name or file.
pub fn scenario(spec: &str) -> Result<deadreckon_sim::Scenario> {
    let path = std::path::Path::new(spec);
    if path.extension().is_some_and(|e| e == "toml") || path.is_file() {
        return Ok(deadreckon_sim::Scenario::load(path)?);
    }
    Ok(deadreckon_sim::Scenario::builtin(spec)?)
}

/// Simulates and writes `drive` + `truth_params.toml` into `dir`.
pub fn simulate_to(
    spec: &str,
    seed: u64,
    dir: &std::path::Path,
) -> Result<deadreckon_sim::SimOutput> {
    write_scenario(scenario(spec)?, spec, seed, dir)
}

pub fn write_scenario(
    sc: deadreckon_sim::Scenario,
    spec: &str,
    seed: u64,
    dir: &std::path::Path,
) -> Result<deadreckon_sim::SimOutput> {
    let out = deadreckon_sim::simulate(&sc, seed).with_context(|| format!("simulating {spec}"))?;
    // Written whole: a failure leaves no partial drive.
    deadreckon_io::write_drive_whole(dir, &out.drive, |tmp| {
        deadreckon_io::write_truth_params(&tmp.join("truth_params.toml"), &out.truth_params)
    })
    .with_context(|| format!("writing {}", dir.display()))?;
    Ok(out)
}

/// The wheel-health monitor's settings: the defaults, or none with `--no-wheel-monitor`.
pub fn wheel_monitor(off: bool) -> Option<deadreckon_core::wheel_health::WheelMonitorConfig> {
    (!off).then(Default::default)
}

/// The wheel-health lines of `run` and `calibrate`.
pub fn print_wheel_health(h: &deadreckon_core::wheel_health::WheelHealth) -> Result<()> {
    for l in deadreckon_api::text::wheel_health_lines(h) {
        outln!("{l}");
    }
    Ok(())
}

/// Prints the comparison table of `compare` and `demo`; `t0` is subtracted from the outage times.
pub fn print_comparison(c: &deadreckon_eval::compare::Comparison, t0: f64) -> Result<()> {
    for l in deadreckon_api::text::comparison_lines(c, t0) {
        outln!("{l}");
    }
    Ok(())
}

pub use deadreckon_api::text::{gated_text, params_header, params_row, stats_line};
