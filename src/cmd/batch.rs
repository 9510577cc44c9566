//! `deadreckon batch`: calibrate (and evaluate) many drives in parallel, one
//! CSV row per drive, and each vehicle's calibration history. The work is
//! `deadreckon_fleet`'s; this parses, reports progress and prints.

use std::io::Write;
use std::time::Instant;

use anyhow::Result;
use deadreckon_core::calibrate::Method;
use deadreckon_fleet::{batch, history, inputs, output};

use super::common;

use crate::args::batch::*;

/// Runs `batch`.
pub fn run(a: BatchArgs, quiet: bool, loader: &common::Loader) -> Result<()> {
    let options = a.options()?;
    let hist_opts = a.history_options()?;
    let method = options.request.options.method;
    batch::validate(&options)?;
    let drives = inputs::expand(&a.inputs)?;
    inputs::check_output(&a.out, &drives, "--out")?;
    if let Some(h) = &a.history {
        inputs::check_output(h, &drives, "--history")?;
        inputs::check_distinct(&a.out, h)?;
    }
    // Truth is read only where it is used.
    let read = deadreckon_io::ReadOptions::default();
    let read = if method == Method::Truth || options.outage.is_some() {
        read
    } else {
        read.without_truth()
    };
    // Each drive's shape found from its data (deadreckon_api::shape): batch
    // calibrates cars.
    let asked = a.shape.map(Into::into);
    let load = |p: &std::path::Path| {
        let d = loader
            .drive_with(p, &read)
            .map_err(|e| deadreckon_api::chain_text(&e))?;
        let found = deadreckon_api::shape::detect(p, Some(&d), asked);
        if found.shape != deadreckon_core::kinematics::Shape::FourWheel {
            return Err(format!(
                "a {} ({}): batch calibrates cars (--shape car to calibrate it as one)",
                deadreckon_api::shape::words(found.shape),
                found.reason
            ));
        }
        Ok(d)
    };
    let progress = super::progress::drives_bar(drives.len(), quiet);
    let start = Instant::now();
    let results = batch::run(&drives, &load, &options, &|r: &batch::DriveResult| {
        if let Some(b) = &progress {
            b.inc(1);
            b.set_message(r.path.display().to_string());
        }
    })?;
    let wall_s = start.elapsed().as_secs_f64();
    if let Some(b) = &progress {
        b.finish_and_clear();
    }
    output::write_results(&a.out, &results)?;
    let histories = history::histories(&results, &hist_opts)?;
    if let Some(h) = &a.history {
        output::write_history(h, &histories)?;
    }
    let threads = if a.threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        a.threads
    };
    // Failures on standard error; a closed standard error is no reason to stop.
    let mut err = std::io::stderr().lock();
    for r in &results {
        if let Err(e) = &r.outcome {
            let _ = writeln!(err, "failed: {}: {e}", r.path.display());
        }
    }
    drop(err);
    let written: Vec<&std::path::Path> = std::iter::once(a.out.as_path())
        .chain(a.history.as_deref())
        .collect();
    if quiet {
        return Ok(());
    }
    let text = output::summary_text(&results, &histories, wall_s, threads, &written);
    common::quiet_on_broken_pipe(std::io::stdout().lock().write_all(text.as_bytes()))
}
