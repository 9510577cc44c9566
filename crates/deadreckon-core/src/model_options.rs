//! Additions to the paper's model that a drive's own GNSS may ask for
//! (issue 28): the rear axle's side slip, the steering's ratio, offset and
//! understeer, a gyro bias that walks, a GNSS recovery that waits out a
//! multipath burst, a yaw rate held through a missed gyro reading, the
//! receiver's slowly wandering error carried as filter states, and each
//! wheel row used over the interval it describes.
//!
//! Each is built and measured on its own ([`crate::side_slip`],
//! [`crate::kinematics::steering`], [`crate::gyro_drift`],
//! [`crate::vehicle::Noise::gnss_recovery_after_s`],
//! [`crate::vehicle::Noise::gyro_gap_process_yaw_rate_rps`],
//! [`crate::gnss_error`], [`crate::ekf::WheelRows::Interval`]); none is
//! the paper's,
//! and each costs where its effect is absent (the walking bias 9 % on
//! held-out cars whose gyro does not drift; the recovery's wait held a
//! really lost filter out longer on held-out car 108, 3.12 → 6.18 m). So
//! none is switched on for every drive: with `--corrections auto`
//! ([`crate::held_back`]) each is a candidate judged on the drive's own
//! held-back GNSS, with the streams' corrections, and applied only when it
//! lowers the error there. The estimated ones (side slip, steering) are
//! candidates only at [`crate::held_back::MIN_Z`] standard errors from the
//! paper's model; the four settings (walk, recovery, gyro gap, wheel
//! intervals) have no estimate and are
//! judged on the held-back fixes alone, so a drive too short to judge keeps
//! the paper's model for them.
//!
//! The receiver's wander (σ, τ) is fitted on the drive's own fixes
//! ([`crate::wander_fit`]) after the other options are chosen, with their
//! calibration; it is a candidate when the fit is not white fixes, judged
//! on the held-back fixes like the settings (never on a drive too short to
//! judge), the held-back fixes compared with the dead-reckoned antenna plus
//! the wander the filter still expects
//! ([`crate::outage::through_windows_against_fixes`]).
//!
//! What is applied is stored with the corrections (params.toml `[model]`,
//! [`crate::timing::KnownCorrections::model`]) and every command that
//! applies params.toml sets it on the vehicle
//! ([`ModelOptions::apply_to`]), `stream` included.

use serde::{Deserialize, Serialize};

use crate::calibrate::Calibration;
use crate::drive::Drive;
use crate::gnss_error::Wander;
use crate::vehicle::Vehicle;

/// The walking gyro bias's rate random walk a drive is judged with, rad/s
/// per √s: 3e-6, chosen on the dynamic family's development cars 1–6 among
/// 3e-6, 1e-5 and 3e-5 (`deadreckon-sim/tests/dynamics_ablation.rs`,
/// `a_walking_gyro_bias_takes_back_most_of_what_the_gyro_drift_costs`;
/// held-out cars 101–110 in its ignored twin).
pub const GYRO_BIAS_WALK_RPS_PER_SQRT_S: f64 = 3e-6;

/// The wait of a GNSS recovery a drive is judged with, s: 10, longer than
/// the family's multipath bursts (2–9 s;
/// `deadreckon-sim/tests/gnss_wander.rs`,
/// `multipath_bursts_pulled_the_filter_through_gnss_recoveries`).
pub const GNSS_RECOVERY_AFTER_S: f64 = 10.0;

/// The yaw rate's process noise per 20 ms at a wheel epoch without a gyro
/// reading that a drive is judged with, rad/s: 0.03 (table I's is 1),
/// chosen on the dynamic family's cars 1–30 with the `clocks` effect alone
/// among 0.03 and 0.1 (mean final error of 30 s outages 0.476 and 0.523 m
/// against 0.584 m without it and 0.432 m without the clocks; 100 Hz
/// wheel speeds 0.399 and 0.514 m against 0.549 m;
/// `deadreckon-api/tests/clock_parts.rs`, docs/dynamics.md). Checked on
/// held-out cars 101–110 through `--corrections auto` in
/// `deadreckon-api/tests/dynamic_family_defaults.rs`.
pub const GYRO_GAP_PROCESS_YAW_RATE_RPS: f64 = 0.03;

