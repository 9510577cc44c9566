//! Sensor models: what each stream reports from the truth, when, and with what
//! errors (the `[sensors]` table of a scenario).
//!
//! Every stream samples at `offset_s + i / rate_hz`, so streams with different
//! offsets are not synchronised. The true systematic errors are the scenario's
//! `errors` (a [`Params`](deadreckon_core::Params)); the white noises are drawn from one PCG-64
//! generator per stream, seeded from the simulation seed and the stream, so
//! adding a stream does not change the noise of the others.

use serde::{Deserialize, Serialize};

use crate::imperfections::{ClockSpec, MultipathSpec};

/// What the wheel stream reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum WheelKind {
    /// Encoder ticks per interval (`Wheels::Ticks`), quantised exactly.
    Ticks,
    /// Wheel speeds computed with the nominal circumference (`Wheels::Speeds`).
    Speeds,
}

/// The wheel stream (`[sensors.wheels]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelsSpec {
    /// Ticks or speeds.
    pub kind: WheelKind,
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Time of the first sample, s.
    #[serde(default)]
    pub offset_s: f64,
    /// Speeds only: white noise on each wheel speed, m/s (default 0.02).
    #[serde(default = "default_wheel_speed_noise")]
    pub noise_std_mps: f64,
    /// Speeds only: quantisation step of the reported speeds, m/s (default 0.01; 0: none).
    #[serde(default = "default_wheel_speed_resolution")]
    pub resolution_mps: f64,
    /// Speeds only: jitter of the counted wheel rotation, as a distance along the
    /// tyre, m (default 0). Real wheel speeds come from counting tone-ring teeth,
    /// so their error is the difference of two edge-timing errors: `(e_k −
    /// e_{k−1})/dt`. Unlike white noise, its integral (the distance) stays
    /// bounded. 1 mm at 25 Hz gives about 0.035 m/s per sample, the high-pass
    /// noise measured on the comma2k19 RAV4's wheel speeds (0.038 m/s).
    #[serde(default)]
    pub edge_jitter_m: f64,
    /// Tone-ring tooth-spacing error: standard deviation of each tooth's
    /// position, as a fraction of the tooth pitch (default 0; 0.002–0.01 is
    /// typical), fixed per wheel and tooth. Ticks count the misplaced edges,
    /// speeds are the rotation inferred from them
    /// ([`crate::imperfections`]).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub tooth_error_std: f64,
    /// The wheel ECU's clock (default: true time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockSpec>,
}

fn default_wheel_speed_noise() -> f64 {
    0.02
}
fn default_wheel_speed_resolution() -> f64 {
    0.01
}

/// A scalar stream: the gyro (`[sensors.gyro]`, noise in rad/s) or the CAN
/// speed (`[sensors.speed]`, noise in m/s).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScalarSpec {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Time of the first sample, s.
    #[serde(default)]
    pub offset_s: f64,
    /// White-noise standard deviation in the stream's unit: rad/s for the gyro
    /// (table II: 0.003), m/s for the CAN speed (table II: 0.1).
    pub noise_std: f64,
    /// Delay of the stream: a sample describing time t is stamped t + this, s
    /// (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub latency_s: f64,
    /// Gyro only: relative scale error, the reading is (1 + this) × the
    /// angular rate (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub scale_error: f64,
    /// Gyro only: a three-axis IMU mounted with this `[pitch, roll]`, degrees
    /// (nose up, left side up): the drive then has `imu.gyro` (three axes,
    /// whose z is the yaw-rate stream) and `imu.accel` (specific force, noise
    /// [`ACCEL_NOISE_STD_MPS2`]) at the gyro's times.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt_deg: Option<[f64; 2]>,
    /// Gyro only: standard deviation of a slowly drifting bias (first-order
    /// Gauss–Markov, stationary) added to the constant one, rad/s (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bias_drift_std_rps: f64,
    /// Gyro only: correlation time of the drifting bias, s (default 300).
    #[serde(
        default = "default_bias_drift_tau",
        skip_serializing_if = "is_default_bias_drift_tau"
    )]
    pub bias_drift_tau_s: f64,
    /// The stream's own clock (default: true time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockSpec>,
}

impl ScalarSpec {
    /// A stream at `rate_hz` with white noise `noise_std` and nothing else:
    /// on the sensor's clock, no offset, latency, scale error, tilt or
    /// bias drift (the drift's τ at its default).
    pub fn plain(rate_hz: f64, noise_std: f64) -> ScalarSpec {
        ScalarSpec {
            rate_hz,
            offset_s: 0.0,
            noise_std,
            latency_s: 0.0,
            scale_error: 0.0,
            tilt_deg: None,
            bias_drift_std_rps: 0.0,
            bias_drift_tau_s: default_bias_drift_tau(),
            clock: None,
        }
    }
}

fn default_bias_drift_tau() -> f64 {
    300.0
}
fn is_default_bias_drift_tau(x: &f64) -> bool {
    *x == default_bias_drift_tau()
}

