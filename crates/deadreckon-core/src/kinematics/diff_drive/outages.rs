//! Sliding GNSS outages for the differential drive: each outage starts
//! either from the alignment of the preceding dead-reckoned stretch to its
//! fixes, or from the GNSS-aided filter's state at its start.

use super::filter::{DiffDriveFilter, FilterNoise};
use super::{align, at, DiffDriveDrive, N_PARAMS};
use crate::kinematics::evaluate::{KinematicOutages, KinematicWindow};
use crate::{Error, Input, Need, Rule, Task, Value};

/// Where an outage starts from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum OutageStart {
    /// The rigid alignment (closed-form Procrustes) of the dead-reckoned
    /// antenna over the `warmup_s` before the outage to the fixes there:
    /// what a user does without a filter.
    Align,
    /// The state of the GNSS-aided filter ([`super::filter`]) at the
    /// outage's start, predicted without fixes through the outage; the
    /// fixes' wander estimated at the start is carried into the outage
    /// (it decays with its time constant).
    Filter(FilterNoise),
}

impl OutageStart {
    /// Its name in reports and on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            OutageStart::Align => "align",
            OutageStart::Filter(_) => "filter",
        }
    }
}

/// The outages of [`evaluate_diff_drive`] and how the filter's fixes went.
#[derive(Debug, Clone, PartialEq)]
pub struct DiffDriveOutages {
    /// The windows.
    pub outages: KinematicOutages,
    /// How the outages started.
    pub start: OutageStart,
    /// Filter start only: fixes used before the last outage's start.
    pub fixes_used: usize,
    /// Filter start only: fixes rejected by the gate before the last
    /// outage's start.
    pub fixes_rejected: usize,
    /// Filter start only: jumps of the fixes' error taken (the gate kept
    /// rejecting, the wander was widened) before the last outage's start.
    pub fix_jumps: usize,
    /// Filter start only: for each window, the filter's predicted standard
    /// deviation of the final error per axis, m (the root of half the trace
    /// of the predicted fix's covariance plus the fix's white noise).
    pub predicted_std_m: Vec<f64>,
    /// Filter start only: for each window, the covariance of the fix the
    /// filter predicts at its end (the state's part, without the fix's
    /// white noise), m²: what the 95 % bound is made of
    /// ([`crate::bound_diff`]).
    pub predicted_cov_m2: Vec<crate::bound::Cov2>,
}

impl DiffDriveOutages {
    /// Filter start only: the root mean square over the windows of the
    /// predicted standard deviation per axis, and of the final error per
    /// axis (`√(mean e²/2)`), m. The two agree when the filter's covariance
    /// is honest.
    pub fn rms_per_axis(&self) -> Option<(f64, f64)> {
        let n = self.predicted_std_m.len();
        if n == 0 || n != self.outages.windows.len() {
            return None;
        }
        let predicted = self.predicted_std_m.iter().map(|s| s * s).sum::<f64>() / n as f64;
        let achieved = self
            .outages
            .windows
            .iter()
            .map(|w| 0.5 * w.final_error_m.powi(2))
            .sum::<f64>()
            / n as f64;
        Some((predicted.sqrt(), achieved.sqrt()))
    }
}

/// The default `warmup_s` of [`evaluate_diff_drive`] (`evaluate --align`):
/// a minute of fixes before the first outage and aligned before each, s.
pub const DEFAULT_WARMUP_S: f64 = 60.0;

