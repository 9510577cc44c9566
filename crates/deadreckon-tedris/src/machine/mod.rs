//! The TedriS state machine of section 3.3, fed one sample at a time.
//!
//! ```text
//!            reference heading good                  all repositories filled
//!  Blind ────────────────────────────▶ Training ────────────────────────────▶ Update
//!    ▲                                  ▲    │ reference lost                   │ reference lost
//!    │ no model yet                     │    ▼                                  ▼
//!    └──────────────────────────────── Predicting ◀─────────────────────────────┘
//!                reference back: Training again (then Update after `retrain_s`)
//! ```
//!
//! Every wheel sample advances the dead-reckoned heading by γ̂ (eq. 4–5) and the
//! rear-axle position by the rear wheel distance along that heading. While the
//! reference is good, the output is anchored to it: the heading offset is the mean
//! of (reference − DR heading) over `heading_anchor_window_s`, compared at the lag h
//! (the reference responds h samples after the wheels), and the position offset the
//! mean of (fix, lever arm removed − DR position) over `position_anchor_window_s`.
//! When the reference is lost both offsets freeze and the chain runs on the wheels alone.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::config::TedrisConfig;
use crate::history::{
    centre_per_segment, masked_ccf, rms_about_segment_means, BlockFormer, History, Sample,
};
use crate::minimise::brent;
use crate::model::{design_row, TedrisModel};
use crate::predict::Predictor;
use crate::repository::{Repositories, StraightLine, Tuple};
use crate::Error;
use deadreckon_core::angle::wrap;

mod calibration;
mod scale;
mod sync;
mod training;

pub use calibration::{heading_lag, InstalledCalibration};
pub use sync::{course_convention, ConventionFit, CourseConvention};
pub use training::straight_line;

/// Rear wheel distances travelled since the previous wheel sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WheelSample {
    /// Timestamp, s.
    pub t_s: f64,
    /// Rear-left wheel distance, m.
    pub left_m: f64,
    /// Rear-right wheel distance, m.
    pub right_m: f64,
}

/// A reference heading: the GNSS course as a yaw, or the integrated gyro heading.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HeadingSample {
    /// Timestamp, s.
    pub t_s: f64,
    /// Yaw, rad, counter-clockwise from east (any branch: it is unwrapped here).
    pub yaw_rad: f64,
}

/// A GNSS antenna position.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PositionFix {
    /// Timestamp, s.
    pub t_s: f64,
    /// East, m.
    pub east_m: f64,
    /// North, m.
    pub north_m: f64,
}

/// Geometry the machine needs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Geometry {
    /// Rear track width, m (nominal yaw rate ω / track before a model exists).
    pub track_rear_m: f64,
    /// GNSS antenna distance forward of the rear-axle centre, m.
    pub lever_arm_m: f64,
    /// The reference heading is a GNSS course (of the antenna, gated by speed);
    /// false for a gyro heading.
    pub heading_is_course: bool,
}

/// The phase of section 3.3.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// No reference and no model: the heading follows the nominal ω / track.
    Blind,
    /// Reference good, repositories not yet filled (or just back after an outage).
    Training,
    /// Reference good, repositories filled: DCF updates (eq. 6) and refits.
    Update,
    /// Reference lost: dead reckoning with the model.
    Predicting,
}

/// The estimate after one wheel sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// Timestamp, s.
    pub t_s: f64,
    /// Rear-axle centre, east, m.
    pub east_m: f64,
    /// Rear-axle centre, north, m.
    pub north_m: f64,
    /// Yaw, rad, counter-clockwise from east, wrapped to (−π, π].
    pub yaw_rad: f64,
    /// Rear wheel speed, m/s.
    pub speed_mps: f64,
    /// Heading rate, rad/s.
    pub yaw_rate_rps: f64,
    /// Phase after the sample.
    pub phase: Phase,
}

