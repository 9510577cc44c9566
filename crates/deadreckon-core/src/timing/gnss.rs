//! The GNSS delay: the least squares between the fixes and the
//! dead-reckoned track ([`gnss_delay`], [`regress_gnss`]).

use super::scalar::status_of;
use super::{jackknife_std, lag1, Delay, DelayOptions};
use crate::calibrate::{self, CalibrationOptions};
use crate::drive::Drive;
use crate::ekf::{self, FilterOptions, Init, SensorSet, WheelRows};
use crate::model::{V, X, Y, YAW, YAW_RATE};
use crate::reference::Reference;
use crate::{Error, Params};

/// The GNSS delay's steps stop once a step would move it by less than this
/// fraction of its standard error (issue 30: each step is a calibration).
pub const GNSS_SETTLED_FRACTION_OF_STD: f64 = 0.1;

/// How the GNSS delay's dead-reckoned reference uses the wheel rows,
/// whichever step the calibrating filter takes: each row over the interval
/// it describes ([`WheelRows::Interval`]), with the gyro's and the CAN
/// speed's readings stamped inside that interval. With the paper's step
/// ([`WheelRows::Instant`], the filter's default) the reference carries the
/// previous interval's speed, its positions trail by about a wheel period
/// while the speed changes, and the fixes read that as a negative receiver
/// delay (issues 28 and 29: −29, −16 and −9 ms at 25, 50 and 100 Hz on
/// family car 1 with a true delay of 0); with the readings taken into the
/// interval after theirs, the CAN speed, which outweighs 48-tooth tick
/// counts, did the same (the evaluation scenario: −21.7, −16.8 and
/// −10.1 ms; `tests/gnss_delay_family.rs`). The delay estimated is the
/// receiver's.
pub const REFERENCE_WHEEL_ROWS: WheelRows = WheelRows::Interval;

/// The GNSS delay against the smoothed track, calibrating with `copts` at
/// each step (see the module documentation). `params` (the calibration's
/// result at the final delay) is returned with it.
pub fn gnss_delay(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delay, Option<Params>), Error> {
    gnss_delay_of(&mut drive.clone(), copts, o, [0.0; 3])
}

