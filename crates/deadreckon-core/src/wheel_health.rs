//! Slipping and bad wheels: a per-wheel monitor of the wheels' residuals
//! against what the other sensors say, which drops a wheel from the fusion
//! while it misbehaves and takes it back when it agrees again.
//!
//! The per-measurement χ² gate of [`crate::filter`] sees one epoch at a time,
//! and with the paper's loose process noise on the speed the first wheel
//! updated in an epoch is predicted from almost nothing (its NIS stays near 0
//! whatever it reads). The monitor looks at the redundancy instead: after the
//! epoch's updates, each wheel's reading `z` is compared with what the updated
//! state predicts for it, `h(x̂⁺)` (the wheel's model of eq. 6 or 8 with the
//! speed and yaw rate that the other wheels, the gyro and the CAN speed agree
//! on). The residuals are summed over two sliding windows, in the sensor's
//! unit (ticks, or metres for wheel speeds), and normalised:
//!
//! ```text
//! T = Σ (z − h) / sqrt(V),   V = Σ σ_z² + σ_q² + (ε · Σ |h|)²
//! ```
//!
//! with `σ_z` the reading's white noise (wheel speeds: `wheel_speed_mps · dt`
//! per reading), `σ_q` the quantisation of a window of ticks (two edges of
//! `wheel_ticks` each: counts telescope, so a window's count is off by at most
//! one tick whatever its length) and `ε` the relative error a calibrated wheel
//! model still has ([`WheelMonitorConfig::relative_error`]; in the short
//! window the larger [`WheelMonitorConfig::slip_relative_error`], so a wheel a
//! few percent off is classed as bad rather than slipping). Under no fault `T`
//! is about standard normal, so `T²` is compared with χ²(1) quantiles:
//!
//! - the **short window** (`short_window_s`, half a second) catches a wheel
//!   that spins or locks for a moment (slip);
//! - the **long window** (`long_window_m` of travel) catches a wheel that reads
//!   a few percent wrong for good (a spare tyre, a damaged tone ring). Epochs
//!   of a short-window alarm are kept out of it, so a burst of slip does not
//!   linger there.
//!
//! A wheel is dropped when either `|T|` exceeds `drop_sigma` (its readings are
//! then not fused: the filter's `update_wheel_*` return `None` for it), and
//! readmitted when both are back within `readmit_sigma` and it has been out at
//! least `min_drop_s`. While it is out its residual is taken against the other
//! sensors alone, so a wheel that stays wrong stays out. Each dropped stretch
//! is recorded with the reason and counted per wheel ([`WheelHealth`]).
//!
//! A run's verdicts (which wheel went out or came back, at which check) can
//! be recorded and replayed ([`Verdicts`]): the checkpointed smoother
//! ([`crate::checkpoint`]) re-runs stretches of its forward pass with the
//! verdicts that pass reached instead of a copy of the monitor's windows in
//! every checkpoint.

use std::collections::VecDeque;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::event::Measurement;
use crate::filter::{Filter, Layout};
use crate::model::V;

/// Settings of the wheel-health monitor (the defaults are what the tests and
/// the built-in drives were checked with; see each field).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WheelMonitorConfig {
    /// Length of the short (slip) window, s (default 0.5).
    pub short_window_s: f64,
    /// Length of the long (bad wheel) window, m of travel (default 50).
    pub long_window_m: f64,
    /// Relative error of a calibrated wheel model, ε (default 0.005: 0.5 %,
    /// which covers calibration errors and the unmodelled tyre effects of
    /// real cars; a 3 % smaller wheel is 6 times that).
    pub relative_error: f64,
    /// Relative error allowed in the short window, ε_slip (default 0.02): a
    /// wheel that reads 3 % wrong for good is the long window's to find; a
    /// spinning wheel turns 10–30 % faster than the ground.
    pub slip_relative_error: f64,
    /// `|T|` above which a wheel is dropped, in standard deviations (default
    /// 4.5: p ≈ 7e-6 per test for a standard normal `T`).
    pub drop_sigma: f64,
    /// `|T|` below which (both windows) a dropped wheel is readmitted
    /// (default 2).
    pub readmit_sigma: f64,
    /// Shortest time a wheel stays out once dropped, s (default 1).
    pub min_drop_s: f64,
}

