//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::evo;
use deadreckon_core::metrics::{self, Summary};
use deadreckon_core::outage;

use deadreckon_core::kinematics::diff_drive::{self, evaluate_diff_drive, DiffDriveDrive};
use deadreckon_core::kinematics::{self, KinematicOptions, Shape};

use super::kinematic::{ShapeArg, YawArg};
use super::{common, kinematic};

/// `evaluate --metric`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MetricArg {
    /// Drift per --segment-m of path, reset to the truth at each segment.
    Drift,
    /// Distance travelled before the error reaches --threshold-m, then reset.
    #[value(name = "reset-1m")]
    Reset1m,
    /// evo's relative pose error per --delta-m of path, translation part.
    Rpe,
    /// evo's absolute pose error, no alignment.
    Ape,
}

impl MetricArg {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            MetricArg::Drift => "drift",
            MetricArg::Reset1m => "reset-1m",
            MetricArg::Rpe => "rpe",
            MetricArg::Ape => "ape",
        }
    }
}

/// `evaluate --pairs-from`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PairsFromArg {
    /// The estimate's travelled path chooses the pairs (evo's default).
    Estimate,
    /// The reference's (evo's --pairs_from_reference).
    Reference,
}

/// Arguments of `evaluate`.
#[derive(Args, Debug)]
pub struct EvaluateArgs {
    /// The drive directory or recording (a tricycle `dataset.txt` is dead-reckoned through its own kinematics).
    pub dir: PathBuf,
    /// `nominal` or a params.toml. Without it, `--outage` calibrates with RTS on the drive itself.
    #[arg(long)]
    pub params: Option<String>,
    /// drift (reset to the truth every 100 m), reset-1m (reset when the error
    /// reaches 1 m), rpe (evo's relative pose error per --delta-m of path,
    /// translation part) or ape (evo's absolute pose error, no alignment).
    #[arg(long, value_enum, default_value_t = MetricArg::Drift)]
    pub metric: MetricArg,
    /// rpe/ape: the estimated track (dead-reckoned, filtered, smoothed).
    #[arg(long, default_value = "dead-reckoned")]
    pub track: String,
    /// rpe/ape: the reference track (truth, or an estimated one).
    #[arg(long, default_value = "truth")]
    pub reference: String,
    /// rpe: path length between the poses of a pair, m (evo's --delta with --delta_unit m).
    #[arg(long, default_value_t = 100.0, value_parser = common::positive)]
    pub delta_m: f64,
    /// rpe: whose travelled path chooses the pairs: estimate (evo's default) or reference (evo's --pairs_from_reference).
    #[arg(long, value_enum, default_value_t = PairsFromArg::Estimate)]
    pub pairs_from: PairsFromArg,
    /// rpe/ape: largest time difference of associated poses, s (evo's --t_max_diff).
    #[arg(long, default_value_t = evo::DEFAULT_MAX_DIFF_S, value_parser = common::positive)]
    pub max_diff_s: f64,
    /// Segment length of the drift metric, m.
    #[arg(long, default_value_t = 100.0, value_parser = common::positive)]
    pub segment_m: f64,
    /// Error threshold of the reset metric, m.
    #[arg(long, default_value_t = 1.0, value_parser = common::positive)]
    pub threshold_m: f64,
    /// Evaluate over sliding GNSS outages of this length, s (instead of --metric).
    #[arg(long, value_parser = common::positive)]
    pub outage: Option<f64>,
    /// Step between outage windows, s (default: half the outage length).
    #[arg(long, value_parser = common::positive)]
    pub step: Option<f64>,
    /// GNSS-aided time before the first outage window, s.
    #[arg(long, default_value_t = 5.0, value_parser = common::non_negative)]
    pub warmup: f64,
    /// Filter timing: wheel or each.
    #[arg(long, value_enum, default_value_t = common::TimingArg::Wheel)]
    pub timing: common::TimingArg,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// The vehicle shape: car (the default) or diff-drive (outages start from the alignment of the preceding --align seconds of dead reckoning to the fixes). A tricycle log is recognised by itself.
    #[arg(long, value_enum, default_value_t = ShapeArg::Car)]
    pub shape: ShapeArg,
    /// Differential drive: the yaw rate integrated, gyro or odometry (default: the params file's, else gyro).
    #[arg(long, value_enum)]
    pub yaw: Option<YawArg>,
    /// Differential drive: seconds of fixes before each outage the dead reckoning is aligned to.
    #[arg(long, default_value_t = 60.0, value_parser = common::positive)]
    pub align: f64,
    /// Without --params: the timing and mounting corrections estimated and
    /// applied before the calibration (all: IMU tilt and every stream's
    /// delay; gnss: tilt and GNSS delay; none). With --params: those stored
    /// in the file are applied.
    #[arg(long, value_enum, default_value_t = common::CorrectionsArg::Gnss)]
    pub corrections: common::CorrectionsArg,
    /// Evaluate only data from this time on, s (drive clock).
    #[arg(long = "from", value_parser = common::finite, allow_hyphen_values = true)]
    pub from_s: Option<f64>,
    /// Evaluate only data before this time, s (drive clock).
    #[arg(long = "until", value_parser = common::finite, allow_hyphen_values = true)]
    pub until_s: Option<f64>,
}

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
