//! Batch use over a whole drive: training ([`train`]) and prediction through
//! GNSS outages with the errors of figures 6 and 7 ([`run_outages`]).
//!
//! The errors are of the rear axle ([`OutageResult`], the type the
//! four-wheel filter's outages have too), against, in order of preference
//! ([`Against`]):
//! - `truth`: `truth.csv` (rear-axle centre), interpolated at each estimate;
//! - `truth aligned at outage start`: for drives without GNSS positions (the robot),
//!   both tracks are translated to agree at the outage start, so the error is the
//!   dead-reckoning drift during the outage;
//! - `gnss`: the hidden fixes, moved from the antenna to the rear-axle
//!   centre with the lever arm along the course (or the estimated yaw).

use deadreckon_core::compared::{Against, Antenna, OutageResult, Position, RearAxle};
use serde::{Deserialize, Serialize};

use deadreckon_core::drive::Drive;
use deadreckon_core::{Track, TrackPoint};

use crate::config::TedrisConfig;
use crate::input::{drive_input, drive_input_with, standstill_gyro_stats, Event, ReferenceSource};
use crate::machine::{Estimate, Phase, Tedris};
use crate::model::TedrisModel;
use crate::Error;

/// A GNSS outage window, s (drive clock).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Outage {
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
}

impl std::str::FromStr for Outage {
    type Err = Error;
    /// Parses `START_S:END_S`.
    fn from_str(s: &str) -> Result<Self, Error> {
        let bad = || {
            Error::Config(format!(
                "outage `{s}` is not START_S:END_S with START_S < END_S"
            ))
        };
        let (a, b) = s.split_once(':').ok_or_else(bad)?;
        let start_s: f64 = a.trim().parse().map_err(|_| bad())?;
        let end_s: f64 = b.trim().parse().map_err(|_| bad())?;
        if !(start_s.is_finite() && end_s.is_finite() && start_s < end_s) {
            return Err(bad());
        }
        Ok(Outage { start_s, end_s })
    }
}

/// The errors over one outage: the rear axle against the reference
/// ([`OutageResult`], the type the four-wheel filter's outages have too), the
/// threshold of `time_to_threshold_s`, and how much of it TedriS predicted.
/// Its JSON keeps the figures' names (`mean_error_m`, `time_to_1m_s`, ...).
#[derive(Debug, Clone, PartialEq)]
pub struct OutageError {
    /// The errors and what they compare.
    pub result: OutageResult,
    /// The threshold of `time_to_threshold_s`, m (1 m for a car; 0.159 m for the paper's robot).
    pub threshold_m: f64,
    /// Estimates of the outage made while the machine was predicting with a model.
    pub predicted_fraction: f64,
}

impl OutageError {
    /// Start, s.
    pub fn start_s(&self) -> f64 {
        self.result.start_s
    }

    /// Mean horizontal error, m.
    pub fn mean_error_m(&self) -> f64 {
        self.result.mean_m()
    }

    /// Largest horizontal error, m.
    pub fn max_error_m(&self) -> f64 {
        self.result.max_m()
    }

    /// Error at the last estimate of the outage, m.
    pub fn final_error_m(&self) -> f64 {
        self.result.final_m()
    }

    /// Time from the outage start until the error first reaches 1 m, s.
    pub fn time_to_1m_s(&self) -> Option<f64> {
        self.result.time_to(1.0)
    }

    /// Time from the outage start until the error first reaches
    /// `threshold_m`, s.
    pub fn time_to_threshold_s(&self) -> Option<f64> {
        self.result.time_to(self.threshold_m)
    }
}

impl Serialize for OutageError {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut m = s.serialize_struct("OutageError", 10)?;
        m.serialize_field("start_s", &self.result.start_s)?;
        m.serialize_field("end_s", &self.result.end_s)?;
        m.serialize_field("mean_error_m", &self.mean_error_m())?;
        m.serialize_field("max_error_m", &self.max_error_m())?;
        m.serialize_field("final_error_m", &self.final_error_m())?;
        m.serialize_field("time_to_1m_s", &self.time_to_1m_s())?;
        m.serialize_field("threshold_m", &self.threshold_m)?;
        m.serialize_field("time_to_threshold_s", &self.time_to_threshold_s())?;
        m.serialize_field("points", &self.result.points())?;
        m.serialize_field("predicted_fraction", &self.predicted_fraction)?;
        m.end()
    }
}

/// The result of [`run_outages`].
#[derive(Debug, Clone)]
pub struct OutageReport {
    /// What the errors are measured against.
    pub reference: Against,
    /// The reference heading source used.
    pub source: ReferenceSource,
    /// One entry per outage.
    pub outages: Vec<OutageError>,
    /// The estimated track over the whole drive (covariances are not estimated: zeros).
    pub track: Track,
    /// The phase after each track point.
    pub phases: Vec<Phase>,
    /// The machine at the end of the drive (model retrained on this drive included).
    pub machine: Tedris,
}

/// Options of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct RunOptions {
    /// Reference heading source (default: [`ReferenceSource::auto`]).
    pub source: Option<ReferenceSource>,
    /// The error threshold reported as `time_to_threshold_s`, m (default 1).
    pub threshold_m: Option<f64>,
}