impl Default for WheelMonitorConfig {
    fn default() -> Self {
        WheelMonitorConfig {
            short_window_s: 0.5,
            long_window_m: 50.0,
            relative_error: 0.005,
            slip_relative_error: 0.02,
            drop_sigma: 4.5,
            readmit_sigma: 2.0,
            min_drop_s: 1.0,
        }
    }
}

/// Why a wheel was dropped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DropReason {
    /// The short window: a spinning or locking wheel.
    Slip,
    /// The long window: a wheel that reads wrong for a long stretch.
    Bias,
}

impl DropReason {
    /// "slip" or "bias".
    pub fn name(&self) -> &'static str {
        match self {
            DropReason::Slip => "slip",
            DropReason::Bias => "bias",
        }
    }
}

/// One stretch during which a wheel was out of the fusion.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DroppedInterval {
    /// First epoch out, s.
    pub start_s: f64,
    /// Epoch of readmission (or the last epoch, when still out at the end), s.
    pub end_s: f64,
    /// What dropped it.
    pub reason: DropReason,
    /// Largest `|T|` seen while out, standard deviations.
    pub peak_sigma: f64,
}

/// What the monitor saw of one wheel.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct WheelReport {
    /// Epochs in which the wheel's reading was checked.
    pub epochs_checked: u64,
    /// Epochs in which the wheel was out of the fusion.
    pub epochs_dropped: u64,
    /// Every stretch out of the fusion, in time order.
    pub intervals: Vec<DroppedInterval>,
    /// Largest `|T|` of the short window over the run.
    pub max_short_sigma: f64,
    /// Largest `|T|` of the long window over the run.
    pub max_long_sigma: f64,
}

impl WheelReport {
    /// Total time out of the fusion, s.
    pub fn dropped_s(&self) -> f64 {
        self.intervals
            .iter()
            .fold(0.0, |s, i| s + (i.end_s - i.start_s))
    }
    /// Stretches dropped for `reason`.
    pub fn count(&self, reason: DropReason) -> usize {
        self.intervals.iter().filter(|i| i.reason == reason).count()
    }
}

/// The monitor's report over a run, per wheel FL, FR, RL, RR.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct WheelHealth {
    /// Per wheel.
    pub wheels: [WheelReport; 4],
}

impl WheelHealth {
    /// True when no wheel was ever dropped.
    pub fn all_good(&self) -> bool {
        self.wheels.iter().all(|w| w.intervals.is_empty())
    }
    /// One line per wheel: `name: n slip, m bias, x s out (y of z epochs)`.
    pub fn lines(&self) -> Vec<String> {
        WHEEL_NAMES
            .iter()
            .zip(&self.wheels)
            .filter(|(_, w)| w.epochs_checked > 0)
            .map(|(n, w)| {
                format!(
                    "wheel {n}: {} slip, {} bias, {:.1} s out ({} of {} epochs), max |T| {:.1} short / {:.1} long",
                    w.count(DropReason::Slip),
                    w.count(DropReason::Bias),
                    w.dropped_s(),
                    w.epochs_dropped,
                    w.epochs_checked,
                    w.max_short_sigma,
                    w.max_long_sigma
                )
            })
            .collect()
    }
}

/// Wheel names in state order.
pub const WHEEL_NAMES: [&str; 4] = ["fl", "fr", "rl", "rr"];

/// One epoch's residual of one wheel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Entry {
    t_s: f64,
    /// z − h, in the sensor's unit.
    r: f64,
    /// |h|, same unit.
    h: f64,
    /// White-noise variance of the reading.
    var: f64,
    /// Ground distance of the epoch, m.
    dist_m: f64,
}

/// A sliding sum of entries.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
struct Window {
    entries: VecDeque<Entry>,
    r: f64,
    h: f64,
    var: f64,
    dist_m: f64,
}

