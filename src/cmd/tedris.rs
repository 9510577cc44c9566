//! `deadreckon tedris train|run`: TedriS over a drive directory (the library is
//! `deadreckon-tedris`, the commands' steps `deadreckon_api::tedris`).

use anyhow::Result;
use deadreckon_api::tedris;
use deadreckon_tedris::RunOptions;

use super::common;
use crate::args::tedris::{RunArgs, TedrisCommand, TrainArgs};

/// Runs a TedriS subcommand.
pub fn run(c: TedrisCommand, load: &common::Loader) -> Result<()> {
    match c {
        TedrisCommand::Train(a) => train(a, load),
        TedrisCommand::Run(a) => run_outages(a, load),
    }
}

/// `tedris train`.
fn train(a: TrainArgs, load: &common::Loader) -> Result<()> {
    deadreckon_api::load::check_range(a.from_s, a.until_s)?;
    let inputs: Vec<&std::path::Path> = std::iter::once(a.dir.as_path())
        .chain(a.config.as_deref())
        .chain(a.params.as_deref().map(std::path::Path::new))
        .collect();
    common::check_output(&a.out, &inputs)?;
    let drive = deadreckon_api::load::cut(load.drive(&a.dir)?, a.from_s, a.until_s)?;
    let (m, source) = tedris::train(&drive, &a.options()?)?;
    tedris::write_model(&a.out, &m)?;
    if a.json {
        common::print_json(load, deadreckon_api::json::tedris_train_json(&m, source))
    } else {
        common::print_lines(deadreckon_api::text::tedris_train_lines(&m, source))?;
        outln!("model written to {}", a.out.display());
        Ok(())
    }
}

/// `tedris run`.
fn run_outages(a: RunArgs, load: &common::Loader) -> Result<()> {
    if let Some(p) = &a.out {
        let mut inputs = vec![a.dir.as_path(), a.model.as_path()];
        inputs.extend(a.params.as_deref().map(std::path::Path::new));
        common::check_output(p, &inputs)?;
    }
    let m = tedris::read_model(&a.model)?;
    let outages = a.outage_windows()?;
    let drive = load.drive(&a.dir)?;
    let opts = RunOptions {
        source: a.reference.source(),
        threshold_m: Some(a.threshold_m),
    };
    let (r, corrections) = tedris::run_outages(
        &drive,
        &m,
        &outages,
        &opts,
        a.out.as_deref(),
        a.params.as_deref(),
    )?;
    if a.json {
        let c = corrections.as_deref();
        common::print_json(load, tedris::run_json(&r, &m, a.out.as_deref(), c))
    } else {
        if let Some(c) = &corrections {
            outln!("corrections applied: {c}");
        }
        common::print_lines(deadreckon_api::text::tedris_outage_lines(&r, a.threshold_m))?;
        if let Some(p) = &a.out {
            outln!("track written to {}", p.display());
        }
        Ok(())
    }
}
