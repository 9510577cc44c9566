//! The GNSS-aided filter of the layout the vehicle's noise settings call
//! for, as one object: every place that runs the aided filter over a drive
//! or a stream (the outage evaluation, `run`'s tracks, the NEES, the online
//! filter) goes through [`Aided`], so a choice of layout is made here once.
//!
//! | `[noise]` | layout |
//! |---|---|
//! | neither | the car's five states ([`CarLayout`]) |
//! | `gnss_wander_std_m` > 0 | the receiver's wander ([`crate::gnss_error`]) |
//! | a gyro bias walk or drive std > 0 ([`crate::gyro_drift::carries_bias`]) | the gyro bias as a state |
//! | both | the wander and the gyro bias |
//!
//! With the bias as a state and `[noise] gyro_bias_switch_llr` above 0, the
//! constant bias and the bias as a state run side by side and the drive's
//! own fixes choose between them ([`switch`]: the gyro-bias switch).
//!
//! An epoch hands out an [`AidedEpoch`]: the car's block of the state and
//! covariance, and the receiver's wander where carried, whatever the layout;
//! [`Aided::run_observed`] also hands out its [`EpochUpdates`] (each
//! sensor's innovation and the fix the gate rejected: the report's filter
//! health, of the filter whose tracks `run` writes).

use serde::{Deserialize, Serialize};

use crate::bound::WanderCov;
use crate::drive::Drive;
use crate::ekf::{self, EpochOut, Event, Feeder, FilterOptions, FilterStats};
use crate::event::DriveEvents;
use crate::filter::{CarLayout, Filter, GateCounts, Layout, Update};
use crate::gnss_error::{CarWanderLayout, N_WANDER};
use crate::gyro_drift::{CarBiasLayout, CarWanderBiasLayout, N_BIAS, N_WANDER_BIAS};
use crate::model::{Mat, State};
use crate::vehicle::{Noise, Params, Vehicle};
use crate::Error;

pub mod switch;

pub use switch::BiasSwitch;
use switch::Switch;

/// What one epoch of the aided filter hands out, of any layout.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AidedEpoch {
    /// The epoch's time, s.
    pub t_s: f64,
    /// The car's block of the state `[x, y, ψ, v, ψ̇]`.
    pub x: State,
    /// The car's block of the covariance.
    pub p: Mat,
    /// The receiver's wander estimate `[e_E, e_N]`, m (zeros when not carried).
    pub wander_m: [f64; 2],
    /// The wander's part of the covariance, where carried.
    pub(crate) wander_cov: Option<WanderCov>,
}

/// What one epoch of the aided filter did, of the hypothesis handed out
/// (with the gyro-bias switch, the one whose state the epoch hands out).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpochUpdates<'a> {
    /// The updates applied (or rejected by the χ² gate) at the epoch.
    pub updates: &'a [Update],
    /// The time of the GNSS fix the gate rejected at this epoch (its own
    /// time, which identifies it in the drive).
    pub gated_fix_t_s: Option<f64>,
}

impl<'a> EpochUpdates<'a> {
    fn of<const N: usize>(e: &EpochOut<'a, N>) -> Self {
        EpochUpdates {
            updates: e.updates,
            gated_fix_t_s: e.gated_fix_t_s,
        }
    }
}

/// What [`Aided::run_observed`] hands out after each epoch.
pub type Observe<'c> = dyn FnMut(&AidedEpoch, &EpochUpdates<'_>) + 'c;

impl AidedEpoch {
    fn of<L: Layout<N>, const N: usize>(f: &Filter<L, N>) -> Self {
        let p = f.covariance();
        AidedEpoch {
            t_s: f.time_s(),
            x: f.car_state(),
            p: p.fixed_view::<{ crate::model::N }, { crate::model::N }>(0, 0)
                .into_owned(),
            wander_m: f.wander_m(),
            wander_cov: L::wander_index().map(|w| WanderCov::of(p, w)),
        }
    }
}

/// One filter of layout `L` with its feeder. It keeps no epochs: the
/// smoother runs it again ([`Aided::smoothed_each`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Run<L: Layout<N>, const N: usize> {
    filter: Filter<L, N>,
    feeder: Feeder,
}

