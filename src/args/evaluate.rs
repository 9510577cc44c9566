//! The arguments of `deadreckon evaluate`.

use std::path::PathBuf;

use clap::Args;
use deadreckon_core::evo;

use super::kinematic::{ShapeArg, StartArg, YawArg};

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
    /// `nominal` or a params.toml. Without it, the parameters are calibrated on the drive itself (RTS for a car, against GNSS for a differential drive, against the tracker for a tricycle).
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
    #[arg(long, default_value_t = 100.0, value_parser = super::positive)]
    pub delta_m: f64,
    /// rpe: whose travelled path chooses the pairs: estimate (evo's default) or reference (evo's --pairs_from_reference).
    #[arg(long, value_enum, default_value_t = PairsFromArg::Estimate)]
    pub pairs_from: PairsFromArg,
    /// rpe/ape: largest time difference of associated poses, s (evo's --t_max_diff).
    #[arg(long, default_value_t = evo::DEFAULT_MAX_DIFF_S, value_parser = super::positive)]
    pub max_diff_s: f64,
    /// Segment length of the drift metric, m.
    #[arg(long, default_value_t = 100.0, value_parser = super::positive)]
    pub segment_m: f64,
    /// Error threshold of the reset metric, m.
    #[arg(long, default_value_t = 1.0, value_parser = super::positive)]
    pub threshold_m: f64,
    /// Evaluate over sliding GNSS outages of this length, s (instead of --metric).
    #[arg(long, value_parser = super::positive)]
    pub outage: Option<f64>,
    /// Step between outage windows, s (default: half the outage length).
    #[arg(long, value_parser = super::positive)]
    pub step: Option<f64>,
    /// GNSS-aided time before the first outage window, s.
    #[arg(long, default_value_t = deadreckon_api::evaluate::OUTAGE_WARMUP_S, value_parser = super::non_negative)]
    pub warmup: f64,
    /// With --outage: an alert limit, m; prints when the 95 % error bound
    /// reaches it in each window (time and distance into the outage).
    #[arg(long = "alert-m", value_parser = super::positive)]
    pub alert_m: Option<f64>,
    /// Filter timing: wheel or each.
    #[arg(long, value_enum, default_value_t = super::TimingArg::Wheel)]
    pub timing: super::TimingArg,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    /// The vehicle shape (default: found from the data). A differential drive's outages start from the GNSS-aided filter, or with --start align from the alignment of the preceding --align seconds of dead reckoning to the fixes.
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<ShapeArg>,
    /// Differential drive: the yaw rate integrated, gyro or odometry (default: the params file's, else gyro).
    #[arg(long, value_enum)]
    pub yaw: Option<YawArg>,
    /// Differential drive: seconds before the first outage, and the span of fixes before each outage the dead reckoning is aligned to (--start align) [default: 60].
    #[arg(long, value_parser = super::positive)]
    pub align: Option<f64>,
    /// Differential drive: where each outage starts from: filter (the GNSS-aided filter's state, the fixes' wander carried into the outage) or align (the preceding --align seconds of dead reckoning aligned to the fixes, the baseline) [default: filter].
    #[arg(long, value_enum)]
    pub start: Option<StartArg>,
    /// Without --params: the timing and mounting corrections estimated and
    /// applied before the calibration (auto: each only when it helps on
    /// held-back GNSS; all: IMU tilt and every stream's delay; gnss: tilt and
    /// GNSS delay; none). With --params: those stored in the file are applied.
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::Auto)]
    pub corrections: super::CorrectionsArg,
    /// Evaluate only data from this time on, s (drive clock).
    #[arg(long = "from", value_parser = super::finite, allow_hyphen_values = true)]
    pub from_s: Option<f64>,
    /// Evaluate only data before this time, s (drive clock).
    #[arg(long = "until", value_parser = super::finite, allow_hyphen_values = true)]
    pub until_s: Option<f64>,
}

impl EvaluateArgs {
    /// What a car's drive is measured by: `--outage`, else `--metric`.
    pub fn metric(&self) -> deadreckon_api::evaluate::Metric<'_> {
        use deadreckon_api::evaluate::Metric;
        if let Some(len) = self.outage {
            return Metric::Outages {
                length_s: len,
                step_s: self.step.unwrap_or(len / 2.0),
                warmup_s: self.warmup,
            };
        }
        match self.metric {
            MetricArg::Drift => Metric::Drift {
                segment_m: self.segment_m,
            },
            MetricArg::Reset1m => Metric::Reset {
                threshold_m: self.threshold_m,
            },
            MetricArg::Rpe | MetricArg::Ape => Metric::Evo(deadreckon_api::json::EvoQuery {
                metric: self.metric.name(),
                track: &self.track,
                reference: &self.reference,
                max_diff_s: self.max_diff_s,
                delta_m: self.delta_m,
                pairs_from: match self.pairs_from {
                    PairsFromArg::Estimate => "estimate",
                    PairsFromArg::Reference => "reference",
                },
            }),
        }
    }
}
