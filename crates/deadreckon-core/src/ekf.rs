//! The extended Kalman filter over a whole drive (eq. 11–19 of Welte et al.).
//!
//! Two timing schemes:
//!
//! - [`Timing::WheelEpochs`] (the paper's): one epoch per wheel row; the state is
//!   predicted to the wheel timestamp and updated with the wheels and the most
//!   recent *unused* reading of each other sensor (older readings between two
//!   wheel epochs are discarded, as in the paper) and with a GNSS fix if one
//!   arrived since the previous epoch. While the gyro is live, an epoch
//!   without a gyro reading of its own leaves the steering reading waiting
//!   for the next epoch that has one ([`crate::gyro_hold`]: a gyro on its own
//!   clock is often a few milliseconds late, and the steering must not stand
//!   in for it).
//! - [`Timing::EachMeasurement`]: every reading is processed at its own
//!   timestamp, one epoch per reading; a steering reading that arrives while
//!   the gyro's latest reading is live is applied right after the next gyro
//!   reading ([`crate::gyro_hold`]).
//!
//! Any sensor may be absent: the filter uses the streams the drive has. The
//! per-epoch predicted and updated states, covariances and Jacobians are kept
//! when asked (`record`), for the RTS smoother.
//!
//! Both schemes are causal: a [`Feeder`] takes time-ordered [`Event`]s one at a
//! time (from [`DriveEvents`] over a recorded drive, or from a live stream) and
//! drives the step filter of [`crate::filter`]; [`run`] is that loop over a
//! drive.

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::drive::{Drive, GnssFix, Wheels};
use crate::filter::{AugmentedLayout, CarLayout, Filter, Layout, Prediction};
use crate::gyro_hold::GyroHold;
use crate::kalman::CovarianceForm;
use crate::model::{Mat, State};
use crate::tick_interval::CountingInterval;
use crate::vehicle::Params;
use crate::wheel_health::{WheelHealth, WheelMonitor, WheelMonitorConfig, WheelReading};
use crate::Error;

/// When the filter runs its epochs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Timing {
    /// One epoch per wheel row, with the latest reading of the other sensors (the paper).
    #[default]
    WheelEpochs,
    /// One epoch per reading, each at its own timestamp.
    EachMeasurement,
}

/// What a wheel row's reading describes, and so when the filter uses it
/// ([`Timing::WheelEpochs`] only).
///
/// A wheel-speed row at `t_k` is the mean speed over `(t_{k−1}, t_k]` (the
/// rotation over the last period times the circumference, as ECUs and the
/// simulator report it), and a tick count is the rotation over that
/// interval. The paper's step (eq. 3) carries the state from `t_k` to
/// `t_{k+1}` with the speed the row at `t_k` set, the speed of the interval
/// *before*: whenever the speed changes, the position trails by a wheel
/// period, which the GNSS delay estimate read as a negative delay of
/// 0.7–0.9 wheel periods (−27, −14 and −9 ms at 25, 50 and 100 Hz with a
/// true delay of 0, issue 28).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum WheelRows {
    /// The row updates the state at the start of its interval, `t_{k−1}`;
    /// the step to `t_k` then carries the interval's own speed. Each epoch
    /// is handed out when the next wheel row (or the end of the stream)
    /// has arrived, one wheel period later than with [`WheelRows::Instant`].
    /// Not the default: on the comma2k19 segment it loses (see
    /// docs/calibration.md, "When a wheel row is used").
    Interval,
    /// The row updates the state at its own time (the paper): the step
    /// after it carries that speed over the next interval.
    #[default]
    Instant,
}

fn instant() -> WheelRows {
    WheelRows::Instant
}

/// How the filter's initial state is chosen.
#[allow(clippy::large_enum_variant)] // a plain value passed once per run
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub enum Init {
    /// From GNSS: the first fix for the position (minus the lever arm) and the
    /// direction of the first 10 m of displacement for the yaw. The filter starts at
    /// the first wheel epoch at or after the first fix.
    #[default]
    Gnss,
    /// From `truth.csv` at the first wheel epoch, with a small covariance.
    Truth,
    /// A given state and covariance at the first wheel epoch at or after `t_s`.
    Given {
        /// Start time, s.
        t_s: f64,
        /// Initial state.
        x: State,
        /// Initial covariance.
        p: Mat,
    },
}

