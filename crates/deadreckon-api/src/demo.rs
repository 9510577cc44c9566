//! `deadreckon demo`: the whole four-wheel method on simulated drives.
//! Simulates the calibration and evaluation scenarios, calibrates with
//! nominal, ZUPT, RTS and truth on one and evaluates each on the other (the
//! paper's tables III and IV), runs the paper's plain iteration for
//! comparison, and puts TedriS beside the four-wheel EKF through three 80 s
//! outages on the simulated campus drive. Writes the drives, each
//! calibration's params.toml and two reports.

use std::path::{Path, PathBuf};

use deadreckon_core::calibrate::{self, Calibration, CalibrationOptions, Iteration, PassState};
use deadreckon_core::metrics::Summary;
use deadreckon_core::{Params, ParamsWithStd};
use deadreckon_eval::compare::Comparison;
use deadreckon_eval::crossval::MethodResult;
use deadreckon_eval::report::{self, Source};
use deadreckon_eval::Progress;
use deadreckon_report::Footer;
use deadreckon_sim::SimOutput;

use crate::load::{simulate_to, Loader};
use crate::Error;

/// What the demo computed and where it wrote it.
pub struct Demo {
    /// The output directory.
    pub out: PathBuf,
    /// The simulated calibration drive.
    pub calibration_drive: SimOutput,
    /// The simulated evaluation drive.
    pub evaluation_drive: SimOutput,
    /// Each method calibrated on the one and evaluated on the other.
    pub results: Vec<MethodResult>,
    /// The paper's scheme (5-state passes, plain iteration) on the
    /// calibration drive.
    pub plain: Calibration,
    /// The report of the evaluation drive.
    pub report: PathBuf,
    /// TedriS beside the four-wheel EKF on the campus drive.
    pub comparison: Comparison,
    /// The campus drive's start time, s (subtracted from the outage times).
    pub campus_t0: f64,
    /// The campus drive's report.
    pub campus_report: PathBuf,
}

/// Runs the demo into `out` with the calibration drive's `seed` (the
/// evaluation drive uses `seed + 1`, the campus drive `seed + 2`). The
/// drives are read back through `load` as a user's would be.
pub fn run(
    out: &Path,
    seed: u64,
    load: &Loader,
    steps: &dyn Progress,
    footer: &Footer,
) -> Result<Demo, Error> {
    steps.step("simulating");
    let cal_dir = out.join("calibration");
    let eval_dir = out.join("evaluation");
    let calibration_drive = simulate_to("calibration", seed, &cal_dir)?;
    let evaluation_drive = simulate_to("evaluation", seed + 1, &eval_dir)?;
    let cal = load.drive(&cal_dir)?;
    let eval = load.drive(&eval_dir)?;
    steps.step("calibrating and evaluating");
    let results = deadreckon_eval::crossval::calibrate_and_evaluate(&cal, &eval)?;
    for r in &results {
        if let Some(c) = &r.calibration {
            let file = out.join(format!("params_{}.toml", r.source.name().to_lowercase()));
            let tables = crate::params_file::ParamsTables {
                iterations: Some(c.iterations),
                ..Default::default()
            };
            let name = file.display().to_string();
            crate::params_file::ParamsFile::new(c.estimate, tables, &name)?.write(&file)?;
        }
    }
    // The report of the evaluation drive with the calibrations made on the
    // calibration drive.
    let methods = report::Calibrations {
        sets: results
            .iter()
            .map(|r| report::NamedParams {
                source: r.source,
                params: r.params,
                calibration: r.calibration.clone(),
            })
            .collect(),
        skipped: Vec::new(),
    };
    let mut input = report::four_wheel_input(&eval, &methods, Some(20.0), None, steps)?;
    input.header = report::header(
        &eval,
        "demo: evaluation drive",
        vec![
            ("calibration drive".into(), cal_dir.display().to_string()),
            ("evaluation drive".into(), eval_dir.display().to_string()),
        ],
    );
    input.footer = footer.clone();
    let report_path = out.join("report.html");
    deadreckon_report::write_report(&report_path, &input)?;
    steps.step("paper's plain iteration");
    let plain = calibrate::calibrate(
        &cal,
        &CalibrationOptions {
            state: PassState::Paper,
            iteration: Iteration::Plain,
            max_iterations: 30,
            ..Default::default()
        },
    )?;
    let (comparison, campus_t0, campus_report) = campus(out, seed + 2, load, steps, footer)?;
    Ok(Demo {
        out: out.to_path_buf(),
        calibration_drive,
        evaluation_drive,
        results,
        plain,
        report: report_path,
        comparison,
        campus_t0,
        campus_report,
    })
}