/// What a machine refused or found while it ran ([`Tedris::checks`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct MachineChecks {
    /// Courses refused as inconsistent with the wheels' turn.
    pub inconsistent_headings: u64,
    /// Courses not used while the car reversed.
    pub reversing_courses: u64,
    /// Courses skipped as repeats of the one before (a receiver holding
    /// its last course).
    #[serde(default)]
    pub repeated_courses: u64,
    /// Calibrations refused (worse out of sample, or at a physical bound).
    pub refused_calibrations: u64,
    /// Refits of the regressions installed once trained.
    #[serde(default)]
    pub accepted_refits: u64,
    /// Refits refused: significantly worse out of sample than the
    /// regressions they would replace.
    #[serde(default)]
    pub refused_refits: u64,
    /// Heading segments started.
    pub heading_segments: u32,
    /// Times the watchdog found the model off.
    pub model_alarms: u64,
    /// Samples rejected as invalid (not finite, time going backwards).
    pub rejected_samples: u64,
}

impl MachineChecks {
    /// One line for a table: what was refused, and how often.
    pub fn line(&self) -> String {
        format!(
            "TedriS checks: {} courses inconsistent with the wheels, {} while reversing, {} repeated, {} calibrations refused, {} refits accepted, {} refused, {} heading segments, {} watchdog alarms, {} samples rejected",
            self.inconsistent_headings,
            self.reversing_courses,
            self.repeated_courses,
            self.refused_calibrations,
            self.accepted_refits,
            self.refused_refits,
            self.heading_segments,
            self.model_alarms,
            self.rejected_samples
        )
    }
}

/// The streaming TedriS estimator. Serialises to JSON with its model and buffers.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Tedris {
    config: TedrisConfig,
    geometry: Geometry,
    phase: Phase,
    model: Option<TedrisModel>,
    history: History,
    former: Option<BlockFormer>,
    predictor: Predictor,
    recent: VecDeque<Tuple>,
    next_idx: u64,
    pending_from: u64,
    last_t: Option<f64>,
    /// (time, unwrapped antenna heading, raw yaw, rear-axle heading, usable).
    last_heading: Option<(f64, f64, f64, f64, bool)>,
    /// GNSS courses waiting for the wheel samples after them (the lever-arm
    /// conversion needs the yaw rate centred on the course's time).
    #[serde(default)]
    queued_headings: VecDeque<HeadingSample>,
    /// Time of the last reference heading received (queued or processed).
    #[serde(default)]
    last_heading_in_t: Option<f64>,
    heading_pairs: VecDeque<(f64, f64)>,
    /// (DR sample index, time, reference heading) waiting for their DR sample.
    #[serde(default)]
    deferred_pairs: VecDeque<(u64, f64, f64)>,
    position_pairs: VecDeque<(f64, f64, f64)>,
    heading_offset: f64,
    position_offset: (f64, f64),
    theta_dr: f64,
    pos_dr: (f64, f64),
    /// The dead-reckoned rear-axle position with the wheels' distances
    /// unscaled (see [`scale`]).
    #[serde(default)]
    pos_raw: (f64, f64),
    /// Fixes beside `pos_raw`, for the distance scale (see [`scale`]).
    #[serde(default)]
    chord_points: VecDeque<scale::ChordPoint>,
    speed_mps: f64,
    good_since: Option<f64>,
    last_update_t: f64,
    last_refit_t: f64,
    last_init_try_t: f64,
    rejected: u64,
    /// The current heading segment (see [`Sample::segment`]).
    #[serde(default)]
    segment: u32,
    /// Reference headings refused as inconsistent with the wheels' turn.
    #[serde(default)]
    inconsistent_headings: u64,
    /// GNSS courses not used because the car was reversing.
    #[serde(default)]
    reversing_courses: u64,
    /// GNSS courses skipped as repeats of the course before.
    #[serde(default)]
    repeated_courses: u64,
    /// Calibrations refused: worse out of sample than the model they would
    /// replace, or at a physical bound.
    #[serde(default)]
    refused_calibrations: u64,
    /// Refits of the regressions installed once trained (with the joint
    /// calibration: not significantly worse out of sample, or untestable).
    #[serde(default)]
    accepted_refits: u64,
    /// Refits refused: significantly worse out of sample than the current
    /// regressions (see `Tedris::refit_verdict`).
    #[serde(default)]
    refused_refits: u64,
    /// Calibrations that kept the current kind though another had the
    /// smaller held-back residual, not significantly smaller (see
    /// `machine/calibration.rs`, `kind_switch_evidence`).
    #[serde(default)]
    kept_kinds: u64,
    /// The incumbent of the kind switch on a machine started from a trained
    /// model: the trained model's kind, then the kind each joint
    /// calibration installed (a refit may have set the model's kind by its
    /// block statistics since); `None` while training from scratch, where
    /// every calibration takes the kind with the best held-back residual.
    #[serde(default)]
    calibrated_kind: Option<crate::config::ModelKind>,
    /// The joint calibration last installed, with its standard errors.
    #[serde(default)]
    last_calibration: Option<InstalledCalibration>,
    /// Why no model exists yet: the requirement that failed last, with numbers.
    #[serde(default)]
    untrained_because: Option<String>,
    /// The course convention found on the data (see [`course_convention`]),
    /// once decided; until then the course is taken as the antenna's.
    #[serde(default)]
    convention: Option<CourseConvention>,
    /// Times the watchdog found the model off (see `watch_heading`).
    #[serde(default)]
    model_alarms: u64,
    /// The watchdog's alarm is on.
    #[serde(default)]
    alarm_active: bool,
    /// When the last alarm went off, s.
    #[serde(default)]
    last_alarm_t: Option<f64>,
    /// The convention's fit when it was decided before the first model.
    #[serde(default)]
    pending_convention: Option<ConventionFit>,
}