/// Which sensors the filter uses (all by default, when present in the drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct SensorSet {
    /// Wheel encoders or wheel speeds.
    pub wheels: bool,
    /// Gyro.
    pub gyro: bool,
    /// CAN speed.
    pub speed: bool,
    /// Steering wheel angle.
    pub steering: bool,
    /// GNSS positions.
    pub gnss: bool,
    /// GNSS course as a yaw observation (not in the paper; off by default).
    pub gnss_course: bool,
}

impl Default for SensorSet {
    fn default() -> Self {
        SensorSet {
            wheels: true,
            gyro: true,
            speed: true,
            steering: true,
            gnss: true,
            gnss_course: false,
        }
    }
}

impl SensorSet {
    /// Dead reckoning: every proprioceptive sensor, no GNSS.
    pub fn dead_reckoning() -> Self {
        SensorSet {
            gnss: false,
            gnss_course: false,
            ..Default::default()
        }
    }
}

/// Options of a filter run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FilterOptions {
    /// Timing scheme.
    pub timing: Timing,
    /// Initial state.
    pub init: Init,
    /// Sensors to use.
    pub sensors: SensorSet,
    /// GNSS outages: fixes with `start <= t < end` are hidden from the filter.
    pub gnss_outages: Vec<(f64, f64)>,
    /// Covariance update form.
    pub covariance_form: CovarianceForm,
    /// Keep every epoch (needed by the smoother).
    pub record_epochs: bool,
    /// Keep every innovation (for filter-health plots).
    pub record_innovations: bool,
    /// Stop after the last epoch at or before this time, s.
    pub end_s: Option<f64>,
    /// The wheel-health monitor (slipping and bad wheels dropped from the
    /// fusion while they misbehave, [`crate::wheel_health`]; on by default);
    /// `None` fuses every wheel reading the χ² gate accepts.
    #[serde(default)]
    pub wheel_monitor: Option<WheelMonitorConfig>,
    /// When a wheel row is used ([`WheelRows`]).
    #[serde(default)]
    pub wheel_rows: WheelRows,
}

impl Default for FilterOptions {
    fn default() -> Self {
        FilterOptions {
            timing: Timing::WheelEpochs,
            init: Init::Gnss,
            sensors: SensorSet::default(),
            gnss_outages: Vec::new(),
            covariance_form: CovarianceForm::Joseph,
            record_epochs: true,
            record_innovations: false,
            end_s: None,
            wheel_monitor: Some(WheelMonitorConfig::default()),
            wheel_rows: WheelRows::default(),
        }
    }
}

/// One filter epoch, as the smoother needs it. `N` is 5 for the car state and
/// 11 for the state augmented with the six parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch<const N: usize = 5> {
    /// Timestamp, s.
    pub t_s: f64,
    /// x̂_{k|k-1}.
    pub x_pred: SVector<f64, N>,
    /// P_{k|k-1}.
    pub p_pred: SMatrix<f64, N, N>,
    /// F_k, the Jacobian of the prediction from the previous epoch to this one,
    /// car block only: the full Jacobian is `diag(f, I)` (the parameters of the
    /// augmented state are constants), which keeps a recorded hour of the
    /// 11-state filter a quarter smaller.
    pub f: Mat,
    /// x̂_{k|k}.
    pub x: SVector<f64, N>,
    /// P_{k|k}.
    pub p: SMatrix<f64, N, N>,
}

pub use crate::event::{DriveEvents, Event, Measurement};
pub use crate::filter::{GateCounts, SensorKind, Update, AUG_BIAS, AUG_INV_CIRC, AUG_SCALE, N_AUG};
pub use crate::init::{initial_state, truth_state, GnssInit};

impl<const N: usize> Epoch<N> {
    /// The epoch a filter has just run: its prediction and its updated state.
    pub fn after<L: Layout<N>>(f: &Filter<L, N>, prediction: &Prediction<N>) -> Self {
        Epoch {
            t_s: f.time_s(),
            x_pred: prediction.x,
            p_pred: prediction.p,
            f: prediction.f,
            x: *f.state(),
            p: *f.covariance(),
        }
    }
}

