//! Shared pieces of the commands: loading drives and parameters, printing tables.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::calibrate::Calibration;
use deadreckon_core::ekf::Timing;
use deadreckon_core::{Drive, Params, ParamsWithStd};

/// Reads a drive from a drive directory or, directly, from a recording that a
/// reader understands: a comma2k19 segment directory, a ROS1 `.bag`, a ROS2
/// `.mcap` (with the built-in mapping) or a rosbag2 directory holding one, or a
/// tricycle `dataset.txt`.
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
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if path.is_dir() && !path.join("vehicle.toml").exists() && path.join("processed_log").is_dir() {
        return deadreckon_import::read_comma2k19(path, None)
            .with_context(|| format!("reading comma2k19 segment {}", path.display()));
    }
    if path.is_dir() && path.join("metadata.yaml").is_file() {
        return super::load_ros(path);
    }
    if path.is_file() {
        match ext {
            "bag" | "mcap" => return super::load_ros(path),
            "txt" => {
                let o = deadreckon_import::tricycle::TricycleOptions::default();
                return Ok(deadreckon_import::tricycle::read_tricycle(path, &o)
                    .with_context(|| format!("reading tricycle log {}", path.display()))?
                    .drive);
            }
            _ => anyhow::bail!("{}: not a drive directory and not a recording this tool reads (.bag, .mcap, comma2k19 segment, tricycle .txt)", path.display()),
        }
    }
    deadreckon_io::read_drive_with(path, options)
        .with_context(|| format!("reading drive {}", path.display()))
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
    match s {
        "wheel" => Ok(Timing::WheelEpochs),
        "each" => Ok(Timing::EachMeasurement),
        _ => anyhow::bail!("unknown timing `{s}` (wheel, each)"),
    }
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

/// The `calibrate --json` object: the six parameters, `std`, `iterations`, and more.
pub fn calibration_json(method: &str, c: &Calibration) -> serde_json::Value {
    let mut m = serde_json::Map::new();
    let a = c.estimate.params.to_array();
    let s = c.estimate.std.to_array();
    let mut std = serde_json::Map::new();
    for (i, name) in Params::NAMES.iter().enumerate() {
        m.insert((*name).into(), a[i].into());
        std.insert((*name).into(), s[i].into());
    }
    m.insert("std".into(), std.into());
    m.insert("iterations".into(), c.iterations.into());
    m.insert("converged".into(), c.converged.into());
    m.insert("method".into(), method.into());
    m.insert("samples".into(), serde_json::json!(c.samples));
    m.insert(
        "history".into(),
        c.history
            .iter()
            .map(|p| serde_json::json!(p.to_array()))
            .collect::<Vec<_>>()
            .into(),
    );
    if let Some(st) = &c.filter_stats {
        m.insert(
            "gnss".into(),
            serde_json::json!({"used": st.gnss_updates, "rejected": st.gnss_rejected, "recoveries": st.gnss_recoveries, "hidden": st.gnss_hidden}),
        );
        m.insert("wheel_gaps".into(), st.wheel_gaps.into());
        m.insert("gates".into(), gates_json(&st.gates));
    }
    serde_json::Value::Object(m)
}

/// The per-sensor χ² gate counters as JSON: `{sensor: {accepted, rejected, recovered}}`.
pub fn gates_json(g: &deadreckon_core::filter::GateCounts) -> serde_json::Value {
    g.rows()
        .into_iter()
        .map(|(name, a, r, rec)| {
            (
                name.to_string(),
                serde_json::json!({"accepted": a, "rejected": r, "recovered": rec}),
            )
        })
        .collect::<serde_json::Map<_, _>>()
        .into()
}

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