impl<L: Layout<N>, const N: usize> Run<L, N> {
    fn start(
        vehicle: &Vehicle,
        params: &Params,
        opts: &FilterOptions,
        (t0, x0, p0): (f64, State, Mat),
    ) -> Result<Self, Error> {
        // A gyro bias state starts at the calibrated value (crate::gyro_drift).
        let prior = L::bias_walks().then(|| crate::gyro_drift::prior_std(&vehicle.noise));
        let filter = Filter::<L, N>::new(vehicle, params, prior.as_ref(), t0, x0, p0)?
            .with_covariance_form(opts.covariance_form);
        Ok(Run {
            // A standing car does not turn (crate::standstill).
            feeder: Feeder::new(opts, vehicle, t0).with_standstill(),
            filter,
        })
    }

    /// Feeds one event; `epoch` after every epoch it completes.
    fn push_raw(
        &mut self,
        ev: Event,
        epoch: &mut dyn FnMut(&Filter<L, N>, &EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.feeder
            .push(&mut self.filter, ev, &mut |f, e| epoch(f, &e))
    }

    /// Runs what is waiting: at the end of the stream (`end`,
    /// [`Feeder::finish`]) or before more ([`Feeder::settle`]).
    fn finish_raw(
        &mut self,
        end: bool,
        epoch: &mut dyn FnMut(&Filter<L, N>, &EpochOut<'_, N>),
    ) -> Result<(), Error> {
        self.feeder
            .run_waiting(end, &mut self.filter, &mut |f, e| epoch(f, &e))
    }

    fn push(&mut self, ev: Event, epoch: &mut Observe<'_>) -> Result<(), Error> {
        self.push_raw(ev, &mut |f, e| {
            epoch(&AidedEpoch::of(f), &EpochUpdates::of(e))
        })
    }

    fn finish(&mut self, end: bool, epoch: &mut Observe<'_>) -> Result<(), Error> {
        self.finish_raw(end, &mut |f, e| {
            epoch(&AidedEpoch::of(f), &EpochUpdates::of(e))
        })
    }

    fn dead_reckon(&mut self) {
        self.feeder.dead_reckon()
    }

    fn time_s(&self) -> f64 {
        self.filter.time_s()
    }

    fn now(&self) -> Option<AidedEpoch> {
        Some(AidedEpoch::of(&self.filter))
    }

    fn gates(&self) -> GateCounts {
        *self.filter.gates()
    }

    fn stats(&self) -> FilterStats {
        self.feeder.stats_with(&self.filter)
    }

    /// This run's filter as it stands run again over `drive`, its smoothed
    /// car blocks handed to `visit` from the last epoch to the first
    /// ([`crate::checkpoint::smooth_each`]), the receiver's wander smoothed
    /// with its `φ`. Returns the number of epochs.
    fn smooth_each(
        &self,
        drive: &Drive,
        opts: &FilterOptions,
        visit: &mut (dyn FnMut(f64, &State, &Mat) + Send),
    ) -> Result<usize, Error>
    where
        L: Send + Sync,
    {
        let n = self.filter.noise();
        let wander = L::wander_index().map(|index| crate::rts::WanderStates {
            index,
            wander: crate::gnss_error::Wander {
                std_m: n.gnss_wander_std_m,
                tau_s: n.gnss_wander_tau_s,
            },
        });
        crate::checkpoint::smooth_each(drive, self.filter.clone(), opts, wander, true, |s| {
            visit(
                s.t_s,
                &s.x.fixed_rows::<{ crate::model::N }>(0).into_owned(),
                &s.p.fixed_view::<{ crate::model::N }, { crate::model::N }>(0, 0)
                    .into_owned(),
            )
        })
    }
}

/// The GNSS-aided filter of the layout the vehicle's noise settings call
/// for (see the module documentation), with its feeder. Serialisable: the
/// online filter stops and resumes through it (the variants keep the names
/// the online filter's stages had).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Aided {
    /// The car's five states.
    Car(Box<Run<CarLayout, { crate::model::N }>>),
    /// The gyro bias as a state ([`crate::gyro_drift`]).
    #[serde(rename = "Walking")]
    Bias(Box<Run<CarBiasLayout, N_BIAS>>),
    /// The receiver's wander ([`crate::gnss_error`]).
    Wander(Box<Run<CarWanderLayout, N_WANDER>>),
    /// The receiver's wander and the gyro bias.
    #[serde(rename = "WanderWalking")]
    WanderBias(Box<Run<CarWanderBiasLayout, N_WANDER_BIAS>>),
    /// The constant bias and the bias as a state, switched by the fixes
    /// ([`switch`]).
    Switched(Box<Switch<CarLayout, { crate::model::N }, CarBiasLayout, N_BIAS>>),
    /// The same with the receiver's wander in both.
    WanderSwitched(Box<Switch<CarWanderLayout, N_WANDER, CarWanderBiasLayout, N_WANDER_BIAS>>),
}

/// `$body` with `$run` bound to the [`Run`] of whichever layout.
macro_rules! each {
    ($aided:expr, |$run:ident| $body:expr) => {
        match $aided {
            Aided::Car($run) => $body,
            Aided::Bias($run) => $body,
            Aided::Wander($run) => $body,
            Aided::WanderBias($run) => $body,
            Aided::Switched($run) => $body,
            Aided::WanderSwitched($run) => $body,
        }
    };
}

impl Aided {
    /// The aided filter `vehicle`'s noise settings call for, started at
    /// `start` (time, car state, covariance) with `params`; `opts` as for
    /// [`Feeder::new`] (epochs are kept for [`Aided::smoothed`] when
    /// `opts.record_epochs`).
    pub fn start(
        vehicle: &Vehicle,
        params: &Params,
        opts: &FilterOptions,
        start: (f64, State, Mat),
    ) -> Result<Self, Error> {
        let n = &vehicle.noise;
        if crate::gyro_drift::carries_bias(n) && n.gyro_bias_switch_llr > 0.0 {
            // The constant hypothesis: the same vehicle with the paper's bias.
            let mut constant = vehicle.clone();
            constant.noise.gyro_bias_walk_rps_per_sqrt_s = 0.0;
            constant.noise.gyro_bias_drive_std_rps = 0.0;
            let threshold = n.gyro_bias_switch_llr;
            return Ok(if carries_wander(n) {
                Aided::WanderSwitched(Box::new(Switch::new(
                    Run::start(&constant, params, opts, start)?,
                    Run::start(vehicle, params, opts, start)?,
                    threshold,
                )))
            } else {
                Aided::Switched(Box::new(Switch::new(
                    Run::start(&constant, params, opts, start)?,
                    Run::start(vehicle, params, opts, start)?,
                    threshold,
                )))
            });
        }
        Ok(
            match (carries_wander(n), crate::gyro_drift::carries_bias(n)) {
                (false, false) => Aided::Car(Box::new(Run::start(vehicle, params, opts, start)?)),
                (false, true) => Aided::Bias(Box::new(Run::start(vehicle, params, opts, start)?)),
                (true, false) => Aided::Wander(Box::new(Run::start(vehicle, params, opts, start)?)),
                (true, true) => {
                    Aided::WanderBias(Box::new(Run::start(vehicle, params, opts, start)?))
                }
            },
        )
    }

