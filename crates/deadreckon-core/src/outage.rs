//! Outage evaluation on any drive: GNSS is hidden in sliding windows of a given
//! length; in each, the vehicle dead-reckons from the GNSS-aided filter state at
//! the window start, and the error is measured against the truth or, where the
//! drive has none, against the GNSS fixes that were hidden (compared at the
//! antenna, through the lever arm).
//!
//! Per window: the horizontal error at the end of the window, the drift per
//! 100 m (end error over the distance travelled in the window), and the distance
//! travelled before the error first reaches 1 m (the window's distance when it
//! never does, flagged as censored).
//!
//! Windows count once the heading is known: a window that starts before the
//! aided filter's yaw standard deviation first falls to
//! [`HEADING_KNOWN_YAW_STD_RAD`] (or to twice its median over the drive,
//! where that is higher: a filter without a gyro may never reach 2°) is
//! **unsettled** (the pull-away): evaluated
//! and reported on its own ([`OutageEvaluation::unsettled`]), not in the
//! summaries. Dead reckoning from a heading nobody knows yet measures the
//! initialisation, not the dead reckoning: on a dynamic-world family the
//! first window at pull-away, with the yaw standard deviation still 14–17°,
//! ended 31–66 m off and doubled every mean (issue 28). Later windows all
//! count, whatever their start's yaw standard deviation (each window reports
//! it): leaving out the windows where the filter is unsure would flatter the
//! figures.

use crate::aided::{Aided, AidedEpoch, BiasSwitch};
use crate::bound::{Cov2, WanderCov};
use crate::compared::{Antenna, Position, RearAxle};
use crate::drive::Drive;
use crate::ekf::FilterOptions;
use crate::filter::GateCounts;
use crate::metrics::Summary;
use crate::model::{State, V, X, Y, YAW};
use crate::reference::{Reference, TruthPositions};
use crate::vehicle::Params;
use crate::{Error, Input, Need, Rule, Task, Value};
use nalgebra::SMatrix;

pub use crate::compared::{Against, OutageResult};

/// The result over all windows.
#[derive(Debug, Clone, PartialEq)]
pub struct OutageEvaluation {
    /// Window length, s.
    pub outage_s: f64,
    /// Reference used.
    pub reference: Against,
    /// Every window: the rear axle against the truth, or the antenna
    /// against the hidden fixes.
    pub windows: Vec<OutageResult>,
    /// The χ² gate counters summed over every filter run of the evaluation:
    /// the GNSS-aided run and the dead reckoning through every window.
    pub gates: GateCounts,
    /// Windows that start before the aided filter's yaw standard deviation
    /// first fell to `heading_limit_rad` (the pull-away, before the fixes
    /// told the heading): evaluated, reported on their own, and left out of
    /// `windows` and the summaries.
    pub unsettled: Vec<OutageResult>,
    /// The yaw standard deviation the aided filter must first reach for
    /// windows to count, rad.
    pub heading_limit_rad: f64,
    /// What the aided run's gyro-bias switch saw over the drive (`None`
    /// without one: [`crate::aided::switch`]). Each window dead-reckons
    /// from the hypothesis chosen at its start.
    pub bias_switch: Option<BiasSwitch>,
}

impl OutageEvaluation {
    /// Summary of the errors at the windows' starts, m: what the GNSS-aided
    /// run handed over ([`OutageResult::start_m`]). A receiver's bias against
    /// the truth is in it, and no dead reckoning removes it.
    pub fn start_error(&self) -> Summary {
        Summary::of(&self.windows.iter().map(|w| w.start_m()).collect::<Vec<_>>())
    }
    /// Summary of the final errors, m.
    pub fn final_error(&self) -> Summary {
        Summary::of(&self.windows.iter().map(|w| w.final_m()).collect::<Vec<_>>())
    }
    /// Summary of the drift per 100 m, % (windows that travelled at least 10 m).
    pub fn drift_pct(&self) -> Summary {
        Summary::of(
            &self
                .windows
                .iter()
                .filter(|w| w.distance_m >= 10.0)
                .map(|w| 100.0 * w.final_m() / w.distance_m)
                .collect::<Vec<_>>(),
        )
    }
    /// Summary of the distances before 1 m of error, m (censored windows included at their length).
    pub fn distance_to_1m(&self) -> Summary {
        Summary::of(
            &self
                .windows
                .iter()
                .map(|w| w.distance_to(1.0).unwrap_or(w.distance_m))
                .collect::<Vec<_>>(),
        )
    }
}

