//! The arguments of `deadreckon calibrate`.

use deadreckon_api::calibration::CalibrationRequest;
use deadreckon_core::calibrate::{CalibrationOptions, Iteration, PassState};
use deadreckon_core::ekf::FilterOptions;

use std::path::PathBuf;

use clap::Args;

use super::kinematic::{ShapeArg, YawArg};

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

impl StateArg {
    /// The argument naming `s`.
    pub fn of(s: PassState) -> StateArg {
        match s {
            PassState::Augmented => StateArg::Augmented,
            PassState::Paper => StateArg::Paper,
        }
    }
}

impl IterationArg {
    /// The argument naming `i`.
    pub fn of(i: Iteration) -> IterationArg {
        match i {
            Iteration::Anderson => IterationArg::Anderson,
            Iteration::Plain => IterationArg::Plain,
        }
    }
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
    pub method: Option<super::MethodArg>,
    /// The vehicle shape (default: found from the data).
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<ShapeArg>,
    /// Differential drive: the yaw rate integrated, gyro or odometry.
    #[arg(long, value_enum, default_value_t = YawArg::Gyro)]
    pub yaw: YawArg,
    /// What each smoothing pass carries: augmented (car state + the six parameters) or paper (5-state, parameters fixed).
    #[arg(long, value_enum, default_value_t = StateArg::of(defaults().options.state))]
    pub state: StateArg,
    /// Chaining of the smoothing passes: anderson (accelerated) or plain (the paper's).
    #[arg(long, value_enum, default_value_t = IterationArg::of(defaults().options.iteration))]
    pub iteration: IterationArg,
    /// Maximum smoothing passes.
    #[arg(long, default_value_t = defaults().options.max_iterations as u32, value_parser = clap::value_parser!(u32).range(1..))]
    pub max_iterations: u32,
    /// Filter timing: wheel (the paper's, one epoch per wheel row) or each (every reading at its time).
    #[arg(long, value_enum, default_value_t = super::TimingArg::of(defaults().options.filter.timing))]
    pub timing: super::TimingArg,
    /// Speed below which epochs (car) or windows (tricycle) are dropped for speed-dependent parameters, m/s (default: 2 for a car, 0.05 for a tricycle).
    #[arg(long, value_parser = super::non_negative)]
    pub min_speed: Option<f64>,
    /// Use only data from this time on, s (drive clock).
    #[arg(long = "from", value_parser = super::finite, allow_hyphen_values = true)]
    pub from_s: Option<f64>,
    /// Use only data before this time, s (drive clock).
    #[arg(long = "until", value_parser = super::finite, allow_hyphen_values = true)]
    pub until_s: Option<f64>,
    /// Tricycle and differential drive: length of the windows of the fit, s (default 2 for a tricycle, 60 for a differential drive).
    #[arg(long, value_parser = super::positive)]
    pub window: Option<f64>,
    /// Differential drive: fit every parameter the drive determines, without
    /// keeping a nominal value where the drive's held-back GNSS prefers it.
    #[arg(long)]
    pub every_param: bool,
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
    /// The timing and mounting corrections estimated before calibrating, and
    /// written to params.toml: auto (each applied only when it lowers the
    /// dead-reckoning error through the drive's own GNSS held back from the
    /// calibration), all (driven axle's slip, IMU tilt, every stream's delay,
    /// gyro scale), gnss (as all, the other streams' delays reported, not
    /// applied) or none.
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::of(defaults().corrections))]
    pub corrections: super::CorrectionsArg,
    /// Fuse every wheel reading: no wheel-health monitor (slipping and bad
    /// wheels are then neither dropped nor reported).
    #[arg(long)]
    pub no_wheel_monitor: bool,
}

/// The default request ([`CalibrationRequest::default`]): the one place
/// the options' defaults are read from.
fn defaults() -> CalibrationRequest {
    CalibrationRequest::default()
}

impl CalibrateArgs {
    /// The car's calibration request; a stack format without `--out`
    /// refused.
    pub fn request(&self) -> anyhow::Result<CalibrationRequest> {
        let a = self;
        let method = a.method.unwrap_or(super::MethodArg::Rts);
        let d = defaults().options;
        let options = CalibrationOptions {
            method: method.car()?,
            state: match a.state {
                StateArg::Augmented => PassState::Augmented,
                StateArg::Paper => PassState::Paper,
            },
            iteration: match a.iteration {
                IterationArg::Anderson => Iteration::Anderson,
                IterationArg::Plain => Iteration::Plain,
            },
            max_iterations: a.max_iterations as usize,
            min_speed_mps: a.min_speed.unwrap_or(d.min_speed_mps),
            filter: FilterOptions {
                timing: a.timing.into(),
                wheel_monitor: if a.no_wheel_monitor {
                    None
                } else {
                    d.filter.wheel_monitor
                },
                ..d.filter
            },
            ..d
        };
        if a.out.is_none() && a.format != OutFormat::Params {
            anyhow::bail!(
                "--format {} needs --out DIR",
                format!("{:?}", a.format).to_lowercase()
            );
        }
        Ok(CalibrationRequest {
            options,
            corrections: a.corrections.into(),
            ..defaults()
        })
    }
}

impl From<OutFormat> for deadreckon_api::calibrate::Export {
    fn from(f: OutFormat) -> Self {
        match f {
            OutFormat::Params => Self::Params,
            OutFormat::Autoware => Self::Autoware,
            OutFormat::Eagleye => Self::Eagleye,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        calibrate: CalibrateArgs,
    }

    #[test]
    fn the_defaults_of_calibrate_are_the_librarys_request() {
        let a = Cli::parse_from(["calibrate", "DRIVE"]).calibrate;
        assert_eq!(a.request().unwrap(), CalibrationRequest::default());
    }

    #[test]
    fn the_defaults_of_batch_are_the_fleets_request() {
        #[derive(Parser)]
        struct Batch {
            #[command(flatten)]
            batch: crate::args::batch::BatchArgs,
        }
        let a = Batch::parse_from(["batch", "DRIVE", "--out", "x.csv"]).batch;
        let o = a.options().unwrap();
        assert_eq!(
            o.request,
            deadreckon_fleet::batch::BatchOptions::default().request
        );
        // Its method and options are the library's defaults (only the
        // corrections and the bound differ, by the fleet's choice).
        assert_eq!(o.request.options, CalibrationRequest::default().options);
    }
}