impl Window {
    fn push(&mut self, e: Entry) {
        self.r += e.r;
        self.h += e.h;
        self.var += e.var;
        self.dist_m += e.dist_m;
        self.entries.push_back(e);
    }
    fn pop(&mut self) {
        if let Some(e) = self.entries.pop_front() {
            self.r -= e.r;
            self.h -= e.h;
            self.var -= e.var;
            self.dist_m -= e.dist_m;
        }
        if self.entries.is_empty() {
            // No drift of the running sums.
            *self = Window::default();
        }
    }
    fn clear(&mut self) {
        *self = Window::default();
    }
    /// The normalised sum `T = r / sqrt(V)` as its numerator and variance
    /// `(r, V)`, so that the hot path compares `r²` with `k²·V` and takes the
    /// square root only when a figure is reported. An empty window, or one
    /// without variance, is `(0, 1)` (T = 0).
    fn sum(&self, quant_var: f64, eps: f64) -> Normalised {
        if self.entries.is_empty() {
            return Normalised::ZERO;
        }
        let v = self.var.max(0.0) + quant_var + (eps * self.h).powi(2);
        if v > 0.0 {
            Normalised { r: self.r, v }
        } else {
            Normalised::ZERO
        }
    }
}

/// A normalised sum kept as `T = r / sqrt(v)` without its square root.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Normalised {
    r: f64,
    v: f64,
}

impl Normalised {
    const ZERO: Normalised = Normalised { r: 0.0, v: 1.0 };
    /// `|T| > k` (for k ≥ 0), without a square root or a division.
    fn above(self, k: f64) -> bool {
        self.r * self.r > k * k * self.v
    }
    /// `|T| < k` (for k ≥ 0).
    fn below(self, k: f64) -> bool {
        self.r * self.r < k * k * self.v
    }
    /// `|T|`.
    fn abs(self) -> f64 {
        self.r.abs() / self.v.sqrt()
    }
    /// Raises `max` to `|T|` when it is larger (the division only then).
    fn raise(self, max: &mut f64) {
        if self.above(*max) {
            *max = max.max(self.abs());
        }
    }
}

#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
struct WheelState {
    short: Window,
    long: Window,
    /// Dropped since (s), why, and the peak |T|.
    out: Option<(f64, DropReason, f64)>,
}

/// A wheel reading of one epoch, as the monitor needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WheelReading {
    /// Ticks over `interval_s`.
    Ticks {
        /// Ticks counted.
        ticks: f64,
        /// The interval, s.
        interval_s: f64,
    },
    /// A wheel speed, m/s, standing for the `interval_s` before it.
    Speed {
        /// Reported speed, m/s.
        speed_mps: f64,
        /// The interval, s.
        interval_s: f64,
    },
}

impl WheelReading {
    /// A wheel row's four readings over `interval_s` (`None`: `m` is not a
    /// wheel row).
    pub fn of_row(m: &Measurement, interval_s: f64) -> Option<[Option<WheelReading>; 4]> {
        Some(match *m {
            Measurement::WheelTicks { fl, fr, rl, rr } => [fl, fr, rl, rr].map(|z| {
                Some(WheelReading::Ticks {
                    ticks: z as f64,
                    interval_s,
                })
            }),
            Measurement::WheelSpeeds {
                fl_mps,
                fr_mps,
                rl_mps,
                rr_mps,
            } => [fl_mps, fr_mps, rl_mps, rr_mps].map(|z| {
                Some(WheelReading::Speed {
                    speed_mps: z,
                    interval_s,
                })
            }),
            _ => return None,
        })
    }
}

/// The monitor; see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WheelMonitor {
    config: WheelMonitorConfig,
    wheels: [WheelState; 4],
    report: WheelHealth,
    last_t_s: f64,
}

impl WheelMonitor {
    /// A monitor with `config`, every wheel in.
    pub fn new(config: WheelMonitorConfig) -> Self {
        WheelMonitor {
            config,
            wheels: Default::default(),
            report: WheelHealth::default(),
            last_t_s: f64::NEG_INFINITY,
        }
    }

