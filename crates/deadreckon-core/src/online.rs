//! The four-wheel filter on a live stream: initialisation, the filter and the
//! timing scheme in one serialisable object, fed one [`Event`] at a time.
//!
//! [`Online`] starts from a given pose or from GNSS (the first fix and the
//! direction of the first 10 m, as [`crate::ekf::Init::Gnss`]; events are kept
//! until then and replayed, so the result equals the batch filter's), then
//! emits one [`TrackPoint`] per filter epoch. With [`Online::learning`] it runs
//! the state augmented with the six parameters and keeps them with their
//! standard errors, a validity flag and a percentage calibrated
//! ([`Learned`]), as production stacks learn their parameters while driving.
//!
//! Memory is constant once the filter has started; before, the events since the
//! first GNSS fix are kept (the vehicle has to move 10 m).
//!
//! [`Online::with_corrections`] applies the corrections a params.toml stores
//! (delays, IMU tilt, gyro scale, driven-axle slip) to the events before the
//! filter, through a reorder buffer on corrected time
//! ([`crate::live_corrections`]), so that the output equals the batch filter
//! on the corrected drive; the poses then come out
//! [`Online::hold_s`] seconds of stream time later. [`Online::finish`]
//! keeps what is held back in the state (a resumed stream releases it);
//! [`Online::end`] releases everything at the end of a stream.
//!
//! Each pose can carry its 95 % bound ([`crate::bound_pose`]):
//! [`Online::with_bound`] gives the factor, [`Online::push_poses`] (and
//! `finish_poses`, `end_poses`) the poses with their bounds, equal to
//! [`crate::bound_pose::filtered_bounds_m`] on `run`'s filtered track.

use serde::{Deserialize, Serialize};

use crate::aided::Aided;
use crate::bound::BoundFit;
use crate::bound_pose::{point_bound_m, FixFloor, Pose};
use crate::ekf::{Event, Feeder, FilterOptions, FilterStats, GnssInit};
use crate::filter::AugmentedFilter;
use crate::live_corrections::LiveCorrections;
use crate::model::{Mat, State};
use crate::track::{car_point, TrackPoint};
use crate::vehicle::{Params, Vehicle};
use crate::Error;

/// The target standard errors of the learned parameters: the accuracy of the
/// offline RTS calibration on the project's simulated drives (gyro bias 5% of a
/// typical 1e-3 rad/s bias, speed scale 0.3%, circumferences 0.1%).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnTargets {
    /// Gyro bias, rad/s.
    pub gyro_bias_rps: f64,
    /// Speed scale (unitless).
    pub speed_scale: f64,
    /// Circumference, relative (0.001 = 0.1%).
    pub circumference_rel: f64,
}

impl Default for LearnTargets {
    fn default() -> Self {
        LearnTargets {
            gyro_bias_rps: 5e-5,
            speed_scale: 3e-3,
            circumference_rel: 1e-3,
        }
    }
}

/// Learned parameters with their confidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Learned {
    /// The estimates.
    pub params: Params,
    /// One standard error each (circumferences in metres).
    pub std: Params,
    /// True when every standard error is within its target ([`LearnTargets`]).
    pub valid: bool,
    /// Mean over the six parameters of min(1, target / standard error), in percent.
    pub calibrated_pct: f64,
}

