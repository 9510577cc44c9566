//! The [`Feeder`]: time-ordered events into a step [`Filter`] in one of
//! the two timing schemes, causally (see the module documentation of
//! [`crate::ekf`]).

use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::{FilterOptions, FilterStats, SensorSet, Timing, WheelRows};
use crate::drive::GnssFix;
use crate::event::{Event, Measurement};
use crate::filter::{Filter, Layout, Prediction, SensorKind, Update};
use crate::gyro_hold::GyroHold;
use crate::standstill::Standstill;
use crate::tick_interval::CountingInterval;
use crate::wheel_health::{Verdict, Verdicts, WheelHealth, WheelMonitor, WheelReading};
use crate::Error;

/// Wheel intervals longer than this many times the median interval are gaps:
/// the row is skipped (a tick count over a gap cannot be predicted from the
/// speed at its end).
const GAP_FACTOR: f64 = 5.0;
/// The median wheel interval is taken over the first this many intervals (then
/// kept), so the gap rule is causal.
const GAP_MEDIAN_OF: usize = 64;
/// No gap is declared before this many intervals have been seen.
const GAP_MIN_INTERVALS: usize = 3;

/// Feeds time-ordered events to a [`Filter`] in one of the two timing schemes,
/// causally: an epoch is run once every event with its timestamp has arrived
/// (a later event, or [`Feeder::finish`]). Serialisable with the filter, so a
/// stream can stop and resume.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Feeder {
    timing: Timing,
    sensors: SensorSet,
    outages: Vec<(f64, f64)>,
    start_s: f64,
    end_s: Option<f64>,
    /// Time of the last wheel row (the start of the next wheel interval).
    last_wheel_s: Option<f64>,
    /// The first wheel intervals, for the gap rule.
    intervals: Vec<f64>,
    max_interval_s: Option<f64>,
    /// The interval a wheel row's tick count covers ([`crate::tick_interval`]).
    #[serde(default)]
    counting: CountingInterval,
    /// Events sharing the newest timestamp, not yet processed.
    batch: Vec<Event>,
    /// The paper's scheme: newest unused reading of each other sensor.
    pending_gyro: Option<f64>,
    pending_speed: Option<f64>,
    pending_steering: Option<f64>,
    pending_gnss: Option<GnssFix>,
    /// The gyro's latest reading, live for a while ([`crate::gyro_hold`]).
    #[serde(default)]
    gyro: GyroHold,
    stats: FilterStats,
    #[serde(skip)]
    updates: Vec<Update>,
    /// The time of the GNSS fix the gate rejected at this event, if any.
    #[serde(skip)]
    gated_fix_t_s: Option<f64>,
    /// Whether epochs carry their prediction (a copy of the predicted state and
    /// covariance, which a run that records no epochs does without).
    #[serde(default = "yes")]
    predictions: bool,
    /// The wheel-health monitor, when asked for.
    #[serde(default)]
    monitor: Option<WheelMonitor>,
    /// The monitor's verdicts, recorded or replayed (not saved: a stream
    /// neither records nor replays).
    #[serde(skip)]
    verdicts: Verdicts,
    /// When a wheel row is used (a feeder saved before this was chosen
    /// goes on as it began: [`WheelRows::Instant`]).
    #[serde(default = "instant")]
    wheel_rows: WheelRows,
    /// [`WheelRows::Interval`]: the gyro's and the CAN speed's readings
    /// stamped inside the open wheel interval, in their order, which
    /// update the state of the interval's start when its row arrives.
    #[serde(default)]
    interval_gyro: Vec<f64>,
    #[serde(default)]
    interval_speed: Vec<f64>,
    /// [`WheelRows::Interval`]: the GNSS fix that arrived in the interval
    /// before the open one, due at the open interval's start.
    #[serde(default)]
    due_gnss: Option<GnssFix>,
    /// Whether the car stands ([`crate::standstill`]), in the GNSS-aided
    /// filter only ([`Feeder::with_standstill`]; `None`: not asked).
    #[serde(default)]
    standstill: Option<Standstill>,
}

