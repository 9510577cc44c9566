//! `deadreckon report`: one self-contained HTML page with the papers' tables and
//! figures for a drive. This module turns estimator results into the report's
//! plain data model (`deadreckon_report::ReportInput`) through
//! `deadreckon_eval::report`, and writes the page.

use anyhow::{Context, Result};
use deadreckon_core::{Drive, Params, ParamsWithStd};
use deadreckon_eval::report::{
    calibrations, four_wheel_input, header, tedris_from_model, NamedParams,
};
use deadreckon_report as rp;

use super::{common, progress::Steps};

use crate::args::report::*;

/// Runs `report`.
pub fn run(a: ReportArgs, quiet: bool, load: &common::Loader) -> Result<()> {
    let params = a.params.as_deref().map(std::path::Path::new);
    let inputs: Vec<&std::path::Path> = [Some(a.dir.as_path()), params, a.model.as_deref()]
        .into_iter()
        .flatten()
        .collect();
    common::check_output(&a.out, &inputs)?;
    let steps = Steps::new(8, quiet);
    steps.step("reading the drive");
    let drive = load.drive(&a.dir)?;
    let mut methods = calibrations(&drive, &steps);
    if let Some(p) = &a.params {
        let params = common::load_params(p, &drive)?;
        methods.sets.push(NamedParams {
            name: "given".into(),
            source: deadreckon_eval::report::Source::Given,
            params: ParamsWithStd {
                params,
                std: Params::from_array([0.0; 6]),
            },
            calibration: None,
        });
    }
    let mut input = four_wheel_input(&drive, &methods, a.outage, &steps)?;
    if let Some(m) = &a.model {
        steps.step("TedriS");
        input.tedris = Some(tedris_section(&drive, m, a.outage)?);
    }
    let name = a
        .dir
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| a.dir.display().to_string());
    input.header = header(
        &drive,
        &name,
        vec![("drive".into(), a.dir.display().to_string())],
    );
    input.footer = common::footer();
    deadreckon_report::write_report(&a.out, &input)
        .with_context(|| format!("writing {}", a.out.display()))?;
    steps.finish();
    outln!("wrote {}", a.out.display());
    Ok(())
}

/// The TedriS sections for a drive and a trained model: the cross-correlation,
/// the regression tables of every model kind, the repositories, the training
/// heading against the reference, and the errors through outages of
/// `outage_s` (default 80 s) at a quarter, half and three quarters of the
/// drive, as `compare --model` gives them for those windows.
pub fn tedris_section(
    drive: &Drive,
    model_path: &std::path::Path,
    outage_s: Option<f64>,
) -> Result<rp::Tedris> {
    let m = deadreckon_api::tedris::read_model(model_path)?;
    let windows = deadreckon_eval::compare::default_windows(drive, outage_s.unwrap_or(80.0))?;
    let c = deadreckon_eval::compare::compare(
        drive,
        &windows,
        None,
        Some((m, model_path.display().to_string())),
    )?;
    Ok(tedris_from_model(drive, &c.model, &c)?)
}