/// White noise of the simulated accelerometer, m/s².
pub const ACCEL_NOISE_STD_MPS2: f64 = 0.05;

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// Rows of the rotation taking vehicle axes to the axes of a sensor pitched
/// (nose up) by `pitch` and rolled (left side up) by `roll`, rad: a vehicle
/// vector `v` reads `R·v` in the sensor.
pub fn tilt_rotation(pitch: f64, roll: f64) -> [[f64; 3]; 3] {
    // Sensor = R_x(roll)ᵀ·R_y(−pitch)ᵀ-style: x_s tipped up by pitch, y_s by roll.
    let (sp, cp) = pitch.sin_cos();
    let (sr, cr) = roll.sin_cos();
    // Rotation about y by −pitch (nose up), then about x by roll (left up).
    let ry = [[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]];
    let rx = [[1.0, 0.0, 0.0], [0.0, cr, sr], [0.0, -sr, cr]];
    let mut m = [[0.0; 3]; 3];
    for i in 0..3 {
        for j in 0..3 {
            m[i][j] = (0..3).map(|k| rx[i][k] * ry[k][j]).sum();
        }
    }
    m
}

/// The steering-wheel stream (`[sensors.steering]`).
///
/// The reading is δ = r_s · atan(l_RF·κ + β) + offset with β white of std `noise_std`:
/// exactly the noise model of eq. 7 of the paper, where β is the error on
/// tan(δ/r_s). For small angles this is a steering-wheel noise of about
/// `noise_std · r_s` rad.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringSpec {
    /// Sample rate, Hz.
    pub rate_hz: f64,
    /// Time of the first sample, s.
    #[serde(default)]
    pub offset_s: f64,
    /// Standard deviation of the error on tan(δ/r_s), unitless (table II: 0.02).
    pub noise_std: f64,
    /// Delay of the stream: a sample describing time t is stamped t + this, s
    /// (default 0).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub latency_s: f64,
    /// The true steering ratio r_s (default: the vehicle's nominal one), for
    /// drives on which the ratio is to be calibrated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub true_ratio: Option<f64>,
    /// Steering-wheel angle read when the wheels point straight ahead, rad
    /// (default 0): the reading is r_s · atan(l_RF·κ + β) + this.
    #[serde(default)]
    pub wheel_offset_rad: f64,
    /// The steering ECU's clock (default: true time).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockSpec>,
}

/// The GNSS receiver (`[sensors.gnss]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GnssSpec {
    /// Fix rate, Hz.
    pub rate_hz: f64,
    /// Time of the first fix, s.
    #[serde(default)]
    pub offset_s: f64,
    /// White noise on each coordinate of the antenna position, m (written as `std_m`).
    pub std_m: f64,
    /// White noise on each component of the antenna velocity, m/s; when given,
    /// fixes carry `course_deg` and `speed_mps` computed from the noisy
    /// velocity, so the course noise grows as the speed falls (≈ std / v rad).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity_std_mps: Option<f64>,
    /// Below this measured speed the course is not reported, m/s (default
    /// 0.5), or reported as `low_speed_course` says.
    #[serde(default = "default_min_course_speed")]
    pub min_course_speed_mps: f64,
    /// What the receiver reports as course below `min_course_speed_mps`
    /// (default `dropped`).
    #[serde(default)]
    pub low_speed_course: LowSpeedCourse,
    /// What the course is the direction of (default `antenna_velocity`).
    #[serde(default)]
    pub course_convention: CourseConvention,
    /// A slowly wandering position error added to the white noise: a first-order
    /// Gauss–Markov process per coordinate with this standard deviation, m
    /// (default 0: none), and the correlation time `markov_tau_s`.
    #[serde(default)]
    pub markov_std_m: f64,
    /// Correlation time of the Gauss–Markov position error, s (default 60).
    #[serde(default = "default_markov_tau")]
    pub markov_tau_s: f64,
    /// Latency: each fix describes the vehicle this long before its time
    /// stamp, s (default 0; u-blox receivers are about 0.1 s late).
    #[serde(default)]
    pub latency_s: f64,
    /// Multipath bursts: position offsets of a few metres for a few seconds
    /// (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub multipath: Option<MultipathSpec>,
    /// The receiver's clock (default: true time; GNSS time is usually good,
    /// but the stamps a logger puts on the fixes need not be).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub clock: Option<ClockSpec>,
}

impl GnssSpec {
    /// A receiver at `rate_hz` with white position noise `std_m` and no course.
    pub fn white(rate_hz: f64, std_m: f64) -> Self {
        GnssSpec {
            rate_hz,
            offset_s: 0.0,
            std_m,
            velocity_std_mps: None,
            min_course_speed_mps: default_min_course_speed(),
            low_speed_course: LowSpeedCourse::default(),
            course_convention: CourseConvention::default(),
            markov_std_m: 0.0,
            markov_tau_s: default_markov_tau(),
            latency_s: 0.0,
            multipath: None,
            clock: None,
        }
    }
}

fn default_min_course_speed() -> f64 {
    0.5
}
fn default_markov_tau() -> f64 {
    60.0
}

