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
    // The one rule for "no --params" (deadreckon_api::evaluate::RULE), as
    // `evaluate` applies it, with the outages hidden from the calibration; a
    // params.toml's stored corrections applied to the drive both read.
    let windows: Vec<(f64, f64)> = outages.iter().map(|o| (o.start_s, o.end_s)).collect();
    let (chosen, drive) = deadreckon_api::evaluate::parameters_outages_hidden(
        a.params.as_deref(),
        drive,
        a.corrections.into(),
        load.params_for_other_vehicle,
        &windows,
    )?;
    if let Some(n) = &chosen.note {
        note!("note: {n}");
    }
    let line = match &a.params {
        // `run`'s words (the source) and `evaluate`'s rule.
        None => format!("{} ({})", chosen.source, deadreckon_api::evaluate::RULE),
        Some(_) => deadreckon_api::report_labels::given_line(&chosen.source, chosen.file_corrected),
    };
    let source = chosen.source.clone();
    let corrections = chosen.corrections.clone();
    let params = Some((chosen.params, chosen.label));
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
        if let Some(c) = &corrections {
            v["corrections"] = deadreckon_api::corrections::corrections_json(c);
        }
        v["shape_found"] = found.json();
        common::print_json(load, v)?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        outln!("{}", found.line());
        outln!("parameters: {line}");
        for l in corrections
            .iter()
            .flat_map(deadreckon_api::text::corrections_lines)
        {
            outln!("{l}");
        }
        common::print_comparison(&c, 0.0)?;
    }
    Ok(())
}
