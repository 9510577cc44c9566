//! Time offsets of the streams against the wheel clock.
//!
//! A stream logged late by `d` seconds carries at `t` what happened at `t − d`;
//! the correction moves its timestamps back by `d` ([`Delays::apply`]).
//!
//! - **Gyro, CAN speed, steering** ([`scalar_delay`]): the stream against a
//!   signal derived from the wheels (yaw rate from the rear wheels' speed
//!   difference, the wheels' mean speed, the curvature yaw rate / speed above
//!   [`MIN_CURVATURE_SPEED_MPS`]), both smoothed by a 0.2 s triangle. For
//!   each lag on a grid the stream is fitted as `a + b·x(t − d)` by least
//!   squares; the lag of the smallest residual is
//!   refined by a parabola through its neighbours. The standard error is the
//!   Gauss–Newton one, `σ²/Σ(b·x′ − mean)²`, inflated by `(1 + ρ)/(1 − ρ)` for
//!   the lag-one autocorrelation `ρ` of the residuals. Steering's delay is
//!   the lag of the car's yaw response behind the steering wheel (tyre and
//!   body dynamics included), as openpilot's `lagd` measures it.
//! - **GNSS** ([`gnss_delay`]): a parameter of the least squares between the
//!   fixes and the dead-reckoned track. The drive is calibrated (RTS) with
//!   the fixes moved back by the current delay, dead-reckoned from the
//!   smoothed start (every proprioceptive sensor: wheels, gyro, CAN speed and
//!   steering; `SensorSet::dead_reckoning`), and the fixes' residuals against
//!   the antenna's dead-reckoned position are regressed on its velocity, with
//!   a bias, a rotation and a stretch per 20 s window for the dead
//!   reckoning's drift (`r = −δ·V + b + θ·J(p − p_c) + λ(p − p_c)`), until
//!   `δ` settles. The dead reckoning takes each wheel row over the
//!   interval it describes ([`REFERENCE_WHEEL_ROWS`]) whichever step the
//!   calibrating filter takes, and the scalar streams are moved by their
//!   delays on true time ([`on_true_time`]): the delay is the receiver's,
//!   not the paper's wheel step's lag (issue 29). (Against the
//!   smoothed track, which the fixes pull along, a 0.18 s delay read
//!   0.11 s.) The smoother absorbs
//!   part of a wrong delay, so one step under-corrects (`δ ≈ (1 − α)(d* − d)`):
//!   after a first plain step the delay moves by secant steps on `δ(d) = 0`,
//!   and the standard error of `δ` is divided by the slope `1 − α`. Each
//!   step's calibration starts from the previous step's parameters (a warm
//!   start: the same fixed point within the calibration's tolerance, in
//!   fewer passes; issue 30).
//!
//! **Status**: a delay is *not estimated* (and not applied) with too few
//! samples, when the best lag lies on the search bound ([`DelayOptions::max_delay_s`]:
//! rejected, never clamped), or when its standard error exceeds
//! [`DelayOptions::max_std_s`] (too little excitation: no turns for the gyro,
//! no speed changes for the CAN speed).

use crate::drive::Drive;
pub(crate) use crate::series::lag1;
pub use crate::status::{Status, MEASURED};

/// Speed above which the steering is compared with the curvature, m/s.
pub const MIN_CURVATURE_SPEED_MPS: f64 = 2.0;

/// The reason of a delay that was measured but not applied because only the
/// GNSS delay was asked for (`Which::Gnss`); such a [`Delay`] keeps its
/// measured `delay_s` and `std_s`.
pub const MEASURED_NOT_APPLIED: &str = "measured, not applied: only the GNSS delay was asked for";

/// The streams with a delay.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stream {
    /// The gyro's yaw rate.
    Gyro,
    /// The CAN vehicle speed.
    Speed,
    /// The steering wheel angle.
    Steering,
    /// The GNSS fixes.
    Gnss,
}

impl Stream {
    /// Every stream, in report order.
    pub const ALL: [Stream; 4] = [Stream::Gyro, Stream::Speed, Stream::Steering, Stream::Gnss];
    /// `gyro`, `speed`, `steering`, `gnss`.
    pub fn name(self) -> &'static str {
        match self {
            Stream::Gyro => "gyro",
            Stream::Speed => "speed",
            Stream::Steering => "steering",
            Stream::Gnss => "gnss",
        }
    }
}