    /// What it has seen so far; wheels still out end at the last epoch.
    pub fn report(&self) -> WheelHealth {
        let mut r = self.report.clone();
        for (w, st) in r.wheels.iter_mut().zip(&self.wheels) {
            if let Some((start, reason, peak)) = st.out {
                w.intervals.push(DroppedInterval {
                    start_s: start,
                    end_s: self.last_t_s,
                    reason,
                    peak_sigma: peak,
                });
            }
        }
        r
    }

    /// Whether wheel `i` is out of the fusion now.
    pub fn is_dropped(&self, i: usize) -> bool {
        self.wheels.get(i).is_some_and(|w| w.out.is_some())
    }

    /// Checks one epoch's wheel readings (`None` for a wheel without one)
    /// against the filter's updated state, and marks wheels in or out of the
    /// fusion in `f` for the next epochs.
    pub fn check<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        readings: [Option<WheelReading>; 4],
    ) {
        let t = f.time_s();
        self.last_t_s = t;
        let noise = *f.noise();
        let cfg = self.config;
        let x = f.car_state();
        for (i, reading) in readings.into_iter().enumerate() {
            let Some(reading) = reading else { continue };
            if !f.wheel_present(i) {
                continue;
            }
            let (r, h, var, quant, interval) = match reading {
                WheelReading::Ticks { ticks, interval_s } => {
                    let h = f.predicted_wheel_ticks(i, interval_s);
                    (
                        ticks - h,
                        h.abs(),
                        0.0,
                        2.0 * noise.wheel_ticks.powi(2),
                        interval_s,
                    )
                }
                WheelReading::Speed {
                    speed_mps,
                    interval_s,
                } => {
                    let h = f.predicted_wheel_speed(i);
                    (
                        (speed_mps - h) * interval_s,
                        (h * interval_s).abs(),
                        (noise.wheel_speed_mps * interval_s).powi(2),
                        0.0,
                        interval_s,
                    )
                }
            };
            if !(r.is_finite() && h.is_finite()) {
                continue;
            }
            let entry = Entry {
                t_s: t,
                r,
                h,
                var,
                dist_m: (x[V] * interval).abs(),
            };
            let st = &mut self.wheels[i];
            let rep = &mut self.report.wheels[i];
            rep.epochs_checked += 1;
            if st.out.is_some() {
                rep.epochs_dropped += 1;
            }
            st.short.push(entry);
            while st
                .short
                .entries
                .front()
                .is_some_and(|e| t - e.t_s > cfg.short_window_s)
            {
                st.short.pop();
            }
            let ts = st.short.sum(quant, cfg.slip_relative_error);
            let slipping = ts.above(cfg.drop_sigma);
            if slipping {
                // Keep the burst out of the long window.
                st.long.clear();
            } else {
                st.long.push(entry);
                while st.long.entries.len() > 1
                    && st.long.dist_m - st.long.entries[0].dist_m >= cfg.long_window_m
                {
                    st.long.pop();
                }
            }
            // The long test needs a full window of travel.
            let tl = if st.long.dist_m >= cfg.long_window_m {
                st.long.sum(quant, cfg.relative_error)
            } else {
                Normalised::ZERO
            };
            ts.raise(&mut rep.max_short_sigma);
            tl.raise(&mut rep.max_long_sigma);
            let peak = || ts.abs().max(tl.abs());
            match &mut st.out {
                None => {
                    let reason = if slipping {
                        Some(DropReason::Slip)
                    } else if tl.above(cfg.drop_sigma) {
                        Some(DropReason::Bias)
                    } else {
                        None
                    };
                    if let Some(reason) = reason {
                        st.out = Some((t, reason, peak()));
                        f.set_wheel_excluded(i, true);
                    }
                }
                Some((since, reason, pk)) => {
                    *pk = pk.max(peak());
                    let settled = ts.below(cfg.readmit_sigma)
                        && tl.below(cfg.readmit_sigma)
                        && (*reason == DropReason::Slip || st.long.dist_m >= cfg.long_window_m);
                    if settled && t - *since >= cfg.min_drop_s {
                        rep.intervals.push(DroppedInterval {
                            start_s: *since,
                            end_s: t,
                            reason: *reason,
                            peak_sigma: *pk,
                        });
                        st.out = None;
                        f.set_wheel_excluded(i, false);
                    }
                }
            }
        }
    }
}

