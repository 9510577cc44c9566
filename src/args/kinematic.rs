//! The kinematic shapes' arguments (`--shape`, `--yaw`).

/// `--shape` (default: found from the data, `deadreckon_api::shape`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ShapeArg {
    /// Four wheels, front-steered (the paper's car).
    Car,
    /// Left/right wheels or an odometry twist.
    DiffDrive,
    /// One steered traction wheel and a passive rear axle.
    Tricycle,
}

impl From<ShapeArg> for deadreckon_core::kinematics::Shape {
    fn from(s: ShapeArg) -> Self {
        match s {
            ShapeArg::Car => Self::FourWheel,
            ShapeArg::DiffDrive => Self::DiffDrive,
            ShapeArg::Tricycle => Self::Tricycle,
        }
    }
}

/// The help of `--shape`, the same in every command.
pub const SHAPE_HELP: &str = "The vehicle shape: car, diff-drive or tricycle (default: found from the data and printed with the reason: body velocity or two wheels and no steering is a differential drive, a tricycle log or one steered wheel a tricycle, else a car)";

/// `--yaw` of a differential drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum YawArg {
    /// The gyro.
    Gyro,
    /// The odometry's wheel-speed difference.
    Odometry,
}

impl YawArg {
    /// The name written into params.toml.
    pub fn name(self) -> &'static str {
        match self {
            YawArg::Gyro => "gyro",
            YawArg::Odometry => "odometry",
        }
    }
}

impl From<YawArg> for deadreckon_core::kinematics::diff_drive::YawSource {
    fn from(y: YawArg) -> Self {
        match y {
            YawArg::Gyro => Self::Gyro,
            YawArg::Odometry => Self::Odometry,
        }
    }
}

/// `evaluate --start` of a differential drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum StartArg {
    /// The rigid alignment of the preceding --align seconds of dead reckoning to the fixes.
    Align,
    /// The GNSS-aided filter's state at the outage's start (the fixes' wander carried into it).
    Filter,
}

impl From<StartArg> for deadreckon_core::kinematics::diff_drive::OutageStart {
    fn from(s: StartArg) -> Self {
        match s {
            StartArg::Align => Self::Align,
            StartArg::Filter => Self::Filter(Default::default()),
        }
    }
}
