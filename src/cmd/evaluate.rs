//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use anyhow::Result;

use super::common;
use crate::args::kinematic::StartArg;
use deadreckon_api::shape::Found;
use deadreckon_api::{evaluate, kinematic};
use deadreckon_core::kinematics::Shape;
use deadreckon_core::Drive;

use crate::args::evaluate::*;

/// Runs `evaluate`.
pub fn run(a: EvaluateArgs, load: &common::Loader) -> Result<()> {
    // The shape found from the data, read once (deadreckon_api::shape).
    let read = deadreckon_io::ReadOptions::default();
    let (drive, found) = deadreckon_api::shape::load(load, &a.dir, &read, a.shape.map(Into::into))?;
    if found.shape != Shape::FourWheel {
        return run_kinematic(&a, load, drive, &found);
    }
    if a.start.is_some() || a.align.is_some() {
        anyhow::bail!("--start and --align apply to a differential drive (--shape diff-drive)");
    }
    let drive = match drive {
        Some(d) => d,
        None => load.drive(&a.dir)?,
    };
    let drive = deadreckon_api::load::cut(drive, a.from_s, a.until_s)?;
    // One rule for every metric and command (deadreckon_api::evaluate::RULE).
    let (chosen, drive) = evaluate::parameters(
        a.params.as_deref(),
        drive,
        a.corrections.into(),
        load.params_for_other_vehicle,
    )?;
    if let Some(n) = &chosen.note {
        note!("note: {n}");
    }
    if !a.json {
        outln!("drive: {}", load.checks().span_text());
        outln!("{}", found.line());
    }
    if a.params.is_none() && !a.json {
        outln!("parameters: {} ({})", chosen.label, evaluate::RULE);
    } else if !a.json {
        outln!(
            "parameters: {}",
            deadreckon_api::report_labels::given_line(&chosen.source, chosen.file_corrected)
        );
    }
    let mut ev = evaluate::measure(&drive, chosen, a.timing.into(), a.metric())?;
    ev.alert_m = a.alert_m;
    if a.json {
        let mut v = ev.json();
        v["shape_found"] = found.json();
        common::print_json(load, v)
    } else {
        common::print_lines(ev.lines())
    }
}

/// A tricycle (its log or its drive directory) or a differential drive over
/// sliding outages (`deadreckon_api::kinematic`).
fn run_kinematic(
    a: &EvaluateArgs,
    load: &common::Loader,
    drive: Option<Drive>,
    found: &Found,
) -> Result<()> {
    let tricycle = found.shape == Shape::Tricycle;
    let Some(len) = a.outage else {
        anyhow::bail!(if tricycle {
            "a tricycle is evaluated over sliding outages: give --outage LEN (and --step S)"
        } else {
            "a differential drive is evaluated over sliding GNSS outages: give --outage LEN (and --step S)"
        });
    };
    if !a.json {
        outln!("{}", found.line());
        if a.params.is_none() {
            outln!("parameters: {}", evaluate::RULE);
        }
    }
    let step = a.step.unwrap_or(len / 2.0);
    let params = a.params.as_deref();
    let ev = if tricycle {
        kinematic::evaluate_tricycle(
            &a.dir,
            drive.as_ref(),
            params,
            len,
            step,
            a.from_s,
            a.until_s,
        )?
    } else {
        let yaw = kinematic::diff_yaw(params, a.yaw.map(Into::into));
        let drive = match drive {
            Some(d) => d,
            None => load.drive(&a.dir)?,
        };
        kinematic::evaluate_diff(
            &drive,
            params,
            yaw,
            len,
            step,
            a.align
                .unwrap_or(deadreckon_core::kinematics::diff_drive::DEFAULT_WARMUP_S),
            &a.start.unwrap_or(StartArg::Filter).into(),
            a.from_s,
            a.until_s,
        )?
    };
    let log = deadreckon_api::shape::of_path(&a.dir).is_some();
    let mut v = ev.json();
    v["shape_found"] = found.json();
    match (a.json, log) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&v),
        (true, false) => common::print_json(load, v),
        (false, _) => common::print_lines(ev.lines()),
    }
}