impl Tedris {
    /// A machine that trains from scratch.
    pub fn new(config: TedrisConfig, geometry: Geometry) -> Result<Self, Error> {
        config.validate()?;
        if !(geometry.track_rear_m.is_finite()
            && geometry.track_rear_m > 0.0
            && geometry.lever_arm_m.is_finite())
        {
            return Err(Error::Config(format!("geometry {geometry:?} is not valid")));
        }
        let span = (crate::tuning::HISTORY_INIT_FACTOR * config.init_s).max(config.history_s);
        Ok(Tedris {
            history: History::new(span),
            config,
            geometry,
            phase: Phase::Blind,
            model: None,
            former: None,
            predictor: Predictor::default(),
            recent: VecDeque::new(),
            next_idx: 0,
            pending_from: 0,
            last_t: None,
            last_heading: None,
            queued_headings: VecDeque::new(),
            last_heading_in_t: None,
            heading_pairs: VecDeque::new(),
            deferred_pairs: VecDeque::new(),
            position_pairs: VecDeque::new(),
            heading_offset: 0.0,
            position_offset: (0.0, 0.0),
            theta_dr: 0.0,
            pos_dr: (0.0, 0.0),
            pos_raw: (0.0, 0.0),
            chord_points: VecDeque::new(),
            speed_mps: 0.0,
            good_since: None,
            last_update_t: f64::MIN,
            last_refit_t: f64::MIN,
            last_init_try_t: f64::MIN,
            rejected: 0,
            segment: 0,
            inconsistent_headings: 0,
            reversing_courses: 0,
            repeated_courses: 0,
            refused_calibrations: 0,
            accepted_refits: 0,
            refused_refits: 0,
            kept_kinds: 0,
            calibrated_kind: None,
            last_calibration: None,
            untrained_because: None,
            model_alarms: 0,
            alarm_active: false,
            last_alarm_t: None,
            convention: None,
            pending_convention: None,
        })
    }

    /// A machine that starts from a trained model (and keeps training on new data).
    pub fn with_model(model: TedrisModel, geometry: Geometry) -> Result<Self, Error> {
        model.validate()?;
        let mut m = Tedris::new(model.config.clone(), geometry)?;
        let c = &model.config;
        // This drive's samples are numbered after the model's blocks, so a
        // block's sequence number orders it in time across drives: numbered
        // from 0, a refit sorted the two drives' blocks into one another, and
        // the ARX kind's fit took blocks of different drives for neighbours.
        let start = model.repositories.all_sorted().last().map_or(0, |t| {
            t.seq + model.tau() as u64 + model.lag_samples.unsigned_abs() + 1
        });
        m.next_idx = start;
        m.pending_from = start;
        let mut former = BlockFormer::new(
            model.tau(),
            model.lag_samples,
            1,
            c.slt_max_change_deg.to_radians(),
            start,
        );
        former.mean = model.block_means();
        m.former = Some(former);
        m.convention = model.course_convention.map(|c| c.convention);
        // The trained model's kind is the incumbent of the first kind
        // switch on this drive (its calibrated values are that kind's).
        m.calibrated_kind =
            (model.complete && model.config.joint_calibration()).then_some(model.chosen);
        m.model = Some(model);
        m.fix_slt_window();
        Ok(m)
    }