/// One stream's delay.
#[derive(Debug, Clone, PartialEq)]
pub struct Delay {
    /// How late the stream is, s (positive: logged after the instant it describes).
    pub delay_s: f64,
    /// Standard error, s.
    pub std_s: f64,
    /// Samples used.
    pub samples: usize,
    /// Estimated, or why not.
    pub status: Status,
    /// What the filter's own step adds to the delay it applies, s (with the
    /// paper's step, the GNSS only, else 0): `delay_s` is the receiver's
    /// delay against true time, while the paper's wheel step
    /// ([`crate::ekf::WheelRows::Instant`], the default) dead-reckons
    /// positions that trail by about a wheel period and the scalar streams
    /// as they are corrected; the filter applies the delay its own dead
    /// reckoning matches ([`Delay::applied_s`]). Issue 29; see
    /// [`gnss_delay`]. With the wheel rows over their intervals
    /// ([`Delays::for_wheel_intervals`]) the GNSS's is 0 and each estimated
    /// scalar stream's is half a wheel period (its delay on true time).
    pub step_offset_s: f64,
}

impl Delay {
    fn not_estimated(reason: impl Into<String>) -> Delay {
        Delay {
            delay_s: f64::NAN,
            std_s: f64::NAN,
            samples: 0,
            status: Status::NotEstimated(reason.into()),
            step_offset_s: 0.0,
        }
    }
    /// The delay to apply: the estimate plus the filter's step offset
    /// (`delay_s + step_offset_s`), or 0 when not estimated.
    pub fn applied_s(&self) -> f64 {
        if self.status.is_estimated() {
            self.delay_s + self.step_offset_s
        } else {
            0.0
        }
    }
}

/// The delays of a drive's streams.
#[derive(Debug, Clone, PartialEq)]
pub struct Delays {
    /// Gyro vs the rear wheels' yaw rate.
    pub gyro: Delay,
    /// CAN speed vs the wheels' mean speed.
    pub speed: Delay,
    /// Steering vs the wheels' curvature.
    pub steering: Delay,
    /// GNSS position vs the smoothed track.
    pub gnss: Delay,
}

/// The reason of a delay [`Which::None`] did not ask for.
pub const NOT_ASKED: &str = "not asked for";

impl Delays {
    /// The delays as a filter that uses each wheel row over the interval it
    /// describes ([`crate::ekf::WheelRows::Interval`], the model option
    /// [`crate::model_options::ModelOption::WheelIntervals`]) applies them:
    /// the receiver's delay without the paper's step offset (the GNSS
    /// delay's reference takes the rows over their intervals,
    /// [`REFERENCE_WHEEL_ROWS`]), and each estimated scalar stream on true
    /// time, half a wheel period later than as estimated ([`on_true_time`]:
    /// the estimate aligns the stream with the paper's step). The
    /// estimates themselves are unchanged; the offsets are in
    /// [`Delay::step_offset_s`].
    pub fn for_wheel_intervals(&self, drive: &Drive) -> Delays {
        let half = wheel_half_period_s(drive);
        let mut out = self.clone();
        for s in [Stream::Gyro, Stream::Speed, Stream::Steering] {
            let d = out.get_mut(s);
            d.step_offset_s = if d.status.is_estimated() { half } else { 0.0 };
        }
        out.gnss.step_offset_s = 0.0;
        out
    }

    /// No delay asked for any stream ([`Which::None`]).
    pub fn none() -> Delays {
        let n = || Delay::not_estimated(NOT_ASKED);
        Delays {
            gyro: n(),
            speed: n(),
            steering: n(),
            gnss: n(),
        }
    }
    /// The delay of `s`.
    pub fn get(&self, s: Stream) -> &Delay {
        match s {
            Stream::Gyro => &self.gyro,
            Stream::Speed => &self.speed,
            Stream::Steering => &self.steering,
            Stream::Gnss => &self.gnss,
        }
    }
    /// The delay of `s`, to change.
    pub fn get_mut(&mut self, s: Stream) -> &mut Delay {
        match s {
            Stream::Gyro => &mut self.gyro,
            Stream::Speed => &mut self.speed,
            Stream::Steering => &mut self.steering,
            Stream::Gnss => &mut self.gnss,
        }
    }
    /// The drive with every estimated delay removed (timestamps moved back).
    pub fn apply(&self, drive: &Drive) -> Drive {
        let mut d = drive.clone();
        self.apply_in_place(&mut d);
        d
    }