/// One verdict of the monitor: at its `check`-th check of a run (counted
/// from the start of the recording), wheel `wheel` went out of the fusion
/// (`excluded`) or came back.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Verdict {
    check: u64,
    wheel: u8,
    excluded: bool,
}

/// The monitor's verdicts of one run, recorded or replayed.
///
/// The monitor changes the filter only through its verdicts
/// ([`Filter::set_wheel_excluded`], after an epoch's updates). A run that
/// records them ([`Verdicts::recording`]) can hand a re-run of any stretch
/// of it (the same events in the same order from a saved filter) the
/// verdicts instead of the monitor: the re-run takes the same wheels out
/// and back at the same checks, so its epochs are the run's bit for bit,
/// and the saved copy ([`Verdicts::resume_point`]) holds two counters
/// instead of the monitor's windows (about 63 KB on the bench's hour, most
/// of a checkpoint of [`crate::checkpoint`]: docs/performance.md, "Ninth
/// round"). Outside a recording or a replay the checks are not counted:
/// a feeder's verdicts are then the default and compare equal to a saved
/// and loaded feeder's.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Verdicts {
    /// Checks so far, while recording or replaying.
    checks: u64,
    /// The verdicts so far of a run recording them.
    recorded: Option<Vec<Verdict>>,
    /// The verdicts of the run being replayed, the next at `next`.
    replay: Option<Arc<[Verdict]>>,
    next: usize,
}

impl Verdicts {
    /// Verdicts that record from now on.
    pub fn recording() -> Self {
        Verdicts {
            recorded: Some(Vec::new()),
            ..Verdicts::default()
        }
    }

    /// Where a re-run resumes from this point of a recording: the checks
    /// so far and the index of the next verdict, with nothing recorded and
    /// nothing to replay yet ([`Verdicts::replaying`]).
    pub fn resume_point(&self) -> Self {
        Verdicts {
            checks: self.checks,
            recorded: None,
            replay: None,
            next: self.recorded.as_ref().map_or(self.next, Vec::len),
        }
    }

    /// These verdicts replaying `all` (a whole recording, from
    /// [`Verdicts::take_recorded`]) from their resume point.
    pub fn replaying(self, all: Arc<[Verdict]>) -> Self {
        Verdicts {
            replay: Some(all),
            recorded: None,
            ..self
        }
    }

    /// What was recorded (empty when nothing was), recording no more.
    pub fn take_recorded(&mut self) -> Arc<[Verdict]> {
        self.recorded.take().unwrap_or_default().into()
    }

    /// One check of an epoch's wheel `readings`: by `monitor` where there
    /// is one ([`WheelMonitor::check`]; its verdicts recorded when
    /// recording), else the replayed run's verdicts of this check.
    pub fn check<L: Layout<N>, const N: usize>(
        &mut self,
        monitor: Option<&mut WheelMonitor>,
        f: &mut Filter<L, N>,
        readings: [Option<WheelReading>; 4],
    ) {
        match monitor {
            Some(mon) => {
                let Some(rec) = self.recorded.as_mut() else {
                    mon.check(f, readings);
                    return;
                };
                let before: [bool; 4] = std::array::from_fn(|i| f.wheel_excluded(i));
                mon.check(f, readings);
                for (i, was) in before.into_iter().enumerate() {
                    let now = f.wheel_excluded(i);
                    if now != was {
                        rec.push(Verdict {
                            check: self.checks,
                            wheel: i as u8,
                            excluded: now,
                        });
                    }
                }
            }
            None => {
                let Some(all) = self.replay.as_ref() else {
                    return;
                };
                while let Some(v) = all.get(self.next).filter(|v| v.check == self.checks) {
                    f.set_wheel_excluded(usize::from(v.wheel), v.excluded);
                    self.next += 1;
                }
            }
        }
        self.checks += 1;
    }
}
