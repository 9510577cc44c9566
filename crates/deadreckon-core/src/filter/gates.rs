//! The sensors a [`super::Filter`] updates with ([`SensorKind`]), their
//! χ² gates ([`gate_chi2`]), the outcome of one update ([`Update`]) and the
//! gates' counters ([`GateCounts`]).

use serde::{Deserialize, Serialize};

use crate::vehicle::Noise;

/// How many sensor kinds the gates count (four wheels, gyro, CAN speed,
/// steering, GNSS, course): [`SensorKind::ALL`]'s length.
pub const N_SENSORS: usize = 9;

/// Which sensor a measurement comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum SensorKind {
    /// Wheel `0..4` (FL, FR, RL, RR).
    Wheel(u8),
    /// Gyro.
    Gyro,
    /// CAN speed.
    Speed,
    /// Steering.
    Steering,
    /// GNSS position (2-D; the NIS has 2 degrees of freedom).
    Gnss,
    /// GNSS course.
    Course,
}

impl SensorKind {
    /// Every kind, in a fixed order (for tables).
    pub const ALL: [SensorKind; N_SENSORS] = [
        SensorKind::Wheel(0),
        SensorKind::Wheel(1),
        SensorKind::Wheel(2),
        SensorKind::Wheel(3),
        SensorKind::Gyro,
        SensorKind::Speed,
        SensorKind::Steering,
        SensorKind::Gnss,
        SensorKind::Course,
    ];

    /// A short stable name.
    pub fn name(&self) -> &'static str {
        match self {
            SensorKind::Wheel(0) => "wheel_fl",
            SensorKind::Wheel(1) => "wheel_fr",
            SensorKind::Wheel(2) => "wheel_rl",
            SensorKind::Wheel(_) => "wheel_rr",
            SensorKind::Gyro => "gyro",
            SensorKind::Speed => "speed",
            SensorKind::Steering => "steering",
            SensorKind::Gnss => "gnss",
            SensorKind::Course => "course",
        }
    }

    /// Degrees of freedom of the measurement.
    pub fn dof(&self) -> usize {
        if *self == SensorKind::Gnss {
            2
        } else {
            1
        }
    }

    pub(super) fn slot(&self) -> usize {
        match self {
            SensorKind::Wheel(i) => (*i as usize).min(3),
            SensorKind::Gyro => 4,
            SensorKind::Speed => 5,
            SensorKind::Steering => 6,
            SensorKind::Gnss => 7,
            SensorKind::Course => 8,
        }
    }
}

/// The χ² gate of a sensor, from the vehicle's noise settings.
pub fn gate_chi2(noise: &Noise, sensor: SensorKind) -> f64 {
    match sensor {
        SensorKind::Wheel(_) => noise.wheel_gate_chi2,
        SensorKind::Gyro => noise.gyro_gate_chi2,
        SensorKind::Speed => noise.speed_gate_chi2,
        SensorKind::Steering => noise.steering_gate_chi2,
        SensorKind::Course => noise.course_gate_chi2,
        SensorKind::Gnss => noise.gnss_gate_chi2,
    }
}

/// The outcome of one measurement update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Update {
    /// The sensor.
    pub sensor: SensorKind,
    /// Innovation `z − h(x̂⁻)` (first component for GNSS).
    pub y: f64,
    /// Innovation variance (first diagonal element for GNSS).
    pub s: f64,
    /// Normalised innovation squared `ỹᵀ S⁻¹ ỹ`.
    pub nis: f64,
    /// `ln det S` of the innovation covariance the gate decided with (`ln s`
    /// for a scalar): with `nis`, the measurement's Gaussian log-likelihood
    /// (what [`crate::wander_fit`] compares receiver models by).
    pub ln_det_s: f64,
    /// False when the χ² gate rejected the measurement (the state is unchanged).
    pub accepted: bool,
}

/// Per-sensor gate counters: measurements used and rejected, and recoveries
/// (a measurement accepted after too many consecutive rejections).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct GateCounts {
    /// Accepted measurements, per sensor in [`SensorKind::ALL`] order.
    pub accepted: [u64; N_SENSORS],
    /// Rejected measurements, same order.
    pub rejected: [u64; N_SENSORS],
    /// Recoveries, same order.
    pub recovered: [u64; N_SENSORS],
}

impl GateCounts {
    /// Accepted measurements of one sensor.
    pub fn accepted(&self, k: SensorKind) -> u64 {
        self.accepted[k.slot()]
    }
    /// Rejected measurements of one sensor.
    pub fn rejected(&self, k: SensorKind) -> u64 {
        self.rejected[k.slot()]
    }
    /// Recoveries of one sensor.
    pub fn recovered(&self, k: SensorKind) -> u64 {
        self.recovered[k.slot()]
    }
    /// Adds the counts of another run (e.g. of every outage window).
    pub fn add(&mut self, other: &GateCounts) {
        for i in 0..self.accepted.len() {
            self.accepted[i] += other.accepted[i];
            self.rejected[i] += other.rejected[i];
            self.recovered[i] += other.recovered[i];
        }
    }
    /// The counts added since `earlier` (the same counters at an earlier
    /// time: a filter cloned from it counts on from there).
    pub fn since(&self, earlier: &GateCounts) -> GateCounts {
        let d = |a: &[u64; N_SENSORS], b: &[u64; N_SENSORS]| {
            std::array::from_fn(|k| a[k].saturating_sub(b[k]))
        };
        GateCounts {
            accepted: d(&self.accepted, &earlier.accepted),
            rejected: d(&self.rejected, &earlier.rejected),
            recovered: d(&self.recovered, &earlier.recovered),
        }
    }
    /// Rejected measurements of every sensor.
    pub fn total_rejected(&self) -> u64 {
        self.rejected.iter().sum()
    }
    /// `(name, accepted, rejected, recovered)` for every sensor with any measurement.
    pub fn rows(&self) -> Vec<(&'static str, u64, u64, u64)> {
        SensorKind::ALL
            .iter()
            .filter(|k| self.accepted(**k) + self.rejected(**k) > 0)
            .map(|k| {
                (
                    k.name(),
                    self.accepted(*k),
                    self.rejected(*k),
                    self.recovered(*k),
                )
            })
            .collect()
    }
}
