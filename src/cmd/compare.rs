//! `deadreckon compare`: TedriS and the calibrated four-wheel EKF through the
//! same GNSS outages, in one table. Neither method sees GNSS inside the
//! outages, not even for calibration or training.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::{outage, Drive};
use deadreckon_tedris::{Outage, TedrisConfig, TedrisModel};
use serde_json::json;

use super::common;

/// Arguments of `compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The drive directory (or a recording read directly).
    pub dir: PathBuf,
    /// A GNSS outage `START_S:END_S` on the drive clock (repeatable).
    #[arg(long, required = true)]
    pub outage: Vec<String>,
    /// Four-wheel parameters (params.toml); default: RTS calibration on the drive with the outages hidden.
    #[arg(long)]
    pub params: Option<String>,
    /// TedriS model (model.json); default: trained on the drive with the outages hidden.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// One method's errors through one outage.
struct Row {
    mean: f64,
    max: f64,
    fin: f64,
    to_1m: Option<f64>,
}

/// The drive without GNSS inside the windows.
fn hide(drive: &Drive, windows: &[(f64, f64)]) -> Drive {
    let mut d = drive.clone();
    d.gnss
        .retain(|g| !windows.iter().any(|&(a, b)| g.t_s >= a && g.t_s < b));
    d
}

/// Runs `compare`.
pub fn run(a: CompareArgs) -> Result<()> {
    let drive = common::load_drive(&a.dir)?;
    let outages: Vec<Outage> = a
        .outage
        .iter()
        .map(|s| s.parse::<Outage>())
        .collect::<Result<_, _>>()?;
    let windows: Vec<(f64, f64)> = outages.iter().map(|o| (o.start_s, o.end_s)).collect();
    let hidden = hide(&drive, &windows);

    let (params, params_source) = match &a.params {
        Some(p) => (common::load_params(p, &drive)?, p.clone()),
        None => {
            let c = calibrate::calibrate(&hidden, &CalibrationOptions::default())
                .context("RTS calibration with the outages hidden")?;
            (
                c.estimate.params,
                format!("RTS on the drive, outages hidden ({} passes)", c.iterations),
            )
        }
    };
    let fw = outage::through_windows(&drive, &params, &windows, &FilterOptions::default())?;

    let (model, model_source) = match &a.model {
        Some(m) => {
            let text =
                std::fs::read_to_string(m).with_context(|| format!("reading {}", m.display()))?;
            (
                serde_json::from_str::<TedrisModel>(&text)
                    .with_context(|| format!("parsing {}", m.display()))?,
                m.display().to_string(),
            )
        }
        None => {
            let (m, _) = deadreckon_tedris::train(&hidden, TedrisConfig::default(), None)
                .context("TedriS training with the outages hidden")?;
            (m, "TedriS trained on the drive, outages hidden".into())
        }
    };
    let td = deadreckon_tedris::run_outages(&drive, &model, &outages)?;

    let mut rows = Vec::new();
    for o in &outages {
        let f = fw
            .windows
            .iter()
            .find(|w| w.start_s == o.start_s)
            .map(|w| Row {
                mean: w.errors.iter().map(|e| e.1).sum::<f64>() / w.errors.len().max(1) as f64,
                max: w.max_error_m,
                fin: w.final_error_m,
                to_1m: w.errors.iter().find(|e| e.1 >= 1.0).map(|e| e.0),
            });
        let t = td
            .outages
            .iter()
            .find(|e| e.start_s == o.start_s)
            .map(|e| Row {
                mean: e.mean_error_m,
                max: e.max_error_m,
                fin: e.final_error_m,
                to_1m: e.time_to_1m_s,
            });
        rows.push((o, f, t));
    }
    let row_json = |r: &Option<Row>| match r {
        Some(r) => {
            json!({"mean_error_m": r.mean, "max_error_m": r.max, "final_error_m": r.fin, "time_to_1m_s": r.to_1m})
        }
        None => serde_json::Value::Null,
    };
    if a.json {
        let v = json!({
            "reference": {"four_wheel": fw.reference.name(), "tedris": td.reference},
            "four_wheel_params": params_source,
            "tedris_model": model_source,
            "outages": rows.iter().map(|(o, f, t)| json!({
                "start_s": o.start_s, "end_s": o.end_s,
                "four_wheel": row_json(f), "tedris": row_json(t),
            })).collect::<Vec<_>>(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    println!(
        "four-wheel EKF: {params_source}; errors against the {}",
        fw.reference.name()
    );
    println!(
        "TedriS: {model_source}; errors against the {}",
        td.reference
    );
    println!(
        "{:<20} {:<12} {:>10} {:>10} {:>10} {:>14}",
        "outage (s)", "method", "mean (m)", "max (m)", "final (m)", "time to 1 m (s)"
    );
    let fmt = |r: &Option<Row>| match r {
        Some(r) => format!(
            "{:>10.2} {:>10.2} {:>10.2} {:>14}",
            r.mean,
            r.max,
            r.fin,
            r.to_1m
                .map(|t| format!("{t:.1}"))
                .unwrap_or_else(|| "never".into())
        ),
        None => format!("{:>10} {:>10} {:>10} {:>14}", "-", "-", "-", "-"),
    };
    for (o, f, t) in &rows {
        let w = format!("{:.1}:{:.1}", o.start_s, o.end_s);
        println!("{:<20} {:<12} {}", w, "four-wheel", fmt(f));
        println!("{:<20} {:<12} {}", "", "TedriS", fmt(t));
    }
    Ok(())
}
