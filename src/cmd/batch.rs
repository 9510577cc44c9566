//! `deadreckon batch`: calibrate (and evaluate) many drives in parallel, one
//! CSV row per drive, and each vehicle's calibration history. The work is
//! `deadreckon_fleet`'s; this parses, reports progress and prints.

use std::io::{IsTerminal, Write};
use std::time::Instant;

use anyhow::{Context, Result};
use deadreckon_core::calibrate::{CalibrationOptions, Method};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Params;
use deadreckon_fleet::batch::{BatchOptions, OutageOptions};
use deadreckon_fleet::history::HistoryOptions;
use deadreckon_fleet::{batch, history, inputs, output};
use indicatif::{ProgressBar, ProgressStyle};

use super::common;

use crate::args::batch::*;

fn history_options(a: &BatchArgs) -> Result<HistoryOptions> {
    let mut o = HistoryOptions {
        alpha: a.alpha,
        ..Default::default()
    };
    for t in &a.tolerance {
        let (name, value) = t
            .split_once('=')
            .with_context(|| format!("--tolerance `{t}`: expected NAME=VALUE"))?;
        let i = Params::NAMES
            .iter()
            .position(|n| *n == name.trim())
            .with_context(|| {
                format!(
                    "--tolerance `{t}`: unknown parameter `{name}` (known: {})",
                    Params::NAMES.join(", ")
                )
            })?;
        o.tolerance[i] = value
            .trim()
            .parse()
            .with_context(|| format!("--tolerance `{t}`: `{value}` is not a number"))?;
    }
    o.validate()?;
    Ok(o)
}

fn bar(total: usize, quiet: bool) -> Option<ProgressBar> {
    if quiet || !std::io::stderr().is_terminal() {
        return None;
    }
    let b = ProgressBar::new(total as u64);
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:30} {pos}/{len} drives [{elapsed_precise}, eta {eta}] {wide_msg}",
    ) {
        b.set_style(style);
    }
    Some(b)
}

/// Runs `batch`.
pub fn run(a: BatchArgs, quiet: bool, loader: &common::Loader) -> Result<()> {
    let method: Method = a.method.car()?;
    let hist_opts = history_options(&a)?;
    let options = BatchOptions {
        calibration: CalibrationOptions {
            method,
            max_iterations: a.max_iterations as usize,
            min_speed_mps: a.min_speed,
            filter: FilterOptions {
                timing: a.timing.into(),
                ..Default::default()
            },
            ..Default::default()
        },
        outage: a.outage.map(|len| OutageOptions {
            length_s: len,
            step_s: a.step.unwrap_or(len / 2.0),
            warmup_s: a.warmup,
        }),
        threads: a.threads,
    };
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
    let load = |p: &std::path::Path| loader.drive_with(p, &read).map_err(|e| format!("{e:#}"));
    let progress = bar(drives.len(), quiet);
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
    let mut text = output::summary_line(&results, wall_s, threads);
    text.push_str(&format!("\nwrote {}", a.out.display()));
    if let Some(h) = &a.history {
        text.push_str(&format!("\nwrote {}", h.display()));
    }
    text.push('\n');
    if histories.is_empty() {
        text.push_str("no drive has a vehicle_id in its vehicle.toml: no calibration history\n");
    } else {
        text.push_str(&output::history_table(&histories));
    }
    common::quiet_on_broken_pipe(std::io::stdout().lock().write_all(text.as_bytes()))
}
