//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use anyhow::{Context, Result};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics::{self, Summary};
use deadreckon_core::outage;

use deadreckon_core::kinematics::diff_drive::{self, evaluate_diff_drive, DiffDriveDrive};
use deadreckon_core::kinematics::{self, KinematicOptions, Shape};

use super::{common, kinematic};
use crate::args::kinematic::{ShapeArg, YawArg};

use crate::args::evaluate::*;

/// Runs `evaluate`.
pub fn run(a: EvaluateArgs, load: &common::Loader) -> Result<()> {
    kinematic::check_range(a.from_s, a.until_s)?;
    if kinematic::is_tricycle_log(&a.dir) {
        return run_tricycle(&a);
    }
    if a.shape == ShapeArg::DiffDrive {
        return run_diff_drive(&a, load);
    }
    let drive = load.drive(&a.dir)?;
    let drive = if a.from_s.is_some() || a.until_s.is_some() {
        drive.time_range(a.from_s, a.until_s)
    } else {
        drive
    };
    let timing: deadreckon_core::ekf::Timing = a.timing.into();
    // One rule for every metric (deadreckon_api::evaluate::RULE).
    let (chosen, drive) = match &a.params {
        Some(p) => (
            deadreckon_api::evaluate::Parameters {
                params: common::load_params(p, &drive)?,
                label: p.clone(),
                corrections: None,
            },
            common::apply_stored(p, drive)?,
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

/// The tricycle: sliding outages from the tracker pose, scored at the
/// tracked point with the calibrated mounting.
fn run_tricycle(a: &EvaluateArgs) -> Result<()> {
    let Some(len) = a.outage else {
        anyhow::bail!(
            "a tricycle log is evaluated over sliding outages: give --outage LEN (and --step S)"
        );
    };
    let shape = Shape::Tricycle;
    let drive = kinematic::load_tricycle(&a.dir, a.from_s, a.until_s)?;
    let (params, source) = match &a.params {
        Some(p) => kinematic::load_params(p, shape, &drive)?,
        None => {
            let o = KinematicOptions {
                min_speed_mps: shape.default_min_speed_mps(),
                ..Default::default()
            };
            let c = kinematics::calibrate(&drive, &o).context("calibrating against the tracker")?;
            (
                c.values(),
                "truth (calibrated on the evaluated range)".to_string(),
            )
        }
    };
    let ev = kinematics::evaluate(&drive, &params, len, a.step.unwrap_or(len / 2.0))?;
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&deadreckon_api::json::kinematic_outages_json(
                shape, &ev, &source
            ))?
        );
    } else {
        let s = ev.final_error();
        outln!(
            "{} outage windows of {len} s from the reference pose (parameters: {source})",
            ev.windows.len()
        );
        final_error_table(&s)?;
    }
    Ok(())
}

/// The differential drive: sliding outages, each started from the
/// alignment of the preceding dead reckoning to the fixes, scored against
/// the hidden fix at its end.
fn run_diff_drive(a: &EvaluateArgs, load: &common::Loader) -> Result<()> {
    let Some(len) = a.outage else {
        anyhow::bail!("a differential drive is evaluated over sliding GNSS outages: give --outage LEN (and --step S)");
    };
    let spec = a.params.as_deref().unwrap_or("nominal");
    let file_yaw = if spec == "nominal" {
        None
    } else {
        deadreckon_io::read_kinematic_params(std::path::Path::new(spec))
            .ok()
            .and_then(|f| f.yaw_source)
    };
    let yaw = match (a.yaw, file_yaw.as_deref()) {
        (Some(y), _) => y,
        (None, Some("odometry")) => YawArg::Odometry,
        _ => YawArg::Gyro,
    };
    let (params, source) = if spec == "nominal" {
        (DiffDriveDrive::nominal(), "nominal".to_string())
    } else {
        kinematic::load_params_file(spec, Shape::DiffDrive, &diff_drive::NAMES, Some(yaw.name()))?
    };
    let drive = load.drive(&a.dir)?;
    let dd = kinematic::diff_drive(&drive, yaw, a.from_s, a.until_s)?;
    let ev = evaluate_diff_drive(&dd, &params, len, a.step.unwrap_or(len / 2.0), a.align)?;
    let source = format!("{source}, yaw {}", yaw.name());
    if a.json {
        let mut v = deadreckon_api::json::kinematic_outages_json(Shape::DiffDrive, &ev, &source);
        v["reference"] = "gnss (hidden fixes; start aligned to the preceding fixes)".into();
        v["align_s"] = a.align.into();
        common::print_json(load, v)?;
    } else {
        let s = ev.final_error();
        outln!(
            "{} outage windows of {len} s, each started from {} s of dead reckoning aligned to the fixes (parameters: {source})",
            ev.windows.len(),
            a.align
        );
        final_error_table(&s)?;
    }
    Ok(())
}

/// The final-error line of the kinematic shapes' outage evaluations.
fn final_error_table(s: &deadreckon_core::metrics::Summary) -> Result<()> {
    for l in deadreckon_api::text::summary_table(&[("final error (m)", *s)]) {
        outln!("{l}");
    }
    Ok(())
}