    fn fix_slt_window(&mut self) {
        if let (Some(f), Some(m)) = (self.former.as_mut(), self.model.as_ref()) {
            f.slt_window = (self.config.slt_window_s / m.sample_period_s)
                .round()
                .max(1.0) as u64;
        }
    }

    /// Sets the current pose (for drives whose frame is defined by a known start pose).
    pub fn set_pose(&mut self, east_m: f64, north_m: f64, yaw_rad: f64) {
        self.position_offset = (east_m - self.pos_dr.0, north_m - self.pos_dr.1);
        self.heading_offset = yaw_rad - self.theta_dr;
    }

    /// The phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The model, once the first fit is done.
    pub fn model(&self) -> Option<&TedrisModel> {
        self.model.as_ref()
    }

    /// The recent wheel samples with their synchronised reference heading (diagnostics).
    pub fn history(&self) -> &History {
        &self.history
    }

    /// Samples rejected as invalid (non-finite values, time going backwards).
    pub fn rejected(&self) -> u64 {
        self.rejected
    }

    /// Courses at speed not used because their change since the previous
    /// course disagreed with the wheels' turn (a random course at low speed, a
    /// jump), or because no course within `max_heading_gap_s` before them
    /// could confirm them (the first course after a gap).
    pub fn inconsistent_headings(&self) -> u64 {
        self.inconsistent_headings
    }

    /// What the machine refused or found so far, in one value (for tables
    /// and `--json`).
    pub fn checks(&self) -> MachineChecks {
        MachineChecks {
            inconsistent_headings: self.inconsistent_headings,
            reversing_courses: self.reversing_courses,
            repeated_courses: self.repeated_courses,
            refused_calibrations: self.refused_calibrations,
            accepted_refits: self.accepted_refits,
            refused_refits: self.refused_refits,
            heading_segments: self.segment,
            model_alarms: self.model_alarms,
            rejected_samples: self.rejected,
        }
    }

    /// GNSS courses not used because the rear wheels rolled backwards
    /// (reversing): a receiver then reports the direction of motion, a frozen
    /// course or a random one.
    pub fn reversing_courses(&self) -> u64 {
        self.reversing_courses
    }

    /// Calibrations refused (worse on held-back data than the current model,
    /// or reaching a physical bound).
    pub fn refused_calibrations(&self) -> u64 {
        self.refused_calibrations
    }

    /// The joint calibration last installed: its rows, estimates and
    /// standard errors (the robust ones the model carries, and the OLS ones
    /// for comparison); `None` before the first.
    pub fn last_calibration(&self) -> Option<&InstalledCalibration> {
        self.last_calibration.as_ref()
    }

    /// Refits of the regressions installed once trained: with the joint
    /// calibration, those not significantly worse on held-back data than
    /// the regressions they replaced (or that could not be tested).
    pub fn accepted_refits(&self) -> u64 {
        self.accepted_refits
    }

    /// Refits refused: significantly worse on held-back data than the
    /// current regressions, or not calibratable within the physical bounds
    /// where they are (see the crate docs, "Nothing replaces a model unless
    /// it is better out of sample").
    pub fn refused_refits(&self) -> u64 {
        self.refused_refits
    }

    /// Calibrations that kept the current model kind though another kind
    /// had a smaller held-back heading residual, not significantly smaller
    /// (a kind switch needs strong evidence: the crate docs, "Nothing
    /// replaces a model unless it is better out of sample").
    pub fn kept_kinds(&self) -> u64 {
        self.kept_kinds
    }

    /// Without a model: the training requirement that failed last, with its
    /// numbers (e.g. too few synchronised samples, too little turning).
    pub fn untrained_because(&self) -> Option<&str> {
        self.untrained_because.as_deref()
    }

