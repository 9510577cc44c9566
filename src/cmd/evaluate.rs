//! `deadreckon evaluate`: dead-reckoning accuracy with the papers' metrics
//! (drift per 100 m, distance before 1 m), evo's (relative pose error per
//! 100 m, absolute pose error) or over sliding GNSS outages.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics::{self, Summary};
use deadreckon_core::outage;
use deadreckon_core::{evo, track};

use super::common;

/// Arguments of `evaluate`.
#[derive(Args, Debug)]
pub struct EvaluateArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// `nominal` or a params.toml. Without it, `--outage` calibrates with RTS on the drive itself.
    #[arg(long)]
    pub params: Option<String>,
    /// drift (reset to the truth every 100 m), reset-1m (reset when the error
    /// reaches 1 m), rpe (evo's relative pose error per --delta-m of path,
    /// translation part) or ape (evo's absolute pose error, no alignment).
    #[arg(long, default_value = "drift")]
    pub metric: String,
    /// rpe/ape: the estimated track (dead-reckoned, filtered, smoothed).
    #[arg(long, default_value = "dead-reckoned")]
    pub track: String,
    /// rpe/ape: the reference track (truth, or an estimated one).
    #[arg(long, default_value = "truth")]
    pub reference: String,
    /// rpe: path length between the poses of a pair, m (evo's --delta with --delta_unit m).
    #[arg(long, default_value_t = 100.0)]
    pub delta_m: f64,
    /// rpe: whose travelled path chooses the pairs: estimate (evo's default) or reference (evo's --pairs_from_reference).
    #[arg(long, default_value = "estimate")]
    pub pairs_from: String,
    /// rpe/ape: largest time difference of associated poses, s (evo's --t_max_diff).
    #[arg(long, default_value_t = evo::DEFAULT_MAX_DIFF_S)]
    pub max_diff_s: f64,
    /// Segment length of the drift metric, m.
    #[arg(long, default_value_t = 100.0)]
    pub segment_m: f64,
    /// Error threshold of the reset metric, m.
    #[arg(long, default_value_t = 1.0)]
    pub threshold_m: f64,
    /// Evaluate over sliding GNSS outages of this length, s (instead of --metric).
    #[arg(long)]
    pub outage: Option<f64>,
    /// Step between outage windows, s (default: half the outage length).
    #[arg(long)]
    pub step: Option<f64>,
    /// GNSS-aided time before the first outage window, s.
    #[arg(long, default_value_t = 5.0)]
    pub warmup: f64,
    /// Filter timing: wheel or each.
    #[arg(long, default_value = "wheel")]
    pub timing: String,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Runs `evaluate`.