/// What a receiver reports as course when it moves too slowly to measure one.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum LowSpeedCourse {
    /// No course (an empty `course_deg`).
    #[default]
    Dropped,
    /// A random course, uniform over the circle (many receivers at a standstill).
    Random,
    /// The last course reported at speed, repeated.
    Frozen,
}

/// What a receiver's course is the direction of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
#[non_exhaustive]
pub enum CourseConvention {
    /// The antenna's velocity: the body yaw plus atan(l·ψ̇/v) in turns.
    #[default]
    AntennaVelocity,
    /// The body yaw (a receiver fusing a dual antenna or an IMU).
    BodyYaw,
}

/// All the streams of a scenario (the `[sensors]` table). Absent tables are
/// streams the vehicle does not have.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorsSpec {
    /// Wheel encoders or wheel speeds (required).
    pub wheels: WheelsSpec,
    /// Gyro yaw rate.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro: Option<ScalarSpec>,
    /// CAN vehicle speed.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<ScalarSpec>,
    /// Steering wheel angle.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering: Option<SteeringSpec>,
    /// GNSS fixes.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gnss: Option<GnssSpec>,
    /// Rate of the written truth, Hz (default 100).
    #[serde(default = "default_truth_rate")]
    pub truth_rate_hz: f64,
    /// Wheel faults: spin bursts, a smaller wheel from mid-drive (default none).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_faults: Option<crate::faults::WheelFaultsSpec>,
}

fn default_truth_rate() -> f64 {
    100.0
}

impl SensorsSpec {
    /// The rates and offsets of every stream, with their keys, for validation.
    pub(crate) fn clocks(&self) -> Vec<(&'static str, f64, f64)> {
        let mut v = vec![("sensors.wheels", self.wheels.rate_hz, self.wheels.offset_s)];
        if let Some(g) = &self.gyro {
            v.push(("sensors.gyro", g.rate_hz, g.offset_s));
        }
        if let Some(g) = &self.speed {
            v.push(("sensors.speed", g.rate_hz, g.offset_s));
        }
        if let Some(g) = &self.steering {
            v.push(("sensors.steering", g.rate_hz, g.offset_s));
        }
        if let Some(g) = &self.gnss {
            v.push(("sensors.gnss", g.rate_hz, g.offset_s));
        }
        v.push(("sensors.truth", self.truth_rate_hz, 0.0));
        v
    }

    /// Each stream's own clock, with its table's key and rate, for validation.
    pub(crate) fn ecu_clocks(&self) -> Vec<(&'static str, f64, Option<&ClockSpec>)> {
        let mut v = vec![(
            "sensors.wheels",
            self.wheels.rate_hz,
            self.wheels.clock.as_ref(),
        )];
        if let Some(g) = &self.gyro {
            v.push(("sensors.gyro", g.rate_hz, g.clock.as_ref()));
        }
        if let Some(g) = &self.speed {
            v.push(("sensors.speed", g.rate_hz, g.clock.as_ref()));
        }
        if let Some(g) = &self.steering {
            v.push(("sensors.steering", g.rate_hz, g.clock.as_ref()));
        }
        if let Some(g) = &self.gnss {
            v.push(("sensors.gnss", g.rate_hz, g.clock.as_ref()));
        }
        v
    }

    /// The noise values with their keys, for validation (all must be ≥ 0).
    pub(crate) fn noises(&self) -> Vec<(&'static str, f64)> {
        let mut v = vec![
            ("sensors.wheels.noise_std_mps", self.wheels.noise_std_mps),
            ("sensors.wheels.resolution_mps", self.wheels.resolution_mps),
            ("sensors.wheels.edge_jitter_m", self.wheels.edge_jitter_m),
            (
                "sensors.wheels.tooth_error_std",
                self.wheels.tooth_error_std,
            ),
        ];
        if let Some(g) = &self.gyro {
            v.push(("sensors.gyro.noise_std", g.noise_std));
            v.push(("sensors.gyro.latency_s", g.latency_s));
            v.push(("sensors.gyro.bias_drift_std_rps", g.bias_drift_std_rps));
        }
        if let Some(g) = &self.speed {
            v.push(("sensors.speed.noise_std", g.noise_std));
            v.push(("sensors.speed.latency_s", g.latency_s));
        }
        if let Some(g) = &self.steering {
            v.push(("sensors.steering.noise_std", g.noise_std));
            v.push(("sensors.steering.latency_s", g.latency_s));
        }
        if let Some(g) = &self.gnss {
            v.push(("sensors.gnss.std_m", g.std_m));
            v.push((
                "sensors.gnss.velocity_std_mps",
                g.velocity_std_mps.unwrap_or(0.0),
            ));
            v.push(("sensors.gnss.min_course_speed_mps", g.min_course_speed_mps));
            v.push(("sensors.gnss.markov_std_m", g.markov_std_m));
            v.push(("sensors.gnss.markov_tau_s", g.markov_tau_s));
            v.push(("sensors.gnss.latency_s", g.latency_s));
        }
        v
    }
}

mod suite;

pub(crate) use suite::{Noise, Suite};