/// The speed above which the vehicle counts as moving for the sliding windows, m/s.
pub const MOVING_MPS: f64 = 0.5;

/// The aided filter's yaw standard deviation at which the heading is first
/// known; outage windows starting before are unsettled, rad: 0.035 (2°, the
/// level at which the augmented filter starts learning the distance scale,
/// [`crate::vehicle::SCALE_HOLD_YAW_STD_RAD`]).
pub const HEADING_KNOWN_YAW_STD_RAD: f64 = 0.035;

/// Refuses outage windows that are empty or not inside the drive's wheel time
/// span, naming the span: a window after the end gave a four-wheel error and
/// "NaN … never" for TedriS.
pub fn check_windows(drive: &Drive, windows: &[(f64, f64)]) -> Result<(), Error> {
    let n = drive.wheels.len();
    if n == 0 {
        return Err(Error::needs(Task::OutageEvaluation, Input::WheelRows));
    }
    let (t0, t1) = (drive.wheels.t_s(0), drive.wheels.t_s(n - 1));
    for &(a, b) in windows {
        if !(a.is_finite() && b.is_finite() && a < b) {
            return Err(Error::param(
                "outage window",
                Value::Numbers(vec![a, b]),
                Rule::TimeRange,
            ));
        }
        if a < t0 || b > t1 {
            return Err(Error::param(
                "outage window",
                Value::Numbers(vec![a, b]),
                Rule::InsideDrive {
                    from_s: t0,
                    until_s: t1,
                },
            ));
        }
    }
    Ok(())
}

/// What the aided run tells the windows: its first and last epochs, when
/// the vehicle first moves and when the heading is first known.
struct AidedPass {
    first_t: f64,
    last_t: f64,
    moving_t: Option<f64>,
    /// Every epoch's time and yaw variance.
    yaw_var: Vec<(f64, f64)>,
}

impl AidedPass {
    /// The yaw standard deviation at which the heading counts as known, rad:
    /// [`HEADING_KNOWN_YAW_STD_RAD`], or twice the run's median where that
    /// is higher (a filter without a gyro may never reach 2°: its pull-away
    /// is the time before it settles at its own level).
    fn heading_limit(&self) -> f64 {
        let mut v: Vec<f64> = self.yaw_var.iter().map(|e| e.1).collect();
        if v.is_empty() {
            return HEADING_KNOWN_YAW_STD_RAD;
        }
        let mid = v.len() / 2;
        let median = *v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1;
        HEADING_KNOWN_YAW_STD_RAD.max(2.0 * median.max(0.0).sqrt())
    }

    /// When the yaw standard deviation first falls to `limit`.
    fn heading_known_t(&self, limit: f64) -> Option<f64> {
        self.yaw_var
            .iter()
            .find(|e| e.1 <= limit * limit)
            .map(|e| e.0)
    }
}

impl AidedPass {
    fn after_epoch(&mut self, e: &AidedEpoch) {
        let t = e.t_s;
        if self.first_t.is_nan() {
            self.first_t = t;
        }
        self.last_t = t;
        if self.moving_t.is_none() && e.x[V].abs() > MOVING_MPS {
            self.moving_t = Some(t);
        }
        self.yaw_var.push((t, e.p[(YAW, YAW)]));
    }
}

