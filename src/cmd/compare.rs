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
    let found = deadreckon_api::shape::detect(&a.dir, Some(&drive), a.shape.map(Into::into));
    if found.shape != deadreckon_core::kinematics::Shape::FourWheel {
        anyhow::bail!(
            "compare runs the four-wheel filter and TedriS, and the drive is a {} ({}): --shape car to compare it as a car",
            deadreckon_api::shape::words(found.shape),
            found.reason
        );
    }
    let outages: Vec<Outage> = a
        .outage
        .iter()
        .map(|s| s.parse::<Outage>())
        .collect::<Result<_, _>>()?;
    // A params.toml's stored corrections apply to the drive both estimators read.
    // The one rule for "no --params" (deadreckon_api::evaluate::RULE), with
    // the outages hidden from the calibration.
    let (params, drive, source) = match &a.params {
        Some(p) => {
            let (params, drive, note) = deadreckon_api::load::params_corrected_bound(
                p,
                drive,
                load.params_for_other_vehicle,
            )?;
            if let Some(n) = note {
                note!("note: {n}");
            }
            (Some((params, p.clone())), drive, p.clone())
        }
        None => (
            None,
            drive,
            format!(
                "{} with the outages hidden (rts)",
                deadreckon_api::evaluate::CALIBRATED_HERE
            ),
        ),
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
        let mut v = deadreckon_api::json::comparison_json(&c);
        v["params_source"] = source.into();
        v["shape_found"] = found.json();
        common::print_json(load, v)?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        outln!("{}", found.line());
        outln!("parameters: {source}");
        common::print_comparison(&c, 0.0)?;
    }
    Ok(())
}