fn feed(machine: &mut Tedris, events: &[Event]) -> Vec<Estimate> {
    let mut out = Vec::new();
    for e in events {
        // Invalid samples are counted by the machine and skipped.
        match e {
            Event::Wheel(w) => {
                if let Ok(est) = machine.push_wheel(*w) {
                    out.push(est);
                }
            }
            Event::Heading(h) => {
                let _ = machine.push_heading(*h);
            }
            Event::Fix(f) => {
                let _ = machine.push_fix(*f);
            }
        }
    }
    out
}

/// Trains a model over a whole drive (GNSS or gyro good throughout).
pub fn train(
    drive: &Drive,
    config: TedrisConfig,
    source: Option<ReferenceSource>,
) -> Result<(TedrisModel, ReferenceSource), Error> {
    let input = drive_input(drive, source, &[])?;
    let mut m = Tedris::new(config, input.geometry)?;
    if let Some((e, n, y)) = input.initial_pose {
        m.set_pose(e, n, y);
    }
    feed(&mut m, &input.events);
    let model = m.model().cloned().ok_or_else(|| {
        Error::Insufficient(format!(
            "cannot train on this drive: {}",
            m.untrained_because()
                .unwrap_or("no reference heading reached the machine")
        ))
    })?;
    let refit = model.refit().map(|mut f| {
        if f.fits.iter().any(|k| k.kind == model.chosen) {
            // The machine's choice (by the calibrated heading when automatic).
            f.chosen = model.chosen;
        }
        f.dcf_rad = model.dcf_rad;
        f.dcf_distance_rad_per_m = model.dcf_distance_rad_per_m;
        f.turn_gain = model.turn_gain;
        f.dcf_std_rad = model.dcf_std_rad;
        f.dcf_distance_std_rad_per_m = model.dcf_distance_std_rad_per_m;
        f.turn_gain_std = model.turn_gain_std;
        f.distance_scale = model.distance_scale;
        f.per_metre_straight = model.per_metre_straight;
        f.course_convention = model.course_convention;
        f.refused_kinds = model.refused_kinds.clone();
        f.acceptance = model.acceptance.clone();
        f.settle_kind();
        f
    });
    // A closing refit the physical acceptance refuses is not kept.
    let refit = refit.and_then(|mut f| {
        let chosen = f.chosen;
        m.accept(&mut f).map_err(Error::Insufficient)?;
        if f.chosen != chosen {
            // It would fall back where the machine's model did not.
            return Err(Error::Insufficient("refit refused".into()));
        }
        Ok(f)
    });
    // The closing refit is guarded like every refit once trained.
    let mut refit = match refit {
        Ok(f) if m.closing_refit_accepted(&f) => f,
        _ => model,
    };
    if input.source == ReferenceSource::Gyro {
        let (b, n) = standstill_gyro_stats(drive);
        refit.gyro_bias = (n > 0).then_some((b, n));
    }
    Ok((refit, input.source))
}

/// Runs a drive with GNSS blanked in `outages`, starting from `model`, and
/// measures the error over each outage.
pub fn run_outages(
    drive: &Drive,
    model: &TedrisModel,
    outages: &[Outage],
) -> Result<OutageReport, Error> {
    run_outages_with(drive, model, outages, &RunOptions::default())
}

/// [`run_outages`] with options.
pub fn run_outages_with(
    drive: &Drive,
    model: &TedrisModel,
    outages: &[Outage],
    opts: &RunOptions,
) -> Result<OutageReport, Error> {
    let windows: Vec<(f64, f64)> = outages.iter().map(|o| (o.start_s, o.end_s)).collect();
    deadreckon_core::outage::check_windows(drive, &windows)?;
    let input = drive_input_with(drive, opts.source, &windows, model.gyro_bias)?;
    let mut m = Tedris::with_model(model.clone(), input.geometry)?;
    if let Some((e, n, y)) = input.initial_pose {
        m.set_pose(e, n, y);
    }
    let est = feed(&mut m, &input.events);
    let points: Vec<TrackPoint> = est
        .iter()
        .map(|e| TrackPoint {
            t_s: e.t_s,
            east_m: e.east_m,
            north_m: e.north_m,
            yaw_rad: e.yaw_rad,
            speed_mps: e.speed_mps,
            yaw_rate_rps: e.yaw_rate_rps,
            cov_pose: [0.0; 9],
        })
        .collect();
    let phases: Vec<Phase> = est.iter().map(|e| e.phase).collect();
    let threshold = opts.threshold_m.unwrap_or(1.0);
    let (reference, errors) = if drive.truth.len() >= 2 {
        let aligned = drive.gnss.is_empty() || input.source == ReferenceSource::Gyro;
        let against = if aligned {
            Against::TruthAlignedAtStart
        } else {
            Against::Truth
        };
        (
            against,
            outages
                .iter()
                .map(|o| truth_errors(drive, &points, &phases, o, aligned, threshold))
                .collect(),
        )
    } else {
        (
            Against::Gnss,
            outages
                .iter()
                .map(|o| gnss_errors(drive, &points, &phases, o, threshold))
                .collect(),
        )
    };
    Ok(OutageReport {
        reference,
        source: input.source,
        outages: errors,
        track: Track {
            name: "tedris".into(),
            points,
            origin: drive.vehicle.origin,
        },
        phases,
        machine: m,
    })
}

