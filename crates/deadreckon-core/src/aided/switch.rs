//! The gyro-bias switch: the aided filter with the calibrated constant bias
//! and with the bias as a state side by side, until the drive's own fixes
//! say the state is the better model (issue 28).
//!
//! Both hypotheses take every event. At each GNSS fix each predicts the fix
//! from the fixes before it only, and the switch adds up the log-likelihood
//! ratio of the state over the constant, one fix ahead, each fix's
//! log-likelihood capped at the GNSS gate as [`crate::wander_fit`] scores a
//! receiver model:
//!
//! ```text
//! Λ_k = Σ_{i≤k} ℓ_state(z_i | z_<i) − ℓ_constant(z_i | z_<i),
//! ℓ(z | ·) = −ln 2π − ½·ln det S − ½·min(yᵀS⁻¹y, g)
//! ```
//!
//! Until `Λ` reaches `[noise] gyro_bias_switch_llr` the output (each epoch's
//! state, the state an outage's dead reckoning starts from, the covariance
//! the error bound is made of) is the constant hypothesis's; from the fix
//! at which it does, the state hypothesis's, for the rest of the drive (the
//! constant one is dropped). A switch happens only at a fix, so never
//! during an outage; it is causal, so a stream switches where the batch
//! run does. Dead reckoning without a switch goes on with the constant
//! hypothesis alone.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use super::{AidedEpoch, EpochUpdates, Observe, Run};
use crate::drive::Drive;
use crate::ekf::{EpochOut, Event, FilterOptions, FilterStats};
use crate::filter::{Filter, GateCounts, Layout, SensorKind, Update};
use crate::model::{Mat, State};
use crate::Error;

pub use crate::gyro_switch_defaults::{DEFAULT_DRIVE_STD_RPS, DEFAULT_THRESHOLD_LLR};

/// What the gyro-bias switch has seen: its threshold, the ratio so far and
/// when it fired.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BiasSwitch {
    /// The log-likelihood ratio at which it fires (`[noise] gyro_bias_switch_llr`).
    pub threshold: f64,
    /// The log-likelihood ratio of the bias as a state over the constant,
    /// one fix ahead, summed over the fixes compared (at the switch once
    /// it fired: it stops counting then).
    pub llr: f64,
    /// Fixes compared.
    pub fixes: usize,
    /// The time of the fix at which the state hypothesis took over, s
    /// (`None`: the constant bias throughout).
    pub fired_at_s: Option<f64>,
}

/// What the switch did, in words (`run`'s and `evaluate --outage`'s line).
impl std::fmt::Display for BiasSwitch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (llr, n, t) = (self.llr, self.fixes, self.threshold);
        match self.fired_at_s {
            Some(at) => write!(
                f,
                "gyro-bias switch: fired at {at:.2} s (the fixes favoured the bias as a state by a \
                 log-likelihood ratio of {llr:.2} over {n} fixes, threshold {t}): its state from \
                 then on"
            ),
            None => write!(
                f,
                "gyro-bias switch: not fired (log-likelihood ratio {llr:.2} over {n} fixes, \
                 threshold {t}): the calibrated constant bias throughout"
            ),
        }
    }
}

/// The two hypotheses of layouts `C` (constant bias) and `S` (bias as a
/// state) and the switch between them. At least one hypothesis runs: both
/// before the switch, then the state's alone, or the constant's alone when
/// dead-reckoning before any switch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Switch<C: Layout<NC>, const NC: usize, S: Layout<NS>, const NS: usize> {
    /// The constant bias (`None` once switched).
    constant: Option<Box<Run<C, NC>>>,
    /// The bias as a state (`None` once dead-reckoning without a switch).
    state: Option<Box<Run<S, NS>>>,
    report: BiasSwitch,
    /// The fix log-likelihood's cap (the GNSS gate).
    cap: f64,
}

/// An epoch of the state hypothesis waiting to be paired with the
/// constant's ([`Switch::push`]).
struct Waiting {
    t_s: f64,
    /// The capped log-likelihood of its fixes, and how many.
    log_likelihood: (f64, usize),
    epoch: AidedEpoch,
    /// Its updates' range in the step's buffer.
    updates: std::ops::Range<usize>,
    gated_fix_t_s: Option<f64>,
}

/// The capped log-likelihood of the GNSS fixes of one epoch, and how many.
fn fix_log_likelihood<const N: usize>(e: &EpochOut<'_, N>, cap: f64) -> (f64, usize) {
    e.updates
        .iter()
        .filter(|u| u.sensor == SensorKind::Gnss)
        .fold((0.0, 0), |(s, n), u| {
            (
                s - (2.0 * std::f64::consts::PI).ln() - 0.5 * u.ln_det_s - 0.5 * u.nis.min(cap),
                n + 1,
            )
        })
}

impl<C: Layout<NC>, const NC: usize, S: Layout<NS>, const NS: usize> Switch<C, NC, S, NS> {
    pub(super) fn new(constant: Run<C, NC>, state: Run<S, NS>, threshold: f64) -> Self {
        let cap = constant.filter.noise().gnss_gate_chi2;
        Switch {
            constant: Some(Box::new(constant)),
            state: Some(Box::new(state)),
            report: BiasSwitch {
                threshold,
                llr: 0.0,
                fixes: 0,
                fired_at_s: None,
            },
            cap,
        }
    }

    /// What the switch has seen so far.
    pub fn report(&self) -> BiasSwitch {
        self.report
    }

    /// Feeds one event to both hypotheses; `epoch` after every epoch with
    /// the chosen one's state and updates.
    pub(super) fn push(&mut self, ev: Event, epoch: &mut Observe<'_>) -> Result<(), Error> {
        self.step(Some(ev), false, epoch)
    }