    /// The aided filter on `drive` at the start `opts.init` gives, and the
    /// drive's events it needs (as [`ekf::feed`]).
    pub fn on_drive<'a>(
        drive: &'a Drive,
        params: &Params,
        opts: &FilterOptions,
    ) -> Result<(Self, DriveEvents<'a>), Error> {
        let start = ekf::start(drive, opts)?;
        let a = Self::start(&drive.vehicle, params, opts, start)?;
        let (_, events) = ekf::feed(drive, opts, start.0);
        Ok((a, events))
    }

    /// The batch loop: the aided filter over every event of `drive` up to
    /// `opts.end_s`, `epoch` after each epoch; the filter at the end.
    pub fn run(
        drive: &Drive,
        params: &Params,
        opts: &FilterOptions,
        epoch: &mut dyn FnMut(&AidedEpoch),
    ) -> Result<Self, Error> {
        Self::run_observed(drive, params, opts, &mut |e, _| epoch(e))
    }

    /// [`Aided::run`], `epoch` also given what the epoch's updates were.
    pub fn run_observed(
        drive: &Drive,
        params: &Params,
        opts: &FilterOptions,
        epoch: &mut Observe<'_>,
    ) -> Result<Self, Error> {
        let (mut a, events) = Self::on_drive(drive, params, opts)?;
        let end = opts.end_s.unwrap_or(f64::INFINITY);
        for ev in events.take_while(|e| e.t_s <= end) {
            each!(&mut a, |r| r.push(ev, epoch))?;
        }
        each!(&mut a, |r| r.finish(true, epoch))?;
        Ok(a)
    }