/// A drive's share of wheel epochs without a gyro reading of their own at
/// which the held yaw rate is a candidate: 1 % (a synchronous drive has
/// none; comma2k19's segment 7 %, the dynamic family's 100 Hz cars 2–25 %).
pub const MIN_GYRO_GAP_SHARE: f64 = 0.01;

/// The steering model: ratio, offset and understeer gradient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringModel {
    /// Steering-wheel angle per wheel angle.
    pub steering_ratio: f64,
    /// Steering-wheel reading when going straight, rad.
    pub steering_offset_rad: f64,
    /// Understeer gradient, rad per m/s² (0 when not estimated).
    #[serde(default)]
    pub understeer_gradient_rad_per_mps2: f64,
}

/// The model additions applied to a vehicle (`None`: the vehicle's own).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelOptions {
    /// The rear axle's side-slip gradient, rad per m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rear_slip_gradient_rad_per_mps2: Option<f64>,
    /// The steering's ratio, offset and understeer.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering: Option<SteeringModel>,
    /// The gyro bias's rate random walk, rad/s per √s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_bias_walk_rps_per_sqrt_s: Option<f64>,
    /// How long a GNSS recovery waits, s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gnss_recovery_after_s: Option<f64>,
    /// The yaw rate's process noise per step at an epoch without a gyro
    /// reading, rad/s.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_gap_process_yaw_rate_rps: Option<f64>,
    /// The receiver's wander carried as filter states (σ per axis, m, and
    /// τ, s: the vehicle's `[noise] gnss_wander_std_m`,
    /// `gnss_wander_tau_s`), as fitted on the calibration drive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gnss_wander: Option<Wander>,
    /// Each wheel row used over the interval it describes (the vehicle's
    /// `[noise] wheel_rows_over_interval`; only `true` is written).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wheel_rows_over_interval: Option<bool>,
}

/// One model addition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ModelOption {
    /// The rear axle's side slip ([`crate::side_slip`]).
    SideSlip,
    /// The steering's ratio, offset and understeer
    /// ([`crate::kinematics::steering`]).
    Steering,
    /// A walking gyro bias ([`crate::gyro_drift`]).
    GyroWalk,
    /// A GNSS recovery that waits out a multipath burst.
    GnssRecovery,
    /// The yaw rate held through a wheel epoch without a gyro reading.
    GyroGap,
    /// The receiver's wander as filter states ([`crate::gnss_error`]),
    /// fitted on the drive's fixes ([`crate::wander_fit`]).
    GnssWander,
    /// Each wheel row used over the interval it describes
    /// ([`crate::ekf::WheelRows::Interval`]).
    ///
    /// Why an option and not the filter's step: with each reading in its
    /// own interval (issue 28, stop 50) the evaluation scenario's seed 2
    /// took 30 s outages from 0.459 to 0.395 m, and with a receiver 0.1 s
    /// late seeds 2 and 3 from 0.521 to 0.407 m and from 0.587 to 0.366 m,
    /// but the comma2k19 segment (CAN wheel speeds at about 100 Hz, the
    /// phone's gyro on its own clock) went from 0.595 to 0.890 m
    /// (docs/calibration.md, "When a wheel row is used"). With it, the GNSS
    /// delay is applied without the paper's step offset and each scalar
    /// stream's delay on true time
    /// ([`crate::timing::Delays::for_wheel_intervals`]).
    WheelIntervals,
}

impl ModelOption {
    /// Every option, in the order they are reported.
    pub const ALL: [ModelOption; 7] = [
        ModelOption::SideSlip,
        ModelOption::Steering,
        ModelOption::GyroWalk,
        ModelOption::GnssRecovery,
        ModelOption::GyroGap,
        ModelOption::GnssWander,
        ModelOption::WheelIntervals,
    ];

    /// Words for people.
    pub fn name(self) -> &'static str {
        match self {
            ModelOption::SideSlip => "rear side slip",
            ModelOption::Steering => "steering model",
            ModelOption::GyroWalk => "walking gyro bias",
            ModelOption::GnssRecovery => "GNSS recovery after 10 s",
            ModelOption::GyroGap => "yaw rate held through a missed gyro reading",
            ModelOption::GnssWander => "receiver's wander",
            ModelOption::WheelIntervals => "wheel rows over their intervals",
        }
    }

    /// The key in JSON and params.toml.
    pub fn key(self) -> &'static str {
        match self {
            ModelOption::SideSlip => "side_slip",
            ModelOption::Steering => "steering",
            ModelOption::GyroWalk => "gyro_bias_walk",
            ModelOption::GnssRecovery => "gnss_recovery",
            ModelOption::GyroGap => "gyro_gap",
            ModelOption::GnssWander => "gnss_wander",
            ModelOption::WheelIntervals => "wheel_intervals",
        }
    }
}

