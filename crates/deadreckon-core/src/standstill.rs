//! A standing car does not turn: while every wheel reads zero the filter
//! takes the yaw rate to be zero (issue 28; a zero-angular-rate update).
//!
//! The yaw rate's process noise is loose (table I: 1 rad/s per 20 ms step)
//! so that the measurements set it. At a standstill the wheels say nothing
//! about it (a tick count of zero on 20 ms is ±1 tick: ±2.5 rad/s on a
//! family car), and at an epoch without a gyro reading of its own (2–25 %
//! of the epochs of a car whose wheels and gyro run on their own clocks,
//! [`crate::gyro_hold`]) the yaw rate is free: its variance reaches the
//! heading at every such epoch. On held-out car 107 of the dynamic family
//! (every effect but the receiver's wander, 100 Hz ticks, a quarter of the
//! epochs without a gyro reading) the yaw standard deviation grew from
//! 2.4° to 5.6° through a 20 s stop, and the GNSS fixes, whose multipath
//! bursts the filter had only the heading to explain with (through the
//! antenna's lever arm: the wheels pin the position), turned the heading
//! from 0.0° to −6.1° off before the car pulled away; the 30 s outage
//! that started there ended 19.3 m off.
//!
//! A car cannot yaw without its wheels turning (short of sliding on ice or
//! standing on a turntable). So once every present wheel has read zero for
//! [`STANDSTILL_AFTER_S`], each wheel row until one of them reads otherwise
//! also applies the pseudo-measurement `ψ̇ = 0` with standard deviation
//! [`STANDSTILL_YAW_RATE_STD_RPS`]: the heading holds still, and where the
//! gyro bias is a state the gyro's readings at rest show the bias (the
//! classic zero-angular-rate update). The detector is causal and part of
//! the [`crate::ekf::Feeder`]'s state; the GNSS-aided filter asks for it
//! ([`crate::ekf::Feeder::with_standstill`] in [`crate::aided`]), so the
//! online filter and the batch run apply it at the same epochs, in every
//! command's outages, tracks, NEES and error-bound windows. The
//! calibration's passes do not: there it moved the estimators of the
//! delays, the gyro scale and the circumferences (`tests/corrections.rs`'s
//! tilted drive: a 90 ms gyro delay applied where none was estimated).
//!
//! On car 107 the yaw standard deviation now stays at 2.35° through the
//! stop, the window starts 0.56° off and ends 1.63 m off
//! (`deadreckon-api/tests/dynamic_family_defaults.rs`);
//! `tests/standstill.rs` pins it on a drive built by hand
//! (`fixes_at_a_standstill_rotated_the_heading`).
//!
//! Not done: the fixes at rest still move the heading through the lever
//! arm, as much as their declared noise allows (a 1 m multipath burst for
//! 10 s in the stop of that drive, its fixes otherwise exact, turned it
//! 5.3°; 16.7° before). Holding every state but the position (and the
//! receiver's wander) at a fix while the car stands stopped that (0.0°;
//! car 107's window 0.65 m) but was not kept: on dev cars 1–25 with every
//! effect but the wander it changed little on 23 cars (1.621 → 1.612 m)
//! and took car 20, whose calibration fails either way, from 1.96 to 60.7
//! m (docs/dynamics.md; measured with `ψ̇ = 0` in the calibration's passes
//! too).

use serde::{Deserialize, Serialize};

use crate::event::Measurement;

/// How long every wheel must have read zero before the car is taken to
/// stand, s. A wheel rolling slower than one tooth pitch per this time
/// passes no edge: about 4 cm/s on a 48-tooth ring of 1.9 m, at which a
/// car turning at its tightest (5 m) yaws at 0.008 rad/s, and only until
/// its next edge ends the standstill. Not tuned: the physics above; wheel
/// speed ECUs read exactly zero only at rest anyway; no other value was
/// tried. Checked by `tests/standstill.rs`, and measured (not chosen) on
/// dev cars 1–25 (`deadreckon-sim/tests/bias_switch.rs`'s
/// `bias_switch_on_the_family`) and once on held-out cars 101–110 through
/// `auto` (`deadreckon-api/tests/dynamic_family_defaults.rs`; docs/dynamics.md).
pub const STANDSTILL_AFTER_S: f64 = 1.0;