/// TedriS beside the four-wheel EKF on the simulated campus drive: three
/// 80 s outages, both methods calibrated or trained with the outages
/// hidden, and a report with the TedriS sections.
fn campus(
    out: &Path,
    seed: u64,
    load: &Loader,
    steps: &dyn Progress,
    footer: &Footer,
) -> Result<(Comparison, f64, PathBuf), Error> {
    steps.step("TedriS campus drive");
    let dir = out.join("tedris-car");
    simulate_to("tedris-car", seed, &dir)?;
    let drive = load.drive(&dir)?;
    let (t0, t1) = drive
        .time_span()
        .ok_or(deadreckon_eval::Error::EmptyDrive)?;
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
    steps.step("TedriS report");
    let methods = report::calibrations(&drive, steps);
    let mut input = report::four_wheel_input(&drive, &methods, None, None, steps)?;
    // The report's outage curves are the comparison printed.
    input.tedris = Some(report::tedris_from_model(&drive, &c.model, &c)?);
    input.header = report::header(
        &drive,
        "demo: TedriS campus drive",
        vec![("drive".into(), dir.display().to_string())],
    );
    input.footer = footer.clone();
    let path = out.join("tedris-report.html");
    deadreckon_report::write_report(&path, &input)?;
    Ok((c, t0, path))
}

impl Demo {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        let rows: Vec<serde_json::Value> = self
            .results
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
        serde_json::json!({
            "truth_params": self.calibration_drive.truth_params.to_array(),
            "methods": rows,
            "plain_iterations": self.plain.iterations,
            "tedris_comparison": crate::json::comparison_json(&self.comparison),
        })
    }

    /// The text: the drives, table III (calibration), the RTS errors and
    /// passes against the paper's iteration, table IV (drift), where things
    /// were written, and the TedriS comparison.
    pub fn lines(&self) -> Vec<String> {
        let (sc, se) = (&self.calibration_drive.stats, &self.evaluation_drive.stats);
        let truth = self.calibration_drive.truth_params;
        let mut out = vec![
            format!(
                "calibration drive: {:.2} km, {:.0} s, mean {:.1} km/h; evaluation drive: {:.2} km, {:.0} s",
                sc.distance_m / 1000.0,
                sc.duration_s,
                sc.mean_speed_mps * 3.6,
                se.distance_m / 1000.0,
                se.duration_s
            ),
            String::new(),
            "Table III: parameter calibration".into(),
            crate::text::params_header(),
            crate::text::params_row(
                "GT",
                &ParamsWithStd {
                    params: truth,
                    std: Params::from_array([0.0; 6]),
                },
            ),
        ];
        for r in &self.results {
            out.push(crate::text::params_row(r.source.name(), &r.params));
        }
        if let Some(rts) = self
            .results
            .iter()
            .find(|r| r.source == Source::Rts)
            .and_then(|r| r.calibration.as_ref())
        {
            out.extend(rts_lines(rts, &self.plain, &truth));
        }
        out.push(String::new());
        out.push(
            "Table IV: dead-reckoning drift on the evaluation drive (reset to the truth every 100 m)"
                .into(),
        );
        out.push(format!(
            "{:<8} {:>12} {:>12} {:>6}   {:>24}",
            "method", "mean error", "std", "n", "distance before 1 m error"
        ));
        for r in &self.results {
            let d = Summary::of(&r.drift.errors_pct());
            let s = Summary::of(&r.reset.distances_m);
            out.push(format!(
                "{:<8} {:>11.3}% {:>11.3}% {:>6}   mean {:>6.1} m, median {:>6.1} m",
                r.source.name(),
                d.mean,
                d.std,
                d.n,
                s.mean,
                s.median
            ));
        }
        out.push(String::new());
        out.push(format!(
            "drives and parameters in {}, report in {}",
            self.out.display(),
            self.report.display()
        ));
        out.push(String::new());
        out.push(
            "TedriS and the four-wheel EKF through 80 s GNSS outages on the simulated campus drive"
                .into(),
        );
        out.extend(crate::text::comparison_lines(
            &self.comparison,
            self.campus_t0,
        ));
        out.push(format!("report in {}", self.campus_report.display()));
        out
    }
}

/// The RTS calibration's errors against the truth, and its passes beside
/// the paper's plain iteration.
fn rts_lines(rts: &Calibration, plain: &Calibration, truth: &Params) -> Vec<String> {
    let e = rts.estimate.params.to_array();
    let t = truth.to_array();
    let pct = |i: usize| 100.0 * ((e[i] - t[i]) / t[i]).abs();
    let worst = |p: &Params| {
        (2..6)
            .map(|i| ((p.to_array()[i] - t[i]) / t[i]).abs())
            .fold(0.0, f64::max)
            * 100.0
    };
    vec![
        format!(
            "RTS errors: gyro bias {:.2}%, speed scale {:.3}%, circumferences {:.3}% {:.3}% {:.3}% {:.3}%",
            pct(0),
            pct(1),
            pct(2),
            pct(3),
            pct(4),
            pct(5)
        ),
        format!(
            "RTS smoothing passes: {} (augmented state); the paper's 5-state plain iteration: worst circumference error {:.3}% after 1 pass, {:.3}% after 3, {:.3}% after {}{}",
            rts.iterations,
            worst(&plain.history[0]),
            worst(&plain.history[2.min(plain.history.len() - 1)]),
            worst(plain.history.last().unwrap_or(&plain.estimate.params)),
            plain.iterations,
            if plain.converged { " (converged)" } else { " (not converged)" }
        ),
    ]
}
