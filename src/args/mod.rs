//! What the user types: one module per subcommand with its clap arguments
//! and option words (`ValueEnum`s), and here the options several commands
//! share and the value parsers. The commands in `crate::cmd` take these.

pub mod batch;
pub mod calibrate;
pub mod compare;
pub mod demo;
pub mod evaluate;
pub mod events;
pub mod import;
pub mod kinematic;
pub mod report;
pub mod ros2;
pub mod run;
pub mod simulate;
pub mod stream;
pub mod tedris;

use anyhow::Result;
use deadreckon_core::ekf::Timing;

/// `--wheels`: which wheel file a drive directory with both is read from.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum WheelsArg {
    /// `wheel_ticks.csv` (encoder ticks).
    Ticks,
    /// `wheel_speeds.csv` (wheel speeds).
    Speeds,
}

impl From<WheelsArg> for deadreckon_io::WheelFile {
    fn from(w: WheelsArg) -> Self {
        match w {
            WheelsArg::Ticks => Self::Ticks,
            WheelsArg::Speeds => Self::Speeds,
        }
    }
}

/// `--timing`: the filter's timing scheme.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimingArg {
    /// One epoch per wheel row (the paper's).
    Wheel,
    /// One epoch per reading. Calibrating or learning the parameters this
    /// way needs [noise] process_speed_mps <= 0.5 and process_yaw_rate_rps
    /// <= 0.03 in vehicle.toml (table I's values are refused).
    Each,
}

impl TimingArg {
    /// The argument naming `t` (a default read from the library).
    pub fn of(t: Timing) -> TimingArg {
        match t {
            Timing::WheelEpochs => TimingArg::Wheel,
            Timing::EachMeasurement => TimingArg::Each,
        }
    }
}

impl From<TimingArg> for Timing {
    fn from(t: TimingArg) -> Timing {
        match t {
            TimingArg::Wheel => Timing::WheelEpochs,
            TimingArg::Each => Timing::EachMeasurement,
        }
    }
}

/// `--method`: what a calibration is made against. Which ones a vehicle
/// takes depends on its shape (`calibrate` says).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum MethodArg {
    /// RTS-smoothed states of a GNSS-aided filter (a car).
    Rts,
    /// The gyro bias at standstill (a car).
    Zupt,
    /// `truth.csv` or the tracker (a car, a tricycle).
    Truth,
    /// The GNSS fixes (a differential drive).
    Gnss,
}

impl MethodArg {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            MethodArg::Rts => "rts",
            MethodArg::Zupt => "zupt",
            MethodArg::Truth => "truth",
            MethodArg::Gnss => "gnss",
        }
    }

    /// The four-wheel calibration method (`gnss` is the differential
    /// drive's).
    pub fn car(self) -> Result<deadreckon_core::calibrate::Method> {
        use deadreckon_core::calibrate::Method;
        Ok(match self {
            MethodArg::Rts => Method::Rts,
            MethodArg::Zupt => Method::Zupt,
            MethodArg::Truth => Method::Truth,
            MethodArg::Gnss => anyhow::bail!(
                "--method gnss calibrates a differential drive (--shape diff-drive); a car takes rts, zupt or truth"
            ),
        })
    }
}

/// clap's parser for a quantity that must be a finite number above 0 (a
/// length, a duration, a standard deviation): `nan`, `inf`, 0 and negative
/// values are refused before anything is read.
pub fn positive(s: &str) -> std::result::Result<f64, String> {
    let v = finite(s)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be above 0, got {v}"))
    }
}

/// clap's parser for a finite number at least 0 (a speed threshold, a
/// warm-up time).
pub fn non_negative(s: &str) -> std::result::Result<f64, String> {
    let v = finite(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be 0 or above, got {v}"))
    }
}

/// clap's parser for a finite number (a time on the drive clock, a bias).
pub fn finite(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|e| format!("`{s}` is not a number ({e})"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("must be a finite number, got `{s}`"))
    }
}

/// clap's parser for a probability strictly between 0 and 1 (a
/// significance level).
pub fn probability(s: &str) -> std::result::Result<f64, String> {
    let v = finite(s)?;
    if v > 0.0 && v < 1.0 {
        Ok(v)
    } else {
        Err(format!("must be between 0 and 1 (exclusive), got {v}"))
    }
}

/// `--corrections`: which timing and mounting corrections are estimated and
/// applied before calibrating (see `deadreckon_core::timing`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CorrectionsArg {
    /// Every correction estimated; each applied only when it lowers the dead-reckoning
    /// error through held-back GNSS (the drive's own fixes, hidden in turn).
    Auto,
    /// IMU tilt, every stream's delay and the gyro scale.
    All,
    /// IMU tilt, GNSS delay and gyro scale (the other delays reported, not applied).
    Gnss,
    /// None.
    None,
}

impl CorrectionsArg {
    /// The argument naming `w` (a default read from the library).
    pub fn of(w: deadreckon_core::timing::Which) -> CorrectionsArg {
        use deadreckon_core::timing::Which;
        match w {
            Which::Auto => CorrectionsArg::Auto,
            Which::All => CorrectionsArg::All,
            Which::Gnss => CorrectionsArg::Gnss,
            Which::None => CorrectionsArg::None,
        }
    }
}

impl From<CorrectionsArg> for deadreckon_core::timing::Which {
    fn from(c: CorrectionsArg) -> Self {
        use deadreckon_core::timing::Which;
        match c {
            CorrectionsArg::Auto => Which::Auto,
            CorrectionsArg::All => Which::All,
            CorrectionsArg::Gnss => Which::Gnss,
            CorrectionsArg::None => Which::None,
        }
    }
}