/// Runs the sliding-window outage evaluation.
///
/// The first window starts `warmup_s` after the filter's start, and not before
/// the vehicle first moves (the aided speed above [`MOVING_MPS`]: windows
/// parked at the start measured a standing filter converging, 20 m where the
/// moving ones gave 1.5 m); windows start every `step_s` and must end before
/// the last GNSS fix (and the truth's end).
///
/// With the vehicle's `noise.gnss_wander_std_m` above 0 the aided filter
/// carries the receiver's wander as states ([`crate::gnss_error`]); through
/// a window its estimate decays, and against hidden fixes (no truth) the
/// dead-reckoned antenna is compared with the wander still expected added.
pub fn evaluate(
    drive: &Drive,
    params: &Params,
    outage_s: f64,
    step_s: f64,
    warmup_s: f64,
    base: &FilterOptions,
) -> Result<OutageEvaluation, Error> {
    evaluate_with(drive, params, outage_s, step_s, warmup_s, base, true)
}

/// [`evaluate`] against the hidden GNSS fixes even where the drive has a
/// truth: what a user's drive can tell, as the error bound's fit
/// ([`crate::bound`]) sees it during calibration.
pub fn evaluate_against_fixes(
    drive: &Drive,
    params: &Params,
    outage_s: f64,
    step_s: f64,
    warmup_s: f64,
    base: &FilterOptions,
) -> Result<OutageEvaluation, Error> {
    evaluate_with(drive, params, outage_s, step_s, warmup_s, base, false)
}

/// [`evaluate`] against the truth when `use_truth` and the drive has one,
/// else against the hidden fixes.
fn evaluate_with(
    drive: &Drive,
    params: &Params,
    outage_s: f64,
    step_s: f64,
    warmup_s: f64,
    base: &FilterOptions,
    use_truth: bool,
) -> Result<OutageEvaluation, Error> {
    evaluate_in(drive, params, outage_s, step_s, warmup_s, base, use_truth)
}

