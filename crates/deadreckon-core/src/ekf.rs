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

use crate::drive::{Drive, Wheels};
use crate::filter::{AugmentedLayout, CarLayout, Filter, Layout};
use crate::model::{Mat, State};
use crate::vehicle::Params;
use crate::wheel_health::WheelHealth;
use crate::Error;

mod feeder;
mod options;
mod output;

pub use crate::event::{DriveEvents, Event, Measurement};
pub use crate::filter::{GateCounts, SensorKind, Update, AUG_BIAS, AUG_INV_CIRC, AUG_SCALE, N_AUG};
pub use crate::init::{initial_state, truth_state, GnssInit};
pub use feeder::{EpochOut, Feeder};
pub use options::{FilterOptions, Init, SensorSet, Timing, WheelRows};
pub use output::{Epoch, EpochHook, FilterOutput, FilterStats, InnovationRecord};

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
        return Err(Error::needs(
            crate::Task::Filter,
            crate::Input::WheelEpochsAfterStart,
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
        Feeder::new(opts, &drive.vehicle, t0_s),
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
        out.gnss_gated
            .extend(e.gated_fix_t_s.and_then(|t| fix_index(drive, t)));
        if opts.record_innovations {
            out.innovations.extend(
                e.updates
                    .iter()
                    .map(|u| InnovationRecord::of(f.time_s(), u)),
            );
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

/// The index in `drive.gnss` of the fix at `t_s` (fix times are strictly
/// increasing in a valid drive: the time is the fix's key).
pub(crate) fn fix_index(drive: &Drive, t_s: f64) -> Option<usize> {
    let i = drive.gnss.partition_point(|g| g.t_s < t_s);
    drive.gnss.get(i).is_some_and(|g| g.t_s == t_s).then_some(i)
}

/// The wheel-health monitor's report ([`crate::wheel_health`]) of one run of the 5-state filter over `drive` with
/// `params` and `opts` (the monitor's settings from `opts.wheel_monitor`, the
/// defaults when it has none).
pub fn check_wheels(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<WheelHealth, Error> {
    let opts = FilterOptions {
        wheel_monitor: Some(opts.wheel_monitor.unwrap_or_default()),
        record_epochs: false,
        // Only the monitor's report is returned: innovations recorded here
        // were thrown away (73 MB on the hour's report, issue 30).
        record_innovations: false,
        ..opts.clone()
    };
    let out = run(drive, params, &opts, &mut ())?;
    Ok(out.wheel_health.unwrap_or_default())
}
