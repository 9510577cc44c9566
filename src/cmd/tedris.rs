//! `deadreckon tedris train|run`: TedriS over a drive directory (the library is
//! `deadreckon-tedris`; this file parses, calls and prints).

use std::path::PathBuf;

use anyhow::{bail, Context, Result};
use clap::{Subcommand, ValueEnum};
use deadreckon_tedris::{
    run_outages_with, ModelKind, Outage, ReferenceSource, RunOptions, TedrisConfig, TedrisModel,
    Variant,
};

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
    fn source(self) -> Option<ReferenceSource> {
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
        #[arg(long = "from", value_parser = super::common::finite, allow_hyphen_values = true)]
        from_s: Option<f64>,
        /// Train only on data before this time, s (drive clock).
        #[arg(long = "until", value_parser = super::common::finite, allow_hyphen_values = true)]
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
        #[arg(long, default_value_t = 1.0, value_parser = super::common::positive)]
        threshold_m: f64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
}

/// `--epsilon-k`: a positive finite factor, or `inf` (`None`) for one
/// repository.
#[derive(Debug, Clone, Copy)]
pub struct EpsilonK(Option<f64>);

fn epsilon_k(s: &str) -> std::result::Result<EpsilonK, String> {
    if s.trim() == "inf" {
        Ok(EpsilonK(None))
    } else {
        super::common::positive(s).map(|k| EpsilonK(Some(k)))
    }
}

/// Runs a TedriS subcommand.
pub fn run(c: TedrisCommand, load: &super::common::Loader) -> Result<()> {
    match c {
        TedrisCommand::Train {
            dir,
            out,
            reference,
            model,
            tau,
            epsilon_k,
            separate_repositories,
            variant,
            config,
            from_s,
            until_s,
            json,
        } => {
            if let (Some(a), Some(b)) = (from_s, until_s) {
                if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
                    bail!("--from {a} must be before --until {b}");
                }
            }
            let inputs: Vec<&std::path::Path> = std::iter::once(dir.as_path())
                .chain(config.as_deref())
                .collect();
            super::common::check_output(&out, &inputs)?;
            let drive = load.drive(&dir)?;
            let drive = if from_s.is_some() || until_s.is_some() {
                drive.time_range(from_s, until_s)
            } else {
                drive
            };
            let config = match &config {
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
            let options = deadreckon_api::tedris::TrainOptions {
                reference: reference.source(),
                config,
                variant: variant.map(|v| match v {
                    VariantArg::Paper => Variant::Paper,
                    VariantArg::Extended => Variant::Extended,
                }),
                model: match model {
                    Kind::Auto => None,
                    Kind::Paper => Some(ModelKind::Paper),
                    Kind::Distance => Some(ModelKind::Distance),
                    Kind::Arx => Some(ModelKind::Arx),
                    Kind::Baseline => Some(ModelKind::Baseline),
                },
                tau_samples: tau.map(|t| t as usize),
                epsilon_factor: epsilon_k.map(|k| k.0),
                separate_repositories,
            };
            let (m, source) = deadreckon_api::tedris::train(&drive, &options)?;
            let text = serde_json::to_string_pretty(&m)?;
            // Whole or not at all (a temporary beside it, renamed), with
            // the permissions of a model it replaces.
            deadreckon_io::atomic_write(&out, |w| w.write_all(text.as_bytes()))
                .with_context(|| format!("writing {}", out.display()))?;
            if json {
                super::common::print_json(
                    load,
                    deadreckon_api::json::tedris_train_json(&m, source),
                )?;
            } else {
                print_train(&m, source)?;
                outln!("model written to {}", out.display());
            }
            Ok(())
        }
        TedrisCommand::Run {
            dir,
            model,
            outages,
            out,
            reference,
            threshold_m,
            json,
        } => {
            if let Some(p) = &out {
                super::common::check_output(p, &[&dir, &model])?;
            }
            let m = deadreckon_api::tedris::read_model(&model)?;
            let outages: Vec<Outage> = outages
                .iter()
                .map(|s| s.parse())
                .collect::<Result<_, _>>()?;
            if !(threshold_m.is_finite() && threshold_m > 0.0) {
                bail!("--threshold-m must be a positive number");
            }
            let drive = load.drive(&dir)?;
            let opts = RunOptions {
                source: reference.source(),
                threshold_m: Some(threshold_m),
            };
            let r = run_outages_with(&drive, &m, &outages, &opts)?;
            if let Some(p) = &out {
                deadreckon_io::write_track_csv(p, std::slice::from_ref(&r.track))
                    .with_context(|| format!("writing {}", p.display()))?;
            }
            if json {
                let v = serde_json::json!({
                    "outages": r.outages,
                    "reference": r.reference,
                    "source": r.source,
                    "model": m.chosen.name(),
                    "checks": r.machine.checks(),
                    "track": out.as_ref().map(|p| p.display().to_string()),
                });
                super::common::print_json(load, v)?;
            } else {
                for l in deadreckon_api::text::tedris_outage_lines(&r, threshold_m) {
                    outln!("{l}");
                }
                if let Some(p) = &out {
                    outln!("track written to {}", p.display());
                }
            }
            Ok(())
        }
    }
}

fn print_train(m: &TedrisModel, source: ReferenceSource) -> anyhow::Result<()> {
    for l in deadreckon_api::text::tedris_train_lines(m, source) {
        outln!("{l}");
    }
    Ok(())
}