/// [`gnss_delay`] of a drive it may change: its fixes are moved to each
/// step's delay in place (one copy of the drive, not one per step).
/// `filter_view_s`: the delays the filter's gyro, CAN speed and steering are
/// moved by, minus those `shifted`'s were moved by, for the step offset
/// ([`Delay::step_offset_s`]).
pub(super) fn gnss_delay_of(
    shifted: &mut Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    filter_view_s: [f64; 3],
) -> Result<(Delay, Option<Params>), Error> {
    let drive = &*shifted;
    if drive.gnss.len() < o.min_samples {
        return Ok((
            Delay::not_estimated(format!(
                "{} GNSS fixes, need {}",
                drive.gnss.len(),
                o.min_samples
            )),
            None,
        ));
    }
    let lever = drive.vehicle.gnss_lever_arm_m;
    // The fixes' own times and the vehicle, which each step starts from.
    let fix_times: Vec<f64> = drive.gnss.iter().map(|g| g.t_s).collect();
    let vehicle = drive.vehicle.clone();
    let mut d = 0.0;
    let mut last = None;
    let mut prev: Option<(f64, f64)> = None;
    for _ in 0..o.gnss_iterations.max(1) {
        // As `shift(drive, [0, 0, 0, d])`, in place.
        for (g, &t) in shifted.gnss.iter_mut().zip(&fix_times) {
            g.t_s = t - d;
        }
        shifted.vehicle = vehicle.clone();
        // The parameters only: the wheel health, the manoeuvres, the side
        // slip and the steering are not read here.
        // Each step's calibration starts from the step before's parameters
        // (the drive differs only in the fixes' times by a few ms): one
        // pass instead of two on the bench's 10-minute drive (issue 30).
        let step_opts = match &last {
            Some((_, _, p, _)) => CalibrationOptions {
                initial: Some(*p),
                ..copts.clone()
            },
            None => copts.clone(),
        };
        let cal = calibrate::calibrate_parameters(shifted, &step_opts)?;
        let params = cal.estimate.params;
        // Only the smoothed start is used: smoothed in O(√N) memory
        // (checkpointed re-runs), equal to the first of `rts::smooth` over
        // the recorded run.
        let fopts = FilterOptions {
            record_epochs: true,
            ..copts.filter.clone()
        };
        let s0 = crate::checkpoint::smoothed_start(
            shifted,
            ekf::car_filter(shifted, &params, &fopts)?,
            &fopts,
        )?;
        // Dead reckoning (no GNSS) from the smoothed start: a reference the
        // fixes' timing cannot pull along, its drift taken out per window.
        let Some(s0) = s0 else {
            return Ok((Delay::not_estimated("no smoothed track"), None));
        };
        // The reference integrates the yaw with eq. 3's Euler step, exact
        // for rates held over each wheel interval, as the reference's rows
        // and readings are ([`REFERENCE_WHEEL_ROWS`]). (The trapezoid, which
        // moves the yaw by half a step of each yaw-rate update, made up for
        // the gyro's readings arriving one interval late before they were
        // taken into their own interval; with them there, it turned the
        // heading half a step early: family car 1, wheel speeds at 25, 50
        // and 100 Hz, 0.03 m fixes, no delay: +5.2 ± 3.7, +2.7 ± 1.9 and
        // +1.4 ± 1.1 ms, with Euler −0.9 ± 0.5, −0.3 ± 0.5, −0.1 ± 0.5 ms.)
        // (The calibration and the smoothing above are done with `shifted`;
        // only its fixes are read below.)
        let dr_opts = FilterOptions {
            record_epochs: true,
            init: Init::Given {
                t_s: s0.t_s,
                x: s0.x,
                p: s0.p,
            },
            sensors: SensorSet::dead_reckoning(),
            ..copts.filter.clone()
        };
        let reference = states_at_fixes(
            shifted,
            &params,
            &FilterOptions {
                wheel_rows: REFERENCE_WHEEL_ROWS,
                ..dr_opts.clone()
            },
        )?;
        let Some((delta, std, n)) = regress_gnss(&shifted.gnss, &reference, lever, o.gnss_window_s)
        else {
            return Ok((
                Delay::not_estimated(
                    "too few fixes inside the smoothed track, or no velocity change",
                ),
                None,
            ));
        };
        // The step under-corrects by the part of the error the smoother
        // absorbed: δ(d) ≈ (1 − α)(d* − d). Secant steps on δ(d) = 0
        // converge in a few passes; the standard error of d* is that of δ
        // divided by the slope (1 − α).
        let slope = match prev {
            Some((dp, fp)) if (d - dp).abs() > 1e-9 => {
                let s = (delta - fp) / (d - dp);
                (s < -0.05 && s > -2.0).then_some(s)
            }
            _ => None,
        };
        prev = Some((d, delta));
        let (next, scale) = match slope {
            Some(s) => (d - delta / s, -1.0 / s),
            None => (d + delta, 1.0),
        };
        last = Some((std * scale, n, params, dr_opts));
        // Settled: the next step would move the delay by less than a tenth
        // of its standard error (on the simulated evaluation drive, seed 25,
        // the steps cycled through −19.55, −19.17, −19.86, −19.51 ms with a
        // standard error of 6.1 ms until the cap of `gnss_iterations`).
        if delta.abs() < 1e-4 || (next - d).abs() < GNSS_SETTLED_FRACTION_OF_STD * std * scale {
            break;
        }
        d = next;
        if d.abs() > o.max_delay_s {
            break;
        }
    }
    let Some((std, n, params, dr_opts)) = last else {
        return Ok((Delay::not_estimated("no step"), None));
    };
    let mut delay = status_of(d, std, n, o);
    if delay.status.is_estimated() && o.gnss_step_offset {
        delay.step_offset_s = step_offset_s(
            shifted,
            &params,
            &dr_opts,
            filter_view_s,
            lever,
            o.gnss_window_s,
            std,
        );
    }
    let params = delay.status.is_estimated().then_some(params);
    Ok((delay, params))
}