impl Learned {
    fn new(params: Params, std: Params, t: &LearnTargets) -> Self {
        let c = params.circumferences();
        let cs = std.circumferences();
        let ratios = [
            t.gyro_bias_rps / std.gyro_bias_rps,
            t.speed_scale / std.speed_scale,
            t.circumference_rel * c[0] / cs[0],
            t.circumference_rel * c[1] / cs[1],
            t.circumference_rel * c[2] / cs[2],
            t.circumference_rel * c[3] / cs[3],
        ];
        let valid = ratios.iter().all(|r| *r >= 1.0);
        let pct = 100.0 * ratios.iter().map(|r| r.min(1.0)).sum::<f64>() / 6.0;
        Learned {
            params,
            std,
            valid,
            calibrated_pct: pct,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
enum Stage {
    /// Waiting for the GNSS initialisation; the events since the first fix.
    Waiting { init: GnssInit, buffer: Vec<Event> },
    Learning {
        filter: Box<AugmentedFilter>,
        feeder: Box<Feeder>,
    },
    /// Fixed parameters: the aided filter the vehicle calls for
    /// ([`crate::aided`]; serialised as its layout's name, as the stages
    /// of each layout were before).
    #[serde(untagged)]
    Aided(Aided),
}

/// The filter on a stream; see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Online {
    vehicle: Vehicle,
    params: Params,
    /// Prior standard deviations when learning.
    prior_std: Option<Params>,
    opts: FilterOptions,
    stage: Stage,
    /// The stored corrections and their reorder buffer (absent from states
    /// written before them: none).
    #[serde(default)]
    live: LiveCorrections,
    /// The 95 % bound's factor (states written before it: the filter's
    /// covariance alone).
    #[serde(default = "filter_bound")]
    bound: BoundFit,
    /// The declared accuracy of the fixes given, for the bound's floor.
    #[serde(default)]
    floor: FixFloor,
}

fn filter_bound() -> BoundFit {
    BoundFit::FILTER
}

/// A dead-reckoning start for [`Online::new`].
#[allow(clippy::large_enum_variant)] // a plain value passed once
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Start {
    /// From GNSS, as [`crate::ekf::Init::Gnss`].
    Gnss,
    /// A given time, car state and covariance.
    Given(f64, State, Mat),
}

impl Online {
    /// A filter with fixed `params`. Only `timing`, `sensors`, `gnss_outages`,
    /// `covariance_form` and `end_s` of `opts` apply.
    pub fn new(
        vehicle: &Vehicle,
        params: &Params,
        opts: &FilterOptions,
        start: Start,
    ) -> Result<Self, Error> {
        Self::build(vehicle, params, None, opts, start)
    }

    /// A filter that learns the six parameters, starting from `params` with
    /// standard deviations `prior_std` (circumferences in metres). Refused
    /// under per-reading timing with table I's loose process noise
    /// ([`crate::calibrate::check_learning_noise`]).
    pub fn learning(
        vehicle: &Vehicle,
        params: &Params,
        prior_std: &Params,
        opts: &FilterOptions,
        start: Start,
    ) -> Result<Self, Error> {
        crate::calibrate::check_learning_noise(&vehicle.noise, opts.timing)?;
        Self::build(vehicle, params, Some(*prior_std), opts, start)
    }

    fn build(
        vehicle: &Vehicle,
        params: &Params,
        prior_std: Option<Params>,
        opts: &FilterOptions,
        start: Start,
    ) -> Result<Self, Error> {
        vehicle.validate()?;
        params.validate()?;
        let mut o = Online {
            vehicle: vehicle.clone(),
            params: *params,
            prior_std,
            opts: FilterOptions {
                record_epochs: false,
                record_innovations: false,
                ..opts.clone()
            },
            stage: Stage::Waiting {
                init: GnssInit::new(vehicle.gnss_lever_arm_m),
                buffer: Vec::new(),
            },
            live: LiveCorrections::default(),
            bound: BoundFit::FILTER,
            floor: FixFloor::new(crate::bound_pose::carries_wander(&vehicle.noise)),
        };
        if let Start::Given(t, x, p) = start {
            o.stage = o.started(t, x, p)?;
        }
        Ok(o)
    }

    fn started(&self, t0: f64, x0: State, p0: Mat) -> Result<Stage, Error> {
        Ok(match &self.prior_std {
            None => Stage::Aided(Aided::start(
                &self.vehicle,
                &self.params,
                &self.opts,
                (t0, x0, p0),
            )?),
            Some(sd) => Stage::Learning {
                filter: Box::new(
                    AugmentedFilter::new(&self.vehicle, &self.params, Some(sd), t0, x0, p0)?
                        .with_covariance_form(self.opts.covariance_form),
                ),
                feeder: Box::new(Feeder::new(&self.opts, &self.vehicle, t0)),
            },
        })
    }

    /// True once the filter runs.
    pub fn is_started(&self) -> bool {
        !matches!(self.stage, Stage::Waiting { .. })
    }

    /// The filter applying `known` to the events before filtering them
    /// ([`crate::live_corrections`]); given before the first event.
    pub fn with_corrections(
        mut self,
        known: &crate::timing::KnownCorrections,
    ) -> Result<Self, Error> {
        self.live = LiveCorrections::new(known)?;
        Ok(self)
    }

    /// The filter whose poses carry the 95 % bound of `fit` (default: the
    /// filter's covariance alone, [`BoundFit::FILTER`]).
    pub fn with_bound(mut self, fit: BoundFit) -> Self {
        self.bound = fit;
        self
    }

    /// The 95 % bound's factor the poses carry.
    pub fn bound(&self) -> &BoundFit {
        &self.bound
    }

    /// The stored corrections applied and their reorder buffer.
    pub fn corrections(&self) -> &LiveCorrections {
        &self.live
    }

    /// How long the corrections hold events back, s of stream time (0
    /// without delays or slip): the latency they add to every pose.
    pub fn hold_s(&self) -> f64 {
        self.live.hold_s()
    }

    /// Takes one event (time order); calls `out` with the state after every
    /// epoch it completes. The stored corrections are applied first; an
    /// epoch runs once no later event can change it.
    pub fn push(&mut self, ev: Event, out: &mut dyn FnMut(TrackPoint)) -> Result<(), Error> {
        self.push_poses(ev, &mut |p| out(p.point))
    }

    /// [`Online::push`] with each pose's 95 % bound.
    pub fn push_poses(&mut self, ev: Event, out: &mut dyn FnMut(Pose)) -> Result<(), Error> {
        let mut live = std::mem::take(&mut self.live);
        let r = live.push(ev, &mut |e| self.feed(e, out));
        self.live = live;
        r?;
        self.settle(out, false)
    }

    /// Runs what no later event can change and keeps what the corrections
    /// hold back (in the state: a stream resumed from it, with later
    /// events, continues as if never cut). With nothing held back, all that
    /// is waiting runs, but for the epoch of the last wheel row when each
    /// row is used over its interval (the vehicle's
    /// `wheel_rows_over_interval`): the next row, or [`Online::end`], closes
    /// it.
    pub fn finish(&mut self, out: &mut dyn FnMut(TrackPoint)) -> Result<(), Error> {
        self.finish_poses(&mut |p| out(p.point))
    }

    /// [`Online::finish`] with each pose's 95 % bound.
    pub fn finish_poses(&mut self, out: &mut dyn FnMut(Pose)) -> Result<(), Error> {
        let mut live = std::mem::take(&mut self.live);
        let r = live.pause(&mut |e| self.feed(e, out));
        self.live = live;
        r?;
        self.settle(out, false)?;
        self.waiting_error()
    }

    /// The end of the stream: releases and runs everything the corrections
    /// held back; readings after the last wheel row are dropped, as the
    /// batch filter never uses them.
    pub fn end(&mut self, out: &mut dyn FnMut(TrackPoint)) -> Result<(), Error> {
        self.end_poses(&mut |p| out(p.point))
    }

    /// [`Online::end`] with each pose's 95 % bound.
    pub fn end_poses(&mut self, out: &mut dyn FnMut(Pose)) -> Result<(), Error> {
        let mut live = std::mem::take(&mut self.live);
        let r = live.end(&mut |e| self.feed(e, out));
        self.live = live;
        r?;
        self.settle(out, true)?;
        self.waiting_error()
    }

    fn waiting_error(&self) -> Result<(), Error> {
        match &self.stage {
            Stage::Waiting { init, .. } => Err(init.why_not()),
            _ => Ok(()),
        }
    }

    /// One corrected event, in corrected time order, to the start or the
    /// filter.
    fn feed(&mut self, ev: Event, out: &mut dyn FnMut(Pose)) -> Result<(), Error> {
        let hidden = |t: f64| crate::drive::in_windows(t, &self.opts.gnss_outages);
        if let Some(fix) = ev.gnss_fix().filter(|g| !hidden(g.t_s)) {
            self.floor.push(&fix);
        }
        let (fit, floor) = (self.bound, &mut self.floor);
        let mut emit = |p: TrackPoint| {
            let s = floor.std_at(p.t_s);
            out(Pose {
                point: p,
                bound_95_m: point_bound_m(&fit, &p, s),
            })
        };
        match &mut self.stage {
            Stage::Waiting { init, buffer } => {
                let mut start = None;
                if let Some(fix) = ev.gnss_fix().filter(|g| !hidden(g.t_s)) {
                    if !init.has_first() {
                        // Nothing before the first fix is ever used.
                        buffer.retain(|e| e.t_s >= fix.t_s);
                    }
                    start = init.push(&fix);
                }
                if let Some(b) = buffer.last() {
                    if ev.t_s < b.t_s {
                        return Err(Error::OutOfOrder {
                            t_s: ev.t_s,
                            previous_t_s: b.t_s,
                        });
                    }
                }
                buffer.push(ev);
                if let Some((t0, x0, p0)) = start {
                    let events = std::mem::take(buffer);
                    self.stage = self.started(t0, x0, p0)?;
                    for e in events {
                        self.feed(e, out)?;
                    }
                }
                Ok(())
            }
            Stage::Learning { filter, feeder } => feeder.push(filter.as_mut(), ev, &mut |f, _| {
                emit(car_point(f.time_s(), f.state(), f.covariance()))
            }),
            Stage::Aided(a) => a.push(ev, &mut |e| emit(TrackPoint::from_state(e.t_s, &e.x, &e.p))),
        }
    }

    /// Runs the filter's epoch of the last time fed: every event released
    /// so far is earlier than any still to come.
    ///
    /// At the end of the stream (`end`) the epoch no later row closes is
    /// run too ([`Feeder::finish`]); before it, the wheel interval still
    /// open stays open ([`Feeder::settle`]).
    fn settle(&mut self, out: &mut dyn FnMut(Pose), end: bool) -> Result<(), Error> {
        let (fit, floor) = (self.bound, &mut self.floor);
        let mut emit = |p: TrackPoint| {
            let s = floor.std_at(p.t_s);
            out(Pose {
                point: p,
                bound_95_m: point_bound_m(&fit, &p, s),
            })
        };
        match &mut self.stage {
            Stage::Waiting { .. } => Ok(()),
            Stage::Learning { filter, feeder } => {
                feeder.run_waiting(end, filter.as_mut(), &mut |f, _| {
                    emit(car_point(f.time_s(), f.state(), f.covariance()))
                })
            }
            Stage::Aided(a) if end => {
                a.finish(&mut |e| emit(TrackPoint::from_state(e.t_s, &e.x, &e.p)))
            }
            Stage::Aided(a) => a.settle(&mut |e| emit(TrackPoint::from_state(e.t_s, &e.x, &e.p))),
        }
    }

    /// The filter's time, s (`None` before the start).
    pub fn time_s(&self) -> Option<f64> {
        match &self.stage {
            Stage::Waiting { .. } => None,
            Stage::Learning { filter, .. } => Some(filter.time_s()),
            Stage::Aided(a) => Some(a.time_s()),
        }
    }

    /// Counters so far (`None` before the start).
    pub fn stats(&self) -> Option<FilterStats> {
        match &self.stage {
            Stage::Waiting { .. } => None,
            Stage::Learning { filter, feeder } => Some(feeder.stats_with(filter.as_ref())),
            Stage::Aided(a) => Some(a.stats()),
        }
    }

    /// The learned parameters (`None` unless learning and started).
    pub fn learned(&self, targets: &LearnTargets) -> Option<Learned> {
        match &self.stage {
            Stage::Learning { filter, .. } => {
                Some(Learned::new(filter.params(), filter.params_std()?, targets))
            }
            _ => None,
        }
    }
}