    /// [`Delays::apply`] to a drive in place (no copy).
    pub fn apply_in_place(&self, drive: &mut Drive) {
        shift_in_place(
            drive,
            [
                self.gyro.applied_s(),
                self.speed.applied_s(),
                self.steering.applied_s(),
                self.gnss.applied_s(),
            ],
        )
    }
}

/// The drive with the gyro (one- and three-axis), speed, steering and GNSS
/// timestamps moved back by the given delays, s, in [`Stream::ALL`] order.
pub fn shift(drive: &Drive, delays_s: [f64; 4]) -> Drive {
    let mut d = drive.clone();
    shift_in_place(&mut d, delays_s);
    d
}

/// [`shift`] in place (no copy).
pub fn shift_in_place(d: &mut Drive, delays_s: [f64; 4]) {
    let [g, s, st, gn] = delays_s;
    d.yaw_rate.iter_mut().for_each(|x| x.t_s -= g);
    d.imu.gyro.iter_mut().for_each(|x| x.t_s -= g);
    d.speed.iter_mut().for_each(|x| x.t_s -= s);
    d.steering.iter_mut().for_each(|x| x.t_s -= st);
    d.gnss.iter_mut().for_each(|x| x.t_s -= gn);
}

/// Options of the delay estimation.
#[derive(Debug, Clone, PartialEq)]
pub struct DelayOptions {
    /// Largest delay searched, either sign, s: a best lag on this bound is rejected.
    pub max_delay_s: f64,
    /// Grid step of the lag search, s.
    pub step_s: f64,
    /// Largest standard error of an accepted delay, s.
    pub max_std_s: f64,
    /// Fewest samples (GNSS fixes, or windows of the scalar streams).
    pub min_samples: usize,
    /// Half-width of the triangle smoothing both scalar streams, s, and the
    /// spacing of the points compared (several sample periods of the
    /// slowest stream).
    pub window_s: f64,
    /// Largest number of calibrate-and-regress steps of the GNSS delay.
    pub gnss_iterations: usize,
    /// Window of the GNSS regression's biases, s (each window its own east
    /// and north bias: the receiver's slowly wandering error).
    pub gnss_window_s: f64,
    /// Apply the GNSS delay the filter's own dead reckoning matches (the
    /// receiver's plus [`Delay::step_offset_s`]; default), or the
    /// receiver's (`false`: the offset is 0). Chosen on the comma2k19
    /// segment (`evaluate --outage 20 --step 5`: 0.595 / 0.618 m mean /
    /// median against 0.637 / 0.697 m); on the kinematic family's members
    /// 1–8 the receiver's did as well at 100 Hz wheels and better at 25 Hz
    /// (1.730 against 1.813 m, one member's 0.35 m;
    /// `crates/deadreckon-sim/tests/gnss_delay_applied.rs`).
    pub gnss_step_offset: bool,
}

impl Default for DelayOptions {
    fn default() -> Self {
        DelayOptions {
            max_delay_s: 0.5,
            step_s: 0.005,
            max_std_s: 0.02,
            min_samples: 50,
            window_s: 0.2,
            gnss_iterations: 8,
            gnss_window_s: 20.0,
            gnss_step_offset: true,
        }
    }
}

/// Blocks of consecutive points of the delay's jackknife.
pub const JACKKNIFE_BLOCKS: usize = 20;

/// The delete-a-group jackknife's standard error from the estimates made
/// without each group in turn: `√((g − 1)/g · Σ (θᵢ − θ̄)²)`.
fn jackknife_std(estimates: &[f64]) -> f64 {
    let g = estimates.len() as f64;
    let m = estimates.iter().sum::<f64>() / g;
    ((g - 1.0) / g * estimates.iter().map(|v| (v - m).powi(2)).sum::<f64>()).sqrt()
}

mod corrections;
mod gnss;
mod scalar;

pub use corrections::{
    apply_known, apply_known_in_place, estimate, estimate_lent, estimate_with_params,
    estimate_with_params_owned, on_true_time, prepare, prepare_owned, prepare_with,
    wheel_half_period_s, Corrections, KnownCorrections, Which,
};
pub use gnss::{gnss_delay, regress_gnss, states_at_fixes, REFERENCE_WHEEL_ROWS};
pub use scalar::{gyro_delay, scalar_delay, speed_delay, steering_delay, TimedSample};