fn instant() -> WheelRows {
    WheelRows::Instant
}

fn yes() -> bool {
    true
}

/// What one epoch did: the prediction and the updates.
pub struct EpochOut<'a, const N: usize> {
    /// The prediction to the epoch's time (`None` unless the feeder keeps
    /// predictions: [`Feeder::keep_predictions`]).
    pub prediction: Option<&'a Prediction<N>>,
    /// The updates applied (or rejected) at the epoch.
    pub updates: &'a [Update],
    /// The time of the GNSS fix the χ² gate rejected at this epoch (its own
    /// time, which identifies it in the drive; the epoch may be later).
    pub gated_fix_t_s: Option<f64>,
}

impl Feeder {
    /// A feeder for a filter started at `start_s`: readings before it (and other
    /// sensors' readings at it) are ignored; the first wheel row at or after it
    /// opens the first wheel interval.
    ///
    /// The wheel-row scheme is the one a filter on `vehicle` runs
    /// ([`FilterOptions::wheel_rows_for`]).
    pub fn new(opts: &FilterOptions, vehicle: &crate::vehicle::Vehicle, start_s: f64) -> Self {
        Feeder {
            timing: opts.timing,
            sensors: opts.sensors,
            outages: opts.gnss_outages.clone(),
            start_s,
            end_s: opts.end_s,
            last_wheel_s: None,
            intervals: Vec::new(),
            max_interval_s: None,
            counting: CountingInterval::default(),
            batch: Vec::new(),
            pending_gyro: None,
            pending_speed: None,
            pending_steering: None,
            pending_gnss: None,
            gyro: GyroHold::default(),
            stats: FilterStats::default(),
            updates: Vec::new(),
            gated_fix_t_s: None,
            predictions: opts.record_epochs,
            monitor: opts.wheel_monitor.map(WheelMonitor::new),
            verdicts: Verdicts::default(),
            wheel_rows: opts.wheel_rows_for(vehicle),
            interval_gyro: Vec::new(),
            interval_speed: Vec::new(),
            due_gnss: None,
            standstill: None,
        }
    }

    /// The feeder with the standstill's `ψ̇ = 0` ([`crate::standstill`]):
    /// the GNSS-aided filter's ([`crate::aided`]), not the calibration's
    /// passes, whose estimators of the delays, the gyro scale and the
    /// circumferences it moved (a simulated drive of `tests/corrections.rs`:
    /// a gyro delay of 90 ms applied where none was estimated, the
    /// circumferences +2.4 mm).
    pub fn with_standstill(mut self) -> Self {
        self.standstill = Some(Standstill::default());
        self
    }