/// One recorded innovation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnovationRecord {
    /// Timestamp, s.
    pub t_s: f64,
    /// Sensor.
    pub sensor: SensorKind,
    /// Innovation (first component for GNSS).
    pub y: f64,
    /// Innovation variance (first diagonal element for GNSS).
    pub s: f64,
    /// Normalised innovation squared.
    pub nis: f64,
    /// False when the measurement was rejected by the gate.
    pub accepted: bool,
}

/// Counts of what the filter used, gated and skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FilterStats {
    /// Epochs run.
    pub epochs: usize,
    /// Wheel rows used.
    pub wheel_updates: usize,
    /// Wheel rows skipped because the interval since the previous row was a gap
    /// (more than 5 times the median interval).
    pub wheel_gaps: usize,
    /// Gyro readings used (accepted by the gate).
    pub gyro_updates: usize,
    /// CAN speed readings used (accepted by the gate).
    pub speed_updates: usize,
    /// Steering readings used (accepted by the gate).
    pub steering_updates: usize,
    /// Readings of the other sensors not used because a newer one arrived before the
    /// next wheel epoch (the paper's scheme).
    pub readings_superseded: usize,
    /// Steering readings held back for a later epoch with a gyro reading,
    /// because the gyro was live but had no reading at the steering's epoch
    /// ([`crate::gyro_hold`]).
    #[serde(default)]
    pub steering_deferred: usize,
    /// GNSS fixes used.
    pub gnss_updates: usize,
    /// GNSS fixes rejected by the Mahalanobis gate.
    pub gnss_rejected: usize,
    /// Fixes accepted after `gnss_max_rejections` consecutive rejections, with the
    /// position covariance inflated (the filter had lost the GNSS track).
    pub gnss_recoveries: usize,
    /// GNSS fixes hidden by an outage window.
    pub gnss_hidden: usize,
    /// GNSS course readings used.
    pub course_updates: usize,
    /// Per-sensor χ² gate counters (accepted, rejected, recovered).
    pub gates: GateCounts,
}

/// The result of a filter run.
#[derive(Debug, Clone)]
pub struct FilterOutput<const N: usize = 5> {
    /// Every epoch (empty unless `record_epochs`).
    pub epochs: Vec<Epoch<N>>,
    /// Every innovation (empty unless `record_innovations`).
    pub innovations: Vec<InnovationRecord>,
    /// Counters.
    pub stats: FilterStats,
    /// What the wheel-health monitor saw (`None` without one).
    pub wheel_health: Option<WheelHealth>,
    /// Indices in `drive.gnss` of the fixes the χ² gate rejected, in order.
    pub gnss_gated: Vec<usize>,
}

impl<const N: usize> Default for FilterOutput<N> {
    fn default() -> Self {
        FilterOutput {
            epochs: Vec::new(),
            innovations: Vec::new(),
            stats: FilterStats::default(),
            wheel_health: None,
            gnss_gated: Vec::new(),
        }
    }
}

/// A hook called after every epoch with the time and the updated state and
/// covariance, which it may change (e.g. to reset the state to the truth).
pub trait EpochHook<const N: usize = 5> {
    /// Called after the updates of the epoch at `t_s`.
    fn after_epoch(&mut self, t_s: f64, x: &mut SVector<f64, N>, p: &mut SMatrix<f64, N, N>);
    /// True for a hook that never changes anything (the loop then skips it).
    fn is_noop(&self) -> bool {
        false
    }
}

impl<const N: usize> EpochHook<N> for () {
    fn after_epoch(&mut self, _t_s: f64, _x: &mut SVector<f64, N>, _p: &mut SMatrix<f64, N, N>) {}
    fn is_noop(&self) -> bool {
        true
    }
}

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
    /// When a wheel row is used (a feeder saved before this was chosen
    /// goes on as it began: [`WheelRows::Instant`]).
    #[serde(default = "instant")]
    wheel_rows: WheelRows,
    /// [`WheelRows::Interval`]: the epoch run but not yet handed out, waiting
    /// for the next wheel row's update at its time.
    #[serde(default)]
    held: Option<HeldEpoch>,
}