/// What the filter's own dead reckoning adds to the receiver's delay: the
/// fixes (at the receiver's delay) regressed against the dead reckoning
/// with the filter's wheel step (`opts.wheel_rows`) and its scalar streams
/// moved by `filter_view_s` more, as the filter's are; the fixes moved by
/// each regression's `δ` (the reference is not recalibrated, so nothing
/// absorbs part of it: the slope is 1) until a step moves them by less than
/// [`GNSS_SETTLED_FRACTION_OF_STD`] of `std_s` (at most
/// [`STEP_OFFSET_ITERATIONS`] passes).
/// Returns the offset, 0 when nothing differs from the reference or the
/// regression fails. `drive` is moved and moved back.
///
/// The paper's step trails by about a wheel period while the speed changes,
/// and its scalar streams are moved by delays that read half a wheel period
/// early ([`super::on_true_time`]). On the comma2k19 segment (`evaluate
/// --outage 20 --step 5`) the receiver's delay, 0.0977 s, applied gave
/// 0.637 / 0.697 m mean / median, and the delay the filter's dead
/// reckoning matches, 0.0856 s (the estimate before issue 29), 0.593 /
/// 0.613 m (the same calibration, only the applied delay changed).
fn step_offset_s(
    drive: &mut Drive,
    params: &Params,
    opts: &FilterOptions,
    filter_view_s: [f64; 3],
    lever_m: f64,
    window_s: f64,
    std_s: f64,
) -> f64 {
    if opts.wheel_rows_for(&drive.vehicle) == REFERENCE_WHEEL_ROWS && filter_view_s == [0.0; 3] {
        return 0.0;
    }
    let [g, sp, st] = filter_view_s;
    super::shift_in_place(drive, [g, sp, st, 0.0]);
    let mut offset = 0.0;
    for _ in 0..STEP_OFFSET_ITERATIONS {
        let Ok(reference) = states_at_fixes(drive, params, opts) else {
            break;
        };
        let Some((delta, _, _)) = regress_gnss(&drive.gnss, &reference, lever_m, window_s) else {
            break;
        };
        let step = delta;
        offset += step;
        super::shift_in_place(drive, [0.0, 0.0, 0.0, step]);
        if step.abs() < GNSS_SETTLED_FRACTION_OF_STD * std_s {
            break;
        }
    }
    super::shift_in_place(drive, [-g, -sp, -st, -offset]);
    offset
}

/// At most this many dead-reckoning passes for the step offset (each one
/// filter run without GNSS; not tuned: the comma2k19 segment and the
/// evaluation drive settle in two or three).
pub const STEP_OFFSET_ITERATIONS: usize = 4;

