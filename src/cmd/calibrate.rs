//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six
//! parameters of the four-wheel car; for a tricycle log, the kinematic
//! calibration of its seven parameters against the tracker.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::calibrate::{CalibrationOptions, Iteration, Method, PassState};
use deadreckon_core::ekf::FilterOptions;

use deadreckon_core::kinematics::diff_drive::{calibrate_diff_drive, DiffDriveOptions};
use deadreckon_core::kinematics::{self, KinematicOptions, Shape};

use super::kinematic::{ShapeArg, YawArg};
use super::{common, kinematic};

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

/// `calibrate --state`: what each smoothing pass carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StateArg {
    /// The car state and the six parameters.
    Augmented,
    /// The paper's 5-state filter, parameters fixed within a pass.
    Paper,
}

/// `calibrate --iteration`: how the smoothing passes are chained.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum IterationArg {
    /// Anderson-accelerated.
    Anderson,
    /// The paper's plain fixed-point iteration.
    Plain,
}

impl std::fmt::Display for StateArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StateArg::Augmented => "augmented",
            StateArg::Paper => "paper",
        })
    }
}

impl std::fmt::Display for IterationArg {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            IterationArg::Anderson => "anderson",
            IterationArg::Plain => "plain",
        })
    }
}

/// Arguments of `calibrate`.
#[derive(Args, Debug)]
pub struct CalibrateArgs {
    /// The drive directory or recording (a tricycle `dataset.txt` is calibrated through its own kinematics).
    pub dir: PathBuf,
    /// rts (smoothed states, needs GNSS), zupt (standstill gyro bias), truth (needs truth.csv); a tricycle: truth (its tracker); a differential drive: gnss (default: rts, truth, gnss by shape).
    #[arg(long, value_enum)]
    pub method: Option<common::MethodArg>,
    /// The vehicle shape: car (four wheels, the default) or diff-drive (odometry twist, calibrated against GNSS). A tricycle log is recognised by itself.
    #[arg(long, value_enum, default_value_t = ShapeArg::Car)]
    pub shape: ShapeArg,
    /// Differential drive: the yaw rate integrated, gyro or odometry.
    #[arg(long, value_enum, default_value_t = YawArg::Gyro)]
    pub yaw: YawArg,
    /// What each smoothing pass carries: augmented (car state + the six parameters) or paper (5-state, parameters fixed).
    #[arg(long, value_enum, default_value_t = StateArg::Augmented)]
    pub state: StateArg,
    /// Chaining of the smoothing passes: anderson (accelerated) or plain (the paper's).
    #[arg(long, value_enum, default_value_t = IterationArg::Anderson)]
    pub iteration: IterationArg,
    /// Maximum smoothing passes.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_iterations: u32,
    /// Filter timing: wheel (the paper's, one epoch per wheel row) or each (every reading at its time).
    #[arg(long, value_enum, default_value_t = common::TimingArg::Wheel)]
    pub timing: common::TimingArg,
    /// Speed below which epochs (car) or windows (tricycle) are dropped for speed-dependent parameters, m/s (default: 2 for a car, 0.05 for a tricycle).
    #[arg(long, value_parser = common::non_negative)]
    pub min_speed: Option<f64>,
    /// Use only data from this time on, s (drive clock).
    #[arg(long = "from", value_parser = common::finite, allow_hyphen_values = true)]
    pub from_s: Option<f64>,
    /// Use only data before this time, s (drive clock).
    #[arg(long = "until", value_parser = common::finite, allow_hyphen_values = true)]
    pub until_s: Option<f64>,
    /// Tricycle and differential drive: length of the windows of the fit, s (default 2 for a tricycle, 60 for a differential drive).
    #[arg(long, value_parser = common::positive)]
    pub window: Option<f64>,
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
    /// The timing and mounting corrections estimated and applied before
    /// calibrating, and written to params.toml: all (IMU tilt and every
    /// stream's delay), gnss (tilt and GNSS delay; the others reported, not
    /// applied) or none.
    #[arg(long, value_enum, default_value_t = common::CorrectionsArg::Gnss)]
    pub corrections: common::CorrectionsArg,
    /// Fuse every wheel reading: no wheel-health monitor (slipping and bad
    /// wheels are then neither dropped nor reported).
    #[arg(long)]
    pub no_wheel_monitor: bool,
}

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs, load: &common::Loader) -> Result<()> {
    kinematic::check_range(a.from_s, a.until_s)?;
    // A params.toml onto the drive's own files; the stack formats write new
    // files into a directory, which may be the drive's.
    if let (Some(out), OutFormat::Params) = (&a.out, a.format) {
        common::check_output(out, &[&a.dir])?;
    }
    if kinematic::is_tricycle_log(&a.dir) {
        return run_tricycle(&a);
    }
    if a.shape == ShapeArg::DiffDrive {
        return run_diff_drive(&a, load);
    }
    let method_name = a
        .method
        .unwrap_or(common::MethodArg::Rts)
        .name()
        .to_string();
    let method: Method = a.method.unwrap_or(common::MethodArg::Rts).car()?;
    // Only the truth calibration reads truth.csv.
    let read = deadreckon_io::ReadOptions::default();
    let read = if method == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let drive = load.drive_with(&a.dir, &read)?;
    let drive = if a.from_s.is_some() || a.until_s.is_some() {
        drive.time_range(a.from_s, a.until_s)
    } else {
        drive
    };
    let iteration = match a.iteration {
        IterationArg::Anderson => Iteration::Anderson,
        IterationArg::Plain => Iteration::Plain,
    };
    let state = match a.state {
        StateArg::Augmented => PassState::Augmented,
        StateArg::Paper => PassState::Paper,
    };
    let opts = CalibrationOptions {
        method,
        state,
        iteration,
        max_iterations: a.max_iterations as usize,
        min_speed_mps: a
            .min_speed
            .unwrap_or(Shape::FourWheel.default_min_speed_mps()),
        filter: FilterOptions {
            timing: a.timing.into(),
            wheel_monitor: common::wheel_monitor(a.no_wheel_monitor),
            ..Default::default()
        },
        ..Default::default()
    };
    let cc = deadreckon_api::calibrate::calibrate_car(
        &drive,
        &method_name,
        opts,
        a.corrections.into(),
        &a.dir.display().to_string(),
    )?;
    let mut written = Vec::new();
    if let Some(out) = &a.out {
        let export = || deadreckon_io::stack_params::StackExport {
            estimate: &cc.calibration.estimate,
            samples: cc.calibration.samples,
            noise: &drive.vehicle.noise,
            provenance: cc.provenance(&a.dir.display().to_string()),
        };
        let context = || format!("writing {}", out.display());
        match a.format {
            OutFormat::Params => {
                deadreckon_io::write_params(
                    out,
                    &cc.calibration.estimate,
                    Some(&cc.params_extra()),
                )
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
        common::print_json(load, cc.json())?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        for l in cc.lines(&a.state.to_string(), &a.iteration.to_string()) {
            outln!("{l}");
        }
        for w in &written {
            outln!("wrote {}", w.display());
        }
    }
    Ok(())
}

/// The tricycle: the seven kinematic parameters against the tracker.
fn run_tricycle(a: &CalibrateArgs) -> Result<()> {
    let method = a.method.map_or("truth", common::MethodArg::name);
    anyhow::ensure!(
        method == "truth",
        "a tricycle log has no GNSS and no gyro: it is calibrated against its tracker with --method truth (got `{method}`)"
    );
    let drive = kinematic::load_tricycle(&a.dir, a.from_s, a.until_s)?;
    let shape = Shape::Tricycle;
    let opts = KinematicOptions {
        window_s: a.window.unwrap_or(2.0),
        min_speed_mps: a.min_speed.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let c = kinematics::calibrate(&drive, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        kinematic::write_params(out, shape, method, None, &c)?;
    }
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&deadreckon_api::json::kinematic_calibration_json(
                shape, method, &c
            ))?
        );
    } else {
        kinematic::print_table(&c)?;
        if let Some(out) = &a.out {
            outln!("wrote {}", out.display());
        }
    }
    Ok(())
}

/// The differential drive: five parameters against the GNSS fixes.
fn run_diff_drive(a: &CalibrateArgs, load: &common::Loader) -> Result<()> {
    let method = a.method.map_or("gnss", common::MethodArg::name);
    anyhow::ensure!(
        method == "gnss",
        "a differential drive is calibrated against its GNSS fixes with --method gnss (got `{method}`)"
    );
    let drive = load.drive(&a.dir)?;
    let dd = kinematic::diff_drive(&drive, a.yaw, a.from_s, a.until_s)?;
    let shape = Shape::DiffDrive;
    let opts = DiffDriveOptions {
        window_s: a.window.unwrap_or(DiffDriveOptions::default().window_s),
        min_speed_mps: a.min_speed.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let c = calibrate_diff_drive(&dd, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        kinematic::write_params(out, shape, method, Some(a.yaw.name()), &c)?;
    }
    if a.json {
        let mut v = deadreckon_api::json::kinematic_calibration_json(shape, method, &c);
        v["yaw_source"] = a.yaw.name().into();
        common::print_json(load, v)?;
    } else {
        kinematic::print_table(&c)?;
        if let Some(out) = &a.out {
            outln!("wrote {}", out.display());
        }
    }
    Ok(())
}
