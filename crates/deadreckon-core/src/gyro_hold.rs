//! Whether the gyro is live, so that the steering does not stand in for it
//! (issue 28).
//!
//! On a real car the wheels and the gyro come from different ECUs on their
//! own clocks, with stamp jitter: at the same nominal rate, 2–19 % of wheel
//! rows per 30 s had no gyro reading of their own in the paper's scheme
//! ([`crate::ekf::Timing::WheelEpochs`], each reading used at most once). At
//! such an epoch the yaw rate, whose process noise is loose (table I: 1 rad/s
//! per 20 ms step, so that the measurements set it), was set by the steering
//! wheel: its offset and the understeer turned the heading (a highway window
//! ended 18.8 m off; 1.6 m without the steering).
//!
//! So the gyro is **live** for a while after each reading, and while it is
//! live the steering is applied only together with a gyro reading: in the
//! wheel-epoch scheme an epoch without a gyro reading of its own leaves the
//! steering reading waiting for the next epoch that has one (a newer steering
//! reading supersedes it); in the per-reading scheme a steering reading waits
//! for the next gyro reading and is applied right after it. Both are counted
//! as [`crate::ekf::FilterStats::steering_deferred`]. A gyro that has stopped
//! (no reading for longer than its hold) is not live, and the steering stands
//! in for it as before. Every reading is still used at most once.
//!
//! Rejected: reusing the gyro's latest reading at an epoch without one. On
//! family cars with a jittered gyro it also kept the wheels' noise out of the
//! yaw rate (30 s outages 2.38 → 0.59 m on car 3, 5.32 → 2.12 m on car 2,
//! `tests/gyro_hold.rs`), but on the comma2k19 segment (wheel rows at about
//! 83 Hz, irregular, the phone's gyro at 104 Hz: 7 % of the epochs without a
//! reading) its 20 s outages went from 0.56 to 0.69 m median with the same
//! parameters, where deferring the steering gives 0.57 m: the family's filter
//! under-rates its wheel-speed noise (tone-ring jitter differenced at
//! 100 Hz), which a reused reading covered.
//!
//! What the wheels give at such an epoch is held down instead by
//! [`crate::vehicle::Noise::gyro_gap_process_yaw_rate_rps`] (off by
//! default, a model option `--corrections auto` judges on held-back GNSS,
//! [`crate::model_options`]): the epoch's prediction gives the yaw rate a
//! physical process noise, so it keeps the last reading's value unless the
//! wheels clearly say otherwise; the reading itself is still used once.
//!
//! A reading keeps the gyro live for [`HOLD_INTERVALS`] times the gyro's
//! typical interval (an exponential average of the intervals between its
//! readings, weight [`INTERVAL_WEIGHT`]), and never longer than
//! [`MAX_HOLD_S`]. On synchronous streams (every wheel row with a gyro
//! reading of its own, as the simulator's built-in drives and the golden
//! files have) nothing changes.

use serde::{Deserialize, Serialize};

/// A reading stays live for this many of the gyro's typical intervals: one
/// missed reading (2 intervals of age at the next wheel epoch, less the
/// jitter) is covered, a stopped gyro is not.
pub const HOLD_INTERVALS: f64 = 2.5;
/// A reading is never live for longer than this, s (a 10 Hz gyro's hold).
pub const MAX_HOLD_S: f64 = 0.25;
/// Weight of the newest interval in the gyro's typical interval.
pub const INTERVAL_WEIGHT: f64 = 0.05;

/// The gyro's latest reading and its typical interval: whether it is live.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct GyroHold {
    /// Time and value of the latest reading, s and rad/s.
    last: Option<(f64, f64)>,
    /// The exponential average of the intervals between readings, s.
    interval_s: Option<f64>,
}

impl GyroHold {
    /// Takes a reading of `value` rad/s at `t_s`.
    pub fn push(&mut self, t_s: f64, value: f64) {
        if let Some((t0, _)) = self.last {
            let dt = t_s - t0;
            if dt > 0.0 && dt.is_finite() {
                self.interval_s = Some(match self.interval_s {
                    None => dt,
                    Some(i) => i + INTERVAL_WEIGHT * (dt - i),
                });
            }
        }
        self.last = Some((t_s, value));
    }

    /// How long a reading stays live, s (`None` before two readings).
    pub fn hold_s(&self) -> Option<f64> {
        self.interval_s
            .map(|i| (HOLD_INTERVALS * i).min(MAX_HOLD_S))
    }

    /// The latest reading if it is live at `t_s`.
    pub fn live_at(&self, t_s: f64) -> Option<f64> {
        let (t0, v) = self.last?;
        let age = t_s - t0;
        (age >= 0.0 && age <= self.hold_s()?).then_some(v)
    }

    /// Whether a reading is live at `t_s`.
    pub fn is_live(&self, t_s: f64) -> bool {
        self.live_at(t_s).is_some()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_reading_is_live_for_two_and_a_half_intervals() {
        let mut h = GyroHold::default();
        assert_eq!(h.live_at(0.0), None);
        h.push(0.0, 0.1);
        // One reading: no interval yet, nothing is held.
        assert_eq!(h.live_at(0.001), None);
        for k in 1..=100 {
            h.push(k as f64 * 0.01, 0.1 + k as f64);
        }
        let hold = h.hold_s().unwrap();
        assert!((hold - 0.025).abs() < 1e-12, "{hold}");
        assert_eq!(h.live_at(1.0 + 0.02), Some(100.1));
        assert_eq!(h.live_at(1.0 + 0.026), None);
        // A reading is not live before its own time.
        assert_eq!(h.live_at(0.999), None);
    }

    #[test]
    fn a_slow_gyro_is_held_at_most_max_hold() {
        let mut h = GyroHold::default();
        for k in 0..10 {
            h.push(k as f64, 0.0);
        }
        assert_eq!(h.hold_s(), Some(MAX_HOLD_S));
        assert!(h.is_live(9.0 + MAX_HOLD_S));
        assert!(!h.is_live(9.0 + MAX_HOLD_S + 1e-9));
    }

    #[test]
    fn jittered_intervals_average_to_the_rate() {
        // 100 Hz with ±3 ms stamp jitter (seeded LCG).
        let mut h = GyroHold::default();
        let mut s: u64 = 7;
        for k in 0..2000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let u = (s >> 11) as f64 / (1u64 << 53) as f64;
            h.push(k as f64 * 0.01 + 0.006 * (u - 0.5), 0.0);
        }
        let hold = h.hold_s().unwrap();
        assert!((hold - 0.025).abs() < 0.0015, "{hold}");
    }
}