    /// Takes one event (timestamps must not decrease); `epoch` after every
    /// epoch it completes.
    pub fn push(&mut self, ev: Event, epoch: &mut dyn FnMut(&AidedEpoch)) -> Result<(), Error> {
        each!(self, |r| r.push(ev, &mut |e, _| epoch(e)))
    }

    /// Runs what is still waiting, at the end of a stream
    /// ([`Feeder::finish`]).
    pub fn finish(&mut self, epoch: &mut dyn FnMut(&AidedEpoch)) -> Result<(), Error> {
        each!(self, |r| r.finish(true, &mut |e, _| epoch(e)))
    }

    /// Runs the epoch of the events pushed so far when every later event
    /// is later (a live stream after each input, a run paused for a clone
    /// to dead-reckon from; [`Feeder::settle`]).
    pub fn settle(&mut self, epoch: &mut dyn FnMut(&AidedEpoch)) -> Result<(), Error> {
        each!(self, |r| r.finish(false, &mut |e, _| epoch(e)))
    }

    /// From now on no GNSS ([`Feeder::dead_reckon`]).
    pub fn dead_reckon(&mut self) {
        each!(self, |r| r.dead_reckon())
    }

    /// The filter's time, s.
    pub fn time_s(&self) -> f64 {
        each!(self, |r| r.time_s())
    }

    /// The current state as an epoch hands it out.
    pub fn now(&self) -> Option<AidedEpoch> {
        each!(self, |r| r.now())
    }

    /// The χ² gate counters so far (of the hypothesis handed out, with the
    /// gyro-bias switch).
    pub fn gates(&self) -> GateCounts {
        each!(self, |r| r.gates())
    }

    /// The feeder's counters with the filter's gate counters folded in.
    pub fn stats(&self) -> FilterStats {
        each!(self, |r| r.stats())
    }

    /// What the gyro-bias switch has seen (`None` without one).
    pub fn bias_switch(&self) -> Option<BiasSwitch> {
        match self {
            Aided::Switched(s) => Some(s.report()),
            Aided::WanderSwitched(s) => Some(s.report()),
            _ => None,
        }
    }

    /// Whether the layout carries the receiver's wander.
    pub fn carries_wander(&self) -> bool {
        matches!(
            self,
            Aided::Wander(_) | Aided::WanderBias(_) | Aided::WanderSwitched(_)
        )
    }

    /// The RTS-smoothed car blocks of `drive`, which this filter ran over
    /// with `params` and `opts` ([`Aided::run`]), handed to `visit` from
    /// the last epoch to the first. With the gyro-bias switch, of the
    /// hypothesis the drive ended with (the state's over the whole drive
    /// once it fired: the smoother sees every fix anyway). That hypothesis
    /// runs again from the start and is smoothed segment by segment
    /// ([`crate::checkpoint`]): equal bit for bit to smoothing every epoch
    /// of the run, in O(√N) memory, so a run keeps no epochs. Returns the
    /// number of epochs.
    pub fn smoothed_each(
        &self,
        drive: &Drive,
        params: &Params,
        opts: &FilterOptions,
        visit: &mut (dyn FnMut(f64, &State, &Mat) + Send),
    ) -> Result<usize, Error> {
        let (fresh, _) = Self::on_drive(drive, params, opts)?;
        match (self, &fresh) {
            (Aided::Car(_), Aided::Car(r)) => r.smooth_each(drive, opts, visit),
            (Aided::Bias(_), Aided::Bias(r)) => r.smooth_each(drive, opts, visit),
            (Aided::Wander(_), Aided::Wander(r)) => r.smooth_each(drive, opts, visit),
            (Aided::WanderBias(_), Aided::WanderBias(r)) => r.smooth_each(drive, opts, visit),
            (Aided::Switched(s), Aided::Switched(f)) => s.smooth_each(f, drive, opts, visit),
            (Aided::WanderSwitched(s), Aided::WanderSwitched(f)) => {
                s.smooth_each(f, drive, opts, visit)
            }
            _ => Err(Error::Numerical {
                t_s: self.time_s(),
                what: "the aided filter's layout differs from the run it smooths".into(),
            }),
        }
    }
}

/// Whether the aided filter carries the receiver's wander.
fn carries_wander(noise: &Noise) -> bool {
    noise.gnss_wander_std_m > 0.0
}