    /// Hands one epoch out: counts it and passes its prediction, updates and
    /// gated fix to the callback.
    fn hand_out<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        prediction: Option<&Prediction<N>>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) {
        self.stats.epochs += 1;
        epoch(
            f,
            EpochOut {
                prediction,
                updates: &self.updates,
                gated_fix_t_s: self.gated_fix_t_s,
            },
        );
    }

    /// Whether the epochs passed to the callback carry their prediction (by
    /// default when `record_epochs` is set). Does not change the filtering.
    pub fn keep_predictions(&mut self, keep: bool) {
        self.predictions = keep;
    }

    fn predict<L: Layout<N>, const N: usize>(
        &self,
        f: &mut Filter<L, N>,
        t: f64,
    ) -> Option<Prediction<N>> {
        if self.predictions {
            Some(f.predict_to(t))
        } else {
            f.advance_to(t);
            None
        }
    }

    /// What the wheel-health monitor has seen (`None` without one).
    pub fn wheel_health(&self) -> Option<WheelHealth> {
        self.monitor.as_ref().map(WheelMonitor::report)
    }

    /// Hands the epoch's wheel readings to the monitor (after the epoch's
    /// updates: it compares them with the updated state), or replays its
    /// recorded verdicts ([`Verdicts`]).
    fn monitor_wheels<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        m: &Measurement,
        interval_s: f64,
    ) {
        if let Some(readings) = WheelReading::of_row(m, interval_s) {
            self.verdicts.check(self.monitor.as_mut(), f, readings);
        }
    }

    /// From now on, records the wheel monitor's verdicts
    /// ([`Feeder::take_verdicts`]).
    pub(crate) fn record_verdicts(&mut self) {
        self.verdicts = Verdicts::recording();
    }

    /// The verdicts recorded since [`Feeder::record_verdicts`].
    pub(crate) fn take_verdicts(&mut self) -> Arc<[Verdict]> {
        self.verdicts.take_recorded()
    }

    /// This feeder without its wheel monitor, to re-run from here with the
    /// recorded run's verdicts ([`Feeder::replay_verdicts`]): the same
    /// epochs, without a copy of the monitor's windows.
    pub(crate) fn resume_point(&self) -> Feeder {
        Feeder {
            monitor: None,
            verdicts: self.verdicts.resume_point(),
            ..self.clone()
        }
    }

    /// A [`Feeder::resume_point`] replaying `all`, the whole recording.
    pub(crate) fn replay_verdicts(&mut self, all: Arc<[Verdict]>) {
        self.verdicts = std::mem::take(&mut self.verdicts).replaying(all);
    }

    /// From now on, feeds no GNSS (fixes nor courses; a fix waiting for the
    /// next wheel epoch is dropped): how a clone of a GNSS-aided run
    /// dead-reckons through an outage, keeping everything else it had learnt
    /// (the wheel monitor's windows and verdicts, the wheel-interval rule,
    /// the readings waiting for the next epoch).
    pub fn dead_reckon(&mut self) {
        self.sensors.gnss = false;
        self.sensors.gnss_course = false;
        self.pending_gnss = None;
        self.due_gnss = None;
    }

    /// Counters so far (the gate counters are the filter's: see [`Feeder::stats_with`]).
    pub fn stats(&self) -> &FilterStats {
        &self.stats
    }

    /// Counters so far, with the filter's gate counters folded in.
    pub fn stats_with<L: Layout<N>, const N: usize>(&self, f: &Filter<L, N>) -> FilterStats {
        let g = f.gates();
        let mut st = self.stats;
        st.gates = *g;
        st.gyro_updates = g.accepted(SensorKind::Gyro) as usize;
        st.speed_updates = g.accepted(SensorKind::Speed) as usize;
        st.steering_updates = g.accepted(SensorKind::Steering) as usize;
        st.gnss_updates = g.accepted(SensorKind::Gnss) as usize;
        st.gnss_rejected = g.rejected(SensorKind::Gnss) as usize;
        st.gnss_recoveries = g.recovered(SensorKind::Gnss) as usize;
        st.course_updates = g.accepted(SensorKind::Course) as usize;
        st
    }

    /// Takes one event (timestamps must not decrease); runs the epochs it
    /// completes, calling `epoch` after each with the filter (which the caller
    /// may change, e.g. reset) and what the epoch did.
    #[inline(always)]
    pub fn push<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        ev: Event,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        if !ev.t_s.is_finite() {
            return Err(Error::drive(
                "events",
                crate::DriveFault::NonFiniteTime {
                    index: None,
                    t_s: ev.t_s,
                },
            ));
        }
        if let Some(last) = self.batch.last() {
            if ev.t_s < last.t_s {
                return Err(Error::OutOfOrder {
                    t_s: ev.t_s,
                    previous_t_s: last.t_s,
                });
            }
            if ev.t_s > last.t_s {
                self.process_batch(f, epoch)?;
            }
        }
        // Readings at or before the start are not used; the first wheel row at
        // or after it opens the first interval.
        let keep = if ev.is_wheel() {
            ev.t_s >= self.start_s
        } else {
            ev.t_s > self.start_s
        };
        if keep {
            self.batch.push(ev);
        }
        Ok(())
    }

    /// Runs what is still waiting (at the end of a stream): [`Feeder::settle`],
    /// and with [`WheelRows::Interval`] the epoch at the last wheel row,
    /// which no later row will close.
    pub fn finish<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.run_waiting(true, f, epoch)
    }

    /// Runs the epoch of the readings fed so far, when every later reading
    /// is later than them (a live stream after each input, a run paused to
    /// dead-reckon from): the same epochs as if the stream went on. With
    /// [`WheelRows::Interval`] the last row's interval stays open, for the
    /// next row to close (its epoch would otherwise be handed out twice).
    pub fn settle<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.run_waiting(false, f, epoch)
    }

    /// [`Feeder::finish`] at the end of the stream (`end`), else
    /// [`Feeder::settle`].
    pub fn run_waiting<L: Layout<N>, const N: usize>(
        &mut self,
        end: bool,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.process_batch(f, epoch)?;
        if end && self.wheel_rows == WheelRows::Interval {
            self.last_interval_epoch(f, epoch)?;
        }
        self.clear_scratch();
        Ok(())
    }

    /// The epochs' scratch (not serialised): a feeder that has finished or
    /// settled equals its saved and loaded copy.
    fn clear_scratch(&mut self) {
        self.updates.clear();
        self.gated_fix_t_s = None;
    }

    fn hidden(&self, t: f64) -> bool {
        crate::drive::in_windows(t, &self.outages)
    }

    fn process_batch<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        let mut batch = std::mem::take(&mut self.batch);
        // Equal timestamps: the paper's scheme takes the other readings into the
        // wheel epoch of the same time, so they go first; the per-measurement
        // scheme runs wheels first.
        if batch.len() > 1 {
            match self.timing {
                Timing::WheelEpochs => batch.sort_by_key(|e| (e.is_wheel(), e.rank())),
                Timing::EachMeasurement => batch.sort_by_key(|e| e.rank()),
            }
        }
        let result = batch.iter().try_for_each(|ev| self.event(f, *ev, epoch));
        batch.clear();
        self.batch = batch;
        result
    }

    /// The wheel interval ending at `t`, and whether it is a gap: for tick
    /// counts (`ticks`) the interval they cover ([`crate::tick_interval`]),
    /// which for a regular counter with jittered stamps is its cycle; for
    /// wheel speeds the stamps' (a speed is not a count over an interval).
    fn wheel_interval(&mut self, t: f64, ticks: bool) -> Option<(f64, bool)> {
        let prev = self.last_wheel_s.replace(t)?;
        let interval = t - prev;
        if self.max_interval_s.is_none() || self.intervals.len() < GAP_MEDIAN_OF {
            self.intervals.push(interval);
            if self.intervals.len() >= GAP_MIN_INTERVALS {
                let mut d = self.intervals.clone();
                let mid = d.len() / 2;
                let med = *d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
                self.max_interval_s = Some(GAP_FACTOR * med);
            }
        }
        let gap = self.max_interval_s.is_some_and(|m| interval > m);
        if gap || !ticks {
            return Some((interval, gap));
        }
        Some((self.counting.push(interval), false))
    }

    /// [`WheelRows::Interval`]: the epoch at `start`, the start of the
    /// interval that the wheel row `m` at `end` closes. The state is
    /// predicted to `start`, then updated by everything that describes the
    /// interval (the row over its counting `interval`, and the gyro's and
    /// the CAN speed's readings stamped inside it: the step from `start`
    /// carries their rates), and by the GNSS fix that arrived before
    /// `start`. A gyro live but silent through the interval leaves the
    /// steering waiting, and the step into it takes the gyro gap's yaw-rate
    /// noise ([`crate::gyro_hold`]), as in the paper's scheme.
    #[allow(clippy::too_many_arguments)]
    fn interval_epoch<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        m: &Measurement,
        start: f64,
        end: f64,
        interval: f64,
        gap: bool,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        let use_ = self.sensors;
        // The first interval (the gap rule's first interval seen) starts at
        // the first wheel row after the filter's start.
        let first = self.stats.epochs == 0 && self.intervals.len() == 1;
        let fresh_gyro = !self.interval_gyro.is_empty();
        let gyro_live = use_.gyro && self.gyro.is_live(end);
        let prediction = self.predict_epoch(f, start, gyro_live && !fresh_gyro);
        self.wheel_row(f, m, interval, gap)?;
        for i in 0..self.interval_gyro.len() {
            self.updates.push(f.update_gyro(self.interval_gyro[i])?);
        }
        for i in 0..self.interval_speed.len() {
            self.updates.push(f.update_speed(self.interval_speed[i])?);
        }
        self.interval_gyro.clear();
        self.interval_speed.clear();
        self.steering_update(f, fresh_gyro || !gyro_live)?;
        if let Some(fix) = self.due_gnss.take() {
            self.gnss_update(f, &fix)?;
        }
        if use_.wheels && !gap {
            self.monitor_wheels(f, m, interval);
        }
        // The first interval's start is not an epoch (the paper's scheme
        // hands out its first epoch at the end of the first interval too).
        if !first {
            self.hand_out(f, prediction.as_ref(), epoch);
        }
        self.due_gnss = self.pending_gnss.take();
        Ok(())
    }

    /// [`WheelRows::Interval`], at the end of the stream: the epoch at the
    /// last wheel row, which no row closes (no rates of its own: the
    /// readings after it are not used), with the fix due there.
    fn last_interval_epoch<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.interval_gyro.clear();
        self.interval_speed.clear();
        let Some(t) = self.last_wheel_s.filter(|&t| t > f.time_s()) else {
            return Ok(());
        };
        self.updates.clear();
        self.gated_fix_t_s = None;
        let prediction = self.predict(f, t);
        if let Some(fix) = self.due_gnss.take() {
            self.gnss_update(f, &fix)?;
        }
        self.hand_out(f, prediction.as_ref(), epoch);
        Ok(())
    }

    /// The prediction to the epoch at `t`. `gyro_gap`: the gyro is live
    /// but has no reading for the epoch, so the step takes the gyro gap's
    /// yaw-rate noise when the vehicle sets one ([`crate::gyro_hold`]).
    fn predict_epoch<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        t: f64,
        gyro_gap: bool,
    ) -> Option<Prediction<N>> {
        let gap_q = f.noise().gyro_gap_process_yaw_rate_rps;
        if gyro_gap && gap_q > 0.0 {
            self.stats.gyro_gap_epochs += 1;
            let q = gap_q.min(f.noise().process_yaw_rate_rps);
            f.predict_to_with_yaw_rate_noise(t, q, self.predictions)
        } else {
            self.predict(f, t)
        }
    }

    /// The wheel row `m` over `interval` (when the wheels are used),
    /// counted and skipped when it closes a `gap`.
    fn wheel_row<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        m: &Measurement,
        interval: f64,
        gap: bool,
    ) -> Result<(), Error> {
        if !self.sensors.wheels {
            return Ok(());
        }
        if gap {
            self.stats.wheel_gaps += 1;
            return Ok(());
        }
        self.wheel_updates(f, m, interval)
    }

    /// The steering reading waiting, applied when `now` (an epoch with a
    /// gyro reading of its own, or no live gyro), else left waiting and
    /// counted as deferred.
    fn steering_update<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        now: bool,
    ) -> Result<(), Error> {
        if now {
            if let Some(v) = self.pending_steering.take() {
                self.updates.push(f.update_steering(v)?);
            }
        } else if self.pending_steering.is_some() {
            self.stats.steering_deferred += 1;
        }
        Ok(())
    }

    fn wheel_updates<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        m: &Measurement,
        interval: f64,
    ) -> Result<(), Error> {
        self.stats.wheel_updates += 1;
        match *m {
            Measurement::WheelTicks { fl, fr, rl, rr } => {
                for (i, z) in [fl, fr, rl, rr].into_iter().enumerate() {
                    if let Some(u) = f.update_wheel_ticks(i, z as f64, interval)? {
                        self.updates.push(u);
                    }
                }
            }
            Measurement::WheelSpeeds {
                fl_mps,
                fr_mps,
                rl_mps,
                rr_mps,
            } => {
                for (i, z) in [fl_mps, fr_mps, rl_mps, rr_mps].into_iter().enumerate() {
                    if let Some(u) = f.update_wheel_speed(i, z)? {
                        self.updates.push(u);
                    }
                }
            }
            _ => {}
        }
        // A standing car does not turn (crate::standstill).
        if let Some(standstill) = &mut self.standstill {
            if standstill.push(f.time_s(), m, |i| f.wheel_present(i)) {
                f.update_standstill()?;
            }
        }
        Ok(())
    }

    fn gnss_update<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        fix: &GnssFix,
    ) -> Result<(), Error> {
        let u = f.update_gnss(fix)?;
        self.updates.push(u);
        if !u.accepted {
            self.gated_fix_t_s = Some(fix.t_s);
        }
        if u.accepted && self.sensors.gnss_course {
            if let Some(course) = fix.course_yaw_rad() {
                if let Some(u) = f.update_course(course, fix.speed_mps)? {
                    self.updates.push(u);
                }
            }
        }
        Ok(())
    }

    fn event<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        ev: Event,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        let t = ev.t_s;
        if self.end_s.is_some_and(|e| t > e) {
            return Ok(());
        }
        let use_ = self.sensors;
        self.updates.clear();
        self.gated_fix_t_s = None;
        let over_interval = self.wheel_rows == WheelRows::Interval;
        let supersede = |slot: &mut Option<f64>, v: f64, n: &mut usize| {
            if slot.replace(v).is_some() {
                *n += 1;
            }
        };
        match self.timing {
            Timing::WheelEpochs => match ev.measurement {
                Measurement::YawRate { yaw_rate_rps } if use_.gyro => {
                    if over_interval {
                        self.interval_gyro.push(yaw_rate_rps);
                    } else {
                        supersede(
                            &mut self.pending_gyro,
                            yaw_rate_rps,
                            &mut self.stats.readings_superseded,
                        );
                    }
                    self.gyro.push(t, yaw_rate_rps);
                }
                Measurement::Speed { speed_mps } if use_.speed => {
                    if over_interval {
                        self.interval_speed.push(speed_mps);
                    } else {
                        supersede(
                            &mut self.pending_speed,
                            speed_mps,
                            &mut self.stats.readings_superseded,
                        );
                    }
                }
                Measurement::Steering { steering_wheel_rad } if use_.steering => supersede(
                    &mut self.pending_steering,
                    steering_wheel_rad,
                    &mut self.stats.readings_superseded,
                ),
                Measurement::Gnss { .. } if use_.gnss => {
                    if self.hidden(t) {
                        self.stats.gnss_hidden += 1;
                    } else {
                        self.pending_gnss = ev.gnss_fix();
                    }
                }
                Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => {
                    let ticks = matches!(ev.measurement, Measurement::WheelTicks { .. });
                    let start = self.last_wheel_s;
                    let Some((interval, gap)) = self.wheel_interval(t, ticks) else {
                        // The first row opens the first interval.
                        self.interval_gyro.clear();
                        self.interval_speed.clear();
                        return Ok(());
                    };
                    if over_interval {
                        let start = start.unwrap_or(t);
                        return self.interval_epoch(
                            f,
                            &ev.measurement,
                            start,
                            t,
                            interval,
                            gap,
                            epoch,
                        );
                    }
                    // A gyro reading late by a few milliseconds leaves this
                    // epoch without one: the yaw rate keeps the last
                    // reading's instead of taking the wheels' (gyro_hold).
                    let gyro_gap = use_.gyro && self.pending_gyro.is_none() && self.gyro.is_live(t);
                    let prediction = self.predict_epoch(f, t, gyro_gap);
                    self.wheel_row(f, &ev.measurement, interval, gap)?;
                    let fresh_gyro = self.pending_gyro.is_some();
                    if let Some(v) = self.pending_gyro.take() {
                        self.updates.push(f.update_gyro(v)?);
                    }
                    if let Some(v) = self.pending_speed.take() {
                        self.updates.push(f.update_speed(v)?);
                    }
                    // While the gyro is live, the steering waits for an
                    // epoch with a gyro reading of its own (crate::gyro_hold).
                    self.steering_update(f, fresh_gyro || !(use_.gyro && self.gyro.is_live(t)))?;
                    if let Some(fix) = self.pending_gnss.take() {
                        self.gnss_update(f, &fix)?;
                    }
                    if use_.wheels && !gap {
                        self.monitor_wheels(f, &ev.measurement, interval);
                    }
                    self.hand_out(f, prediction.as_ref(), epoch);
                }
                _ => {}
            },
            Timing::EachMeasurement => {
                let wheel = if ev.is_wheel() {
                    // The first row after the start only opens an interval.
                    let ticks = matches!(ev.measurement, Measurement::WheelTicks { .. });
                    let Some(iv) = self.wheel_interval(t, ticks) else {
                        return Ok(());
                    };
                    Some(iv)
                } else {
                    None
                };
                let used = match ev.measurement {
                    Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => use_.wheels,
                    Measurement::YawRate { .. } => use_.gyro,
                    Measurement::Speed { .. } => use_.speed,
                    Measurement::Steering { .. } => use_.steering,
                    // Online's input only (crate::live_corrections).
                    Measurement::Gyro { .. } | Measurement::Accel { .. } => false,
                    Measurement::Gnss { .. } => {
                        if use_.gnss && self.hidden(t) {
                            self.stats.gnss_hidden += 1;
                            false
                        } else {
                            use_.gnss
                        }
                    }
                };
                if !used {
                    return Ok(());
                }
                if let Measurement::Steering { steering_wheel_rad } = ev.measurement {
                    if use_.gyro && self.gyro.is_live(t) {
                        // Waits for the next gyro reading (a newer steering
                        // reading supersedes it).
                        if self.pending_steering.replace(steering_wheel_rad).is_some() {
                            self.stats.readings_superseded += 1;
                        }
                        self.stats.steering_deferred += 1;
                        return Ok(());
                    }
                    // The gyro has stopped: the steering stands in, and a
                    // reading still waiting is superseded by this one.
                    if self.pending_steering.take().is_some() {
                        self.stats.readings_superseded += 1;
                    }
                }
                let prediction = self.predict(f, t);
                match ev.measurement {
                    Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => {
                        if let Some((interval, gap)) = wheel {
                            if gap {
                                self.stats.wheel_gaps += 1;
                            } else {
                                self.wheel_updates(f, &ev.measurement, interval)?;
                                self.monitor_wheels(f, &ev.measurement, interval);
                            }
                        }
                    }
                    Measurement::YawRate { yaw_rate_rps } => {
                        self.gyro.push(t, yaw_rate_rps);
                        self.updates.push(f.update_gyro(yaw_rate_rps)?);
                        if let Some(v) = self.pending_steering.take() {
                            self.updates.push(f.update_steering(v)?);
                        }
                    }
                    Measurement::Speed { speed_mps } => {
                        self.updates.push(f.update_speed(speed_mps)?)
                    }
                    Measurement::Steering { steering_wheel_rad } => {
                        self.updates.push(f.update_steering(steering_wheel_rad)?)
                    }
                    Measurement::Gnss { .. } => {
                        if let Some(fix) = ev.gnss_fix() {
                            self.gnss_update(f, &fix)?;
                        }
                    }
                    // Not `used` (above).
                    Measurement::Gyro { .. } | Measurement::Accel { .. } => {}
                }
                self.hand_out(f, prediction.as_ref(), epoch);
            }
        }
        Ok(())
    }
}
