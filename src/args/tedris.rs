//! The arguments of `deadreckon tedris`.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
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
    /// γ = α0 + α1·ω + α2·d + α3·ω·d²: the distance kind with a turn gain
    /// falling with the square of the speed (loaded outer tyres in turns).
    Speed,
}

/// TedriS subcommands.
#[derive(Subcommand, Debug)]
pub enum TedrisCommand {
    /// Train a model on a drive (GNSS good throughout) and print the regression
    /// table, lag, µ, W_L, W_H, ε and the repository fill.
    Train(TrainArgs),
    /// Blank GNSS in the outage windows, predict through them, write the track and
    /// report the error over each outage.
    Run(RunArgs),
}

/// Arguments of `tedris train`.
#[derive(Args, Debug)]
pub struct TrainArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// Where to write the model (JSON).
    #[arg(long)]
    pub out: PathBuf,
    /// Reference heading.
    #[arg(long, value_enum, default_value = "auto")]
    pub reference: Reference,
    /// Regression kind.
    #[arg(long, value_enum, default_value = "auto")]
    pub model: Kind,
    /// τ, samples per block.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub tau: Option<u32>,
    /// k of ε = k·(W_H − W_L); `inf` for one repository (the paper's robot).
    #[arg(long, value_parser = epsilon_k)]
    pub epsilon_k: Option<EpsilonK>,
    /// Fit each repository separately, as in the paper (default: pooled slopes).
    #[arg(long)]
    pub separate_repositories: bool,
    /// The method: `paper` (the paper's alone: its regression, ε = 1.5,
    /// separate repositories, eq. 6) or `extended` (default; see docs/tedris.md).
    #[arg(long, value_enum)]
    pub variant: Option<VariantArg>,
    /// A TedriS configuration (JSON; missing keys take their defaults; every
    /// key with its unit and default: docs/tedris.md).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// A params.toml whose stored corrections (delays, IMU tilt, gyro scale;
    /// `calibrate` writes them) are applied to the drive before training;
    /// the model keeps them and `tedris run` applies them too.
    #[arg(long)]
    pub params: Option<String>,
    /// Train only on data from this time on, s (drive clock).
    #[arg(long = "from", value_parser = super::finite, allow_hyphen_values = true)]
    pub from_s: Option<f64>,
    /// Train only on data before this time, s (drive clock).
    #[arg(long = "until", value_parser = super::finite, allow_hyphen_values = true)]
    pub until_s: Option<f64>,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `tedris run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// The trained model.
    #[arg(long)]
    pub model: PathBuf,
    /// An outage window `START_S:END_S` (drive clock); repeatable.
    #[arg(long = "outage", required = true)]
    pub outages: Vec<String>,
    /// Where to write the track (CSV).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Reference heading.
    #[arg(long, value_enum, default_value = "auto")]
    pub reference: Reference,
    /// A params.toml whose stored corrections are applied to the drive
    /// (default: those the model was trained with, if any).
    #[arg(long)]
    pub params: Option<String>,
    /// The error threshold reported as `time_to_threshold_s`, m.
    #[arg(long, default_value_t = 1.0, value_parser = super::positive)]
    pub threshold_m: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
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

impl TrainArgs {
    /// The training options, with the configuration file read.
    pub fn options(&self) -> anyhow::Result<deadreckon_api::tedris::TrainOptions> {
        use anyhow::Context;
        use deadreckon_tedris::{ModelKind, TedrisConfig, Variant};
        let config = match &self.config {
            Some(p) => {
                let text = std::fs::read_to_string(p)
                    .with_context(|| format!("reading {}", p.display()))?;
                Some(
                    serde_json::from_str::<TedrisConfig>(&text)
                        .with_context(|| format!("parsing {}", p.display()))?,
                )
            }
            None => None,
        };
        Ok(deadreckon_api::tedris::TrainOptions {
            reference: self.reference.source(),
            config,
            variant: self.variant.map(|v| match v {
                VariantArg::Paper => Variant::Paper,
                VariantArg::Extended => Variant::Extended,
            }),
            model: match self.model {
                Kind::Auto => None,
                Kind::Paper => Some(ModelKind::Paper),
                Kind::Distance => Some(ModelKind::Distance),
                Kind::Arx => Some(ModelKind::Arx),
                Kind::Baseline => Some(ModelKind::Baseline),
                Kind::Speed => Some(ModelKind::Speed),
            },
            tau_samples: self.tau.map(|t| t as usize),
            epsilon_factor: self.epsilon_k.map(|k| k.0),
            separate_repositories: self.separate_repositories,
            params: self.params.clone(),
        })
    }
}

impl RunArgs {
    /// The `--outage START_S:END_S` windows.
    pub fn outage_windows(
        &self,
    ) -> Result<Vec<deadreckon_tedris::Outage>, deadreckon_tedris::Error> {
        self.outages.iter().map(|s| s.parse()).collect()
    }
}
