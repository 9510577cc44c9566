//! Shared pieces of the commands: loading drives and parameters, printing tables.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::ekf::Timing;
use deadreckon_core::{Drive, Params, ParamsWithStd};

/// Reads a drive from a drive directory or, directly, from a recording that a
/// reader understands: a comma2k19 segment directory, a ROS1 `.bag`, a ROS2
/// `.mcap` (with the `--mapping` file or the built-in mapping) or a rosbag2
/// directory holding one, or a tricycle `dataset.txt`
/// ([`deadreckon_api::read_drive`]).
pub fn load_drive(path: &Path) -> Result<Drive> {
    load_drive_with(path, &deadreckon_io::ReadOptions::default())
}

/// [`load_drive`] with reading options for drive directories (recordings are
/// read whole).
pub fn load_drive_with(path: &Path, options: &deadreckon_io::ReadOptions) -> Result<Drive> {
    let drive = read_drive_any(path, options)?;
    if !super::SKIP_CHECKS.get().copied().unwrap_or(false) {
        plausible(path, &drive)?;
    }
    Ok(drive)
}

/// The cross-stream plausibility checks: warnings on standard error, errors
/// refuse the drive (all of them listed).
pub fn plausible(path: &Path, drive: &Drive) -> Result<()> {
    use deadreckon_core::plausibility::{check, Severity};
    let findings = check(drive);
    let mut errors = Vec::new();
    for f in findings {
        match f.severity {
            Severity::Warning => {
                eprintln!("warning: {}: {} ({})", path.display(), f.message, f.check)
            }
            Severity::Error => errors.push(format!("  {} ({})", f.message, f.check)),
        }
    }
    anyhow::ensure!(
        errors.is_empty(),
        "{}: the streams disagree (a mistake of units, clocks or signs?):\n{}\n\
         (--skip-checks reads the drive anyway)",
        path.display(),
        errors.join("\n")
    );
    Ok(())
}

fn read_drive_any(path: &Path, options: &deadreckon_io::ReadOptions) -> Result<Drive> {
    let mapping = super::ROS_MAPPING.get().map(|m| m.as_path());
    Ok(deadreckon_api::read_drive_with(path, options, mapping)?)
}

/// `--params nominal` or a `params.toml` path.
pub fn load_params(spec: &str, drive: &Drive) -> Result<Params> {
    if spec == "nominal" {
        return Ok(Params::nominal(&drive.vehicle));
    }
    Ok(read_params_file(spec)?.params)
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

/// Parses `--timing`.
pub fn parse_timing(s: &str) -> Result<Timing> {
    Ok(deadreckon_api::options::parse_timing(s)?)
}

/// The header of a table-III-like parameter table.
pub fn params_header() -> String {
    format!(
        "{:<8} {:>22} {:>18} {:>20} {:>20} {:>20} {:>20}",
        "method", "b_gyro (rad/s)", "a_v", "rho_FL (m)", "rho_FR (m)", "rho_RL (m)", "rho_RR (m)"
    )
}

/// One row of a parameter table, with standard errors where they are non-zero.
pub fn params_row(name: &str, p: &ParamsWithStd) -> String {
    let a = p.params.to_array();
    let s = p.std.to_array();
    let cell = |v: f64, e: f64, prec: usize| -> String {
        if e > 0.0 {
            format!("{v:.prec$} ± {e:.prec$}")
        } else {
            format!("{v:.prec$}")
        }
    };
    format!(
        "{:<8} {:>22} {:>18} {:>20} {:>20} {:>20} {:>20}",
        name,
        cell(a[0], s[0], 6),
        cell(a[1], s[1], 5),
        cell(a[2], s[2], 5),
        cell(a[3], s[3], 5),
        cell(a[4], s[4], 5),
        cell(a[5], s[5], 5)
    )
}

pub use deadreckon_api::json::gates_json;

/// A one-line account of what the filter used and gated.
pub fn stats_line(st: &deadreckon_core::ekf::FilterStats) -> String {
    format!(
        "filter: {} epochs, GNSS {} used / {} rejected by the gate ({} recoveries) / {} hidden, {} wheel gaps skipped; rejected by the χ² gates: {}",
        st.epochs,
        st.gnss_updates,
        st.gnss_rejected,
        st.gnss_recoveries,
        st.gnss_hidden,
        st.wheel_gaps,
        gated_text(&st.gates)
    )
}

/// The sensors the χ² gates rejected something of, as `name rejected/total`,
/// or `none`.
pub fn gated_text(g: &deadreckon_core::filter::GateCounts) -> String {
    let gated: Vec<String> = g
        .rows()
        .into_iter()
        .filter(|r| r.2 > 0)
        .map(|(name, a, r, _)| format!("{name} {r}/{}", a + r))
        .collect();
    if gated.is_empty() {
        "none".to_string()
    } else {
        gated.join(", ")
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

/// The wheel-health monitor's settings: the defaults, or none with `--no-wheel-monitor`.
pub fn wheel_monitor(off: bool) -> Option<deadreckon_core::wheel_health::WheelMonitorConfig> {
    (!off).then(Default::default)
}

/// The wheel-health lines of `run` and `calibrate`.
pub fn print_wheel_health(h: &deadreckon_core::wheel_health::WheelHealth) -> Result<()> {
    if h.all_good() {
        outln!("wheel health: no wheel slipped or read wrong");
    }
    for l in h.lines() {
        outln!("{l}");
    }
    for (name, w) in deadreckon_core::wheel_health::WHEEL_NAMES
        .iter()
        .zip(&h.wheels)
    {
        for i in &w.intervals {
            outln!(
                "  wheel {name} out {:.2}..{:.2} s ({}, peak |T| {:.1})",
                i.start_s,
                i.end_s,
                i.reason.name(),
                i.peak_sigma
            );
        }
    }
    Ok(())
}
