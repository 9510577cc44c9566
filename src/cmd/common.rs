//! Shared pieces of the commands: loading drives and parameters, printing tables.

use std::path::Path;

use anyhow::{Context, Result};

pub use crate::args::*;
pub use deadreckon_api::load::Loader;

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
    super::write_data_line(format_args!("{}", serde_json::to_string_pretty(&v)?))?;
    Ok(())
}

/// Prints a `--json` object as it is.
pub fn print_pretty(v: &serde_json::Value) -> Result<()> {
    super::write_data_line(format_args!("{}", serde_json::to_string_pretty(v)?))?;
    Ok(())
}

/// Prints lines of text.
pub fn print_lines(lines: impl IntoIterator<Item = String>) -> Result<()> {
    for l in lines {
        outln!("{l}");
    }
    Ok(())
}

/// Ends quietly when the reader of standard output went away (a closed pipe,
/// as `| head` does); any other write error is an error.
pub fn quiet_on_broken_pipe(r: std::io::Result<()>) -> Result<()> {
    match r {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => Ok(r.context("writing to standard output")?),
    }
}

/// The footer: version and command line.
pub fn footer() -> deadreckon_report::Footer {
    deadreckon_report::Footer {
        version: env!("CARGO_PKG_VERSION").into(),
        command_line: std::env::args().collect::<Vec<_>>().join(" "),
    }
}

/// The wheel-health monitor's settings: the defaults, or none with `--no-wheel-monitor`.
pub fn wheel_monitor(off: bool) -> Option<deadreckon_core::wheel_health::WheelMonitorConfig> {
    (!off).then(Default::default)
}

/// Prints the comparison table of `compare` and `demo`; `t0` is subtracted from the outage times.
pub fn print_comparison(c: &deadreckon_eval::compare::Comparison, t0: f64) -> Result<()> {
    for l in deadreckon_api::text::comparison_lines(c, t0) {
        outln!("{l}");
    }
    Ok(())
}
