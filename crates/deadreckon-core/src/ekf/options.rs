//! The filter's options: when it runs its epochs ([`Timing`]), when a wheel
//! row is used ([`WheelRows`]), how it starts ([`Init`]), which sensors it
//! uses ([`SensorSet`]), all in [`FilterOptions`].

use serde::{Deserialize, Serialize};

use crate::kalman::CovarianceForm;
use crate::model::{Mat, State};
use crate::wheel_health::WheelMonitorConfig;

/// When the filter runs its epochs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Timing {
    /// One epoch per wheel row, with the latest reading of the other sensors (the paper).
    #[default]
    WheelEpochs,
    /// One epoch per reading, each at its own timestamp.
    EachMeasurement,
}

/// What a wheel row's reading describes, and so when the filter uses it
/// ([`Timing::WheelEpochs`] only).
///
/// A wheel-speed row at `t_k` is the mean speed over `(t_{k−1}, t_k]` (the
/// rotation over the last period times the circumference, as ECUs and the
/// simulator report it), and a tick count is the rotation over that
/// interval. The paper's step (eq. 3) carries the state from `t_k` to
/// `t_{k+1}` with the speed the row at `t_k` set, the speed of the interval
/// *before*: whenever the speed changes, the position trails by a wheel
/// period, which the GNSS delay estimate read as a negative delay of
/// 0.7–0.9 wheel periods (−27, −14 and −9 ms at 25, 50 and 100 Hz with a
/// true delay of 0, issue 28).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum WheelRows {
    /// The row updates the state at the start of its interval, `t_{k−1}`,
    /// together with the gyro's and the CAN speed's readings stamped inside
    /// the interval (each one, in order) and the steering's latest; the step
    /// to `t_k` then carries the interval's own rates. A GNSS fix updates
    /// the state at the first interval start after it. The epoch at
    /// `t_{k−1}` is predicted, updated and handed out when the row at `t_k`
    /// has arrived, one wheel period later than with [`WheelRows::Instant`].
    /// Not the default: on the comma2k19 segment it loses (see
    /// docs/calibration.md, "When a wheel row is used").
    Interval,
    /// The row updates the state at its own time (the paper): the step
    /// after it carries that speed over the next interval.
    #[default]
    Instant,
}

/// How the filter's initial state is chosen.
#[allow(clippy::large_enum_variant)] // a plain value passed once per run
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Init {
    /// From GNSS: the first fix for the position (minus the lever arm) and the
    /// direction of the first 10 m of displacement for the yaw. The filter starts at
    /// the first wheel epoch at or after the first fix.
    #[default]
    Gnss,
    /// From `truth.csv` at the first wheel epoch, with a small covariance.
    Truth,
    /// A given state and covariance at the first wheel epoch at or after `t_s`.
    Given {
        /// Start time, s.
        t_s: f64,
        /// Initial state.
        x: State,
        /// Initial covariance.
        p: Mat,
    },
}

/// Which sensors the filter uses (all by default, when present in the drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SensorSet {
    /// Wheel encoders or wheel speeds.
    pub wheels: bool,
    /// Gyro.
    pub gyro: bool,
    /// CAN speed.
    pub speed: bool,
    /// Steering wheel angle.
    pub steering: bool,
    /// GNSS positions.
    pub gnss: bool,
    /// GNSS course as a yaw observation (not in the paper; off by default).
    pub gnss_course: bool,
}

impl Default for SensorSet {
    fn default() -> Self {
        SensorSet {
            wheels: true,
            gyro: true,
            speed: true,
            steering: true,
            gnss: true,
            gnss_course: false,
        }
    }
}

impl SensorSet {
    /// Dead reckoning: every proprioceptive sensor, no GNSS.
    pub fn dead_reckoning() -> Self {
        SensorSet {
            gnss: false,
            gnss_course: false,
            ..Default::default()
        }
    }
}

/// Options of a filter run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FilterOptions {
    /// Timing scheme.
    pub timing: Timing,
    /// Initial state.
    pub init: Init,
    /// Sensors to use.
    pub sensors: SensorSet,
    /// GNSS outages: fixes with `start <= t < end` are hidden from the filter.
    pub gnss_outages: Vec<(f64, f64)>,
    /// Covariance update form.
    pub covariance_form: CovarianceForm,
    /// Keep every epoch (needed by the smoother).
    pub record_epochs: bool,
    /// Keep every innovation (for filter-health plots).
    pub record_innovations: bool,
    /// Stop after the last epoch at or before this time, s.
    pub end_s: Option<f64>,
    /// The wheel-health monitor (slipping and bad wheels dropped from the
    /// fusion while they misbehave, [`crate::wheel_health`]; on by default);
    /// `None` fuses every wheel reading the χ² gate accepts.
    #[serde(default)]
    pub wheel_monitor: Option<WheelMonitorConfig>,
    /// When a wheel row is used ([`WheelRows`]).
    #[serde(default)]
    pub wheel_rows: WheelRows,
}

impl FilterOptions {
    /// The wheel-row scheme a filter on `vehicle` runs: the interval when
    /// the vehicle asks for it (`[noise] wheel_rows_over_interval`, a model
    /// option of `--corrections auto`), else the options' [`WheelRows`].
    pub fn wheel_rows_for(&self, vehicle: &crate::vehicle::Vehicle) -> WheelRows {
        if vehicle.noise.wheel_rows_over_interval {
            WheelRows::Interval
        } else {
            self.wheel_rows
        }
    }
}

impl Default for FilterOptions {
    fn default() -> Self {
        FilterOptions {
            timing: Timing::WheelEpochs,
            init: Init::Gnss,
            sensors: SensorSet::default(),
            gnss_outages: Vec::new(),
            covariance_form: CovarianceForm::Joseph,
            record_epochs: true,
            record_innovations: false,
            end_s: None,
            wheel_monitor: Some(WheelMonitorConfig::default()),
            wheel_rows: WheelRows::default(),
        }
    }
}