impl ModelOptions {
    /// Whether nothing is set.
    pub fn is_empty(&self) -> bool {
        *self == ModelOptions::default()
    }

    /// `self` with `what` taken from `from`.
    pub fn with(mut self, what: ModelOption, from: &ModelOptions) -> ModelOptions {
        match what {
            ModelOption::SideSlip => {
                self.rear_slip_gradient_rad_per_mps2 = from.rear_slip_gradient_rad_per_mps2
            }
            ModelOption::Steering => self.steering = from.steering,
            ModelOption::GyroWalk => {
                self.gyro_bias_walk_rps_per_sqrt_s = from.gyro_bias_walk_rps_per_sqrt_s
            }
            ModelOption::GnssRecovery => self.gnss_recovery_after_s = from.gnss_recovery_after_s,
            ModelOption::GyroGap => {
                self.gyro_gap_process_yaw_rate_rps = from.gyro_gap_process_yaw_rate_rps
            }
            ModelOption::GnssWander => self.gnss_wander = from.gnss_wander,
            ModelOption::WheelIntervals => {
                self.wheel_rows_over_interval = from.wheel_rows_over_interval
            }
        }
        self
    }

    /// Whether `what` is set.
    pub fn has(&self, what: ModelOption) -> bool {
        match what {
            ModelOption::SideSlip => self.rear_slip_gradient_rad_per_mps2.is_some(),
            ModelOption::Steering => self.steering.is_some(),
            ModelOption::GyroWalk => self.gyro_bias_walk_rps_per_sqrt_s.is_some(),
            ModelOption::GnssRecovery => self.gnss_recovery_after_s.is_some(),
            ModelOption::GyroGap => self.gyro_gap_process_yaw_rate_rps.is_some(),
            ModelOption::GnssWander => self.gnss_wander.is_some(),
            ModelOption::WheelIntervals => self.wheel_rows_over_interval.is_some(),
        }
    }

    /// Sets the options on `vehicle` (the others keep its values).
    pub fn apply_to(&self, vehicle: &mut Vehicle) {
        if let Some(g) = self.rear_slip_gradient_rad_per_mps2 {
            vehicle.rear_slip_gradient_rad_per_mps2 = g;
        }
        if let Some(s) = self.steering {
            vehicle.steering_ratio = s.steering_ratio;
            vehicle.steering_offset_rad = s.steering_offset_rad;
            vehicle.understeer_gradient_rad_per_mps2 = s.understeer_gradient_rad_per_mps2;
        }
        if let Some(w) = self.gyro_bias_walk_rps_per_sqrt_s {
            vehicle.noise.gyro_bias_walk_rps_per_sqrt_s = w;
        }
        if let Some(r) = self.gnss_recovery_after_s {
            vehicle.noise.gnss_recovery_after_s = r;
        }
        if let Some(q) = self.gyro_gap_process_yaw_rate_rps {
            vehicle.noise.gyro_gap_process_yaw_rate_rps = q;
        }
        if let Some(w) = self.gnss_wander {
            vehicle.noise.gnss_wander_std_m = w.std_m;
            vehicle.noise.gnss_wander_tau_s = w.tau_s;
        }
        if let Some(i) = self.wheel_rows_over_interval {
            vehicle.noise.wheel_rows_over_interval = i;
        }
    }

    /// An error naming the key whose value no vehicle could have (the
    /// vehicle's own checks, run on a nominal vehicle with the options set).
    pub fn validate(&self) -> Result<(), String> {
        let mut v = Vehicle::paper_car();
        self.apply_to(&mut v);
        v.validate().map_err(|e| format!("model: {e}"))
    }