    /// Runs what is waiting in both (at the end of the stream: `end`).
    pub(super) fn finish(&mut self, end: bool, epoch: &mut Observe<'_>) -> Result<(), Error> {
        self.step(None, end, epoch)
    }

    /// [`Switch::push`] (`Some`) or [`Switch::finish`] (`None`).
    fn step(&mut self, ev: Option<Event>, end: bool, epoch: &mut Observe<'_>) -> Result<(), Error> {
        let (c, s) = match (&mut self.constant, &mut self.state) {
            (Some(c), Some(s)) => (c, s),
            (Some(c), None) => {
                return match ev {
                    Some(ev) => c.push(ev, epoch),
                    None => c.finish(end, epoch),
                }
            }
            (None, Some(s)) => {
                return match ev {
                    Some(ev) => s.push(ev, epoch),
                    None => s.finish(end, epoch),
                }
            }
            (None, None) => return Ok(()),
        };
        // The state hypothesis's epochs wait to be paired with the
        // constant's (both run the same epochs), their updates in one
        // buffer (handed out with the state's epoch once it fired).
        let cap = self.cap;
        let mut waiting: VecDeque<Waiting> = VecDeque::new();
        let mut updates: Vec<Update> = Vec::new();
        let mut keep = |f: &Filter<S, NS>, e: &EpochOut<'_, NS>| {
            let at = updates.len();
            updates.extend_from_slice(e.updates);
            waiting.push_back(Waiting {
                t_s: f.time_s(),
                log_likelihood: fix_log_likelihood(e, cap),
                epoch: AidedEpoch::of(f),
                updates: at..updates.len(),
                gated_fix_t_s: e.gated_fix_t_s,
            })
        };
        match ev {
            Some(ev) => s.push_raw(ev, &mut keep)?,
            None => s.finish_raw(end, &mut keep)?,
        }
        let report = &mut self.report;
        let mut pair = |f: &Filter<C, NC>, e: &EpochOut<'_, NC>| {
            let t = f.time_s();
            let other = waiting.pop_front().filter(|w| w.t_s == t);
            if report.fired_at_s.is_none() {
                let (lc, nc) = fix_log_likelihood(e, cap);
                if let Some((ls, ns)) = other.as_ref().map(|w| w.log_likelihood) {
                    if nc > 0 && ns == nc {
                        report.llr += ls - lc;
                        report.fixes += nc;
                        if report.llr >= report.threshold {
                            report.fired_at_s = Some(t);
                        }
                    }
                }
            }
            match (report.fired_at_s, other) {
                (Some(_), Some(chosen)) => epoch(
                    &chosen.epoch,
                    &EpochUpdates {
                        updates: &updates[chosen.updates],
                        gated_fix_t_s: chosen.gated_fix_t_s,
                    },
                ),
                _ => epoch(&AidedEpoch::of(f), &EpochUpdates::of(e)),
            }
        };
        match ev {
            Some(ev) => c.push_raw(ev, &mut pair)?,
            None => c.finish_raw(end, &mut pair)?,
        }
        if self.report.fired_at_s.is_some() {
            self.constant = None;
        }
        Ok(())
    }

    /// From now on no GNSS: the chosen hypothesis dead-reckons alone (no
    /// fix can switch it).
    pub(super) fn dead_reckon(&mut self) {
        if self.constant.is_some() {
            self.state = None;
        }
        if let Some(c) = &mut self.constant {
            c.dead_reckon();
        }
        if let Some(s) = &mut self.state {
            s.dead_reckon();
        }
    }

    /// `on_constant` or `on_state` of the hypothesis whose output is
    /// handed out (`None` only if neither runs, which the transitions
    /// above never leave).
    fn chosen<T>(
        &self,
        on_constant: impl FnOnce(&Run<C, NC>) -> T,
        on_state: impl FnOnce(&Run<S, NS>) -> T,
    ) -> Option<T> {
        match (&self.constant, &self.state) {
            (Some(c), _) => Some(on_constant(c)),
            (None, Some(s)) => Some(on_state(s)),
            (None, None) => None,
        }
    }

    pub(super) fn time_s(&self) -> f64 {
        self.chosen(|c| c.time_s(), |s| s.time_s())
            .unwrap_or(f64::NAN)
    }

    pub(super) fn now(&self) -> Option<AidedEpoch> {
        self.chosen(|c| c.now(), |s| s.now()).flatten()
    }

    pub(super) fn gates(&self) -> GateCounts {
        self.chosen(|c| c.gates(), |s| s.gates())
            .unwrap_or_default()
    }

    pub(super) fn stats(&self) -> FilterStats {
        self.chosen(|c| c.stats(), |s| s.stats())
            .unwrap_or_default()
    }

    /// The smoothed car blocks of the hypothesis the drive ended with
    /// ([`super::Aided::smoothed_each`]), run again from `fresh`: this
    /// switch as it started.
    pub(super) fn smooth_each(
        &self,
        fresh: &Self,
        drive: &Drive,
        opts: &FilterOptions,
        visit: &mut (dyn FnMut(f64, &State, &Mat) + Send),
    ) -> Result<usize, Error>
    where
        C: Send + Sync,
        S: Send + Sync,
    {
        match (&self.constant, &self.state, &fresh.constant, &fresh.state) {
            (Some(_), _, Some(c), _) => c.smooth_each(drive, opts, visit),
            (None, Some(_), _, Some(s)) => s.smooth_each(drive, opts, visit),
            _ => Err(Error::Numerical {
                t_s: self.time_s(),
                what: "the gyro-bias switch has no hypothesis to smooth".into(),
            }),
        }
    }
}
