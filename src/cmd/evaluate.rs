//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use anyhow::Result;

use super::common;
use crate::args::kinematic::{ShapeArg, StartArg};
use deadreckon_api::{evaluate, kinematic};

use crate::args::evaluate::*;

/// Runs `evaluate`.
pub fn run(a: EvaluateArgs, load: &common::Loader) -> Result<()> {
    let tricycle = kinematic::is_tricycle_log(&a.dir);
    if tricycle || a.shape == ShapeArg::DiffDrive {
        return run_kinematic(&a, load, tricycle);
    }
    if a.start.is_some() || a.align.is_some() {
        anyhow::bail!("--start and --align apply to a differential drive (--shape diff-drive)");
    }
    let drive = deadreckon_api::load::cut(load.drive(&a.dir)?, a.from_s, a.until_s)?;
    // One rule for every metric (deadreckon_api::evaluate::RULE).
    let (chosen, drive) = match &a.params {
        Some(p) => evaluate::given_parameters(p, drive)?,
        None => evaluate::default_parameters(&drive, a.corrections.into())?,
    };
    if !a.json {
        outln!("drive: {}", load.checks().span_text());
    }
    if a.params.is_none() && !a.json {
        outln!("parameters: {} ({})", chosen.label, evaluate::RULE);
    }
    let mut ev = evaluate::measure(&drive, chosen, a.timing.into(), a.metric())?;
    ev.alert_m = a.alert_m;
    if a.json {
        common::print_json(load, ev.json())
    } else {
        common::print_lines(ev.lines())
    }
}

/// A tricycle log or a differential drive over sliding outages
/// (`deadreckon_api::kinematic`).
fn run_kinematic(a: &EvaluateArgs, load: &common::Loader, tricycle: bool) -> Result<()> {
    let Some(len) = a.outage else {
        anyhow::bail!(if tricycle {
            "a tricycle log is evaluated over sliding outages: give --outage LEN (and --step S)"
        } else {
            "a differential drive is evaluated over sliding GNSS outages: give --outage LEN (and --step S)"
        });
    };
    let step = a.step.unwrap_or(len / 2.0);
    let params = a.params.as_deref();
    let ev = if tricycle {
        kinematic::evaluate_tricycle(&a.dir, params, len, step, a.from_s, a.until_s)?
    } else {
        let yaw = kinematic::diff_yaw(params, a.yaw.map(Into::into));
        let drive = load.drive(&a.dir)?;
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
    match (a.json, tricycle) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&ev.json()),
        (true, false) => common::print_json(load, ev.json()),
        (false, _) => common::print_lines(ev.lines()),
    }
}
