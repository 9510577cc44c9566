//! The arguments of `deadreckon batch`.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_api::calibration::CalibrationRequest;
use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Params;
use deadreckon_fleet::batch::{BatchOptions, OutageOptions};

/// `batch`'s default request ([`BatchOptions::default`]: the one
/// calibration request's defaults, corrections none): the one place the
/// options' defaults are read from.
fn defaults() -> CalibrationRequest {
    BatchOptions::default().request
}
use deadreckon_fleet::history::HistoryOptions;

/// Arguments of `batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// Drives: drive directories, directories of drive directories, recordings, or glob patterns.
    #[arg(required = true)]
    pub inputs: Vec<String>,
    /// The vehicle shape (default: found from each drive's data; batch
    /// calibrates cars, and a drive found to be another shape fails with
    /// the reason unless --shape car).
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<super::kinematic::ShapeArg>,
    /// The results CSV, one row per drive (written atomically; must not be an input).
    #[arg(long)]
    pub out: PathBuf,
    /// The calibration history CSV, one row per vehicle and parameter and one per change.
    #[arg(long)]
    pub history: Option<PathBuf>,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// rts, zupt or truth (needs truth.csv): `batch` calibrates cars.
    #[arg(long, value_enum, default_value_t = CarMethodArg::Rts)]
    pub method: CarMethodArg,
    /// Maximum smoothing passes per drive.
    #[arg(long, default_value_t = defaults().options.max_iterations as u32, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_iterations: u32,
    /// Filter timing: wheel or each.
    #[arg(long, value_enum, default_value_t = super::TimingArg::of(defaults().options.filter.timing))]
    pub timing: super::TimingArg,
    /// Speed below which epochs are dropped for speed-dependent parameters, m/s.
    #[arg(long, default_value_t = defaults().options.min_speed_mps, value_parser = super::non_negative)]
    pub min_speed: f64,
    /// Also evaluate each drive, with its own parameters, through sliding GNSS outages of this length, s.
    #[arg(long, value_parser = super::positive)]
    pub outage: Option<f64>,
    /// Step between outage windows, s (default: half the outage length).
    #[arg(long, value_parser = super::positive)]
    pub step: Option<f64>,
    /// GNSS-aided time before the first outage window, s.
    #[arg(long, default_value_t = deadreckon_api::evaluate::OUTAGE_WARMUP_S, value_parser = super::non_negative)]
    pub warmup: f64,
    /// The timing and mounting corrections estimated and applied on each drive
    /// before calibrating, as `calibrate --corrections`: all, gnss or none
    /// (default: per-drive delays add variance the history's χ² test does
    /// not know of; see docs/fleet.md).
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::of(defaults().corrections))]
    pub corrections: super::CorrectionsArg,
    /// Significance level of the history's χ² and change-point tests.
    #[arg(long, default_value_t = 1e-3, value_parser = super::probability)]
    pub alpha: f64,
    /// Drive-to-drive tolerance of a parameter, NAME=VALUE in its unit (repeatable; defaults in docs/fleet.md).
    #[arg(long, value_delimiter = ',')]
    pub tolerance: Vec<String>,
}

/// `batch --method`: the car's calibration methods only (`gnss`, the
/// differential drive's, is not offered: `batch` calibrates cars).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CarMethodArg {
    /// RTS-smoothed states of a GNSS-aided filter.
    Rts,
    /// The gyro bias at standstill.
    Zupt,
    /// `truth.csv`.
    Truth,
}

impl CarMethodArg {
    /// The core's method.
    pub fn method(self) -> deadreckon_core::calibrate::Method {
        use deadreckon_core::calibrate::Method;
        match self {
            CarMethodArg::Rts => Method::Rts,
            CarMethodArg::Zupt => Method::Zupt,
            CarMethodArg::Truth => Method::Truth,
        }
    }
}

impl BatchArgs {
    /// The calibration and outage options of every drive.
    pub fn options(&self) -> Result<BatchOptions> {
        let a = self;
        let method = a.method.method();
        let d = defaults().options;
        let options = BatchOptions {
            request: CalibrationRequest {
                options: CalibrationOptions {
                    method,
                    max_iterations: a.max_iterations as usize,
                    min_speed_mps: a.min_speed,
                    filter: FilterOptions {
                        timing: a.timing.into(),
                        ..d.filter
                    },
                    ..d
                },
                corrections: a.corrections.into(),
                ..defaults()
            },
            outage: a.outage.map(|len| OutageOptions {
                length_s: len,
                step_s: a.step.unwrap_or(len / 2.0),
                warmup_s: a.warmup,
            }),
            threads: a.threads,
        };
        Ok(options)
    }

    /// `--alpha` and `--tolerance NAME=VALUE` as the history's options.
    pub fn history_options(&self) -> Result<HistoryOptions> {
        let a = self;
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
}
