//! Fixed-interval RTS smoothing of the car states in O(√N) memory, for the
//! calibration's long drives.
//!
//! The forward pass keeps no epochs: every about √N epochs it keeps a
//! checkpoint (the step filter, its [`Feeder`] without the wheel monitor
//! and the position in the drive's events, all a few kilobytes). The
//! backward pass then takes the segments from the last to the first: it
//! re-runs the filter from the segment's checkpoint (the same events in the
//! same order, with the wheel monitor's verdicts that the forward pass
//! recorded, so the same epochs bit for bit) and smooths through them with
//! eq. (20) and (22), carrying the smoothed state and the first epoch of
//! the following segment across the boundary. The result equals
//! [`crate::rts::smooth_states`] over a recorded run exactly, at twice the
//! filter time and with memory for the output states, √N checkpoints and
//! four segments of epochs instead of every epoch (2.3 KB each with 11
//! states), the segments' length balancing the two (`segment_len`). The
//! re-runs go two at a time in parallel while the segments before them are
//! smoothed (the same numbers: each re-run is the forward pass's own
//! steps), so the backward pass takes about half the forward pass's wall
//! time more on two cores; a pass that already runs in parallel with others
//! (on one of rayon's workers: the held-back folds) re-runs its segments
//! one after the other through one buffer.

use std::sync::Arc;

use nalgebra::{Cholesky, SVector};

use crate::drive::Drive;
use crate::ekf::{self, DriveEvents, Epoch, Feeder, FilterOptions, FilterStats};
use crate::filter::{Filter, Layout};
use crate::model::State;
use crate::rts::{Smoothed, WanderStates};
use crate::wheel_health::Verdict;
use crate::Error;

/// Smallest segment length, epochs.
const MIN_SEGMENT: usize = 64;

/// The heap a checkpoint's feeder holds besides its own size, B: its
/// vectors (the first wheel intervals for the gap rule, the waiting
/// events). Measured: 0.31 MB for the 234 checkpoints of the two held-back
/// folds of `deadreckon calibrate` on `command_cost write DIR 3600`
/// (heaptrack, docs/performance.md, "Ninth round"), 1.3 KB each. Only
/// sets the segments' length ([`segment_len`]), which no number depends
/// on.
const FEEDER_HEAP_BYTES: usize = 1300;

/// The segment length, epochs, that holds the least memory in the
/// checkpoints and the re-run buffers together: `E` epochs in segments of
/// `s` keep about `E / s` checkpoints of `c` bytes and `k` buffers of `s`
/// epochs of `b` bytes, `E·c/s + k·s·b`, least at `s = √(E·c / (k·b))`
/// (then the two parts are equal). `k` is 1 on one of rayon's workers,
/// whose backward pass re-runs one segment at a time, and 4 on the
/// calling thread ([`backward`]). `E` is the wheel rows with the paper's
/// wheel epochs, every event with an epoch per measurement.
///
/// Until the ninth round of docs/performance.md the segments were √(events)
/// long (twice that on rayon's workers), when a checkpoint held a copy of
/// the wheel monitor's windows (about 63 KB on the bench's hour); with
/// its verdicts replayed a checkpoint is about the size of one epoch, and
/// the buffers were most of the memory (heaptrack of `deadreckon
/// calibrate` on `command_cost write DIR 3600`). The numbers do not
/// depend on the length: every segment re-runs the forward pass's own
/// steps (`held_back_parallel.rs` compares the pools' numbers bit for
/// bit; `tests/lean_passes.rs` and `tests/stream.rs` smoothing a recorded
/// run).
fn segment_len<L: Layout<N>, const N: usize>(drive: &Drive, opts: &FilterOptions) -> usize {
    let events = drive.wheels.len()
        + drive.yaw_rate.len()
        + drive.speed.len()
        + drive.steering.len()
        + drive.gnss.len();
    let epochs = match opts.timing {
        ekf::Timing::WheelEpochs => drive.wheels.len(),
        ekf::Timing::EachMeasurement => events,
    };
    let buffers = if rayon::current_thread_index().is_some() {
        1
    } else {
        4
    };
    let c = std::mem::size_of::<Checkpoint<'_, L, N>>() + FEEDER_HEAP_BYTES;
    let b = std::mem::size_of::<Epoch<N>>();
    let s = (epochs as f64 * c as f64 / (buffers * b) as f64).sqrt();
    (s as usize).max(MIN_SEGMENT)
}

