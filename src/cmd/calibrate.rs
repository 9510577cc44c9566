//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six
//! parameters of the four-wheel car; for a tricycle log, the kinematic
//! calibration of its seven parameters against the tracker.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{self, CalibrationOptions, Iteration, Method, PassState};
use deadreckon_core::ekf::FilterOptions;

use deadreckon_core::kinematics::{self, KinematicOptions, Shape};

use super::{common, kinematic};

/// Arguments of `calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// The drive directory or recording (a tricycle `dataset.txt` is calibrated through its own kinematics).
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
    /// Speed below which epochs (car) or windows (tricycle) are dropped for speed-dependent parameters, m/s (default: 2 for a car, 0.05 for a tricycle).
    #[arg(long)]
    pub min_speed: Option<f64>,
    /// Use only data from this time on, s (drive clock).
    #[arg(long = "from")]
    pub from_s: Option<f64>,
    /// Use only data before this time, s (drive clock).
    #[arg(long = "until")]
    pub until_s: Option<f64>,
    /// Tricycle: length of the relative-motion windows of the fit, s.
    #[arg(long, default_value_t = 2.0)]
    pub window: f64,
    /// Write the parameters here (params.toml).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs) -> Result<()> {
    kinematic::check_range(a.from_s, a.until_s)?;
    if kinematic::is_tricycle_log(&a.dir) {
        return run_tricycle(&a);
    }
    let method: Method = a.method.parse()?;
    // Only the truth calibration reads truth.csv.
    let read = deadreckon_io::ReadOptions::default();
    let read = if method == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let drive = common::load_drive_with(&a.dir, &read)?;
    let drive = if a.from_s.is_some() || a.until_s.is_some() {
        drive.time_range(a.from_s, a.until_s)
    } else {
        drive
    };
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
        min_speed_mps: a
            .min_speed
            .unwrap_or(Shape::FourWheel.default_min_speed_mps()),
        filter: FilterOptions {
            timing: common::parse_timing(&a.timing)?,
            ..Default::default()
        },
        ..Default::default()
    };
    let c = calibrate::calibrate(&drive, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        let mut extra = toml::Table::new();
        extra.insert("method".into(), a.method.clone().into());
        extra.insert("iterations".into(), (c.iterations as i64).into());
        extra.insert("converged".into(), c.converged.into());
        deadreckon_io::write_params(out, &c.estimate, Some(&extra))
            .with_context(|| format!("writing {}", out.display()))?;
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
        if let Some(out) = &a.out {
            println!("wrote {}", out.display());
        }
    }
    Ok(())
}

/// The tricycle: the seven kinematic parameters against the tracker.
fn run_tricycle(a: &CalibrateArgs) -> Result<()> {
    anyhow::ensure!(
        a.method == "truth",
        "a tricycle log has no GNSS and no gyro: it is calibrated against its tracker with --method truth (got `{}`)",
        a.method
    );
    let drive = kinematic::load_tricycle(&a.dir, a.from_s, a.until_s)?;
    let shape = Shape::Tricycle;
    let opts = KinematicOptions {
        window_s: a.window,
        min_speed_mps: a.min_speed.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let c = kinematics::calibrate(&drive, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        kinematic::write_params(out, shape, &a.method, &c)?;
    }
    if a.json {
        println!(
            "{}",
            serde_json::to_string_pretty(&kinematic::calibration_json(shape, &a.method, &c))?
        );
    } else {
        kinematic::print_table(&c);
        if let Some(out) = &a.out {
            println!("wrote {}", out.display());
        }
    }
    Ok(())
}