/// The truth's rear-axle position at `t`, linearly interpolated.
pub(crate) fn truth_at(drive: &Drive, t: f64) -> Option<(f64, f64)> {
    let tr = &drive.truth;
    let i = tr.partition_point(|p| p.t_s < t);
    if i == 0 || i >= tr.len() {
        return tr
            .get(i)
            .filter(|p| (p.t_s - t).abs() < 1e-9)
            .map(|p| (p.east_m, p.north_m));
    }
    let (a, b) = (&tr[i - 1], &tr[i]);
    let f = (t - a.t_s) / (b.t_s - a.t_s);
    Some((
        a.east_m + f * (b.east_m - a.east_m),
        a.north_m + f * (b.north_m - a.north_m),
    ))
}

/// The summary of the errors `(t, m)` over an outage.
pub(crate) fn summarise_errors(
    o: &Outage,
    against: Against,
    errs: &[(f64, f64)],
    predicted: usize,
    total: usize,
    threshold: f64,
) -> OutageError {
    OutageError {
        result: OutageResult::new::<RearAxle>(
            o.start_s,
            o.end_s,
            against,
            errs.iter().map(|e| (e.0 - o.start_s, e.1)).collect(),
            Vec::new(),
            f64::NAN,
        ),
        threshold_m: threshold,
        predicted_fraction: if total > 0 {
            predicted as f64 / total as f64
        } else {
            0.0
        },
    }
}

fn truth_errors(
    drive: &Drive,
    pts: &[TrackPoint],
    phases: &[Phase],
    o: &Outage,
    aligned: bool,
    threshold: f64,
) -> OutageError {
    let mut errs = Vec::new();
    let mut offset: Option<(f64, f64)> = None;
    let (mut pred, mut total) = (0, 0);
    for (p, ph) in pts.iter().zip(phases) {
        if p.t_s < o.start_s || p.t_s >= o.end_s {
            continue;
        }
        let Some((te, tn)) = truth_at(drive, p.t_s) else {
            continue;
        };
        total += 1;
        pred += usize::from(*ph == Phase::Predicting);
        let (oe, on) = if aligned {
            *offset.get_or_insert((te - p.east_m, tn - p.north_m))
        } else {
            (0.0, 0.0)
        };
        let est = Position::<RearAxle>::new(p.east_m + oe, p.north_m + on);
        errs.push((p.t_s, est.distance_to(&Position::new(te, tn))));
    }
    let against = if aligned {
        Against::TruthAlignedAtStart
    } else {
        Against::Truth
    };
    summarise_errors(o, against, &errs, pred, total, threshold)
}

fn gnss_errors(
    drive: &Drive,
    pts: &[TrackPoint],
    phases: &[Phase],
    o: &Outage,
    threshold: f64,
) -> OutageError {
    let mut errs = Vec::new();
    let (mut pred, mut total) = (0, 0);
    for (g_t, i, e) in gnss_error_points(drive, pts, o.start_s, o.end_s) {
        total += 1;
        pred += usize::from(phases[i] == Phase::Predicting);
        errs.push((g_t, e));
    }
    summarise_errors(o, Against::Gnss, &errs, pred, total, threshold)
}

/// The horizontal error of a TedriS track (`pts`, rear axle) against the
/// (hidden) GNSS fixes of `drive` in `[start_s, end_s)`, each fix moved from
/// the antenna to the rear axle along its course: `(fix time, index of the
/// track point used, error m)`. Fixes without a track point within 0.5 s are
/// left out. The reference of outage errors on drives without truth.
pub fn gnss_error_points(
    drive: &Drive,
    pts: &[TrackPoint],
    start_s: f64,
    end_s: f64,
) -> Vec<(f64, usize, f64)> {
    let l = drive.vehicle.gnss_lever_arm_m;
    let mut out = Vec::new();
    for g in drive
        .gnss
        .iter()
        .filter(|g| g.t_s >= start_s && g.t_s < end_s)
    {
        let i = pts.partition_point(|p| p.t_s < g.t_s).saturating_sub(1);
        let Some(p) = pts.get(i).filter(|p| (p.t_s - g.t_s).abs() < 0.5) else {
            continue;
        };
        let yaw = g.course_yaw_rad().unwrap_or(p.yaw_rad);
        let fix = Position::<Antenna>::new(g.east_m, g.north_m).rear_axle(yaw, l);
        let ahead = (g.t_s - p.t_s) * p.speed_mps;
        let est = Position::<RearAxle>::new(
            p.east_m + ahead * p.yaw_rad.cos(),
            p.north_m + ahead * p.yaw_rad.sin(),
        );
        out.push((g.t_s, i, est.distance_to(&fix)));
    }
    out
}
