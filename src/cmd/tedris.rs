//! `deadreckon tedris train|run`: TedriS over a drive directory (the library is
//! `deadreckon-tedris`; this file parses, calls and prints).

use anyhow::{bail, Context, Result};
use deadreckon_tedris::{
    run_outages_with, ModelKind, Outage, ReferenceSource, RunOptions, TedrisConfig, TedrisModel,
    Variant,
};

use crate::args::tedris::*;

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
            deadreckon_api::load::check_range(from_s, until_s)?;
            let inputs: Vec<&std::path::Path> = std::iter::once(dir.as_path())
                .chain(config.as_deref())
                .collect();
            super::common::check_output(&out, &inputs)?;
            let drive = deadreckon_api::load::cut(load.drive(&dir)?, from_s, until_s)?;
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
