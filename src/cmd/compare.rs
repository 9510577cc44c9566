//! `deadreckon compare`: TedriS and the calibrated four-wheel EKF through the
//! same GNSS outages, in one table. Neither method sees GNSS inside the
//! outages, not even for calibration or training.

use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use deadreckon_eval::compare::compare;
use deadreckon_tedris::Outage;

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

/// Runs `compare`.
pub fn run(a: CompareArgs, load: &common::Loader) -> Result<()> {
    let drive = load.drive(&a.dir)?;
    let outages: Vec<Outage> = a
        .outage
        .iter()
        .map(|s| s.parse::<Outage>())
        .collect::<Result<_, _>>()?;
    // A params.toml's stored corrections apply to the drive both estimators read.
    let (params, drive) = match &a.params {
        Some(p) => {
            let (params, drive) = common::load_params_corrected(p, drive)?;
            (Some((params, p.clone())), drive)
        }
        None => (None, drive),
    };
    let model = match &a.model {
        Some(m) => Some((
            deadreckon_api::tedris::read_model(m)?,
            m.display().to_string(),
        )),
        None => None,
    };
    let c = compare(&drive, &outages, params, model)?;
    if a.json {
        common::print_json(load, deadreckon_api::json::comparison_json(&c))?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        common::print_comparison(&c, 0.0)?;
    }
    Ok(())
}
