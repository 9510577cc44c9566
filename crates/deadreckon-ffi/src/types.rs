//! The plain C structs the API fills and takes.

use deadreckon_core::ekf::Timing;
use deadreckon_core::filter::GateCounts;
use deadreckon_core::online::Learned;
use deadreckon_core::track::TrackPoint;
use deadreckon_core::Params;

use crate::status::{DrStatus, Fail};

/// `DrOptions::timing`: one epoch per wheel row with the newest reading of
/// each other sensor (the paper's scheme; `stream --timing wheel`).
pub const DR_TIMING_WHEEL: i32 = 0;
/// `DrOptions::timing`: one epoch per reading (`stream --timing each`).
pub const DR_TIMING_EACH: i32 = 1;

/// The options of `deadreckon stream`. `dr_default_options` gives the
/// defaults (wheel timing, not learning).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrOptions {
    /// `DR_TIMING_WHEEL` or `DR_TIMING_EACH`.
    pub timing: i32,
    /// Learn the six parameters as the filter runs (the 11-state filter;
    /// `stream --learn`).
    pub learn: bool,
}

impl Default for DrOptions {
    fn default() -> Self {
        DrOptions {
            timing: DR_TIMING_WHEEL,
            learn: false,
        }
    }
}

impl DrOptions {
    pub(crate) fn timing(&self) -> Result<Timing, Fail> {
        match self.timing {
            DR_TIMING_WHEEL => Ok(Timing::WheelEpochs),
            DR_TIMING_EACH => Ok(Timing::EachMeasurement),
            t => Err(Fail::new(
                DrStatus::BadConfig,
                format!(
                    "timing {t} is neither DR_TIMING_WHEEL ({DR_TIMING_WHEEL}) nor DR_TIMING_EACH ({DR_TIMING_EACH})"
                ),
            )),
        }
    }
}

/// One pose, as `deadreckon stream` prints it: the rear-axle centre after a
/// filter epoch, with the covariance of (east, north, yaw).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrPose {
    /// Time, s (the drive's clock).
    pub t_s: f64,
    /// East of the origin, m.
    pub east_m: f64,
    /// North of the origin, m.
    pub north_m: f64,
    /// Yaw, rad, counter-clockwise from east, in (-π, π].
    pub yaw_rad: f64,
    /// Longitudinal speed, m/s.
    pub speed_mps: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_rps: f64,
    /// Covariance of (east, north, yaw), row by row (m², m·rad, rad²).
    pub cov_pose: [f64; 9],
}

impl From<TrackPoint> for DrPose {
    fn from(p: TrackPoint) -> Self {
        DrPose {
            t_s: p.t_s,
            east_m: p.east_m,
            north_m: p.north_m,
            yaw_rad: p.yaw_rad,
            speed_mps: p.speed_mps,
            yaw_rate_rps: p.yaw_rate_rps,
            cov_pose: p.cov_pose,
        }
    }
}

/// The six parameters of the paper's eq. 9 (or their standard errors).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrParams {
    /// Gyro bias, rad/s (gyro = true yaw rate + bias).
    pub gyro_bias_rps: f64,
    /// CAN speed scale (CAN speed = scale · true speed).
    pub speed_scale: f64,
    /// Front-left wheel circumference, m.
    pub circumference_fl_m: f64,
    /// Front-right wheel circumference, m.
    pub circumference_fr_m: f64,
    /// Rear-left wheel circumference, m.
    pub circumference_rl_m: f64,
    /// Rear-right wheel circumference, m.
    pub circumference_rr_m: f64,
}

impl From<Params> for DrParams {
    fn from(p: Params) -> Self {
        DrParams {
            gyro_bias_rps: p.gyro_bias_rps,
            speed_scale: p.speed_scale,
            circumference_fl_m: p.circumference_fl_m,
            circumference_fr_m: p.circumference_fr_m,
            circumference_rl_m: p.circumference_rl_m,
            circumference_rr_m: p.circumference_rr_m,
        }
    }
}

/// The parameters learned so far (`DrOptions::learn`), as `stream
/// --params-out` writes them.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DrLearned {
    /// The estimates.
    pub params: DrParams,
    /// One standard error each (circumferences in m).
    pub std: DrParams,
    /// True when every standard error is within its target (gyro bias
    /// 5e-5 rad/s, speed scale 0.3 %, circumferences 0.1 %).
    pub valid: bool,
    /// Mean over the six of min(1, target / standard error), percent.
    pub calibrated_pct: f64,
}

impl From<Learned> for DrLearned {
    fn from(l: Learned) -> Self {
        DrLearned {
            params: l.params.into(),
            std: l.std.into(),
            valid: l.valid,
            calibrated_pct: l.calibrated_pct,
        }
    }
}

/// The number of sensors the χ² gate counts.
pub const DR_GATE_SENSORS: usize = 9;

/// Where each sensor's counts are in `DrGateCounts`' arrays.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DrGateSensor {
    /// Front-left wheel.
    WheelFl = 0,
    /// Front-right wheel.
    WheelFr = 1,
    /// Rear-left wheel.
    WheelRl = 2,
    /// Rear-right wheel.
    WheelRr = 3,
    /// Gyro.
    Gyro = 4,
    /// CAN speed.
    Speed = 5,
    /// Steering.
    Steering = 6,
    /// GNSS position.
    Gnss = 7,
    /// GNSS course.
    Course = 8,
}

/// The χ² gate's counts per sensor, indexed by `DrGateSensor`.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DrGateCounts {
    /// Measurements the gate accepted.
    pub accepted: [u64; DR_GATE_SENSORS],
    /// Measurements the gate rejected (state unchanged).
    pub rejected: [u64; DR_GATE_SENSORS],
    /// Measurements accepted after a run of rejections, with the covariance
    /// inflated (the filter had lost that sensor's track).
    pub recovered: [u64; DR_GATE_SENSORS],
}

impl From<GateCounts> for DrGateCounts {
    fn from(g: GateCounts) -> Self {
        DrGateCounts {
            accepted: g.accepted,
            rejected: g.rejected,
            recovered: g.recovered,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use deadreckon_core::filter::SensorKind;

    #[test]
    fn the_gate_slots_are_those_of_the_core() {
        let ours = [
            DrGateSensor::WheelFl,
            DrGateSensor::WheelFr,
            DrGateSensor::WheelRl,
            DrGateSensor::WheelRr,
            DrGateSensor::Gyro,
            DrGateSensor::Speed,
            DrGateSensor::Steering,
            DrGateSensor::Gnss,
            DrGateSensor::Course,
        ];
        assert_eq!(SensorKind::ALL.len(), DR_GATE_SENSORS);
        for (k, s) in SensorKind::ALL.iter().zip(ours) {
            let mut g = GateCounts::default();
            g.accepted[s as usize] = 7;
            assert_eq!(g.accepted(*k), 7, "{k:?}");
        }
    }
}
