//! `deadreckon demo`: the whole four-wheel method on simulated drives: simulate
//! the calibration and evaluation scenarios, calibrate with nominal, ZUPT, RTS
//! and truth, evaluate each on the evaluation drive, print the analogues of the
//! paper's tables III and IV.

use std::path::PathBuf;

use anyhow::{Context, Result};
use deadreckon_core::calibrate::{self, CalibrationOptions, Iteration, PassState};
use deadreckon_core::metrics::Summary;
use deadreckon_core::{Params, ParamsWithStd};

use super::common;
use deadreckon_eval::report;

use crate::args::demo::*;

/// Runs `demo`.
pub fn run(a: DemoArgs, quiet: bool, load: &common::Loader) -> Result<()> {
    let steps = super::progress::Steps::new(16, quiet);
    steps.step("simulating");
    let cal_dir = a.out.join("calibration");
    let eval_dir = a.out.join("evaluation");
    let sim_cal = common::simulate_to("calibration", a.seed, &cal_dir)?;
    let sim_eval = common::simulate_to("evaluation", a.seed + 1, &eval_dir)?;
    // Read back what was written, as a user's drive would be.
    let cal = load.drive(&cal_dir)?;
    let eval = load.drive(&eval_dir)?;
    steps.step("calibrating and evaluating");
    let results = deadreckon_eval::crossval::calibrate_and_evaluate(&cal, &eval)?;
    for r in &results {
        if let Some(c) = &r.calibration {
            let file = a
                .out
                .join(format!("params_{}.toml", r.source.name().to_lowercase()));
            let mut extra = toml::Table::new();
            extra.insert("iterations".into(), (c.iterations as i64).into());
            deadreckon_io::write_params(&file, &c.estimate, Some(&extra))?;
        }
    }
    // The report of the evaluation drive with the calibrations made on the calibration drive.
    let methods = report::Calibrations {
        sets: results
            .iter()
            .map(|r| report::NamedParams {
                name: r.source.name().into(),
                source: r.source,
                params: r.params,
                calibration: r.calibration.clone(),
            })
            .collect(),
        skipped: Vec::new(),
    };
    let mut input = report::four_wheel_input(&eval, &methods, Some(20.0), &steps)?;
    input.header = report::header(
        &eval,
        "demo: evaluation drive",
        vec![
            ("calibration drive".into(), cal_dir.display().to_string()),
            ("evaluation drive".into(), eval_dir.display().to_string()),
        ],
    );
    input.footer = common::footer();
    let report_path = a.out.join("report.html");
    deadreckon_report::write_report(&report_path, &input)?;
    steps.step("paper's plain iteration");
    // The paper's scheme (5-state passes, plain iteration), for comparison of convergence.
    let plain = calibrate::calibrate(
        &cal,
        &CalibrationOptions {
            state: PassState::Paper,
            iteration: Iteration::Plain,
            max_iterations: 30,
            ..Default::default()
        },
    )?;
    let truth = sim_cal.truth_params;
    let tedris = tedris_part(&a, &steps, load)?;
    steps.finish();
    if a.json {
        let rows: Vec<serde_json::Value> = results
            .iter()
            .map(|r| {
                let d = Summary::of(&r.drift.errors_pct());
                let s = Summary::of(&r.reset.distances_m);
                serde_json::json!({
                    "method": r.source.name(),
                    "params": r.params.params.to_array(),
                    "std": r.params.std.to_array(),
                    "iterations": r.calibration.as_ref().map(|c| c.iterations),
                    "drift": {"mean_pct": d.mean, "std_pct": d.std, "n": d.n},
                    "reset_1m": {"mean_m": s.mean, "median_m": s.median, "min_m": s.min, "max_m": s.max, "n": s.n},
                })
            })
            .collect();
        let v = serde_json::json!({
            "truth_params": truth.to_array(),
            "methods": rows,
            "plain_iterations": plain.iterations,
            "tedris_comparison": deadreckon_api::json::comparison_json(&tedris.0),
        });
        outln!("{}", serde_json::to_string_pretty(&v)?);
        return Ok(());
    }
    outln!(
        "calibration drive: {:.2} km, {:.0} s, mean {:.1} km/h; evaluation drive: {:.2} km, {:.0} s",
        sim_cal.stats.distance_m / 1000.0,
        sim_cal.stats.duration_s,
        sim_cal.stats.mean_speed_mps * 3.6,
        sim_eval.stats.distance_m / 1000.0,
        sim_eval.stats.duration_s
    );
    outln!();
    outln!("Table III: parameter calibration");
    outln!("{}", common::params_header());
    outln!(
        "{}",
        common::params_row(
            "GT",
            &ParamsWithStd {
                params: truth,
                std: Params::from_array([0.0; 6])
            }
        )
    );
    for r in &results {
        outln!("{}", common::params_row(r.source.name(), &r.params));
    }
    if let Some(rts) = results
        .iter()
        .find(|r| r.source == report::Source::Rts)
        .and_then(|r| r.calibration.as_ref())
    {
        let e = rts.estimate.params.to_array();
        let t = truth.to_array();
        outln!(
            "RTS errors: gyro bias {:.2}%, speed scale {:.3}%, circumferences {:.3}% {:.3}% {:.3}% {:.3}%",
            100.0 * ((e[0] - t[0]) / t[0]).abs(),
            100.0 * ((e[1] - t[1]) / t[1]).abs(),
            100.0 * ((e[2] - t[2]) / t[2]).abs(),
            100.0 * ((e[3] - t[3]) / t[3]).abs(),
            100.0 * ((e[4] - t[4]) / t[4]).abs(),
            100.0 * ((e[5] - t[5]) / t[5]).abs()
        );
        let worst = |p: &Params| {
            (2..6)
                .map(|i| ((p.to_array()[i] - t[i]) / t[i]).abs())
                .fold(0.0, f64::max)
                * 100.0
        };
        outln!(
            "RTS smoothing passes: {} (augmented state); the paper's 5-state plain iteration: worst circumference error {:.3}% after 1 pass, {:.3}% after 3, {:.3}% after {}{}",
            rts.iterations,
            worst(&plain.history[0]),
            worst(&plain.history[2.min(plain.history.len() - 1)]),
            worst(plain.history.last().unwrap_or(&plain.estimate.params)),
            plain.iterations,
            if plain.converged { " (converged)" } else { " (not converged)" }
        );
    }
    outln!();
    outln!(
        "Table IV: dead-reckoning drift on the evaluation drive (reset to the truth every 100 m)"
    );
    outln!(
        "{:<8} {:>12} {:>12} {:>6}   {:>24}",
        "method",
        "mean error",
        "std",
        "n",
        "distance before 1 m error"
    );
    for r in &results {
        let d = Summary::of(&r.drift.errors_pct());
        let s = Summary::of(&r.reset.distances_m);
        outln!(
            "{:<8} {:>11.3}% {:>11.3}% {:>6}   mean {:>6.1} m, median {:>6.1} m",
            r.source.name(),
            d.mean,
            d.std,
            d.n,
            s.mean,
            s.median
        );
    }
    outln!();
    outln!(
        "drives and parameters in {}, report in {}",
        a.out.display(),
        report_path.display()
    );
    outln!();
    outln!("TedriS and the four-wheel EKF through 80 s GNSS outages on the simulated campus drive");
    common::print_comparison(&tedris.0, tedris.1)?;
    outln!("report in {}", tedris.2.display());
    Ok(())
}

