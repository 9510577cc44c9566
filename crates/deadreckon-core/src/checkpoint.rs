//! Fixed-interval RTS smoothing of the car states in O(√N) memory, for the
//! calibration's long drives.
//!
//! The forward pass keeps no epochs: every about √N epochs it keeps a
//! checkpoint (the step filter, its [`Feeder`] and the position in the drive's
//! events, all a few kilobytes). The backward pass then takes the segments from
//! the last to the first: it re-runs the filter from the segment's checkpoint
//! (the same events in the same order, so the same epochs bit for bit) and
//! smooths through them with eq. (20) and (22), carrying the smoothed state and
//! the first epoch of the following segment across the boundary. The result
//! equals [`crate::rts::smooth_states`] over a recorded run exactly, at twice
//! the filter time and with memory for the output states, √N checkpoints and
//! one segment of epochs instead of every epoch (2.3 KB each with 11 states).

use nalgebra::{Cholesky, SVector};

use crate::drive::Drive;
use crate::ekf::{self, DriveEvents, Epoch, Feeder, FilterOptions, FilterStats};
use crate::filter::{Filter, Layout};
use crate::model::State;
use crate::rts::Smoothed;
use crate::Error;

/// Smallest segment length, epochs.
const MIN_SEGMENT: usize = 64;

struct Checkpoint<'a, L: Layout<N>, const N: usize> {
    filter: Filter<L, N>,
    feeder: Feeder,
    events: DriveEvents<'a>,
    /// Epochs run before this checkpoint.
    epochs_before: usize,
}

/// The forward pass: `f` run over `drive` keeping only a checkpoint every
/// about √N epochs. Returns the checkpoints, the number of epochs and the
/// filter's counters.
fn forward<'a, L: Layout<N>, const N: usize>(
    drive: &'a Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<(Vec<Checkpoint<'a, L, N>>, usize, FilterStats), Error> {
    let (mut feeder, events) = ekf::feed(drive, opts, f.time_s());
    // The forward pass keeps no predictions; the re-runs do.
    feeder.keep_predictions(false);
    let total_events = drive.wheels.len()
        + drive.yaw_rate.len()
        + drive.speed.len()
        + drive.steering.len()
        + drive.gnss.len();
    let segment = ((total_events as f64).sqrt() as usize).max(MIN_SEGMENT);

    let mut cps = vec![Checkpoint {
        filter: f.clone(),
        feeder: feeder.clone(),
        events: events.clone(),
        epochs_before: 0,
    }];
    let (mut f, mut feeder, mut events) = (f, feeder, events);
    let mut noop = |_: &mut Filter<L, N>, _: ekf::EpochOut<'_, N>| {};
    while let Some(ev) = events.next() {
        feeder.push(&mut f, ev, &mut noop)?;
        let n = feeder.stats().epochs;
        if n >= cps.last().map_or(0, |c| c.epochs_before) + segment {
            // An epoch held for the next wheel row (`ekf::WheelRows::Interval`)
            // is handed out by the re-run, which needs its prediction: the
            // checkpoint waits until the held epoch has one.
            match feeder.holds_epoch() {
                Some(false) => {
                    feeder.keep_predictions(true);
                    continue;
                }
                Some(true) => feeder.keep_predictions(false),
                None => {}
            }
            cps.push(Checkpoint {
                filter: f.clone(),
                feeder: feeder.clone(),
                events: events.clone(),
                epochs_before: n,
            });
        }
    }
    feeder.finish(&mut f, &mut noop)?;
    let total = feeder.stats().epochs;
    let stats = feeder.stats_with(&f);
    if cps.last().is_some_and(|c| c.epochs_before == total) && cps.len() > 1 {
        cps.pop();
    }
    Ok((cps, total, stats))
}