/// The car filter run over `drive` with `opts`, its states interpolated at
/// the GNSS fixes' times inside its span as [`Reference::state_at`] would
/// interpolate the recorded epochs (linear between the epochs around each
/// fix; the last epoch's state at its own time), as the reference of the
/// fixes' times only: the epochs stream past, none is kept.
pub fn states_at_fixes(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<Reference, Error> {
    let mut f = ekf::car_filter(drive, params, opts)?;
    let (mut feeder, events) = ekf::feed(drive, opts, f.time_s());
    let fixes = &drive.gnss;
    let (mut t_out, mut x_out) = (Vec::new(), Vec::new());
    // The next fix not yet placed, and the previous epoch.
    let mut next = 0;
    let mut prev: Option<(f64, crate::model::State)> = None;
    let mut epoch = |f: &mut crate::filter::Filter<crate::filter::CarLayout, 5>,
                     e: ekf::EpochOut<'_, 5>| {
        if e.prediction.is_none() {
            return;
        }
        let (t1, x1) = (f.time_s(), *f.state());
        match prev {
            // Fixes before the first epoch are outside the span.
            None => {
                while next < fixes.len() && fixes[next].t_s < t1 {
                    next += 1;
                }
            }
            // Fixes in [t0, t1): between the two epochs.
            Some((t0, x0)) => {
                while next < fixes.len() && fixes[next].t_s < t1 {
                    let t = fixes[next].t_s;
                    let a = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
                    t_out.push(t);
                    x_out.push(x0 * (1.0 - a) + x1 * a);
                    next += 1;
                }
            }
        }
        prev = Some((t1, x1));
    };
    let end = opts.end_s.unwrap_or(f64::INFINITY);
    for ev in events.take_while(|e| e.t_s <= end) {
        feeder.push(&mut f, ev, &mut epoch)?;
    }
    feeder.finish(&mut f, &mut epoch)?;
    // A fix at the last epoch's time takes its state.
    if let Some((t1, x1)) = prev {
        if next < fixes.len() && fixes[next].t_s == t1 {
            t_out.push(t1);
            x_out.push(x1);
        }
    }
    Ok(Reference::from_states(t_out, x_out))
}