/// [`evaluate`] with the aided filter the vehicle calls for ([`Aided`]).
fn evaluate_in(
    drive: &Drive,
    params: &Params,
    outage_s: f64,
    step_s: f64,
    warmup_s: f64,
    base: &FilterOptions,
    use_truth: bool,
) -> Result<OutageEvaluation, Error> {
    if !(outage_s > 0.0 && step_s > 0.0) {
        return Err(Error::param(
            "outage length and step (s)",
            Value::Numbers(vec![outage_s, step_s]),
            Rule::Positive,
        ));
    }
    // The truth's positions, borrowed: the windows read nothing else of it.
    let truth = if use_truth {
        TruthPositions::new(&drive.truth)
    } else {
        None
    };
    let reference = if truth.is_some() {
        Against::Truth
    } else {
        Against::Gnss
    };
    if reference == Against::Gnss && drive.gnss.len() < 2 {
        return Err(Error::needs(Task::OutageEvaluation, Input::TruthOrGnss));
    }
    // A first GNSS-aided pass finds where windows can start and end.
    let aided_opts = FilterOptions {
        record_epochs: false,
        record_innovations: false,
        ..base.clone()
    };
    let mut aided = AidedPass {
        first_t: f64::NAN,
        last_t: f64::NAN,
        moving_t: None,
        yaw_var: Vec::new(),
    };
    Aided::run(drive, params, &aided_opts, &mut |e| aided.after_epoch(e))?;
    if aided.first_t.is_nan() {
        return Err(Need::FilterEpochs.into());
    }
    let mut end_limit = aided.last_t;
    if let Some(t) = &truth {
        end_limit = end_limit.min(t.span().map(|s| s.1).unwrap_or(f64::NEG_INFINITY));
    } else if let Some(g) = drive.gnss.last() {
        end_limit = end_limit.min(g.t_s);
    }
    let Some(moving_t) = aided.moving_t else {
        return Err(Need::Motion {
            min_speed_mps: MOVING_MPS,
        }
        .into());
    };
    let first_t = aided.first_t;
    let fix_std_m = crate::bound::fix_scatter_std_m(&drive.gnss);
    let heading_limit = aided.heading_limit();
    let heading_known_t = aided.heading_known_t(heading_limit);
    drop(aided.yaw_var);
    let mut starts = Vec::new();
    let mut start = (first_t + warmup_s).max(moving_t);
    while start + outage_s <= end_limit {
        starts.push(start);
        start += step_s;
    }

    // The second pass steps the same filter; at each window start a clone of
    // it (filter, feeder and the events still to come) goes on without GNSS
    // to the window's end. The clone keeps what the aided run had learnt, the
    // wheel monitor's verdicts included (a fresh filter started from the
    // aided state forgot that a wheel was out).
    let (mut f, mut events) = Aided::on_drive(drive, params, &aided_opts)?;
    let mut upcoming = events.next();
    let mut noop = |_: &AidedEpoch| {};
    let mut windows = Vec::new();
    let mut unsettled = Vec::new();
    let mut gates = GateCounts::default();
    for &start in &starts {
        let end = start + outage_s;
        // Every epoch at or before the start, then the pending ones (the
        // run goes on: a wheel interval still open stays open).
        while let Some(ev) = upcoming.filter(|e| e.t_s <= start) {
            f.push(ev, &mut noop)?;
            upcoming = events.next();
        }
        f.settle(&mut noop)?;
        let t0 = f.time_s();
        let yaw_std = f
            .now()
            .map_or(f64::NAN, |e| e.p[(YAW, YAW)].max(0.0).sqrt());
        let before = f.gates();
        let (mut g, mut evs, mut next) = (f.clone(), events.clone(), upcoming);
        g.dead_reckon();
        let mut states: Vec<(f64, State)> = Vec::new();
        let mut wander: Vec<[f64; 2]> = Vec::new();
        let mut covs: Vec<[[f64; 3]; 3]> = Vec::new();
        let mut wander_covs: Vec<WanderCov> = Vec::new();
        let mut keep = |e: &AidedEpoch| {
            states.push((e.t_s, e.x));
            wander.push(e.wander_m);
            covs.push(pose_block(&e.p));
            if let Some(w) = e.wander_cov {
                wander_covs.push(w);
            }
        };
        while let Some(ev) = next.filter(|e| e.t_s <= end) {
            g.push(ev, &mut keep)?;
            next = evs.next();
        }
        g.finish(&mut keep)?;
        gates.add(&g.gates().since(&before));
        // The bound's floor: the declared accuracy of the last fix handed
        // over; none where the filter carries the receiver's wander (its
        // covariance holds the offset then: counted once).
        let handed = drive.gnss.partition_point(|g| g.t_s <= start);
        let receiver = Cov2::circular(if f.carries_wander() {
            0.0
        } else {
            handed
                .checked_sub(1)
                .map_or(0.0, |i| crate::bound::receiver_std_m(&drive.gnss[i]))
        });
        if let Some((mut w, _)) = window_errors(
            drive,
            truth.as_ref(),
            &states,
            &wander,
            (&covs, &wander_covs),
            (fix_std_m, receiver),
            t0,
            start,
            end,
        ) {
            w.start_yaw_std_rad = Some(yaw_std);
            if heading_known_t.is_none_or(|k| start < k) {
                unsettled.push(w);
            } else {
                windows.push(w);
            }
        }
    }
    // The aided run's own counts, through the end of the drive.
    while let Some(ev) = upcoming {
        f.push(ev, &mut noop)?;
        upcoming = events.next();
    }
    f.finish(&mut noop)?;
    gates.add(&f.gates());
    if windows.is_empty() && unsettled.is_empty() {
        return Err(Need::OutageWindow {
            outage_s,
            warmup_s,
            span_s: (first_t, end_limit),
            moving_from_s: Some(moving_t),
        }
        .into());
    }
    if windows.is_empty() {
        return Err(Need::KnownHeading {
            outage_s,
            yaw_std_rad: heading_limit,
            known_from_s: heading_known_t,
            windows: unsettled.len(),
        }
        .into());
    }
    Ok(OutageEvaluation {
        outage_s,
        reference,
        windows,
        gates,
        unsettled,
        heading_limit_rad: heading_limit,
        bias_switch: f.bias_switch(),
    })
}