    /// Times the watchdog found the model off in the update phase: the
    /// dead-reckoned heading drifted from the reference faster than
    /// `tuning::MAX_HEADING_DRIFT_RPS` over the anchor window (each time, a
    /// calibration is due at once).
    pub fn model_alarms(&self) -> u64 {
        self.model_alarms
    }

    /// When the watchdog last found the model off, s.
    pub fn last_model_alarm_s(&self) -> Option<f64> {
        self.last_alarm_t
    }

    /// Heading segments started so far.
    pub fn segments(&self) -> u32 {
        self.segment
    }

    /// The state as JSON.
    pub fn to_json(&self) -> Result<String, Error> {
        serde_json::to_string(self).map_err(|e| Error::Json(e.to_string()))
    }

    /// A state saved by [`Tedris::to_json`].
    pub fn from_json(s: &str) -> Result<Self, Error> {
        let m: Tedris = serde_json::from_str(s).map_err(|e| Error::Json(e.to_string()))?;
        m.config.validate()?;
        if let Some(model) = &m.model {
            model.validate()?;
        }
        Ok(m)
    }

    /// The model's distance scale (1 without a model).
    fn distance_scale(&self) -> f64 {
        self.model.as_ref().map_or(1.0, |m| m.distance_scale.value)
    }

    fn heading_out(&self) -> f64 {
        self.theta_dr + self.heading_offset
    }

    fn lag(&self) -> i64 {
        self.model.as_ref().map_or(0, |m| m.lag_samples)
    }

    /// Feeds one wheel sample; returns the estimate after it.
    pub fn push_wheel(&mut self, w: WheelSample) -> Result<Estimate, Error> {
        if !(w.t_s.is_finite() && w.left_m.is_finite() && w.right_m.is_finite())
            || self.last_t.is_some_and(|t| w.t_s <= t)
        {
            self.rejected += 1;
            return Err(Error::Input(format!(
                "wheel sample at t={} s is not finite or not after the previous one",
                w.t_s
            )));
        }
        let dt = self.last_t.map_or(0.0, |t| w.t_s - t);
        self.last_t = Some(w.t_s);
        let omega = w.right_m - w.left_m;
        let dist = 0.5 * (w.left_m + w.right_m);
        let moving = crate::history::moving(omega, dist, dt);
        let rate = match &self.model {
            Some(m) => {
                let per_sample = if m.per_metre_straight { 0.0 } else { m.dcf_rad };
                let dcf = per_sample + m.dcf_distance_rad_per_m * dist;
                let r = self.predictor.step(m, omega, dist, dcf).total_rad;
                // Wheels at rest do not turn the car.
                if moving {
                    r
                } else {
                    0.0
                }
            }
            None => omega / self.geometry.track_rear_m,
        };
        let before = self.heading_out();
        self.theta_dr += rate;
        let mid = before + 0.5 * rate;
        let (c, s) = (mid.cos(), mid.sin());
        self.pos_raw.0 += dist * c;
        self.pos_raw.1 += dist * s;
        let travelled = dist * self.distance_scale();
        self.pos_dr.0 += travelled * c;
        self.pos_dr.1 += travelled * s;
        self.speed_mps = if dt > 0.0 { travelled / dt } else { 0.0 };
        let idx = self.next_idx;
        self.next_idx += 1;
        self.history.push(Sample {
            idx,
            t_s: w.t_s,
            dt_s: dt,
            omega_m: omega,
            dist_m: dist,
            theta_rad: None,
            theta_dr_rad: self.theta_dr,
            segment: 0,
            lever_rad: 0.0,
        });
        self.flush_headings(w.t_s);
        if !self.deferred_pairs.is_empty() {
            self.resolve_pairs(w.t_s);
        }
        self.advance_phase(w.t_s);
        let (e, n) = (
            self.pos_dr.0 + self.position_offset.0,
            self.pos_dr.1 + self.position_offset.1,
        );
        Ok(Estimate {
            t_s: w.t_s,
            east_m: e,
            north_m: n,
            yaw_rad: wrap(self.heading_out()),
            speed_mps: self.speed_mps,
            yaw_rate_rps: if dt > 0.0 { rate / dt } else { 0.0 },
            phase: self.phase,
        })
    }

