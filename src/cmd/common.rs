//! Shared pieces of the commands: loading drives and parameters, printing tables.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::calibrate::Calibration;
use deadreckon_core::ekf::Timing;
use deadreckon_core::{Drive, Params, ParamsWithStd};

/// Reads a drive directory.
pub fn load_drive(dir: &Path) -> Result<Drive> {
    deadreckon_io::read_drive(dir).with_context(|| format!("reading drive {}", dir.display()))
}

/// `--params nominal` or a `params.toml` path.
pub fn load_params(spec: &str, drive: &Drive) -> Result<Params> {
    if spec == "nominal" {
        return Ok(Params::nominal(&drive.vehicle));
    }
    let p = deadreckon_io::read_params(Path::new(spec))
        .with_context(|| format!("reading parameters {spec}"))?;
    p.params
        .validate()
        .with_context(|| format!("parameters in {spec}"))?;
    Ok(p.params)
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
            serde_json::json!({"used": st.gnss_updates, "rejected": st.gnss_rejected, "hidden": st.gnss_hidden}),
        );
        m.insert("wheel_gaps".into(), st.wheel_gaps.into());
    }
    serde_json::Value::Object(m)
}

/// A one-line account of what the filter used and gated.
pub fn stats_line(st: &deadreckon_core::ekf::FilterStats) -> String {
    format!(
        "filter: {} epochs, GNSS {} used / {} rejected by the gate / {} hidden, {} wheel gaps skipped",
        st.epochs, st.gnss_updates, st.gnss_rejected, st.gnss_hidden, st.wheel_gaps
    )
}