/// An epoch waiting for the next wheel row ([`WheelRows::Interval`]): its
/// prediction (when the feeder keeps predictions), flattened so the feeder
/// stays independent of the state's size.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
struct HeldEpoch {
    /// x̂_{k|k-1}, then P_{k|k-1} column by column, then the car block of F
    /// column by column; empty without a prediction.
    prediction: Vec<f64>,
}

impl HeldEpoch {
    fn new<const N: usize>(prediction: Option<&Prediction<N>>) -> Self {
        let mut v = Vec::new();
        if let Some(p) = prediction {
            v.reserve(N + N * N + 25);
            v.extend_from_slice(p.x.as_slice());
            v.extend_from_slice(p.p.as_slice());
            v.extend_from_slice(p.f.as_slice());
        }
        HeldEpoch { prediction: v }
    }

    fn prediction<const N: usize>(&self) -> Option<Prediction<N>> {
        let v = &self.prediction;
        if v.len() != N + N * N + 25 {
            return None;
        }
        Some(Prediction {
            x: SVector::from_column_slice(&v[..N]),
            p: SMatrix::from_column_slice(&v[N..N + N * N]),
            f: Mat::from_column_slice(&v[N + N * N..]),
        })
    }
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
    pub fn new(opts: &FilterOptions, start_s: f64) -> Self {
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
            wheel_rows: opts.wheel_rows,
            held: None,
        }
    }

    /// Whether an epoch is run but not yet handed out ([`WheelRows::Interval`]),
    /// and whether it carries its prediction.
    pub fn holds_epoch(&self) -> Option<bool> {
        self.held.as_ref().map(|h| !h.prediction.is_empty())
    }

    /// Hands out the held epoch, if any.
    fn release<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) {
        let Some(held) = self.held.take() else {
            return;
        };
        let prediction = held.prediction::<N>();
        self.stats.epochs += 1;
        epoch(
            f,
            EpochOut {
                prediction: prediction.as_ref(),
                updates: &self.updates,
                gated_fix_t_s: self.gated_fix_t_s,
            },
        );
        self.updates.clear();
        self.gated_fix_t_s = None;
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
    /// updates: it compares them with the updated state).
    fn monitor_wheels<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        m: &Measurement,
        interval_s: f64,
    ) {
        let Some(mon) = self.monitor.as_mut() else {
            return;
        };
        let readings = match *m {
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
            _ => return,
        };
        mon.check(f, readings);
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
            return Err(Error::InvalidDrive(format!(
                "event time {} is not finite",
                ev.t_s
            )));
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

    /// Runs what is still waiting (at the end of a stream).
    pub fn finish<L: Layout<N>, const N: usize>(
        &mut self,
        f: &mut Filter<L, N>,
        epoch: &mut dyn FnMut(&mut Filter<L, N>, EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.process_batch(f, epoch)?;
        self.release(f, epoch);
        // The epochs' scratch (not serialised): a feeder that has finished
        // equals its saved and loaded copy.
        self.updates.clear();
        self.gated_fix_t_s = None;
        Ok(())
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
        // A held epoch keeps its updates until it is handed out.
        if self.held.is_none() {
            self.updates.clear();
            self.gated_fix_t_s = None;
        }
        let supersede = |slot: &mut Option<f64>, v: f64, n: &mut usize| {
            if slot.replace(v).is_some() {
                *n += 1;
            }
        };
        match self.timing {
            Timing::WheelEpochs => match ev.measurement {
                Measurement::YawRate { yaw_rate_rps } if use_.gyro => {
                    supersede(
                        &mut self.pending_gyro,
                        yaw_rate_rps,
                        &mut self.stats.readings_superseded,
                    );
                    self.gyro.push(t, yaw_rate_rps);
                }
                Measurement::Speed { speed_mps } if use_.speed => supersede(
                    &mut self.pending_speed,
                    speed_mps,
                    &mut self.stats.readings_superseded,
                ),
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
                    let Some((interval, gap)) = self.wheel_interval(t, ticks) else {
                        return Ok(());
                    };
                    let at_start = self.wheel_rows == WheelRows::Interval;
                    if at_start {
                        // The row describes the interval that ends now: it
                        // updates the state at the interval's start, which
                        // the step below carries over the interval; the
                        // epoch there is then complete.
                        if use_.wheels {
                            if gap {
                                self.stats.wheel_gaps += 1;
                            } else {
                                self.wheel_updates(f, &ev.measurement, interval)?;
                                self.monitor_wheels(f, &ev.measurement, interval);
                            }
                        }
                        self.release(f, epoch);
                    }
                    let prediction = self.predict(f, t);
                    if use_.wheels && !at_start {
                        if gap {
                            self.stats.wheel_gaps += 1;
                        } else {
                            self.wheel_updates(f, &ev.measurement, interval)?;
                        }
                    }
                    let fresh_gyro = self.pending_gyro.is_some();
                    if let Some(v) = self.pending_gyro.take() {
                        self.updates.push(f.update_gyro(v)?);
                    }
                    if let Some(v) = self.pending_speed.take() {
                        self.updates.push(f.update_speed(v)?);
                    }
                    // While the gyro is live, the steering waits for an
                    // epoch with a gyro reading of its own (crate::gyro_hold).
                    if fresh_gyro || !(use_.gyro && self.gyro.is_live(t)) {
                        if let Some(v) = self.pending_steering.take() {
                            self.updates.push(f.update_steering(v)?);
                        }
                    } else if self.pending_steering.is_some() {
                        self.stats.steering_deferred += 1;
                    }
                    if let Some(fix) = self.pending_gnss.take() {
                        self.gnss_update(f, &fix)?;
                    }
                    if at_start {
                        self.held = Some(HeldEpoch::new(prediction.as_ref()));
                        return Ok(());
                    }
                    if use_.wheels && !gap {
                        self.monitor_wheels(f, &ev.measurement, interval);
                    }
                    self.stats.epochs += 1;
                    epoch(
                        f,
                        EpochOut {
                            prediction: prediction.as_ref(),
                            updates: &self.updates,
                            gated_fix_t_s: self.gated_fix_t_s,
                        },
                    );
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
                self.stats.epochs += 1;
                epoch(
                    f,
                    EpochOut {
                        prediction: prediction.as_ref(),
                        updates: &self.updates,
                        gated_fix_t_s: self.gated_fix_t_s,
                    },
                );
            }
        }
        Ok(())
    }
}

/// Runs the EKF over `drive` with the calibration `params`.
pub fn run(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    hook: &mut dyn EpochHook,
) -> Result<FilterOutput, Error> {
    run_filter(drive, car_filter(drive, params, opts)?, opts, hook)
}

/// Runs the EKF with the state augmented by the six parameters, which start at
/// `params` with standard deviations `prior_std` (circumferences in metres) and
/// are then estimated with the car state. Used by the calibration.
pub fn run_augmented(
    drive: &Drive,
    params: &Params,
    prior_std: &Params,
    opts: &FilterOptions,
) -> Result<FilterOutput<N_AUG>, Error> {
    let f = augmented_filter(drive, params, prior_std, opts)?;
    run_filter(drive, f, opts, &mut ())
}

/// The 5-state filter at the start `opts.init` gives on `drive`.
pub fn car_filter(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<Filter<CarLayout, 5>, Error> {
    let (t0, x0, p0) = start(drive, opts)?;
    Ok(
        Filter::<CarLayout, 5>::new(&drive.vehicle, params, None, t0, x0, p0)?
            .with_covariance_form(opts.covariance_form),
    )
}

/// A filter of a layout without parameter states (the car's five states,
/// or with the receiver's wander: [`crate::gnss_error::CarWanderLayout`])
/// at the start `opts.init` gives on `drive`; the wander (when the layout
/// has it) starts at zero with the variance `noise.gnss_wander_std_m²`.
pub fn fixed_filter<L: Layout<N>, const N: usize>(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<Filter<L, N>, Error> {
    let (t0, x0, p0) = start(drive, opts)?;
    // A walking gyro bias (crate::gyro_drift) starts at the calibrated value.
    let prior = L::bias_walks().then(|| crate::gyro_drift::prior_std(&drive.vehicle.noise));
    Ok(
        Filter::<L, N>::new(&drive.vehicle, params, prior.as_ref(), t0, x0, p0)?
            .with_covariance_form(opts.covariance_form),
    )
}

/// The 11-state filter (parameters as states, starting at `params` with
/// standard deviations `prior_std`) at the start `opts.init` gives on `drive`.
pub fn augmented_filter(
    drive: &Drive,
    params: &Params,
    prior_std: &Params,
    opts: &FilterOptions,
) -> Result<Filter<AugmentedLayout, N_AUG>, Error> {
    let (t0, x0, p0) = start(drive, opts)?;
    Ok(
        Filter::<AugmentedLayout, N_AUG>::new(&drive.vehicle, params, Some(prior_std), t0, x0, p0)?
            .with_covariance_form(opts.covariance_form),
    )
}

pub(crate) fn start(drive: &Drive, opts: &FilterOptions) -> Result<(f64, State, Mat), Error> {
    drive.validate()?;
    start_validated(drive, opts)
}

/// [`start`] on a drive already validated (the outage evaluation validates once,
/// not once per window).
fn start_validated(drive: &Drive, opts: &FilterOptions) -> Result<(f64, State, Mat), Error> {
    let (t0, x0, p0) = initial_state(drive, opts)?;
    if first_wheel_at_or_after(&drive.wheels, t0) + 1 >= drive.wheels.len() {
        return Err(Error::Insufficient(
            "no wheel epochs after the initial time".into(),
        ));
    }
    Ok((t0, x0, p0))
}

/// Index of the first wheel row at or after `t` (binary search; rows are sorted).
fn first_wheel_at_or_after(w: &Wheels, t: f64) -> usize {
    let (mut lo, mut hi) = (0, w.len());
    while lo < hi {
        let mid = (lo + hi) / 2;
        if w.t_s(mid) < t {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    lo
}

/// The feeder of a filter started at `t0_s` and the drive's events it needs
/// (from the wheel row before the first one at or after `t0_s`).
pub fn feed<'a>(drive: &'a Drive, opts: &FilterOptions, t0_s: f64) -> (Feeder, DriveEvents<'a>) {
    let w = &drive.wheels;
    let k0 = first_wheel_at_or_after(w, t0_s);
    let before_first = if k0 > 0 {
        w.t_s(k0 - 1)
    } else {
        f64::NEG_INFINITY
    };
    (
        Feeder::new(opts, t0_s),
        DriveEvents::new(drive, before_first),
    )
}

/// The batch loop: every event of the drive after the start through a
/// [`Feeder`] into the filter `f`, recording epochs and innovations as `opts`
/// asks, with `hook` after every epoch.
pub fn run_filter<L: Layout<N>, const N: usize>(
    drive: &Drive,
    mut f: Filter<L, N>,
    opts: &FilterOptions,
    hook: &mut dyn EpochHook<N>,
) -> Result<FilterOutput<N>, Error> {
    let (mut feeder, events) = feed(drive, opts, f.time_s());
    let mut out = FilterOutput::<N>::default();
    let mut record = |f: &mut Filter<L, N>, e: EpochOut<'_, N>| {
        if !hook.is_noop() {
            let (mut x, mut p) = (*f.state(), *f.covariance());
            hook.after_epoch(f.time_s(), &mut x, &mut p);
            f.set_state(x, p);
        }
        if let Some(t) = e.gated_fix_t_s {
            // Fix times are strictly increasing in a valid drive: the time
            // is the fix's key.
            let i = drive.gnss.partition_point(|g| g.t_s < t);
            if drive.gnss.get(i).is_some_and(|g| g.t_s == t) {
                out.gnss_gated.push(i);
            }
        }
        if opts.record_innovations {
            out.innovations
                .extend(e.updates.iter().map(|u| InnovationRecord {
                    t_s: f.time_s(),
                    sensor: u.sensor,
                    y: u.y,
                    s: u.s,
                    nis: u.nis,
                    accepted: u.accepted,
                }));
        }
        if let Some(prediction) = e.prediction {
            out.epochs.push(Epoch::after(f, prediction));
        }
    };
    // Events after `end_s` are never used: stop reading there.
    let end = opts.end_s.unwrap_or(f64::INFINITY);
    for ev in events.take_while(|e| e.t_s <= end) {
        feeder.push(&mut f, ev, &mut record)?;
    }
    feeder.finish(&mut f, &mut record)?;
    out.stats = feeder.stats_with(&f);
    out.wheel_health = feeder.wheel_health();
    Ok(out)
}
