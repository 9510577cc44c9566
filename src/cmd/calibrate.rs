//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six parameters.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{self, CalibrationOptions, Iteration, Method, PassState};
use deadreckon_core::ekf::FilterOptions;

use super::common;

/// What `calibrate --out` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum OutFormat {
    /// deadreckon's params.toml.
    Params,
    /// Autoware's imu_corrector.param.yaml and vehicle_velocity_converter.param.yaml.
    Autoware,
    /// Eagleye's eagleye_config.yaml keys and velocity_scale_factor.txt.
    Eagleye,
}

/// Arguments of `calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// rts (smoothed states, needs GNSS), zupt (standstill gyro bias), truth (needs truth.csv).
    #[arg(long, default_value = "rts")]
    pub method: String,
    /// What each smoothing pass carries: augmented (car state + the six parameters) or paper (5-state, parameters fixed).
    #[arg(long, default_value = "augmented")]
    pub state: String,
    /// Chaining of the smoothing passes: anderson (accelerated) or plain (the paper's).
    #[arg(long, default_value = "anderson")]
    pub iteration: String,
    /// Maximum smoothing passes.
    #[arg(long, default_value_t = 60)]
    pub max_iterations: usize,
    /// Filter timing: wheel (the paper's, one epoch per wheel row) or each (every reading at its time).
    #[arg(long, default_value = "wheel")]
    pub timing: String,
    /// Speed below which epochs are dropped for speed-dependent parameters, m/s.
    #[arg(long, default_value_t = 2.0)]
    pub min_speed: f64,
    /// Write the parameters here: a params.toml, or with --format autoware or
    /// eagleye a directory (created if missing).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// What --out holds: params (params.toml), autoware (imu_corrector and
    /// vehicle_velocity_converter parameter files) or eagleye (configuration
    /// keys and the saved velocity scale factor); see docs/stack-params.md.
    #[arg(long, value_enum, default_value_t = OutFormat::Params)]
    pub format: OutFormat,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs) -> Result<()> {
    let method: Method = a.method.parse()?;
    // Only the truth calibration reads truth.csv.
    let read = deadreckon_io::ReadOptions::default();
    let read = if method == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let drive = common::load_drive_with(&a.dir, &read)?;
    let iteration = match a.iteration.as_str() {
        "anderson" => Iteration::Anderson,
        "plain" => Iteration::Plain,
        s => anyhow::bail!("unknown iteration `{s}` (anderson, plain)"),
    };
    let state = match a.state.as_str() {
        "augmented" => PassState::Augmented,
        "paper" => PassState::Paper,
        s => anyhow::bail!("unknown pass state `{s}` (augmented, paper)"),
    };
    let opts = CalibrationOptions {
        method,
        state,
        iteration,
        max_iterations: a.max_iterations,
        min_speed_mps: a.min_speed,
        filter: FilterOptions {
            timing: common::parse_timing(&a.timing)?,
            ..Default::default()
        },
        ..Default::default()
    };
    let c = calibrate::calibrate(&drive, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    let mut written = Vec::new();
    if let Some(out) = &a.out {
        let export = || deadreckon_io::stack_params::StackExport {
            estimate: &c.estimate,
            samples: c.samples,
            noise: &drive.vehicle.noise,
            provenance: format!(
                "Calibrated on {} with --method {} ({} passes, {}).",
                a.dir.display(),
                a.method,
                c.iterations,
                if c.converged {
                    "converged"
                } else {
                    "NOT converged"
                }
            ),
        };
        let context = || format!("writing {}", out.display());
        match a.format {
            OutFormat::Params => {
                let mut extra = toml::Table::new();
                extra.insert("method".into(), a.method.clone().into());
                extra.insert("iterations".into(), (c.iterations as i64).into());
                extra.insert("converged".into(), c.converged.into());
                deadreckon_io::write_params(out, &c.estimate, Some(&extra))
                    .with_context(context)?;
                written.push(out.clone());
            }
            OutFormat::Autoware => written.extend(
                deadreckon_io::stack_params::write_autoware(out, &export())
                    .with_context(context)?,
            ),
            OutFormat::Eagleye => written.extend(
                deadreckon_io::stack_params::write_eagleye(out, &export()).with_context(context)?,
            ),
        }
    } else if a.format != OutFormat::Params {
        anyhow::bail!(
            "--format {} needs --out DIR",
            format!("{:?}", a.format).to_lowercase()
        );
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&common::calibration_json(&a.method, &c))?
        );
    } else {
        println!("{}", common::params_header());
        println!("{}", common::params_row(&a.method, &c.estimate));
        if method == Method::Rts {
            println!(
                "{} smoothing passes ({} state, {} iteration), {}",
                c.iterations,
                a.state,
                a.iteration,
                if c.converged {
                    "converged"
                } else {
                    "NOT converged: raise --max-iterations"
                }
            );
        }
        if let Some(st) = &c.filter_stats {
            println!("{}", common::stats_line(st));
        }
        for w in &written {
            println!("wrote {}", w.display());
        }
    }
    Ok(())
}
