//! `deadreckon report`: one self-contained HTML page with the papers' tables
//! and figures for a drive ([`deadreckon_api::report`]).

use anyhow::Result;

use super::{common, progress::Steps};
use crate::args::report::ReportArgs;

/// Runs `report`.
pub fn run(a: ReportArgs, quiet: bool, load: &common::Loader) -> Result<()> {
    let params = a.params.as_deref().map(std::path::Path::new);
    let inputs: Vec<&std::path::Path> = [Some(a.dir.as_path()), params, a.model.as_deref()]
        .into_iter()
        .flatten()
        .collect();
    common::check_output(&a.out, &inputs)?;
    let steps = Steps::new(9, quiet);
    steps.step("reading the drive");
    let drive = load.drive(&a.dir)?;
    let o = deadreckon_api::report::ReportOptions {
        dir: &a.dir,
        params: a.params.as_deref(),
        model: a.model.as_deref(),
        outage_s: a.outage,
        step_s: a.step,
        corrections: a.corrections.into(),
        shape: a.shape.map(Into::into),
    };
    let found = deadreckon_api::shape::detect(&a.dir, Some(&drive), o.shape);
    outln!("{}", found.line());
    // The one rule for "no --params" (deadreckon_api::evaluate::RULE): the
    // report calibrates on the drive, and shows a given file beside.
    outln!(
        "parameters: {}{}",
        deadreckon_api::evaluate::CALIBRATED_HERE,
        a.params
            .as_deref()
            .map_or(String::new(), |p| format!(", and {p} as given"))
    );
    deadreckon_api::report::write(drive, &o, &a.out, &steps, &common::footer())?;
    steps.finish();
    outln!("wrote {}", a.out.display());
    Ok(())
}