/// The `(X, Y, YAW)` block of a filter covariance.
fn pose_block<const N: usize>(p: &SMatrix<f64, N, N>) -> [[f64; 3]; 3] {
    let i = [X, Y, YAW];
    let mut b = [[0.0; 3]; 3];
    for (r, &a) in i.iter().enumerate() {
        for (c, &d) in i.iter().enumerate() {
            b[r][c] = p[(a, d)];
        }
    }
    b
}

/// The errors of dead-reckoned `states` (from `t0`, the start of dead reckoning)
/// over the window `[start, end)`, against the truth or, without it, the GNSS
/// fixes of the window (compared at the antenna, plus the receiver's wander
/// the filter still expects, `wander[k]` at `states[k]`, when given: the
/// fixes carry it). With `covs` (the pose covariance at each state, and
/// the wander's part of it where the filter carries the wander) each
/// error also gets the covariance the error bound is made of (the point
/// compared — against a fix, the antenna plus the wander), and the window
/// the two parts that hold for all of it: `receiver`, the declared accuracy
/// of the last fix before the outage ([`crate::bound`]), and the
/// reference's own (a fix's is `fix_std_m` per axis). Against fixes, also
/// the last error as `[east, north]`, m (estimate less fix). `None` when
/// nothing compares.
#[allow(clippy::too_many_arguments)]
fn window_errors(
    drive: &Drive,
    truth: Option<&TruthPositions>,
    states: &[(f64, State)],
    wander: &[[f64; 2]],
    (covs, wander_covs): (&[[[f64; 3]; 3]], &[WanderCov]),
    (fix_std_m, receiver): (f64, Cov2),
    t0: f64,
    start: f64,
    end: f64,
) -> Option<(OutageResult, Option<[f64; 2]>)> {
    let lever = drive.vehicle.gnss_lever_arm_m;
    let inside = |s: &(f64, State)| s.0 >= t0 && s.0 <= end;
    let covs: Vec<[[f64; 3]; 3]> = states
        .iter()
        .zip(covs)
        .filter(|(s, _)| inside(s))
        .map(|(_, c)| *c)
        .collect();
    let wander_covs: Vec<WanderCov> = states
        .iter()
        .zip(wander_covs)
        .filter(|(s, _)| inside(s))
        .map(|(_, c)| *c)
        .collect();
    let mut cov_at = Vec::new();
    // The antenna the fixes see: the car's plus the wander expected.
    let seen: Vec<(f64, State)> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| inside(s))
        .map(|(k, s)| {
            let mut x = s.1;
            if let Some(e) = wander.get(k) {
                x[X] += e[0];
                x[Y] += e[1];
            }
            (s.0, x)
        })
        .collect();
    let states: Vec<(f64, State)> = states.iter().filter(|s| inside(s)).copied().collect();
    let mut errors = Vec::new();
    let mut last_offset = None;
    match truth {
        Some(t) => {
            for (k, (ts, x)) in states.iter().enumerate() {
                if let Some((east, north)) = t.position_at(*ts) {
                    let (est, truth) = (
                        Position::<RearAxle>::new(x[X], x[Y]),
                        Position::<RearAxle>::new(east, north),
                    );
                    errors.push((*ts - t0, est.distance_to(&truth)));
                    if let Some(c) = covs.get(k) {
                        cov_at.push(Cov2::rear_axle(c));
                    }
                }
            }
        }
        None => {
            let traj = Reference::from_states(
                seen.iter().map(|s| s.0).collect(),
                seen.iter().map(|s| s.1).collect(),
            );
            let first = drive.gnss.partition_point(|g| g.t_s <= t0);
            for g in drive.gnss[first..].iter().take_while(|g| g.t_s <= end) {
                if let Some(x) = traj.state_at(g.t_s) {
                    let antenna = Position::<RearAxle>::new(x[X], x[Y]).antenna(x[YAW], lever);
                    let fix = Position::<Antenna>::new(g.east_m, g.north_m);
                    errors.push((g.t_s - t0, antenna.distance_to(&fix)));
                    last_offset = Some(antenna.offset_from(&fix));
                    // The covariance of the last epoch at or before the fix.
                    let k = states.partition_point(|s| s.0 <= g.t_s).saturating_sub(1);
                    if let Some(c) = covs.get(k) {
                        cov_at.push(Cov2::at_fix(c, wander_covs.get(k), x[YAW], lever));
                    }
                }
            }
        }
    }
    errors.last()?;
    let mut dist = vec![0.0];
    for w in states.windows(2) {
        let d = dist.last().copied().unwrap_or(0.0)
            + (w[1].1[X] - w[0].1[X]).hypot(w[1].1[Y] - w[0].1[Y]);
        dist.push(d);
    }
    let distance_m = dist.last().copied().unwrap_or(0.0);
    let dist_at = |dt: f64| -> f64 {
        let k = states.partition_point(|s| s.0 - t0 <= dt);
        dist[k.saturating_sub(1).min(dist.len() - 1)]
    };
    let travelled = errors.iter().map(|e| dist_at(e.0)).collect();
    let mut out = match truth {
        Some(_) => {
            OutageResult::new::<RearAxle>(start, end, Against::Truth, errors, travelled, distance_m)
        }
        None => {
            OutageResult::new::<Antenna>(start, end, Against::Gnss, errors, travelled, distance_m)
        }
    };
    if cov_at.len() == out.errors.len() {
        out.covariances_m2 = cov_at;
        // The floor and the reference's own covariance hold for the whole
        // window: stored once.
        out.floor_m2 = receiver;
        out.reference_m2 = Cov2::circular(match truth {
            Some(_) => 0.0,
            None => fix_std_m,
        });
    }
    // Every window is kept to the end of the evaluation (an error per epoch
    // against the truth): without the pushes' spare capacity, up to as much
    // again (docs/performance.md, "Fifth round").
    out.errors.shrink_to_fit();
    out.covariances_m2.shrink_to_fit();
    Some((out, last_offset))
}