    /// The words of what is set, for people ("rear side slip 0.0049 rad per
    /// m/s², …"); empty when nothing is.
    pub fn words(&self) -> String {
        let mut parts = Vec::new();
        if let Some(g) = self.rear_slip_gradient_rad_per_mps2 {
            parts.push(format!("rear side slip {g:.4} rad per m/s²"));
        }
        if let Some(s) = self.steering {
            parts.push(format!(
                "steering ratio {:.2}, offset {:+.2}°, understeer {:.4} rad per m/s²",
                s.steering_ratio,
                s.steering_offset_rad.to_degrees(),
                s.understeer_gradient_rad_per_mps2
            ));
        }
        if let Some(w) = self.gyro_bias_walk_rps_per_sqrt_s {
            parts.push(format!("gyro bias walking {w:.1e} rad/s per √s"));
        }
        if let Some(r) = self.gnss_recovery_after_s {
            parts.push(format!("GNSS recovery after {r:.0} s"));
        }
        if let Some(q) = self.gyro_gap_process_yaw_rate_rps {
            parts.push(format!(
                "yaw rate held through a missed gyro reading ({q} rad/s per 20 ms)"
            ));
        }
        if let Some(w) = self.gnss_wander {
            parts.push(format!(
                "receiver's wander {:.2} m over {:.0} s",
                w.std_m, w.tau_s
            ));
        }
        if self.wheel_rows_over_interval == Some(true) {
            parts.push("wheel rows over their intervals".into());
        }
        parts.join(", ")
    }
}

/// The model additions `drive` can be judged with, each with its z (its
/// estimate's distance from the paper's model in standard errors; NaN for
/// the settings, which have no estimate), and their values: the side slip
/// and the steering from the calibration `cal` of the drive (estimated, at
/// least `min_z` standard errors from the paper's model), the walking bias
/// when the drive has a gyro and its vehicle does not walk already, the
/// recovery's wait when the vehicle has none, the held yaw rate when at
/// least [`MIN_GYRO_GAP_SHARE`] of the wheel epochs have no gyro reading
/// ([`gyro_gap_share`]) and the vehicle does not hold it already, the
/// wheel intervals when the drive has wheel rows and the vehicle does not
/// use the intervals already.
pub fn candidates(
    drive: &Drive,
    cal: &Calibration,
    min_z: f64,
) -> (Vec<(ModelOption, f64)>, ModelOptions) {
    let mut out = Vec::new();
    let mut values = ModelOptions::default();
    let z_of = |value: f64, from: f64, std: Option<f64>| -> f64 {
        std.filter(|s| *s > 0.0)
            .map_or(f64::NAN, |s| (value - from) / s)
    };
    if let Some(s) = cal.side_slip.as_ref().filter(|s| s.gradient.estimated) {
        let z = z_of(
            s.gradient.value,
            drive.vehicle.rear_slip_gradient_rad_per_mps2,
            s.gradient.std,
        );
        if z.is_finite() && z.abs() >= min_z {
            values.rear_slip_gradient_rad_per_mps2 = Some(s.gradient.value);
            out.push((ModelOption::SideSlip, z));
        }
    }
    if let Some(st) = cal
        .steering
        .as_ref()
        .filter(|s| s.ratio.estimated && s.offset.estimated)
    {
        let v = &drive.vehicle;
        let understeer = st.understeer.as_ref().filter(|u| u.estimated);
        // The largest of the three departures from the vehicle's model.
        let z = [
            z_of(st.ratio.value, v.steering_ratio, st.ratio.std),
            z_of(st.offset.value, v.steering_offset_rad, st.offset.std),
            understeer.map_or(f64::NAN, |u| {
                z_of(u.value, v.understeer_gradient_rad_per_mps2, u.std)
            }),
        ]
        .into_iter()
        .filter(|z| z.is_finite())
        .max_by(|a, b| a.abs().total_cmp(&b.abs()))
        .unwrap_or(f64::NAN);
        if z.is_finite() && z.abs() >= min_z {
            values.steering = Some(SteeringModel {
                steering_ratio: st.ratio.value,
                steering_offset_rad: st.offset.value,
                understeer_gradient_rad_per_mps2: understeer
                    .map_or(v.understeer_gradient_rad_per_mps2, |u| u.value),
            });
            out.push((ModelOption::Steering, z));
        }
    }
    if !drive.yaw_rate.is_empty() && drive.vehicle.noise.gyro_bias_walk_rps_per_sqrt_s == 0.0 {
        values.gyro_bias_walk_rps_per_sqrt_s = Some(GYRO_BIAS_WALK_RPS_PER_SQRT_S);
        out.push((ModelOption::GyroWalk, f64::NAN));
    }
    if drive.vehicle.noise.gnss_recovery_after_s == 0.0 {
        values.gnss_recovery_after_s = Some(GNSS_RECOVERY_AFTER_S);
        out.push((ModelOption::GnssRecovery, f64::NAN));
    }
    if drive.vehicle.noise.gyro_gap_process_yaw_rate_rps == 0.0
        && gyro_gap_share(drive) >= MIN_GYRO_GAP_SHARE
    {
        values.gyro_gap_process_yaw_rate_rps = Some(GYRO_GAP_PROCESS_YAW_RATE_RPS);
        out.push((ModelOption::GyroGap, f64::NAN));
    }
    if !drive.vehicle.noise.wheel_rows_over_interval && !drive.wheels.is_empty() {
        values.wheel_rows_over_interval = Some(true);
        out.push((ModelOption::WheelIntervals, f64::NAN));
    }
    (out, values)
}