/// TedriS beside the four-wheel EKF on the simulated campus drive: three 80 s
/// outages, both methods calibrated or trained with the outages hidden, and a
/// report with the TedriS sections.
fn tedris_part(
    a: &DemoArgs,
    steps: &super::progress::Steps,
    load: &common::Loader,
) -> Result<(deadreckon_eval::compare::Comparison, f64, PathBuf)> {
    steps.step("TedriS campus drive");
    let dir = a.out.join("tedris-car");
    common::simulate_to("tedris-car", a.seed + 2, &dir)?;
    let drive = load.drive(&dir)?;
    let (t0, t1) = drive.time_span().context("empty drive")?;
    let outages: Vec<deadreckon_tedris::Outage> = [0.3, 0.55, 0.8]
        .iter()
        .map(|f| {
            let s = t0 + f * (t1 - t0) - 40.0;
            deadreckon_tedris::Outage {
                start_s: s,
                end_s: s + 80.0,
            }
        })
        .collect();
    let c = deadreckon_eval::compare::compare(&drive, &outages, None, None)?;
    // The report of the campus drive, with the TedriS sections.
    steps.step("TedriS report");
    let methods = report::calibrations(&drive, steps);
    let mut input = report::four_wheel_input(&drive, &methods, None, steps)?;
    // The report's outage curves are the comparison printed above.
    input.tedris = Some(report::tedris_from_model(&drive, &c.model, &c)?);
    input.header = report::header(
        &drive,
        "demo: TedriS campus drive",
        vec![("drive".into(), dir.display().to_string())],
    );
    input.footer = common::footer();
    let path = a.out.join("tedris-report.html");
    deadreckon_report::write_report(&path, &input)?;
    Ok((c, t0, path))
}
