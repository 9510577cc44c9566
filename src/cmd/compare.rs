//! `deadreckon compare`: TedriS and the calibrated four-wheel EKF through the
//! same GNSS outages, in one table. Neither method sees GNSS inside the
//! outages, not even for calibration or training.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::{outage, Drive, Params};
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
pub struct Row {
    /// Mean horizontal error, m.
    pub mean: f64,
    /// Largest error, m.
    pub max: f64,
    /// Error at the end, m.
    pub fin: f64,
    /// Time until the error first reaches 1 m, s.
    pub to_1m: Option<f64>,
}

/// The comparison through a set of outages.
pub struct Comparison {
    /// Where the four-wheel parameters came from.
    pub params_source: String,
    /// Where the TedriS model came from.
    pub model_source: String,
    /// The four-wheel reference ("truth" or "gnss").
    pub four_wheel_reference: String,
    /// The TedriS reference.
    pub tedris_reference: String,
    /// Per outage: the window, the four-wheel row, the TedriS row.
    pub rows: Vec<(Outage, Option<Row>, Option<Row>)>,
    /// The TedriS model used.
    pub model: TedrisModel,
    /// The four-wheel filter's χ² gate counters over the run.
    pub four_wheel_gates: deadreckon_core::filter::GateCounts,
    /// TedriS's checks over the run: (headings refused as inconsistent with
    /// the wheels, calibrations refused, heading segments, watchdog alarms).
    pub tedris_checks: (u64, u64, u32, u64),
}

/// The drive without GNSS inside the windows.
pub fn hide(drive: &Drive, windows: &[(f64, f64)]) -> Drive {
    let mut d = drive.clone();
    d.gnss
        .retain(|g| !windows.iter().any(|&(a, b)| g.t_s >= a && g.t_s < b));
    d
}

/// Runs both methods through `outages`. Without `params`, the four-wheel
/// parameters are calibrated (RTS) on the drive with the outages hidden; without
/// `model`, TedriS is trained on the drive with the outages hidden.
pub fn compare(
    drive: &Drive,
    outages: &[Outage],
    params: Option<(Params, String)>,
    model: Option<(TedrisModel, String)>,
) -> Result<Comparison> {
    let windows: Vec<(f64, f64)> = outages.iter().map(|o| (o.start_s, o.end_s)).collect();
    let hidden = hide(drive, &windows);
    let (params, params_source) = match params {
        Some(p) => p,
        None => {
            let c = calibrate::calibrate(&hidden, &CalibrationOptions::default())
                .context("RTS calibration with the outages hidden")?;
            (
                c.estimate.params,
                format!("RTS on the drive, outages hidden ({} passes)", c.iterations),
            )
        }
    };
    let fw = outage::through_windows(drive, &params, &windows, &FilterOptions::default())?;
    let (model, model_source) = match model {
        Some(m) => m,
        None => {
            let (m, _) = deadreckon_tedris::train(&hidden, TedrisConfig::default(), None)
                .context("TedriS training with the outages hidden")?;
            (m, "TedriS trained on the drive, outages hidden".into())
        }
    };
    let td = deadreckon_tedris::run_outages(drive, &model, outages)?;
    let mut rows = Vec::new();
    for o in outages {
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
        rows.push((*o, f, t));
    }
    Ok(Comparison {
        params_source,
        model_source,
        four_wheel_reference: fw.reference.name().into(),
        tedris_reference: td.reference.clone(),
        rows,
        model,
        four_wheel_gates: fw.gates,
        tedris_checks: (
            td.machine.inconsistent_headings(),
            td.machine.refused_calibrations(),
            td.machine.segments(),
            td.machine.model_alarms(),
        ),
    })
}

/// The comparison as JSON.
pub fn to_json(c: &Comparison) -> serde_json::Value {
    let row_json = |r: &Option<Row>| match r {
        Some(r) => {
            json!({"mean_error_m": r.mean, "max_error_m": r.max, "final_error_m": r.fin, "time_to_1m_s": r.to_1m})
        }
        None => serde_json::Value::Null,
    };
    json!({
        "reference": {"four_wheel": c.four_wheel_reference, "tedris": c.tedris_reference},
        "four_wheel_params": c.params_source,
        "tedris_model": c.model_source,
        "four_wheel_gates": super::common::gates_json(&c.four_wheel_gates),
        "tedris_checks": {
            "inconsistent_headings": c.tedris_checks.0,
            "refused_calibrations": c.tedris_checks.1,
            "heading_segments": c.tedris_checks.2,
            "model_alarms": c.tedris_checks.3,
        },
        "outages": c.rows.iter().map(|(o, f, t)| json!({
            "start_s": o.start_s, "end_s": o.end_s,
            "four_wheel": row_json(f), "tedris": row_json(t),
        })).collect::<Vec<_>>(),
    })
}

/// Prints the comparison table; `t0` is subtracted from the outage times.
pub fn print(c: &Comparison, t0: f64) -> anyhow::Result<()> {
    outln!(
        "four-wheel EKF: {}; errors against the {}",
        c.params_source,
        c.four_wheel_reference
    );
    outln!(
        "TedriS: {}; errors against the {}",
        c.model_source,
        c.tedris_reference
    );
    outln!(
        "{:<20} {:<12} {:>10} {:>10} {:>10} {:>16}",
        "outage (s)",
        "method",
        "mean (m)",
        "max (m)",
        "final (m)",
        "time to 1 m (s)"
    );
    let fmt = |r: &Option<Row>| match r {
        Some(r) => format!(
            "{:>10.2} {:>10.2} {:>10.2} {:>16}",
            r.mean,
            r.max,
            r.fin,
            r.to_1m
                .map(|t| format!("{t:.1}"))
                .unwrap_or_else(|| "never".into())
        ),
        None => format!("{:>10} {:>10} {:>10} {:>16}", "-", "-", "-", "-"),
    };
    for (o, f, t) in &c.rows {
        let w = format!("{:.1}:{:.1}", o.start_s - t0, o.end_s - t0);
        outln!("{:<20} {:<12} {}", w, "four-wheel", fmt(f));
        outln!("{:<20} {:<12} {}", "", "TedriS", fmt(t));
    }
    Ok(())
}

/// Runs `compare`.
pub fn run(a: CompareArgs, load: &common::Loader) -> Result<()> {
    let drive = load.drive(&a.dir)?;
    let outages: Vec<Outage> = a
        .outage
        .iter()
        .map(|s| s.parse::<Outage>())
        .collect::<Result<_, _>>()?;
    let params = match &a.params {
        Some(p) => Some((common::load_params(p, &drive)?, p.clone())),
        None => None,
    };
    let model = match &a.model {
        Some(m) => {
            let text =
                std::fs::read_to_string(m).with_context(|| format!("reading {}", m.display()))?;
            Some((
                serde_json::from_str::<TedrisModel>(&text)
                    .with_context(|| format!("parsing {}", m.display()))?,
                m.display().to_string(),
            ))
        }
        None => None,
    };
    let c = compare(&drive, &outages, params, model)?;
    if a.json {
        outln!("{}", serde_json::to_string_pretty(&to_json(&c))?);
    } else {
        print(&c, 0.0)?;
    }
    Ok(())
}