struct Checkpoint<'a, L: Layout<N>, const N: usize> {
    filter: Filter<L, N>,
    /// The feeder without its wheel monitor ([`Feeder::resume_point`]).
    feeder: Feeder,
    events: DriveEvents<'a>,
    /// Epochs run before this checkpoint.
    epochs_before: usize,
}

/// What the forward pass keeps.
struct Forward<'a, L: Layout<N>, const N: usize> {
    /// A checkpoint every about √N epochs.
    cps: Vec<Checkpoint<'a, L, N>>,
    /// The number of epochs.
    total: usize,
    /// The filter's counters.
    stats: FilterStats,
    /// The wheel monitor's verdicts, which the re-runs replay.
    verdicts: Arc<[Verdict]>,
}

/// The forward pass: `f` run over `drive` keeping only a checkpoint every
/// about √N epochs.
fn forward<'a, L: Layout<N>, const N: usize>(
    drive: &'a Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
    standstill: bool,
) -> Result<Forward<'a, L, N>, Error> {
    let (feeder, events) = ekf::feed(drive, opts, f.time_s());
    // The aided filter's standstill (crate::standstill), as its run had it.
    let mut feeder = if standstill {
        feeder.with_standstill()
    } else {
        feeder
    };
    // The forward pass keeps no predictions; the re-runs do. It records
    // the wheel monitor's verdicts, which the re-runs replay.
    feeder.keep_predictions(false);
    feeder.record_verdicts();
    let segment = segment_len::<L, N>(drive, opts);

    let mut cps = vec![Checkpoint {
        filter: f.clone(),
        feeder: feeder.resume_point(),
        events: events.clone(),
        epochs_before: 0,
    }];
    let (mut f, mut feeder, mut events) = (f, feeder, events);
    let mut noop = |_: &mut Filter<L, N>, _: ekf::EpochOut<'_, N>| {};
    while let Some(ev) = events.next() {
        feeder.push(&mut f, ev, &mut noop)?;
        let n = feeder.stats().epochs;
        if n >= cps.last().map_or(0, |c| c.epochs_before) + segment {
            cps.push(Checkpoint {
                filter: f.clone(),
                feeder: feeder.resume_point(),
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
    Ok(Forward {
        cps,
        total,
        stats,
        verdicts: feeder.take_verdicts(),
    })
}

impl<L: Layout<N>, const N: usize> Checkpoint<'_, L, N> {
    /// Re-runs the filter from this checkpoint to epoch `end` (exclusive),
    /// recording the epochs into `buf` (cleared first), with the forward
    /// pass's wheel verdicts.
    fn rerun(
        &self,
        end: usize,
        verdicts: &Arc<[Verdict]>,
        buf: &mut Vec<Epoch<N>>,
    ) -> Result<(), Error> {
        let (mut f, mut feeder, mut events) = (
            self.filter.clone(),
            self.feeder.clone(),
            self.events.clone(),
        );
        feeder.keep_predictions(true);
        feeder.replay_verdicts(Arc::clone(verdicts));
        buf.clear();
        // The segment's epochs exactly: no doubled capacity to carry.
        buf.reserve_exact(end.saturating_sub(self.epochs_before));
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

/// The backward pass's segments from the last to the first: each re-run
/// from its checkpoint ([`Checkpoint::rerun`]) and handed to `visit` with
/// its index, in that order. Two segments are re-run at a time in parallel
/// (rayon), while `visit` smooths through the two before them: the same
/// epochs and the same order as one segment after the other (bit for bit),
/// in about half the wall time on two cores, with four segments' epochs in
/// memory instead of one. Called on one of rayon's workers (a pass already
/// running in parallel with others), the segments go one after the other
/// through one buffer: the threads are busy, and the four buffers were the
/// memory of nothing gained.
fn backward<'a, L: Layout<N>, const N: usize>(
    cps: &[Checkpoint<'a, L, N>],
    total: usize,
    verdicts: &Arc<[Verdict]>,
    mut visit: impl FnMut(usize, &mut Vec<Epoch<N>>) -> Result<(), Error> + Send,
) -> Result<(), Error>
where
    Checkpoint<'a, L, N>: Sync,
{
    let end_of = |j: usize| cps.get(j + 1).map_or(total, |c| c.epochs_before);
    // Already on one of rayon's workers (the held-back folds, the wander
    // fit's runs: passes in parallel with others), the pool's threads are
    // busy: the segments one after the other through one buffer, the same
    // epochs in the same order, with one segment's epochs in memory instead
    // of four (the default `calibrate`'s peak is two fold calibrations at
    // once: docs/performance.md, "Fifth round").
    if rayon::current_thread_index().is_some() {
        let mut buf = Vec::new();
        for j in (0..cps.len()).rev() {
            cps[j].rerun(end_of(j), verdicts, &mut buf)?;
            visit(j, &mut buf)?;
        }
        return Ok(());
    }
    // Segments `lo..hi` (at most two) re-run into `bufs`: `bufs[0]` takes
    // segment `hi − 1`, `bufs[1]` segment `hi − 2`.
    let rerun = |lo: usize, hi: usize, bufs: &mut [Vec<Epoch<N>>; 2]| -> Result<(), Error> {
        let [b1, b0] = bufs;
        match hi - lo {
            0 => Ok(()),
            1 => cps[lo].rerun(end_of(lo), verdicts, b1),
            _ => {
                let (r1, r0) = rayon::join(
                    || cps[hi - 1].rerun(end_of(hi - 1), verdicts, b1),
                    || cps[hi - 2].rerun(end_of(hi - 2), verdicts, b0),
                );
                r1.and(r0)
            }
        }
    };
    let (mut ready, mut spare) = ([Vec::new(), Vec::new()], [Vec::new(), Vec::new()]);
    let mut hi = cps.len();
    let mut lo = hi.saturating_sub(2);
    rerun(lo, hi, &mut ready)?;
    while hi > 0 {
        let (next_lo, next_hi) = (lo.saturating_sub(2), lo);
        let (visited, rerun_next) = rayon::join(
            || -> Result<(), Error> {
                visit(hi - 1, &mut ready[0])?;
                if hi - lo == 2 {
                    visit(hi - 2, &mut ready[1])?;
                }
                Ok(())
            },
            || rerun(next_lo, next_hi, &mut spare),
        );
        // The errors in the order one segment after the other meets them.
        visited?;
        rerun_next?;
        std::mem::swap(&mut ready, &mut spare);
        (lo, hi) = (next_lo, next_hi);
    }
    Ok(())
}

/// Runs `f` over `drive` and returns the smoothed car states `(t, x)` of every
/// epoch, with the filter's counters.
pub fn smooth_car_states<L: Layout<N> + Send + Sync, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<(Vec<(f64, State)>, FilterStats), Error> {
    let (t, x, stats) = smooth_car_columns(drive, f, opts)?;
    Ok((t.into_iter().zip(x).collect(), stats))
}

/// [`smooth_car_states`] as a column of times and one of states, s: what
/// [`crate::reference::Reference::from_states`] takes, without a third
/// copy of every epoch on the way (the calibration's passes; half the peak
/// memory of zipping and unzipping).
pub fn smooth_car_columns<L: Layout<N> + Send + Sync, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<(Vec<f64>, Vec<State>, FilterStats), Error> {
    let Forward {
        cps,
        total,
        stats,
        verdicts,
    } = forward(drive, f, opts, false)?;
    if total == 0 {
        return Ok((Vec::new(), Vec::new(), stats));
    }
    // Backward, segment by segment.
    let mut out_t = vec![0.0; total];
    let mut out_x = vec![State::zeros(); total];
    // The first epoch of the following segment and its smoothed state.
    let mut next: Option<(Epoch<N>, SVector<f64, N>)> = None;
    backward(&cps, total, &verdicts, |j, buf| {
        let end = cps.get(j + 1).map_or(total, |c| c.epochs_before);
        let before = cps[j].epochs_before;
        // The epoch after the segment's last and its smoothed state: the
        // following segment's first, or this segment's last itself.
        let (carried, mut x1) = match next.take() {
            None => {
                let last = buf.pop().expect("a segment has epochs");
                out_t[end - 1] = last.t_s;
                out_x[end - 1] = last.x.fixed_rows::<5>(0).into_owned();
                (last, last.x)
            }
            Some(n) => n,
        };
        // Eq. (20), (22) through the segment, from the boundary (the
        // following epoch read in place, not copied).
        for k in (0..buf.len()).rev() {
            let e = &buf[k];
            let e1 = buf.get(k + 1).unwrap_or(&carried);
            let chol = Cholesky::new(e1.p_pred).ok_or_else(|| Error::Numerical {
                t_s: e1.t_s,
                what: "predicted covariance is not positive definite".into(),
            })?;
            let u = chol.solve(&(x1 - e1.x_pred));
            let x = e.x + e.p * crate::rts::ft_times(&e1.f, &u);
            out_t[before + k] = e.t_s;
            out_x[before + k] = x.fixed_rows::<5>(0).into_owned();
            x1 = x;
        }
        next = Some((buf.first().copied().unwrap_or(carried), x1));
        Ok(())
    })?;
    Ok((out_t, out_x, stats))
}

/// Runs `f` over `drive` and returns the smoothed state and covariance of
/// its first epoch (`None`: no epoch), equal bit for bit to the first of
/// [`crate::rts::smooth`] over the recorded run ([`crate::rts::step`] through
/// every epoch, segment by segment), in O(√N) memory instead of every epoch
/// and every smoothed covariance.
pub fn smoothed_start<L: Layout<N> + Send + Sync, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
) -> Result<Option<Smoothed<N>>, Error> {
    let mut first = None;
    smooth_each(drive, f, opts, None, false, |s| first = Some(*s))?;
    Ok(first)
}

/// Runs `f` over `drive` and hands the smoothed state and covariance of
/// every epoch to `visit`, from the last epoch to the first: equal bit for
/// bit to [`crate::rts::smooth_carrying`] over the recorded run (the
/// receiver's wander smoothed with its `φ` where `wander` is given), in
/// O(√N) memory instead of every epoch (the smoothed track of `run` and of
/// the report: [`crate::aided::Aided::smoothed_each`]). Returns the number
/// of epochs. `standstill`: the filter's feeder takes the standstill's
/// `ψ̇ = 0` ([`crate::ekf::Feeder::with_standstill`]), as the GNSS-aided
/// filter's does.
pub fn smooth_each<L: Layout<N> + Send + Sync, const N: usize>(
    drive: &Drive,
    f: Filter<L, N>,
    opts: &FilterOptions,
    wander: Option<WanderStates>,
    standstill: bool,
    mut visit: impl FnMut(&Smoothed<N>) + Send,
) -> Result<usize, Error> {
    let Forward {
        cps,
        total,
        verdicts,
        ..
    } = forward(drive, f, opts, standstill)?;
    if total == 0 {
        return Ok(0);
    }
    // The first epoch of the following segment and its smoothed state.
    let mut next: Option<(Epoch<N>, Smoothed<N>)> = None;
    backward(&cps, total, &verdicts, |_, buf| {
        let (carried, mut s1) = match next.take() {
            Some(n) => n,
            None => {
                let last = buf.pop().ok_or_else(|| Error::Numerical {
                    t_s: f64::NAN,
                    what: "a smoothing segment re-ran no epoch".into(),
                })?;
                let s = Smoothed {
                    t_s: last.t_s,
                    x: last.x,
                    p: last.p,
                };
                visit(&s);
                (last, s)
            }
        };
        // The following epoch read in place, not copied.
        for k in (0..buf.len()).rev() {
            let (e, e1) = (&buf[k], buf.get(k + 1).unwrap_or(&carried));
            let phi = wander.map(|w| (w.index, w.wander.phi((e1.t_s - e.t_s).max(0.0))));
            s1 = crate::rts::step_with(e, e1, &s1, phi)?;
            visit(&s1);
        }
        next = Some((buf.first().copied().unwrap_or(carried), s1));
        Ok(())
    })?;
    Ok(total)
}