/// The standard deviation of the standstill's `ψ̇ = 0`, rad/s: a tenth of
/// table II's gyro noise (0.003 rad/s), so that a gyro reading at rest
/// moves the yaw rate by at most 1 % of its error (σ²/(σ² + β_ω²)). Not
/// tuned: a standing car's yaw rate is zero; the value only keeps the
/// gain finite. Checked as [`STANDSTILL_AFTER_S`].
pub const STANDSTILL_YAW_RATE_STD_RPS: f64 = 3e-4;

/// The standstill detector: since when every present wheel has read zero.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Standstill {
    /// The first of the wheel rows, all zero, up to the latest (`None`
    /// after a row with a wheel turning).
    zero_since_s: Option<f64>,
}

impl Standstill {
    /// Takes the wheel row `m` at `t_s` (only the wheels `present` count);
    /// whether the car stands: every present wheel has read zero since at
    /// least [`STANDSTILL_AFTER_S`] before. Rows of other sensors, or with
    /// no wheel present, leave the detector as it is and say no.
    pub fn push(&mut self, t_s: f64, m: &Measurement, present: impl Fn(usize) -> bool) -> bool {
        let zero = match *m {
            Measurement::WheelTicks { fl, fr, rl, rr } => {
                all_zero([fl, fr, rl, rr].map(|z| z as f64), &present)
            }
            Measurement::WheelSpeeds {
                fl_mps,
                fr_mps,
                rl_mps,
                rr_mps,
            } => all_zero([fl_mps, fr_mps, rl_mps, rr_mps], &present),
            _ => return false,
        };
        match zero {
            Some(true) => {
                let since = *self.zero_since_s.get_or_insert(t_s);
                t_s - since >= STANDSTILL_AFTER_S
            }
            Some(false) => {
                self.zero_since_s = None;
                false
            }
            None => false,
        }
    }
}

/// Whether every present wheel reads zero (`None` when none is present).
fn all_zero(z: [f64; 4], present: &impl Fn(usize) -> bool) -> Option<bool> {
    let mut any = false;
    for (i, v) in z.into_iter().enumerate() {
        if present(i) {
            any = true;
            if v != 0.0 {
                return Some(false);
            }
        }
    }
    any.then_some(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ticks(z: i64) -> Measurement {
        Measurement::WheelTicks {
            fl: z,
            fr: z,
            rl: z,
            rr: z,
        }
    }

    #[test]
    fn a_car_stands_once_its_wheels_have_read_zero_for_the_whole_span() {
        let mut s = Standstill::default();
        let all = |_: usize| true;
        assert!(!s.push(0.0, &ticks(3), all));
        assert!(!s.push(0.02, &ticks(0), all));
        assert!(!s.push(0.02 + STANDSTILL_AFTER_S - 0.01, &ticks(0), all));
        assert!(s.push(0.02 + STANDSTILL_AFTER_S, &ticks(0), all));
        assert!(s.push(5.0, &ticks(0), all));
        // One wheel turning ends it at once, and the span starts over.
        let one = Measurement::WheelTicks {
            fl: 0,
            fr: 1,
            rl: 0,
            rr: 0,
        };
        assert!(!s.push(5.02, &one, all));
        assert!(!s.push(5.04, &ticks(0), all));
        assert!(!s.push(5.04 + STANDSTILL_AFTER_S - 0.01, &ticks(0), all));
        // A wheel without a sensor does not count; no wheel at all never stands.
        let mut s = Standstill::default();
        let not_fr = |i: usize| i != 1;
        assert!(!s.push(0.0, &one, not_fr));
        assert!(s.push(STANDSTILL_AFTER_S, &one, not_fr));
        let mut s = Standstill::default();
        assert!(!s.push(0.0, &ticks(0), |_| false));
        assert!(!s.push(9.0, &ticks(0), |_| false));
    }

    #[test]
    fn wheel_speeds_stand_at_exact_zero_only() {
        let speeds = |v: f64| Measurement::WheelSpeeds {
            fl_mps: v,
            fr_mps: v,
            rl_mps: v,
            rr_mps: v,
        };
        let mut s = Standstill::default();
        let all = |_: usize| true;
        assert!(!s.push(0.0, &speeds(0.0), all));
        assert!(!s.push(2.0, &speeds(0.01), all));
        assert!(!s.push(2.02, &speeds(0.0), all));
        assert!(s.push(3.02, &speeds(0.0), all));
        // Other sensors' rows change nothing.
        assert!(!s.push(3.03, &Measurement::YawRate { yaw_rate_rps: 0.0 }, all));
        assert!(s.push(3.04, &speeds(0.0), all));
    }
}
