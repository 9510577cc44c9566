//! `deadreckon compare`: TedriS and the calibrated four-wheel EKF through the
//! same GNSS outages, in one table. Neither method sees GNSS inside the
//! outages, not even for calibration or training.

use anyhow::Result;
use deadreckon_eval::compare::compare;
use deadreckon_tedris::Outage;

use super::common;

use crate::args::compare::*;

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
            let (params, drive) = deadreckon_api::load::params_corrected(p, drive)?;
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