/// The GNSS-aided filter run once with GNSS hidden in every window of
/// `windows` (s): the errors through each window, as for the sliding evaluation.
/// Used to compare methods through the same outages.
pub fn through_windows(
    drive: &Drive,
    params: &Params,
    windows: &[(f64, f64)],
    base: &FilterOptions,
) -> Result<OutageEvaluation, Error> {
    through_windows_in(drive, params, windows, base, true)
}

/// [`through_windows`] measured against the hidden fixes even where the
/// drive has a truth: what the drive's own data can tell
/// ([`crate::held_back`] chooses the corrections by it).
pub fn through_windows_against_fixes(
    drive: &Drive,
    params: &Params,
    windows: &[(f64, f64)],
    base: &FilterOptions,
) -> Result<OutageEvaluation, Error> {
    through_windows_in(drive, params, windows, base, false)
}

fn through_windows_in(
    drive: &Drive,
    params: &Params,
    windows: &[(f64, f64)],
    base: &FilterOptions,
    use_truth: bool,
) -> Result<OutageEvaluation, Error> {
    check_windows(drive, windows)?;
    let truth = if use_truth {
        TruthPositions::new(&drive.truth)
    } else {
        None
    };
    let reference = if truth.is_some() {
        Against::Truth
    } else {
        Against::Gnss
    };
    let opts = FilterOptions {
        gnss_outages: windows.to_vec(),
        record_epochs: false,
        ..base.clone()
    };
    // The gyro bias and the receiver's wander are carried where the
    // vehicle says so, as in `evaluate`, `run`'s tracks and `stream`.
    let mut hook = Collect::default();
    // Against fixes, each window's last hidden fix is also scored: the
    // epoch at or before it is kept (its state and covariance).
    let last_fix: Vec<Option<usize>> = match truth {
        Some(_) => Vec::new(),
        None => windows.iter().map(|&w| last_fix_in(drive, w)).collect(),
    };
    let mut at_fix: Vec<Option<AtFix>> = vec![None; last_fix.len()];
    let mut open = 0;
    let aided = Aided::run(drive, params, &opts, &mut |e| {
        hook.states.push((e.t_s, e.x));
        if e.wander_cov.is_some() {
            hook.wander.push(e.wander_m);
        }
        while open < last_fix.len() && windows[open].1 < e.t_s {
            open += 1;
        }
        for k in open..last_fix.len() {
            if windows[k].0 >= e.t_s {
                break;
            }
            if last_fix[k].is_some_and(|i| e.t_s <= drive.gnss[i].t_s) {
                at_fix[k] = Some((e.x, pose_block(&e.p), e.wander_cov));
            }
        }
    })?;
    let mut out = Vec::new();
    for (k, &(a, b)) in windows.iter().enumerate() {
        // Dead reckoning starts at the last epoch before the window.
        let i = hook.states.partition_point(|s| s.0 < a);
        let t0 = hook
            .states
            .get(i.saturating_sub(1))
            .map(|s| s.0)
            .unwrap_or(a);
        // Against hidden fixes, the antenna plus the wander the filter
        // still expects: the fixes carry it (as `evaluate` compares).
        if let Some(w) = window_errors(
            drive,
            truth.as_ref(),
            &hook.states,
            &hook.wander,
            (&[], &[]),
            (0.0, Cov2::circular(0.0)),
            t0,
            a,
            b,
        ) {
            let (mut w, last_offset) = w;
            if let (Some(i), Some(Some(at)), Some(d)) = (
                last_fix.get(k).copied().flatten(),
                at_fix.get(k),
                last_offset,
            ) {
                w.fix_log_likelihood = Some(fix_log_likelihood(drive, &drive.gnss[i], at, d));
            }
            out.push(w);
        }
    }
    Ok(OutageEvaluation {
        outage_s: windows.iter().map(|w| w.1 - w.0).fold(0.0, f64::max),
        reference,
        windows: out,
        gates: aided.gates(),
        unsettled: Vec::new(),
        heading_limit_rad: f64::INFINITY,
        bias_switch: aided.bias_switch(),
    })
}

