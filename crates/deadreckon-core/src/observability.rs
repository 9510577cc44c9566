//! What a calibration drive contained: an inventory of its manoeuvres from the
//! wheels alone (speed: the mean of the wheels with the nominal
//! circumference; yaw rate: the rear wheels' difference over the rear track),
//! and what it lacked, with the parameters each lack weakens.
//!
//! The classes, per wheel interval: a **stop** (speed below
//! [`STOP_SPEED_MPS`] for at least [`MIN_STOP_S`]), **above the threshold**
//! (speed above the calibration's speed threshold), and above it a **left
//! turn** or **right turn** (|ψ̇| above [`TURN_RATE_RPS`]) or a **straight**
//! (|ψ̇| below [`STRAIGHT_RATE_RPS`]). The minimum amounts below are rules of
//! thumb, not measured costs: a drive below them is reported as lacking.

use serde::{Deserialize, Serialize};

use crate::drive::{Drive, Wheels};

/// Below this speed the car stands, m/s.
pub const STOP_SPEED_MPS: f64 = 0.05;
/// Shortest standstill counted as a stop, s.
pub const MIN_STOP_S: f64 = 1.0;
/// Above this yaw rate a stretch is a turn, rad/s (about 3°/s).
pub const TURN_RATE_RPS: f64 = 0.05;
/// Below this yaw rate a stretch is straight, rad/s.
pub const STRAIGHT_RATE_RPS: f64 = 0.01;
/// Least time in each turn direction, s.
pub const MIN_TURN_S: f64 = 20.0;
/// Least time above the speed threshold, s.
pub const MIN_ABOVE_S: f64 = 120.0;
/// Least time straight, s.
pub const MIN_STRAIGHT_S: f64 = 60.0;
/// Least stops.
pub const MIN_STOPS: usize = 2;

/// The manoeuvres of a drive.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Manoeuvres {
    /// Time covered by the wheel rows, s.
    pub duration_s: f64,
    /// Time above the speed threshold, s.
    pub above_threshold_s: f64,
    /// Time in left (counter-clockwise) turns above the threshold, s.
    pub left_turn_s: f64,
    /// Time in right turns above the threshold, s.
    pub right_turn_s: f64,
    /// Time straight above the threshold, s.
    pub straight_s: f64,
    /// Standstills of at least [`MIN_STOP_S`].
    pub stops: usize,
    /// Time in those standstills, s.
    pub stopped_s: f64,
}

/// One thing a drive lacked.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Lack {
    /// What was missing, with the amount found and the amount wanted.
    pub what: String,
    /// The parameters (names as in `params.toml`) it weakens.
    pub weakens: Vec<&'static str>,
    /// Why.
    pub why: &'static str,
}

/// The inventory of `drive` with the calibration's speed threshold.
pub fn manoeuvres(drive: &Drive, min_speed_mps: f64) -> Manoeuvres {
    let v = &drive.vehicle;
    let k = v.wheel_circumference_m / f64::from(v.ticks_per_rev.max(1));
    let n = drive.wheels.len();
    let mut m = Manoeuvres::default();
    let mut still_s = 0.0;
    let close = |still: &mut f64, m: &mut Manoeuvres| {
        if *still >= MIN_STOP_S {
            m.stops += 1;
            m.stopped_s += *still;
        }
        *still = 0.0;
    };
    for i in 1..n {
        let dt = drive.wheels.t_s(i) - drive.wheels.t_s(i - 1);
        if !(dt > 0.0 && dt.is_finite()) {
            continue;
        }
        // Wheel speeds FL, FR, RL, RR, m/s.
        let s: [f64; 4] = match &drive.wheels {
            Wheels::Ticks(r) => {
                let r = &r[i];
                [r.fl, r.fr, r.rl, r.rr].map(|t| t as f64 * k / dt)
            }
            Wheels::Speeds(r) => {
                let r = &r[i];
                [r.fl_mps, r.fr_mps, r.rl_mps, r.rr_mps]
            }
        };
        let present: Vec<f64> = (0..4)
            .filter(|&w| v.wheels_present[w])
            .map(|w| s[w])
            .collect();
        if present.is_empty() {
            continue;
        }
        let speed = present.iter().sum::<f64>() / present.len() as f64;
        m.duration_s += dt;
        if speed.abs() < STOP_SPEED_MPS {
            still_s += dt;
            continue;
        }
        close(&mut still_s, &mut m);
        if speed.abs() < min_speed_mps {
            continue;
        }
        m.above_threshold_s += dt;
        if !(v.wheels_present[2] && v.wheels_present[3]) {
            continue;
        }
        let rate = (s[3] - s[2]) / v.track_rear_m;
        if rate > TURN_RATE_RPS {
            m.left_turn_s += dt;
        } else if rate < -TURN_RATE_RPS {
            m.right_turn_s += dt;
        } else if rate.abs() < STRAIGHT_RATE_RPS {
            m.straight_s += dt;
        }
    }
    close(&mut still_s, &mut m);
    m
}

impl Manoeuvres {
    /// What the drive lacked (empty when it had enough of everything).
    pub fn lacking(&self) -> Vec<Lack> {
        let circ = vec![
            "circumference_fl_m",
            "circumference_fr_m",
            "circumference_rl_m",
            "circumference_rr_m",
        ];
        let mut out = Vec::new();
        if self.above_threshold_s < MIN_ABOVE_S {
            let mut w = vec!["speed_scale"];
            w.extend(&circ);
            out.push(Lack {
                what: format!(
                    "{:.0} s above the speed threshold (want {MIN_ABOVE_S:.0} s)",
                    self.above_threshold_s
                ),
                weakens: w,
                why: "the scale and circumferences are fitted on samples above the threshold only",
            });
        }
        for (name, t) in [("left", self.left_turn_s), ("right", self.right_turn_s)] {
            if t < MIN_TURN_S {
                out.push(Lack {
                    what: format!("{t:.0} s of {name} turns (want {MIN_TURN_S:.0} s)"),
                    weakens: vec![
                        "gyro_bias_rps",
                        "circumference_fl_m",
                        "circumference_fr_m",
                        "circumference_rl_m",
                        "circumference_rr_m",
                    ],
                    why: "turns one way only leave a gyro bias and a left/right circumference difference looking alike",
                });
            }
        }
        if self.straight_s < MIN_STRAIGHT_S {
            out.push(Lack {
                what: format!(
                    "{:.0} s of straight driving (want {MIN_STRAIGHT_S:.0} s)",
                    self.straight_s
                ),
                weakens: circ.clone(),
                why: "straights compare the four wheels without the turn geometry",
            });
        }
        if self.stops < MIN_STOPS {
            out.push(Lack {
                what: format!(
                    "{} stops of at least {MIN_STOP_S:.0} s (want {MIN_STOPS})",
                    self.stops
                ),
                weakens: vec!["gyro_bias_rps"],
                why: "at a standstill the gyro reads its bias alone",
            });
        }
        out
    }
}
