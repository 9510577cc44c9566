//! The receiver's wander (σ, τ) estimated from a drive's own fixes.
//!
//! Each candidate receiver model — white fixes (the paper's), or the wander
//! of [`crate::gnss_error`] with a standard deviation from [`STD_GRID_M`]
//! and a time constant from [`TAU_GRID_S`] — runs the GNSS-aided filter over
//! the drive; the model whose fix innovations are the most likely wins. The
//! log-likelihood of a fix is the 2-D Gaussian's,
//! `−ln 2π − ½·ln det S − ½·min(yᵀS⁻¹y, g)`, with the NIS capped at the gate
//! `g` (`noise.gnss_gate_chi2`): a multipath burst costs every model the
//! same per rejected fix instead of favouring whichever model is loose
//! enough to swallow it. The differential-drive filter's fix model was
//! identified the same way
//! ([`crate::kinematics::diff_drive::filter::fix_log_likelihood`]).
//!
//! The fixes' own `std_m` stays their white noise: a receiver whose
//! reported accuracy already covers its wander is best described by white
//! fixes, and the fit says so.

use crate::drive::Drive;
use crate::ekf::{self, EpochOut, FilterOptions};
use crate::filter::{CarLayout, Filter, Layout, SensorKind};
use crate::gnss_error::{CarWanderLayout, Wander, N_WANDER};
use crate::vehicle::{Params, Vehicle};
use crate::{Error, Input, Task};
use rayon::prelude::*;

/// The wander standard deviations tried, m per axis.
pub const STD_GRID_M: [f64; 5] = [0.25, 0.5, 1.0, 1.5, 2.0];
/// The wander time constants tried, s.
pub const TAU_GRID_S: [f64; 3] = [30.0, 60.0, 120.0];

/// One candidate's fit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Candidate {
    /// The wander, `None` for white fixes.
    pub wander: Option<Wander>,
    /// Mean log-likelihood per fix.
    pub log_likelihood: f64,
    /// Fixes it averages.
    pub fixes: usize,
}

/// The fit: every candidate, and the most likely one.
#[derive(Debug, Clone, PartialEq)]
pub struct WanderFit {
    /// Every candidate, white fixes first.
    pub candidates: Vec<Candidate>,
    /// The most likely candidate's wander (`None`: white fixes).
    pub best: Option<Wander>,
}

/// Fits the receiver model to `drive`'s fixes with the parameters `params`
/// and the filter options `opts` (outage windows in them hide fixes from the
/// fit too). An error when the filter cannot run or sees no fix.
pub fn fit(drive: &Drive, params: &Params, opts: &FilterOptions) -> Result<WanderFit, Error> {
    let opts = FilterOptions {
        record_epochs: false,
        record_innovations: false,
        ..opts.clone()
    };
    // White fixes first, then the grid, τ by τ: each candidate its own
    // filter run, independent of the others, so they run in parallel
    // (rayon) and are collected in this order (the same numbers as one
    // after the other).
    let grid: Vec<Option<Wander>> = std::iter::once(None)
        .chain(TAU_GRID_S.iter().flat_map(|&tau_s| {
            STD_GRID_M
                .iter()
                .map(move |&std_m| Some(Wander { std_m, tau_s }))
        }))
        .collect();
    let candidates = grid
        .into_par_iter()
        .map(|w| match w {
            None => likelihood::<CarLayout, 5>(drive, &drive.vehicle, params, None, &opts, None),
            Some(w) => {
                let mut v = drive.vehicle.clone();
                v.noise.gnss_wander_std_m = w.std_m;
                v.noise.gnss_wander_tau_s = w.tau_s;
                likelihood::<CarWanderLayout, N_WANDER>(drive, &v, params, None, &opts, Some(w))
            }
        })
        .collect::<Vec<_>>()
        .into_iter()
        .collect::<Result<Vec<Candidate>, Error>>()?;
    if candidates[0].fixes == 0 {
        return Err(Error::needs(Task::WanderFit, Input::GnssFixAfterStart));
    }
    let best = candidates
        .iter()
        .max_by(|a, b| a.log_likelihood.total_cmp(&b.log_likelihood))
        .and_then(|c| c.wander);
    Ok(WanderFit { candidates, best })
}

/// The mean capped log-likelihood per fix of one receiver model (the
/// filter's parameter states, if it has any, start with `prior_std`).
pub(crate) fn likelihood<L: Layout<N>, const N: usize>(
    drive: &Drive,
    vehicle: &Vehicle,
    params: &Params,
    prior_std: Option<&Params>,
    opts: &FilterOptions,
    wander: Option<Wander>,
) -> Result<Candidate, Error> {
    let (t0, x0, p0) = ekf::start(drive, opts)?;
    let mut f = Filter::<L, N>::new(vehicle, params, prior_std, t0, x0, p0)?
        .with_covariance_form(opts.covariance_form);
    let gate = vehicle.noise.gnss_gate_chi2;
    let (mut feeder, events) = ekf::feed(drive, opts, f.time_s());
    let (mut sum, mut n) = (0.0, 0usize);
    let mut add = |_: &mut Filter<L, N>, e: EpochOut<'_, N>| {
        for u in e.updates.iter().filter(|u| u.sensor == SensorKind::Gnss) {
            sum += -(2.0 * std::f64::consts::PI).ln() - 0.5 * u.ln_det_s - 0.5 * u.nis.min(gate);
            n += 1;
        }
    };
    let end = opts.end_s.unwrap_or(f64::INFINITY);
    for ev in events.take_while(|e| e.t_s <= end) {
        feeder.push(&mut f, ev, &mut add)?;
    }
    feeder.finish(&mut f, &mut add)?;
    Ok(Candidate {
        wander,
        log_likelihood: if n > 0 { sum / n as f64 } else { f64::NAN },
        fixes: n,
    })
}