    fn advance_phase(&mut self, t: f64) {
        let ref_ok = self
            .last_heading_in_t
            .is_some_and(|h| t - h <= self.config.reference_timeout_s);
        match (self.phase, ref_ok) {
            (Phase::Training | Phase::Update, false) => self.start_outage(),
            (Phase::Predicting | Phase::Blind, true) => {
                self.predictor.end_correction();
                self.good_since = Some(t);
                self.phase = Phase::Training;
            }
            (Phase::Training, true) => {
                let ready = self.model.as_ref().is_some_and(|m| m.complete);
                if ready
                    && self
                        .good_since
                        .is_some_and(|g| t - g >= self.config.retrain_s)
                {
                    self.phase = Phase::Update;
                    self.update_dcf(t);
                }
            }
            (Phase::Update, true) => {
                if self.last_refit_t == f64::MIN {
                    // A loaded model: the first refit comes one interval from now.
                    self.last_refit_t = t;
                }
                if t - self.last_refit_t >= self.config.refit_interval_s {
                    self.refit(t);
                } else if t - self.last_update_t >= self.config.update_interval_s {
                    self.update_dcf(t);
                }
            }
            (Phase::Predicting | Phase::Blind, false) => {}
        }
    }

    fn start_outage(&mut self) {
        let Some(model) = &self.model else {
            self.phase = Phase::Blind;
            return;
        };
        let fit = model.chosen_fit();
        let tau = model.tau() as u64;
        // The trailing run of contiguous blocks.
        let mut run: Vec<&Tuple> = Vec::new();
        for t in self.recent.iter().rev() {
            if run.last().is_some_and(|l| l.seq != t.seq + tau) {
                break;
            }
            run.push(t);
        }
        run.reverse();
        let e: Vec<f64> = run
            .iter()
            .filter_map(|t| {
                let r = design_row(fit.kind, t)?;
                let n = model.straight().bin(t.omega_m)?;
                Some(t.gamma_rad - fit.beta(n).iter().zip(&r).map(|(a, b)| a * b).sum::<f64>())
            })
            .collect();
        let u = fit.correction().innovations(&e);
        let skipped = run.last().map_or(0, |l| {
            (self.next_idx.saturating_sub(l.seq + tau) / tau) as usize
        });
        let model = model.clone();
        self.predictor.begin_correction(&model, e, u, skipped);
        self.phase = Phase::Predicting;
    }

    /// Feeds one GNSS antenna position.
    pub fn push_fix(&mut self, f: PositionFix) -> Result<(), Error> {
        if !(f.t_s.is_finite() && f.east_m.is_finite() && f.north_m.is_finite()) {
            self.rejected += 1;
            return Err(Error::Input(format!("fix at t={} s is not finite", f.t_s)));
        }
        let Some(t_last) = self.last_t else {
            return Ok(());
        };
        let yaw = self.heading_out();
        let ahead = (f.t_s - t_last).clamp(-1.0, 1.0) * self.speed_mps;
        let (c, s) = (yaw.cos(), yaw.sin());
        let (pe, pn) = (self.pos_dr.0 + ahead * c, self.pos_dr.1 + ahead * s);
        let l = self.geometry.lever_arm_m;
        let (me, mn) = (f.east_m - l * c, f.north_m - l * s);
        let raw_ahead = ahead / self.distance_scale();
        let raw = (
            self.pos_raw.0 + raw_ahead * c,
            self.pos_raw.1 + raw_ahead * s,
        );
        self.keep_chord_point(f.t_s, (me, mn), raw);
        self.position_pairs.push_back((f.t_s, me - pe, mn - pn));
        let win = self.config.position_anchor_window_s;
        while self
            .position_pairs
            .front()
            .is_some_and(|p| f.t_s - p.0 > win)
        {
            self.position_pairs.pop_front();
        }
        let n = self.position_pairs.len() as f64;
        self.position_offset = (
            self.position_pairs.iter().map(|p| p.1).sum::<f64>() / n,
            self.position_pairs.iter().map(|p| p.2).sum::<f64>() / n,
        );
        Ok(())
    }
}
