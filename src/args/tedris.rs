//! The arguments of `deadreckon tedris`.

use std::path::PathBuf;

use clap::{Subcommand, ValueEnum};
use deadreckon_tedris::ReferenceSource;

/// The reference heading the model learns from.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum Reference {
    /// GNSS course if the receiver gives one, else the gyro, else the course from chords between fixes.
    Auto,
    /// The receiver's course over ground (`course_deg`).
    Course,
    /// The direction between successive GNSS fixes.
    Track,
    /// The integrated gyro (the paper's robot).
    Gyro,
}

impl Reference {
    pub fn source(self) -> Option<ReferenceSource> {
        match self {
            Reference::Auto => None,
            Reference::Course => Some(ReferenceSource::GnssCourse),
            Reference::Track => Some(ReferenceSource::GnssTrack),
            Reference::Gyro => Some(ReferenceSource::Gyro),
        }
    }
}

/// The method variant.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum VariantArg {
    /// The paper's method alone.
    Paper,
    /// With this crate's additions (the default).
    Extended,
}

/// The regression.
#[derive(ValueEnum, Clone, Copy, Debug)]
pub enum Kind {
    /// Chosen on the data: with the joint calibration (the default), the kind
    /// whose calibrated heading has the smallest residual on held-back data
    /// (paper, distance or baseline with a GNSS course); without it, the smallest BIC
    /// among kinds with white final innovations.
    Auto,
    /// The paper's γ = α0 + α1·ω.
    Paper,
    /// γ = α0 + α1·ω + α2·d (travelled distance per sample).
    Distance,
    /// ARX(1,1) over consecutive blocks.
    Arx,
    /// The plain least-squares model: γ = α1·ω + α2·d, one global fit, no
    /// intercept, no repositories.
    Baseline,
}

/// TedriS subcommands.
#[derive(Subcommand, Debug)]
pub enum TedrisCommand {
    /// Train a model on a drive (GNSS good throughout) and print the regression
    /// table, lag, µ, W_L, W_H, ε and the repository fill.
    Train {
        /// The drive directory.
        dir: PathBuf,
        /// Where to write the model (JSON).
        #[arg(long)]
        out: PathBuf,
        /// Reference heading.
        #[arg(long, value_enum, default_value = "auto")]
        reference: Reference,
        /// Regression kind.
        #[arg(long, value_enum, default_value = "auto")]
        model: Kind,
        /// τ, samples per block.
        #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
        tau: Option<u32>,
        /// k of ε = k·(W_H − W_L); `inf` for one repository (the paper's robot).
        #[arg(long, value_parser = epsilon_k)]
        epsilon_k: Option<EpsilonK>,
        /// Fit each repository separately, as in the paper (default: pooled slopes).
        #[arg(long)]
        separate_repositories: bool,
        /// The method: `paper` (the paper's alone: its regression, ε = 1.5,
        /// separate repositories, eq. 6) or `extended` (default; see docs/tedris.md).
        #[arg(long, value_enum)]
        variant: Option<VariantArg>,
        /// A TedriS configuration (JSON; missing keys take their defaults; every
        /// key with its unit and default: docs/tedris.md).
        #[arg(long)]
        config: Option<PathBuf>,
        /// Train only on data from this time on, s (drive clock).
        #[arg(long = "from", value_parser = super::finite, allow_hyphen_values = true)]
        from_s: Option<f64>,
        /// Train only on data before this time, s (drive clock).
        #[arg(long = "until", value_parser = super::finite, allow_hyphen_values = true)]
        until_s: Option<f64>,
        /// Print JSON instead of tables.
        #[arg(long)]
        json: bool,
    },
    /// Blank GNSS in the outage windows, predict through them, write the track and
    /// report the error over each outage.
    Run {
        /// The drive directory.
        dir: PathBuf,
        /// The trained model.
        #[arg(long)]
        model: PathBuf,
        /// An outage window `START_S:END_S` (drive clock); repeatable.
        #[arg(long = "outage", required = true)]
        outages: Vec<String>,
        /// Where to write the track (CSV).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Reference heading.
        #[arg(long, value_enum, default_value = "auto")]
        reference: Reference,
        /// The error threshold reported as `time_to_threshold_s`, m.
        #[arg(long, default_value_t = 1.0, value_parser = super::positive)]
        threshold_m: f64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

/// `--epsilon-k`: a positive finite factor, or `inf` (`None`) for one
/// repository.
#[derive(Debug, Clone, Copy)]
pub struct EpsilonK(pub Option<f64>);

fn epsilon_k(s: &str) -> std::result::Result<EpsilonK, String> {
    if s.trim() == "inf" {
        Ok(EpsilonK(None))
    } else {
        super::positive(s).map(|k| EpsilonK(Some(k)))
    }
}