/// Dead reckons through outages of `outage_s` every `step_s`, the first
/// starting `warmup_s` after the first sample, each started as `start`
/// says (the alignment spans the `warmup_s` before the outage), and scores
/// each against the last fix at or before its end.
pub fn evaluate_diff_drive(
    d: &DiffDriveDrive,
    params: &[f64],
    outage_s: f64,
    step_s: f64,
    warmup_s: f64,
    start: &OutageStart,
) -> Result<DiffDriveOutages, Error> {
    let finite = [outage_s, step_s, warmup_s].iter().all(|v| v.is_finite());
    if !finite || outage_s <= 0.0 || step_s <= 0.0 || warmup_s <= 0.0 {
        return Err(Error::param(
            "outage, step and alignment lengths (s)",
            Value::Numbers(vec![outage_s, step_s, warmup_s]),
            Rule::Positive,
        ));
    }
    if params.len() != N_PARAMS || params.iter().any(|v| !v.is_finite()) {
        return Err(Error::param(
            "parameters",
            Value::Numbers(params.to_vec()),
            Rule::FiniteCount(N_PARAMS),
        ));
    }
    let (Some(first), Some(last)) = (d.samples.first(), d.samples.last()) else {
        return Err(Error::needs(Task::DeadReckoning, Input::Odometry));
    };
    let mut filter = match start {
        OutageStart::Align => None,
        OutageStart::Filter(noise) => {
            Some(DiffDriveFilter::start(d, params, noise)?.ok_or_else(|| {
                Error::from(Need::FilterStart {
                    path_m: noise.init_path_m,
                    fixes: 3,
                })
            })?)
        }
    };
    let mut next_fix = filter
        .as_ref()
        .map_or(0, |f| d.fixes.partition_point(|x| x.0 <= f.t_s));
    let mut windows = Vec::new();
    let mut predicted_std_m = Vec::new();
    let mut predicted_cov_m2 = Vec::new();
    let (mut used, mut rejected, mut jumps) = (0, 0, 0);
    let mut ts = first.t_s + warmup_s;
    while ts + outage_s <= last.t_s {
        let t_a = ts - warmup_s;
        let a = d.samples.partition_point(|s| s.t_s < t_a);
        let b = d
            .samples
            .partition_point(|s| s.t_s <= ts + outage_s)
            .saturating_sub(1);
        let fa = d.fixes.partition_point(|f| f.0 < d.samples[a].t_s);
        let fm = d.fixes.partition_point(|f| f.0 <= ts);
        let fe = d.fixes.partition_point(|f| f.0 <= ts + outage_s);
        let start_s = ts;
        ts += step_s;
        if b <= a || fm < fa + 2 || fe <= fm {
            continue;
        }
        let (tf, fx, fy) = d.fixes[fe - 1];
        let predicted = match filter.as_mut() {
            None => {
                let tr = d.local_track(params, a, b, false);
                let p: Vec<[f64; 2]> = d.fixes[fa..fm].iter().map(|f| at(&tr, f.0).0).collect();
                let q: Vec<[f64; 2]> = d.fixes[fa..fm].iter().map(|f| [f.1, f.2]).collect();
                let Some((th, t)) = align(&p, &q) else {
                    continue;
                };
                let (s, c) = th.sin_cos();
                let e = at(&tr, tf).0;
                [t[0] + c * e[0] - s * e[1], t[1] + s * e[0] + c * e[1]]
            }
            Some(f) => {
                if f.t_s > start_s {
                    continue;
                }
                // The fixes up to the outage's start, then the filter
                // predicted through the outage without them.
                while next_fix < fm {
                    let (t, e, n) = d.fixes[next_fix];
                    f.predict_to(t);
                    f.update_fix(e, n)?;
                    next_fix += 1;
                }
                f.predict_to(start_s);
                used = f.fixes_used;
                rejected = f.fixes_rejected;
                jumps = f.fix_jumps;
                let mut blind = f.clone();
                blind.predict_to(tf);
                let (z, cov) = blind.predicted_fix();
                let white = match start {
                    OutageStart::Filter(n) => n.fix_white_m.powi(2),
                    OutageStart::Align => 0.0,
                };
                predicted_std_m.push((0.5 * cov.trace() + white).sqrt());
                predicted_cov_m2.push(crate::bound::Cov2 {
                    ee_m2: cov[(0, 0)],
                    en_m2: 0.5 * (cov[(0, 1)] + cov[(1, 0)]),
                    nn_m2: cov[(1, 1)],
                });
                [z[0], z[1]]
            }
        };
        let i0 = d.samples.partition_point(|s| s.t_s < start_s);
        let path_m = (i0 + 1..=b)
            .map(|k| {
                0.5 * (d.samples[k - 1].v_mps + d.samples[k].v_mps).abs()
                    * (d.samples[k].t_s - d.samples[k - 1].t_s)
            })
            .sum();
        windows.push(KinematicWindow {
            start_s,
            end_s: tf,
            path_m,
            final_error_m: (predicted[0] - fx).hypot(predicted[1] - fy),
        });
    }
    if windows.is_empty() {
        return Err(Need::OutageWindow {
            outage_s,
            warmup_s,
            span_s: (first.t_s, last.t_s),
            moving_from_s: None,
        }
        .into());
    }
    Ok(DiffDriveOutages {
        outages: KinematicOutages {
            outage_s,
            step_s,
            windows,
        },
        start: *start,
        fixes_used: used,
        fixes_rejected: rejected,
        fix_jumps: jumps,
        predicted_std_m,
        predicted_cov_m2,
    })
}