/// One regression step of the GNSS delay: the fixes' residuals against the
/// antenna's position on `reference` at the fixes' times, regressed on the
/// antenna's velocity with an east and north bias and a small rotation about
/// the window's centre per `window_s` window (`r = −δ·V + b + θ·J(p − p_c) + λ(p − p_c)`:
/// the heading and scale drift of a dead-reckoned reference). Returns `(δ, std, fixes)`: `δ` is how much later the
/// fixes still are than `reference`. `None` with fewer than 10 fixes per
/// window on average or a velocity that does not vary.
pub fn regress_gnss(
    fixes: &[crate::drive::GnssFix],
    reference: &Reference,
    lever_m: f64,
    window_s: f64,
) -> Option<(f64, f64, usize)> {
    // (window, residual, antenna velocity, antenna position)
    type Row = (i64, [f64; 2], [f64; 2], [f64; 2]);
    let mut rows: Vec<Row> = Vec::new();
    let t0 = fixes.first()?.t_s;
    for g in fixes {
        let Some(x) = reference.state_at(g.t_s) else {
            continue;
        };
        let (c, s) = (x[YAW].cos(), x[YAW].sin());
        let ant = [x[X] + lever_m * c, x[Y] + lever_m * s];
        let va = [
            x[V] * c - lever_m * x[YAW_RATE] * s,
            x[V] * s + lever_m * x[YAW_RATE] * c,
        ];
        let w = ((g.t_s - t0) / window_s).floor() as i64;
        rows.push((w, [g.east_m - ant[0], g.north_m - ant[1]], va, ant));
    }
    let n = rows.len();
    let windows = rows.last().map_or(0, |r| r.0 + 1) as usize;
    if n < 10 * windows.max(1) || n < 10 {
        return None;
    }
    // Partial out each window's east and north bias and small rotation
    // about its centre (the reference's drift) from the residuals and the
    // velocities.
    let mut centred: Vec<([f64; 2], [f64; 2])> = Vec::with_capacity(n);
    // Per window: Σ v·v and Σ v·r, for the jackknife.
    let mut per_window: Vec<(f64, f64)> = Vec::new();
    let mut i = 0;
    while i < n {
        let w = rows[i].0;
        let j = i + rows[i..].iter().take_while(|r| r.0 == w).count();
        let m = (j - i) as f64;
        let pc = [0, 1].map(|k| rows[i..j].iter().map(|r| r.3[k]).sum::<f64>() / m);
        // Nuisance columns besides the biases: a rotation J·(p − p_c) and a
        // stretch (p − p_c) about the window's centre (the reference's
        // heading and scale drift), made orthogonal to each other.
        let mut cols: Vec<Vec<[f64; 2]>> = vec![
            rows[i..j]
                .iter()
                .map(|r| [-(r.3[1] - pc[1]), r.3[0] - pc[0]])
                .collect(),
            rows[i..j]
                .iter()
                .map(|r| [r.3[0] - pc[0], r.3[1] - pc[1]])
                .collect(),
        ];
        let centre = |v: &mut Vec<[f64; 2]>| {
            let m = [0, 1].map(|k| v.iter().map(|a| a[k]).sum::<f64>() / v.len() as f64);
            for a in v.iter_mut() {
                a[0] -= m[0];
                a[1] -= m[1];
            }
        };
        let dot = |a: &[[f64; 2]], b: &[[f64; 2]]| -> f64 {
            a.iter()
                .zip(b)
                .map(|(p, q)| p[0] * q[0] + p[1] * q[1])
                .sum()
        };
        let remove = |v: &mut Vec<[f64; 2]>, q: &[[f64; 2]]| {
            let qq = dot(q, q);
            if qq > 1e-9 {
                let c = dot(v, q) / qq;
                for (a, b) in v.iter_mut().zip(q) {
                    a[0] -= c * b[0];
                    a[1] -= c * b[1];
                }
            }
        };
        for c in cols.iter_mut() {
            centre(c);
        }
        let first = cols[0].clone();
        remove(&mut cols[1], &first);
        let mut rr: Vec<[f64; 2]> = rows[i..j].iter().map(|r| r.1).collect();
        let mut vv: Vec<[f64; 2]> = rows[i..j].iter().map(|r| r.2).collect();
        for v in [&mut rr, &mut vv] {
            centre(v);
            for c in &cols {
                remove(v, c);
            }
        }
        let (mut wvv, mut wvr) = (0.0, 0.0);
        for (r, v) in rr.iter().zip(&vv) {
            wvv += v[0] * v[0] + v[1] * v[1];
            wvr += v[0] * r[0] + v[1] * r[1];
        }
        per_window.push((wvv, wvr));
        centred.extend(rr.into_iter().zip(vv));
        i = j;
    }
    let svv: f64 = centred.iter().map(|(_, v)| v[0] * v[0] + v[1] * v[1]).sum();
    let svr: f64 = centred.iter().map(|(r, v)| v[0] * r[0] + v[1] * r[1]).sum();
    if svv.is_nan() || svv <= 0.0 {
        return None;
    }
    let delta = -svr / svv;
    let res: Vec<[f64; 2]> = centred
        .iter()
        .map(|(r, v)| [0, 1].map(|k| r[k] + delta * v[k]))
        .collect();
    let dof = (2 * n) as f64 - (4 * windows.max(1)) as f64 - 1.0;
    let s2 = res.iter().map(|p| p[0] * p[0] + p[1] * p[1]).sum::<f64>() / dof.max(1.0);
    let rho = 0.5
        * (lag1(&res.iter().map(|p| p[0]).collect::<Vec<_>>())
            + lag1(&res.iter().map(|p| p[1]).collect::<Vec<_>>()));
    let gn_std = (s2 / svv * (1.0 + rho) / (1.0 - rho)).sqrt();
    // Delete-a-window jackknife: the residuals' correlation over a window
    // and from one window to the next (a wandering fix error, the reference's
    // drift) that the Gauss–Newton error does not see. On eight family cars
    // with 0.2 s of latency the errors in Gauss–Newton units had an RMS of
    // 1.8.
    let w = per_window.len();
    let jack_std = if w >= 5 {
        let d: Vec<f64> = per_window
            .iter()
            .filter(|(wvv, _)| svv - wvv > 0.0)
            .map(|(wvv, wvr)| -(svr - wvr) / (svv - wvv))
            .collect();
        jackknife_std(&d)
    } else {
        0.0
    };
    Some((delta, gn_std.max(jack_std), n))
}