pub fn run(a: EvaluateArgs) -> Result<()> {
    let drive = common::load_drive(&a.dir)?;
    let timing = common::parse_timing(&a.timing)?;
    if let Some(len) = a.outage {
        let (params, source) = match &a.params {
            Some(p) => (common::load_params(p, &drive)?, p.clone()),
            None => {
                let c = calibrate::calibrate(&drive, &CalibrationOptions::default())
                    .context("RTS calibration with GNSS")?;
                (c.estimate.params, format!("rts ({} passes)", c.iterations))
            }
        };
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
        let (fe, dr, d1) = (ev.final_error(), ev.drift_pct(), ev.distance_to_1m());
        if a.json {
            let v = deadreckon_api::json::outage_json(len, &source, &ev);
            println!("{}", serde_json::to_string_pretty(&v)?);
        } else {
            println!(
                "{} outage windows of {len} s against the {} (parameters: {source})",
                ev.windows.len(),
                ev.reference.name()
            );
            println!(
                "{:<28} {:>9} {:>9} {:>9} {:>9}",
                "", "mean", "median", "p95", "max"
            );
            for (name, s) in [
                ("final error (m)", fe),
                ("drift per 100 m (%)", dr),
                ("distance before 1 m (m)", d1),
            ] {
                println!(
                    "{:<28} {:>9.3} {:>9.3} {:>9.3} {:>9.3}",
                    name, s.mean, s.median, s.p95, s.max
                );
            }
            println!(
                "rejected by the χ² gates: {}",
                common::gated_text(&ev.gates)
            );
        }
        return Ok(());
    }
    let params = common::load_params(a.params.as_deref().unwrap_or("nominal"), &drive)?;
    match a.metric.as_str() {
        "drift" => {
            let r = metrics::drift(&drive, &params, a.segment_m, timing)?;
            let s = Summary::of(&r.errors_pct());
            if a.json {
                let v = deadreckon_api::json::drift_json(&r, a.segment_m);
                println!("{}", serde_json::to_string_pretty(&v)?);
            } else {
                println!("drift per {} m over {} segments: mean {:.3}%, std {:.3}%, median {:.3}%, max {:.3}%", a.segment_m, s.n, s.mean, s.std, s.median, s.max);
                println!("rejected by the χ² gates: {}", common::gated_text(&r.gates));
            }
        }
        "reset-1m" => {
            let r = metrics::reset_on_error(&drive, &params, a.threshold_m, timing)?;
            let s = Summary::of(&r.distances_m);
            if a.json {
                let v = deadreckon_api::json::reset_json(&r, a.threshold_m);
                println!("{}", serde_json::to_string_pretty(&v)?);
            } else {
                println!(
                    "distance before {} m of error over {} resets: mean {:.1} m, median {:.1} m, min {:.1} m, max {:.1} m",
                    a.threshold_m, s.n, s.mean, s.median, s.min, s.max
                );
                println!("rejected by the χ² gates: {}", common::gated_text(&r.gates));
            }
        }
        "rpe" | "ape" => {
            let opts = FilterOptions {
                timing,
                ..Default::default()
            };
            let all = common::all_tracks(&drive, &params, &opts, None)?;
            // On the values the TUM/KITTI files carry, so evo on the files agrees.
            let reference = &evo::as_written(track::find(&all, &a.reference)?);
            let estimate = &evo::as_written(track::find(&all, &a.track)?);
            let pairs_from = match a.pairs_from.as_str() {
                "estimate" => evo::PairsFrom::Estimate,
                "reference" => evo::PairsFrom::Reference,
                s => anyhow::bail!("unknown --pairs-from `{s}` (estimate, reference)"),
            };
            let r = if a.metric == "rpe" {
                evo::rpe(
                    reference,
                    estimate,
                    &evo::RpeOptions {
                        delta_m: a.delta_m,
                        max_diff_s: a.max_diff_s,
                        pairs_from,
                    },
                )
            } else {
                evo::ape(reference, estimate, a.max_diff_s)
            }
            .with_context(|| format!("{} of `{}` against `{}`", a.metric, a.track, a.reference))?;
            if a.json {
                let q = deadreckon_api::json::EvoQuery {
                    metric: &a.metric,
                    track: &a.track,
                    reference: &a.reference,
                    max_diff_s: a.max_diff_s,
                    delta_m: a.delta_m,
                    pairs_from: &a.pairs_from,
                };
                let v = deadreckon_api::json::evo_json(&q, &r);
                println!("{}", serde_json::to_string_pretty(&v)?);
            } else {
                let what = if a.metric == "rpe" {
                    format!(
                        "RPE per {} m (translation, pairs from the {})",
                        a.delta_m, a.pairs_from
                    )
                } else {
                    "APE (translation, no alignment)".to_string()
                };
                let s = r.stats;
                println!(
                    "{what} of `{}` against `{}`: {} errors over {} associated poses (as evo {})",
                    a.track,
                    a.reference,
                    r.errors_m.len(),
                    r.matched,
                    evo::EVO_VERSION
                );
                println!(
                    "rmse {:.4} m, mean {:.4} m, median {:.4} m, std {:.4} m, min {:.4} m, max {:.4} m",
                    s.rmse, s.mean, s.median, s.std, s.min, s.max
                );
            }
        }
        m => anyhow::bail!("unknown metric `{m}` (drift, reset-1m, rpe, ape)"),
    }
    Ok(())
}