impl<L: Layout<N>, const N: usize> Checkpoint<'_, L, N> {
    /// Re-runs the filter from this checkpoint to epoch `end` (exclusive),
    /// recording the epochs into `buf` (cleared first).
    fn rerun(&self, end: usize, buf: &mut Vec<Epoch<N>>) -> Result<(), Error> {
        let (mut f, mut feeder, mut events) = (
            self.filter.clone(),
            self.feeder.clone(),
            self.events.clone(),
        );
        feeder.keep_predictions(true);
        buf.clear();
        let mut record = |f: &mut Filter<L, N>, e: ekf::EpochOut<'_, N>| {
            if let Some(prediction) = e.prediction {
                buf.push(Epoch::after(f, prediction));
            }
        };
        while feeder.stats().epochs < end {
            match events.next() {
                Some(ev) => feeder.push(&mut f, ev, &mut record)?,
                None => {
                    feeder.finish(&mut f, &mut record)?;
                    break;
                }
            }
        }
        if self.epochs_before + buf.len() != end {
            return Err(Error::Numerical {
                t_s: f.time_s(),
                what: "the re-run of a smoothing segment did not reproduce the forward pass".into(),
            });
        }
        Ok(())
    }
}

/// Runs `f` over `drive` and returns the smoothed car states `(t, x)` of every
/// epoch, with the filter's counters.
pub fn smooth_car_states<L: Layout<N>, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<(Vec<(f64, State)>, FilterStats), Error> {
    let (cps, total, stats) = forward(drive, f, opts)?;
    if total == 0 {
        return Ok((Vec::new(), stats));
    }
    // Backward, segment by segment.
    let mut out = vec![(0.0, State::zeros()); total];
    // The first epoch of the following segment and its smoothed state.
    let mut next: Option<(Epoch<N>, SVector<f64, N>)> = None;
    let mut buf: Vec<Epoch<N>> = Vec::new();
    for j in (0..cps.len()).rev() {
        let end = cps.get(j + 1).map_or(total, |c| c.epochs_before);
        let cp = &cps[j];
        cp.rerun(end, &mut buf)?;
        // Eq. (20), (22) through the segment, from the boundary.
        let mut s1 = match &next {
            None => {
                let last = buf[buf.len() - 1];
                out[end - 1] = (last.t_s, last.x.fixed_rows::<5>(0).into_owned());
                buf.pop();
                (last, last.x)
            }
            Some(n) => *n,
        };
        for k in (0..buf.len()).rev() {
            let (e, e1) = (&buf[k], &s1.0);
            let chol = Cholesky::new(e1.p_pred).ok_or_else(|| Error::Numerical {
                t_s: e1.t_s,
                what: "predicted covariance is not positive definite".into(),
            })?;
            let u = chol.solve(&(s1.1 - e1.x_pred));
            let x = e.x + e.p * crate::rts::ft_times(&e1.f, &u);
            out[cp.epochs_before + k] = (e.t_s, x.fixed_rows::<5>(0).into_owned());
            s1 = (*e, x);
        }
        next = Some(s1);
    }
    Ok((out, stats))
}

/// Runs `f` over `drive` and returns the smoothed state and covariance of
/// its first epoch (`None`: no epoch), equal bit for bit to the first of
/// [`crate::rts::smooth`] over the recorded run ([`crate::rts::step`] through
/// every epoch, segment by segment), in O(√N) memory instead of every epoch
/// and every smoothed covariance.
pub fn smoothed_start<L: Layout<N>, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<Option<Smoothed<N>>, Error> {
    let (cps, total, _) = forward(drive, f, opts)?;
    if total == 0 {
        return Ok(None);
    }
    // The first epoch of the following segment and its smoothed state.
    let mut next: Option<(Epoch<N>, Smoothed<N>)> = None;
    let mut buf: Vec<Epoch<N>> = Vec::new();
    for j in (0..cps.len()).rev() {
        let end = cps.get(j + 1).map_or(total, |c| c.epochs_before);
        cps[j].rerun(end, &mut buf)?;
        let mut s1 = match next {
            None => {
                let last = buf.pop().expect("a segment has epochs");
                let s = Smoothed {
                    t_s: last.t_s,
                    x: last.x,
                    p: last.p,
                };
                (last, s)
            }
            Some(n) => n,
        };
        for k in (0..buf.len()).rev() {
            let s = crate::rts::step(&buf[k], &s1.0, &s1.1)?;
            s1 = (buf[k], s);
        }
        next = Some(s1);
    }
    Ok(next.map(|(_, s)| s))
}