/// The car state, its pose covariance and the wander's part of the
/// covariance at the last epoch at or before a window's last fix.
type AtFix = (State, [[f64; 3]; 3], Option<WanderCov>);

/// The index of the last fix inside `(a, b]`.
fn last_fix_in(drive: &Drive, (a, b): (f64, f64)) -> Option<usize> {
    let k = drive.gnss.partition_point(|g| g.t_s <= b);
    (k > 0 && drive.gnss[k - 1].t_s > a).then(|| k - 1)
}

/// `ln N(d; 0, S)` of a hidden fix `fix` off the dead-reckoned antenna by
/// `d` (east, north, m), with `S` the antenna's covariance at `at` (the
/// pose's carried to the antenna, plus the wander's where the filter
/// carries it) and the fix's declared noise, as the filter's update
/// would take it.
fn fix_log_likelihood(drive: &Drive, fix: &crate::drive::GnssFix, at: &AtFix, d: [f64; 2]) -> f64 {
    let (x, p3, wander) = at;
    let s = Cov2::at_fix(p3, wander.as_ref(), x[YAW], drive.vehicle.gnss_lever_arm_m);
    let noise = Cov2::circular(crate::bound::receiver_std_m(fix));
    s.scaled_plus(1.0, &noise).log_density(d)
}

/// Every epoch's time and car state, and the receiver's wander estimate
/// where the filter carries it.
#[derive(Default)]
struct Collect {
    states: Vec<(f64, State)>,
    wander: Vec<[f64; 2]>,
}

#[cfg(test)]
#[path = "outage_tests.rs"]
mod window_tests;
