//! What a calibration drive contained: an inventory of its manoeuvres from the
//! wheels alone (speed: the mean of the wheels with the nominal
//! circumference; yaw rate: the rear wheels' difference over the rear track),
//! and what it lacked, with the parameters each lack weakens.
//!
//! The classes: a **stop** (speed below [`STOP_SPEED_MPS`] for at least
//! [`MIN_STOP_S`], per wheel interval), and over moving blocks of at least
//! [`BLOCK_S`] (means over the block) **above the threshold** (speed above the
//! calibration's speed threshold), and above it a **left turn** or **right
//! turn** (|ψ̇| above [`TURN_RATE_RPS`]) or a **straight** (|ψ̇| below
//! [`STRAIGHT_RATE_RPS`]). Blocks, because one wheel interval of ticks is too
//! coarse a yaw rate: with 48 ticks on a 1.92 m tyre one tick of difference
//! over 20 ms is 2 m/s, and the inventory found 98 s of left turns on a
//! simulated drive without any.
//!
//! The minimum amounts below are rules of thumb: a drive below them is
//! reported as lacking. What each lack costs was measured on variants of the
//! simulated calibration drive (six seeds each,
//! `crates/deadreckon-sim/tests/observability.rs`): for the RTS calibration
//! only the time above the speed threshold matters (the drive cut to its
//! first 240 s: speed-scale and circumference errors ×3.2 and ×3.3); without
//! turns or without stops its errors stay within ×0.7–1.3 of the whole
//! drive's. Turns and straights feed the gyro's scale error, stops the ZUPT
//! calibration.

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
    /// The parameters it weakens (names as in `params.toml`; a calibration
    /// method in parentheses when only that method needs it).
    pub weakens: Vec<&'static str>,
    /// Why.
    pub why: &'static str,
}

/// Shortest moving stretch classified at once, s: speed and yaw rate are
/// the means over it.
pub const BLOCK_S: f64 = 2.0;

/// A moving stretch being summed.
#[derive(Default)]
struct Block {
    dt: f64,
    dist: f64,
    rear_diff: f64,
}

/// The inventory of `drive` with the calibration's speed threshold.
pub fn manoeuvres(drive: &Drive, min_speed_mps: f64) -> Manoeuvres {
    let v = &drive.vehicle;
    let k = v.wheel_circumference_m / f64::from(v.ticks_per_rev.max(1));
    let n = drive.wheels.len();
    let mut m = Manoeuvres::default();
    let mut still_s = 0.0;
    let rear = v.wheels_present[2] && v.wheels_present[3];
    let track = v.track_rear_m;
    let mut block = Block::default();
    let flush = |b: &mut Block, m: &mut Manoeuvres| {
        if b.dt <= 0.0 {
            return;
        }
        let (speed, rate) = (b.dist / b.dt, b.rear_diff / b.dt / track);
        if speed.abs() >= min_speed_mps {
            m.above_threshold_s += b.dt;
            if rear {
                if rate > TURN_RATE_RPS {
                    m.left_turn_s += b.dt;
                } else if rate < -TURN_RATE_RPS {
                    m.right_turn_s += b.dt;
                } else if rate.abs() < STRAIGHT_RATE_RPS {
                    m.straight_s += b.dt;
                }
            }
        }
        *b = Block::default();
    };
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
            flush(&mut block, &mut m);
            continue;
        }
        close(&mut still_s, &mut m);
        // Moving: summed over a block of at least BLOCK_S before it is
        // classified (one wheel interval of ticks is too coarse a yaw rate:
        // a tick of difference over 20 ms is 2 m/s of speed difference).
        block.dt += dt;
        block.dist += speed * dt;
        block.rear_diff += (s[3] - s[2]) * dt;
        if block.dt >= BLOCK_S {
            flush(&mut block, &mut m);
        }
    }
    flush(&mut block, &mut m);
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
                why:
                    "the scale and circumferences are fitted on samples above the threshold only; \
                      measured on the simulated calibration drive cut to its first 240 s: \
                      errors ×3.2 (speed scale) and ×3.3 (circumferences)",
            });
        }
        for (name, t) in [("left", self.left_turn_s), ("right", self.right_turn_s)] {
            if t < MIN_TURN_S {
                out.push(Lack {
                    what: format!("{t:.0} s of {name} turns (want {MIN_TURN_S:.0} s)"),
                    weakens: vec!["gyro_scale"],
                    why: "the gyro's scale error is estimated from turns (at least 2 of 20° \
                          between 5 stretches of straight driving); \
                          measured on the simulated calibration drive without turns: the six \
                          parameters of the RTS calibration are not weakened (errors ×0.7–1.0)",
                });
            }
        }
        if self.straight_s < MIN_STRAIGHT_S {
            out.push(Lack {
                what: format!(
                    "{:.0} s of straight driving (want {MIN_STRAIGHT_S:.0} s)",
                    self.straight_s
                ),
                weakens: vec!["gyro_scale"],
                why: "the gyro's scale error compares the heading between stretches of straight driving",
            });
        }
        if self.stops < MIN_STOPS {
            out.push(Lack {
                what: format!(
                    "{} stops of at least {MIN_STOP_S:.0} s (want {MIN_STOPS})",
                    self.stops
                ),
                weakens: vec!["gyro_bias_rps (ZUPT)"],
                why: "the ZUPT calibration reads the gyro bias at standstill only; \
                      measured on the simulated calibration drive without stops: the RTS \
                      calibration is not weakened (errors ×1.0–1.3)",
            });
        }
        out
    }
}
