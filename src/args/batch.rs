//! The arguments of `deadreckon batch`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `batch`.
#[derive(Args, Debug)]
pub struct BatchArgs {
    /// Drives: drive directories, directories of drive directories, recordings, or glob patterns.
    #[arg(required = true)]
    pub inputs: Vec<String>,
    /// The results CSV, one row per drive (written atomically; must not be an input).
    #[arg(long)]
    pub out: PathBuf,
    /// The calibration history CSV, one row per vehicle and parameter and one per change.
    #[arg(long)]
    pub history: Option<PathBuf>,
    /// Worker threads (0: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// rts, zupt or truth (needs truth.csv).
    #[arg(long, value_enum, default_value_t = super::MethodArg::Rts)]
    pub method: super::MethodArg,
    /// Maximum smoothing passes per drive.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_iterations: u32,
    /// Filter timing: wheel or each.
    #[arg(long, value_enum, default_value_t = super::TimingArg::Wheel)]
    pub timing: super::TimingArg,
    /// Speed below which epochs are dropped for speed-dependent parameters, m/s.
    #[arg(long, default_value_t = 2.0, value_parser = super::non_negative)]
    pub min_speed: f64,
    /// Also evaluate each drive, with its own parameters, through sliding GNSS outages of this length, s.
    #[arg(long, value_parser = super::positive)]
    pub outage: Option<f64>,
    /// Step between outage windows, s (default: half the outage length).
    #[arg(long, value_parser = super::positive)]
    pub step: Option<f64>,
    /// GNSS-aided time before the first outage window, s.
    #[arg(long, default_value_t = 5.0, value_parser = super::non_negative)]
    pub warmup: f64,
    /// Significance level of the history's χ² and change-point tests.
    #[arg(long, default_value_t = 1e-3, value_parser = super::probability)]
    pub alpha: f64,
    /// Drive-to-drive tolerance of a parameter, NAME=VALUE in its unit (repeatable; defaults in docs/fleet.md).
    #[arg(long, value_delimiter = ',')]
    pub tolerance: Vec<String>,
}