/// The receiver's wander fitted on `drive`'s fixes with `params` and the
/// filter options `opts` ([`crate::wander_fit::fit`]): `None` when white
/// fixes are the most likely (or the fit cannot run: no fix after the
/// filter's start).
pub fn wander_candidate(
    drive: &Drive,
    params: &crate::vehicle::Params,
    opts: &crate::ekf::FilterOptions,
) -> Option<Wander> {
    crate::wander_fit::fit(drive, params, opts).ok()?.best
}

/// The share of the drive's wheel intervals `(t_{k−1}, t_k]` in which no
/// gyro reading is stamped (0 without a gyro or with fewer than two wheel
/// rows): the wheel epochs of the paper's scheme without a gyro reading of
/// their own.
pub fn gyro_gap_share(drive: &Drive) -> f64 {
    let n = drive.wheels.len();
    if drive.yaw_rate.is_empty() || n < 2 {
        return 0.0;
    }
    let gyro = &drive.yaw_rate;
    let (mut j, mut empty) = (0, 0usize);
    for k in 1..n {
        let (a, b) = (drive.wheels.t_s(k - 1), drive.wheels.t_s(k));
        while j < gyro.len() && gyro[j].t_s <= a {
            j += 1;
        }
        if !(j < gyro.len() && gyro[j].t_s <= b) {
            empty += 1;
        }
    }
    empty as f64 / (n - 1) as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_set_only_their_keys_on_the_vehicle() {
        let v0 = Vehicle::paper_car();
        let all = ModelOptions {
            rear_slip_gradient_rad_per_mps2: Some(0.005),
            steering: Some(SteeringModel {
                steering_ratio: 15.8,
                steering_offset_rad: 0.02,
                understeer_gradient_rad_per_mps2: 0.003,
            }),
            gyro_bias_walk_rps_per_sqrt_s: Some(3e-6),
            gnss_recovery_after_s: Some(10.0),
            gyro_gap_process_yaw_rate_rps: Some(0.03),
            gnss_wander: Some(Wander {
                std_m: 1.0,
                tau_s: 60.0,
            }),
            wheel_rows_over_interval: Some(true),
        };
        let only_walk = ModelOptions::default().with(ModelOption::GyroWalk, &all);
        let mut v = v0.clone();
        only_walk.apply_to(&mut v);
        assert_eq!(v.noise.gyro_bias_walk_rps_per_sqrt_s, 3e-6);
        assert_eq!(v.steering_ratio, v0.steering_ratio);
        assert_eq!(
            v.rear_slip_gradient_rad_per_mps2,
            v0.rear_slip_gradient_rad_per_mps2
        );
        assert_eq!(
            v.noise.gnss_recovery_after_s,
            v0.noise.gnss_recovery_after_s
        );
        let mut w = v0.clone();
        all.apply_to(&mut w);
        assert_eq!(w.steering_offset_rad, 0.02);
        assert_eq!(w.understeer_gradient_rad_per_mps2, 0.003);
        assert_eq!(w.noise.gnss_recovery_after_s, 10.0);
        assert_eq!(
            (w.noise.gnss_wander_std_m, w.noise.gnss_wander_tau_s),
            (1.0, 60.0)
        );
        assert_eq!(v.noise.gnss_wander_std_m, 0.0);
        assert!(w.noise.wheel_rows_over_interval && !v.noise.wheel_rows_over_interval);
        assert!(all.validate().is_ok());
        for o in ModelOption::ALL {
            assert!(all.has(o) && !ModelOptions::default().has(o));
        }
        // A walk no gyro has is refused by the vehicle's own check.
        let bad = ModelOptions {
            gyro_bias_walk_rps_per_sqrt_s: Some(f64::NAN),
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().contains("gyro_bias_walk"));
    }
}
