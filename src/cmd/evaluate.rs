//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use anyhow::Result;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics::{self, Summary};
use deadreckon_core::outage;

use super::common;
use crate::args::kinematic::ShapeArg;
use deadreckon_api::kinematic;

use crate::args::evaluate::*;

/// Runs `evaluate`.
pub fn run(a: EvaluateArgs, load: &common::Loader) -> Result<()> {
    let tricycle = kinematic::is_tricycle_log(&a.dir);
    if tricycle || a.shape == ShapeArg::DiffDrive {
        return run_kinematic(&a, load, tricycle);
    }
    let drive = deadreckon_api::load::cut(load.drive(&a.dir)?, a.from_s, a.until_s)?;
    let timing: deadreckon_core::ekf::Timing = a.timing.into();
    // One rule for every metric (deadreckon_api::evaluate::RULE).
    let (chosen, drive) = match &a.params {
        Some(p) => (
            deadreckon_api::evaluate::Parameters {
                params: deadreckon_api::load::params(p, &drive)?,
                label: p.clone(),
                corrections: None,
            },
            deadreckon_api::load::apply_stored(p, drive)?,
        ),
        None => deadreckon_api::evaluate::default_parameters(&drive, a.corrections.into())?,
    };
    let params = chosen.params;
    let source = chosen.label;
    let corrections = chosen.corrections;
    if !a.json {
        outln!("drive: {}", load.checks().span_text());
    }
    if a.params.is_none() && !a.json {
        outln!("parameters: {source} ({})", deadreckon_api::evaluate::RULE);
    }
    if let Some(len) = a.outage {
        let base = FilterOptions {
            timing,
            ..Default::default()
        };
        let ev = outage::evaluate(
            &drive,
            &params,
            len,
            a.step.unwrap_or(len / 2.0),
            a.warmup,
            &base,
        )?;
        if a.json {
            let mut v = deadreckon_api::json::outage_json(len, &source, &ev);
            if let Some(c) = &corrections {
                v["corrections"] = deadreckon_api::corrections::corrections_json(c);
            }
            common::print_json(load, v)?;
        } else {
            for l in deadreckon_api::text::outage_lines(&ev, &source, corrections.as_ref()) {
                outln!("{l}");
            }
        }
        return Ok(());
    }
    let with_source = |mut v: serde_json::Value| {
        v["params"] = source.clone().into();
        if let Some(c) = &corrections {
            v["corrections"] = deadreckon_api::corrections::corrections_json(c);
        }
        v
    };
    match a.metric {
        MetricArg::Drift => {
            let r = metrics::drift(&drive, &params, a.segment_m, timing)?;
            let s = Summary::of(&r.errors_pct());
            if a.json {
                let v = deadreckon_api::json::drift_json(&r, a.segment_m);
                common::print_json(load, with_source(v))?;
            } else {
                outln!("drift per {} m over {} segments: mean {:.3}%, std {:.3}%, median {:.3}%, max {:.3}%", a.segment_m, s.n, s.mean, s.std, s.median, s.max);
                outln!("rejected by the χ² gates: {}", common::gated_text(&r.gates));
            }
        }
        MetricArg::Reset1m => {
            let r = metrics::reset_on_error(&drive, &params, a.threshold_m, timing)?;
            let s = Summary::of(&r.distances_m);
            if a.json {
                let v = deadreckon_api::json::reset_json(&r, a.threshold_m);
                common::print_json(load, with_source(v))?;
            } else {
                outln!(
                    "distance before {} m of error over {} resets: mean {:.1} m, median {:.1} m, min {:.1} m, max {:.1} m",
                    a.threshold_m, s.n, s.mean, s.median, s.min, s.max
                );
                outln!("rejected by the χ² gates: {}", common::gated_text(&r.gates));
            }
        }
        MetricArg::Rpe | MetricArg::Ape => {
            let q = deadreckon_api::json::EvoQuery {
                metric: a.metric.name(),
                track: &a.track,
                reference: &a.reference,
                max_diff_s: a.max_diff_s,
                delta_m: a.delta_m,
                pairs_from: match a.pairs_from {
                    PairsFromArg::Estimate => "estimate",
                    PairsFromArg::Reference => "reference",
                },
            };
            let r = deadreckon_api::evaluate::evo_metric(&drive, &params, timing, &q)?;
            if a.json {
                let v = deadreckon_api::json::evo_json(&q, &r);
                common::print_json(load, with_source(v))?;
            } else {
                for l in deadreckon_api::text::evo_lines(&q, &r) {
                    outln!("{l}");
                }
            }
        }
    }
    Ok(())
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
        kinematic::evaluate_diff(&drive, params, yaw, len, step, a.align, a.from_s, a.until_s)?
    };
    match (a.json, tricycle) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&ev.json()),
        (true, false) => common::print_json(load, ev.json()),
        (false, _) => common::print_lines(ev.lines()),
    }
}
