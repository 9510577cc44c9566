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
use crate::history::{centre_per_segment, masked_ccf, BlockFormer, History, Sample};
use crate::minimise::brent;
use crate::model::{design_row, TedrisModel};
use crate::predict::Predictor;
use crate::repository::{Repositories, StraightLine, Tuple};
use crate::Error;
use deadreckon_core::angle::wrap;

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
    /// Calibrations refused: worse out of sample than the model they would
    /// replace, or at a physical bound.
    #[serde(default)]
    refused_calibrations: u64,
    /// Why no model exists yet: the requirement that failed last, with numbers.
    #[serde(default)]
    untrained_because: Option<String>,
    /// The course convention found on the data (see [`course_convention`]),
    /// once decided; until then the course is taken as the antenna's.
    #[serde(default)]
    convention: Option<CourseConvention>,
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
        let cap = (4 * config.init_samples).max(config.history_samples);
        Ok(Tedris {
            history: History::new(cap),
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
            speed_mps: 0.0,
            good_since: None,
            last_update_t: f64::MIN,
            last_refit_t: f64::MIN,
            last_init_try_t: f64::MIN,
            rejected: 0,
            segment: 0,
            inconsistent_headings: 0,
            refused_calibrations: 0,
            untrained_because: None,
            convention: None,
            pending_convention: None,
        })
    }

    /// A machine that starts from a trained model (and keeps training on new data).
    pub fn with_model(model: TedrisModel, geometry: Geometry) -> Result<Self, Error> {
        model.validate()?;
        let mut m = Tedris::new(model.config.clone(), geometry)?;
        let c = &model.config;
        let mut former = BlockFormer::new(
            c.tau_samples,
            model.lag_samples,
            1,
            c.slt_max_change_deg.to_radians(),
            0,
        );
        former.use_mean = c.block_mean;
        m.former = Some(former);
        m.convention = model.course_convention.map(|c| c.convention);
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

    /// Reference headings not used because their change since the previous one
    /// disagreed with the wheels' turn (a random course at low speed, a jump).
    pub fn inconsistent_headings(&self) -> u64 {
        self.inconsistent_headings
    }

    /// Calibrations refused (worse on held-back data than the current model,
    /// or reaching a physical bound).
    pub fn refused_calibrations(&self) -> u64 {
        self.refused_calibrations
    }

    /// Without a model: the training requirement that failed last, with its
    /// numbers (e.g. too few synchronised samples, too little turning).
    pub fn untrained_because(&self) -> Option<&str> {
        self.untrained_because.as_deref()
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
        self.pos_dr.0 += dist * mid.cos();
        self.pos_dr.1 += dist * mid.sin();
        self.speed_mps = if dt > 0.0 { dist / dt } else { 0.0 };
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
        let tau = model.config.tau_samples as u64;
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

    /// Feeds one reference heading. A GNSS course (with a lever arm) is held
    /// until the wheel samples up to half a fix interval after it have arrived:
    /// its conversion to the rear-axle heading uses the yaw rate centred on its
    /// time (a yaw rate from the samples before it lags by half an interval,
    /// which skews the heading increments through every turn entry and exit and
    /// attenuates the fitted slope α1 by about 1.5 % on the simulated car).
    pub fn push_heading(&mut self, hs: HeadingSample) -> Result<(), Error> {
        if !(hs.t_s.is_finite() && hs.yaw_rad.is_finite())
            || self.last_heading_in_t.is_some_and(|t| hs.t_s <= t)
        {
            self.rejected += 1;
            return Err(Error::Input(format!(
                "heading at t={} s is not finite or not after the previous one",
                hs.t_s
            )));
        }
        self.last_heading_in_t = Some(hs.t_s);
        if self.geometry.heading_is_course && self.geometry.lever_arm_m != 0.0 {
            self.queued_headings.push_back(hs);
            // A course more than 1 s older than the newest is processed with the
            // samples there are (wheel samples missing).
            while self
                .queued_headings
                .front()
                .is_some_and(|q| hs.t_s - q.t_s > 1.0)
            {
                if let Some(q) = self.queued_headings.pop_front() {
                    self.process_heading(q);
                }
            }
            if let Some(t) = self.last_t {
                self.flush_headings(t);
            }
        } else {
            self.process_heading(hs);
        }
        Ok(())
    }

    /// Half-width of the lever-arm window of a course at `t`, s.
    fn half_window(&self, t: f64) -> f64 {
        0.5 * self
            .last_heading
            .map_or(0.25, |p| (t - p.0).clamp(0.1, 0.5))
    }

    /// Processes the queued courses whose window is covered by wheel samples up to `t_wheel`.
    fn flush_headings(&mut self, t_wheel: f64) {
        while let Some(q) = self.queued_headings.front().copied() {
            if t_wheel < q.t_s + self.half_window(q.t_s) {
                break;
            }
            self.queued_headings.pop_front();
            self.process_heading(q);
        }
    }

    /// The wheels' heading change over samples with `a < t ≤ b`, rad (nominal track).
    fn wheel_turn(&self, a: f64, b: f64) -> f64 {
        let mut w = 0.0;
        for s in self.history.iter().rev() {
            if s.t_s <= a {
                break;
            }
            if s.t_s <= b {
                w += s.omega_m;
            }
        }
        w / self.geometry.track_rear_m
    }

    fn process_heading(&mut self, hs: HeadingSample) {
        let prev = self.last_heading;
        let gap_ok = |p: &(f64, f64, f64, f64, bool)| hs.t_s - p.0 <= self.config.max_heading_gap_s;
        // A GNSS course is the antenna's: the antenna moves at atan(l ψ̇ / v) from the
        // rear-axle heading. ψ̇ and v are the wheels' over the fix interval centred
        // on the course's time (samples whose mid-time lies within ± half the
        // interval since the previous heading); slow courses are not used, nor
        // courses whose change since the previous one disagrees with the wheels'
        // turn (receivers report random courses at low speed).
        let mut usable = true;
        let mut lever = 0.0;
        if self.geometry.heading_is_course {
            let hw = self.half_window(hs.t_s);
            let (w0, w1) = (hs.t_s - hw, hs.t_s + hw);
            let (mut sw, mut sd, mut st) = (0.0, 0.0, 0.0);
            for s in self.history.iter().rev() {
                let mid = s.t_s - 0.5 * s.dt_s;
                if mid <= w0 {
                    break;
                }
                if mid <= w1 && s.dt_s.is_finite() {
                    sw += s.omega_m;
                    sd += s.dist_m;
                    st += s.dt_s;
                }
            }
            let v = if st > 0.0 { sd / st } else { 0.0 };
            if v.abs() < self.config.min_course_speed_mps.max(1e-3) {
                usable = false;
            } else {
                let yaw_rate = sw / self.geometry.track_rear_m / st;
                if self.convention.is_none_or(|c| c.is_antenna()) {
                    lever = (self.geometry.lever_arm_m * yaw_rate / v).atan();
                }
                let consistent = prev.is_some_and(|p| {
                    gap_ok(&p)
                        && (wrap(hs.yaw_rad - p.2) - self.wheel_turn(p.0, hs.t_s)).abs()
                            <= self.config.course_consistency_rad
                });
                if !consistent {
                    usable = false;
                    self.inconsistent_headings += 1;
                }
            }
        }
        // Unwrap only within a segment; a new segment starts on the branch
        // nearest the dead-reckoned heading, so a stop or an outage never adds
        // whole turns.
        let continuing = prev.is_some_and(|p| p.4 && usable && gap_ok(&p));
        let theta = match prev {
            Some((_, th, raw, _, _)) if continuing => th + wrap(hs.yaw_rad - raw),
            _ => {
                let near = self.heading_out() + lever;
                near + wrap(hs.yaw_rad - near)
            }
        };
        if usable && !continuing {
            self.segment += 1;
        }
        let theta_m = theta - lever;
        self.last_heading = Some((hs.t_s, theta, hs.yaw_rad, theta_m, usable));
        if self.good_since.is_none() {
            self.good_since = Some(hs.t_s);
        }
        // Synchronise: every pending wheel sample up to this heading gets its θ,
        // linearly interpolated between the two rear-axle headings around it.
        let lag = self.lag();
        let mut assigned = Vec::new();
        while self.pending_from < self.next_idx {
            let idx = self.pending_from;
            let Some(s) = self.history.get(idx).copied() else {
                self.pending_from += 1;
                continue;
            };
            if s.t_s > hs.t_s {
                break;
            }
            self.pending_from += 1;
            let Some((tp, _, _, thp, prev_usable)) = prev else {
                continue;
            };
            if !(usable && prev_usable) || hs.t_s - tp > self.config.max_heading_gap_s || s.t_s < tp
            {
                continue;
            }
            let a = if hs.t_s > tp {
                (s.t_s - tp) / (hs.t_s - tp)
            } else {
                1.0
            };
            let th = thp + a * (theta_m - thp);
            let lever_p = prev.map_or(0.0, |p| p.1 - p.3);
            if let Some(m) = self.history.get_mut(idx) {
                m.theta_rad = Some(th);
                m.segment = self.segment;
                m.lever_rad = lever_p + a * (lever - lever_p);
            }
            assigned.push((idx, s.t_s, th));
        }
        for (idx, t, th) in assigned {
            let src = idx as i64 - lag;
            if src < 0 {
                continue;
            }
            // With a negative lag the reference leads the wheels: the DR heading
            // it pairs with comes with a later wheel sample.
            self.deferred_pairs.push_back((src as u64, t, th));
        }
        self.resolve_pairs(hs.t_s);
        self.train(hs.t_s);
    }

    /// Turns the deferred (DR sample, time, reference) triples whose DR sample
    /// exists into anchor pairs and updates the heading offset.
    fn resolve_pairs(&mut self, t_now: f64) {
        let newest = self.next_idx.saturating_sub(1);
        let mut added = false;
        while let Some(&(src, t, th)) = self.deferred_pairs.front() {
            if self.next_idx == 0 || src > newest {
                break;
            }
            self.deferred_pairs.pop_front();
            if let Some(dr) = self.history.get(src).map(|s| s.theta_dr_rad) {
                let d = self.heading_offset + wrap(th - dr - self.heading_offset);
                self.heading_pairs.push_back((t, d));
                added = true;
            }
        }
        if !added {
            return;
        }
        let win = self.config.heading_anchor_window_s;
        while self
            .heading_pairs
            .front()
            .is_some_and(|p| t_now - p.0 > win)
        {
            self.heading_pairs.pop_front();
        }
        if !self.heading_pairs.is_empty() {
            self.heading_offset = anchor(&self.heading_pairs, t_now, self.config.anchor_trend);
        }
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
        let (pe, pn) = (
            self.pos_dr.0 + ahead * yaw.cos(),
            self.pos_dr.1 + ahead * yaw.sin(),
        );
        let l = self.geometry.lever_arm_m;
        let (me, mn) = (f.east_m - l * yaw.cos(), f.north_m - l * yaw.sin());
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

    /// Forms blocks and fits, after new samples were synchronised.
    fn train(&mut self, t: f64) {
        let final_upto = self.pending_from.saturating_sub(1);
        if self.model.is_none() {
            if t - self.last_init_try_t >= 1.0 {
                let n = self.history.gamma_count();
                if n >= self.config.init_samples {
                    self.last_init_try_t = t;
                    self.init(t, final_upto);
                } else {
                    self.untrained_because = Some(format!(
                        "{n} wheel samples have a synchronised reference heading on both sides; init_samples needs {}",
                        self.config.init_samples
                    ));
                }
            }
            return;
        }
        let Some(former) = self.former.as_mut() else {
            return;
        };
        let tuples = former.form(&self.history, final_upto);
        let Some(model) = self.model.as_mut() else {
            return;
        };
        for tu in tuples {
            model.repositories.insert(tu);
            self.recent.push_back(tu);
        }
        while self.recent.len() > 32 {
            self.recent.pop_front();
        }
        if !model.complete && model.repositories.complete(model.config.required_bins) {
            self.refit(t);
        }
    }

    fn sample_period(&self) -> f64 {
        let dts: Vec<f64> = self
            .history
            .iter()
            .map(|s| s.dt_s)
            .filter(|d| d.is_finite() && *d > 0.0)
            .collect();
        let p = crate::stats::median(&dts);
        if p.is_finite() {
            p
        } else {
            0.04
        }
    }

    /// First fit: the lag from the cross-correlation over the history, the blocks,
    /// the straight-line band and the repositories. Waits (returns) while the
    /// cross-correlation peak is below `min_ccf_peak` (too little turning yet).
    fn init(&mut self, t: f64, final_upto: u64) {
        let ccf = masked_ccf(&self.history, self.config.max_lag_samples);
        let peak = ccf_peak_value(&ccf);
        let full = self.history.len() >= self.history.capacity();
        if peak < self.config.min_ccf_peak && !full {
            self.untrained_because = Some(format!(
                "the cross-correlation peak of ω and γ is {peak:.3}; min_ccf_peak needs {} (too little turning yet)",
                self.config.min_ccf_peak
            ));
            return;
        }
        let ccf = if self.decide_convention() {
            masked_ccf(&self.history, self.config.max_lag_samples)
        } else {
            ccf
        };
        self.rebuild(t, final_upto, ccf);
    }

    /// Rebuilds the repositories from the history with the lag of `ccf`.
    fn rebuild(&mut self, t: f64, final_upto: u64, ccf: crate::ccf::CrossCorrelation) -> bool {
        let c = &self.config;
        let lag = self.choose_lag(&ccf);
        let period = self.sample_period();
        let slt_window = (c.slt_window_s / period).round().max(1.0) as u64;
        let start = self.history.span().map_or(0, |s| s.0);
        let mut former = BlockFormer::new(
            c.tau_samples,
            lag,
            slt_window,
            c.slt_max_change_deg.to_radians(),
            start,
        );
        former.use_mean = c.block_mean;
        let tuples = former.form(&self.history, final_upto);
        let Some(straight) = straight_line(&tuples, c.epsilon_factor) else {
            self.untrained_because = Some(format!(
                "{} blocks of tau_samples = {} are too few for the straight-line parameters",
                tuples.len(),
                c.tau_samples
            ));
            return false;
        };
        let mut repos = Repositories::new(straight, c.min_fill, c.max_fill);
        for tu in &tuples {
            repos.insert(*tu);
        }
        let per_metre =
            c.per_metre_straight && c.joint_calibration && self.geometry.heading_is_course;
        match TedrisModel::fit(c.clone(), period, lag, ccf, repos) {
            Ok(mut model) => {
                model.per_metre_straight = per_metre;
                model.course_convention = self
                    .model
                    .as_ref()
                    .and_then(|m| m.course_convention)
                    .or(self.pending_convention);
                model.settle_kind();
                self.recent = tuples.iter().rev().take(32).rev().copied().collect();
                self.model = Some(model);
                self.estimate_gain();
                self.former = Some(former);
                self.last_refit_t = t;
                self.update_dcf(t);
                self.untrained_because = None;
                true
            }
            Err(e) => {
                if self.model.is_none() {
                    self.untrained_because = Some(format!("the first fit failed: {e}"));
                }
                false
            }
        }
    }

    /// Decides the course convention on the history once it can
    /// ([`course_convention`]); with a body-yaw course the lever-arm angle is
    /// put back on every synchronised heading. True when the headings changed.
    fn decide_convention(&mut self) -> bool {
        if !self.geometry.heading_is_course
            || self.geometry.lever_arm_m == 0.0
            || self.convention.is_some()
        {
            return false;
        }
        let Some(fit) = course_convention(&self.history, self.config.max_lag_samples) else {
            return false;
        };
        self.convention = Some(fit.convention);
        if let Some(m) = self.model.as_mut() {
            m.course_convention = Some(fit);
        } else {
            self.pending_convention = Some(fit);
        }
        if fit.convention.is_antenna() {
            return false;
        }
        let idx: Vec<u64> = self.history.iter().map(|s| s.idx).collect();
        for i in idx {
            if let Some(s) = self.history.get_mut(i) {
                if let Some(th) = s.theta_rad.as_mut() {
                    *th += s.lever_rad;
                }
                s.lever_rad = 0.0;
            }
        }
        // The last heading's value too, for the next interpolation.
        if let Some(h) = self.last_heading.as_mut() {
            h.3 = h.1;
        }
        true
    }

    /// The lag h: from the heading fit ([`heading_lag`]) when `lag_from_heading`
    /// is on and it has the data, else at the cross-correlation peak.
    fn choose_lag(&self, ccf: &crate::ccf::CrossCorrelation) -> i64 {
        let from_ccf = ccf.peak_lag_within(self.config.lag_tolerance);
        if self.config.lag_from_heading {
            heading_lag(&self.history, self.config.max_lag_samples).unwrap_or(from_ccf)
        } else {
            from_ccf
        }
    }

    /// Refit. Until training first completes, the lag is re-estimated on the
    /// history, and a different lag with a higher correlation peak rebuilds the
    /// repositories from the history; otherwise (and always once complete) the
    /// regressions are refitted on the repositories as they are.
    fn refit(&mut self, t: f64) {
        self.last_refit_t = t;
        if self.convention.is_none() && self.decide_convention() {
            // The history's headings changed: rebuild the blocks on them.
            let final_upto = self.pending_from.saturating_sub(1);
            let ccf = masked_ccf(&self.history, self.config.max_lag_samples);
            if self.rebuild(t, final_upto, ccf) {
                return;
            }
        }
        let Some(old) = &self.model else { return };
        let ccf = masked_ccf(&self.history, self.config.max_lag_samples);
        let better =
            self.config.lag_from_heading || ccf_peak_value(&ccf) > ccf_peak_value(&old.ccf);
        if !old.complete && self.choose_lag(&ccf) != old.lag_samples && better {
            let final_upto = self.pending_from.saturating_sub(1);
            if self.rebuild(t, final_upto, ccf) {
                return;
            }
        }
        let Some(old) = &self.model else { return };
        let convention = old.course_convention;
        let (gain, per_metre, dist, dcf, joint) = (
            old.turn_gain,
            old.per_metre_straight,
            old.dcf_distance_rad_per_m,
            old.dcf_rad,
            old.config.joint_calibration,
        );
        if let Ok(mut m) = TedrisModel::fit(
            old.config.clone(),
            old.sample_period_s,
            old.lag_samples,
            old.ccf.clone(),
            old.repositories.clone(),
        ) {
            m.turn_gain = gain;
            m.per_metre_straight = per_metre;
            m.course_convention = convention;
            m.settle_kind();
            if joint {
                // The calibrated values stand until a calibration beats them.
                m.dcf_distance_rad_per_m = dist;
                m.dcf_rad = dcf;
            }
            self.model = Some(m);
        }
        self.estimate_gain();
        self.update_dcf(t);
    }

    fn estimate_gain(&mut self) {
        let Some(model) = self.model.as_mut() else {
            return;
        };
        if !model.config.turn_gain || model.config.joint_calibration {
            return;
        }
        let samples: Vec<Sample> = self.history.iter().copied().collect();
        let seg = (model.config.gain_segment_s / model.sample_period_s).round() as usize;
        if let Some(g) = crate::gain::estimate_turn_gain(model, &samples, seg) {
            model.turn_gain = g;
        }
    }

    /// Eq. (6): the DCF minimising the RMSE between the reference heading and the
    /// DR heading over the last `update_window_s` (the constant offset removed).
    fn update_dcf(&mut self, t: f64) {
        self.last_update_t = t;
        if self
            .model
            .as_ref()
            .is_some_and(|m| m.config.joint_calibration)
        {
            self.calibrate(t);
            return;
        }
        let Some(model) = self.model.as_mut() else {
            return;
        };
        let tau = model.config.tau_samples;
        let lag = model.lag_samples;
        let t0 = t - model.config.update_window_s;
        let samples: Vec<Sample> = self.history.iter().copied().collect();
        let Some(first) = samples.iter().position(|s| s.t_s >= t0) else {
            return;
        };
        let warm = first.saturating_sub(tau);
        let mut p = Predictor::default();
        let mut cum = Vec::with_capacity(samples.len() - warm);
        let (mut acc, mut n) = (0.0, 0.0);
        for (k, s) in samples[warm..].iter().enumerate() {
            let r = p.step(model, s.omega_m, s.dist_m, 0.0);
            if warm + k >= first && s.moving() {
                acc += r.base_rad;
                n += 1.0;
            }
            if warm + k >= first {
                cum.push((acc, n));
            }
        }
        let win = &samples[first..];
        let pairs: Vec<(usize, f64, u32)> = win
            .iter()
            .enumerate()
            .filter_map(|(j, s)| {
                let th = s.theta_rad?;
                let src = usize::try_from(j as i64 - lag)
                    .ok()
                    .filter(|&i| i < cum.len())?;
                Some((src, th, s.segment))
            })
            .collect();
        if pairs.len() < 2 * tau.max(10) {
            return;
        }
        let segs: Vec<u32> = pairs.iter().map(|p| p.2).collect();
        // The RMS difference with an offset per heading segment.
        let cost = |dcf: f64| {
            let mut d: Vec<Vec<f64>> = pairs
                .iter()
                .map(|&(i, th, _)| vec![th - (cum[i].0 + dcf * cum[i].1)])
                .collect();
            centre_per_segment(&mut d, &segs);
            (d.iter().map(|v| v[0] * v[0]).sum::<f64>() / d.len() as f64).sqrt()
        };
        let (lo, hi) = (
            model.dcf0_rad - model.dcf_bound_rad,
            model.dcf0_rad + model.dcf_bound_rad,
        );
        let (x, _) = brent(cost, lo, hi, model.dcf_bound_rad * 1e-6, 200);
        // A minimum at the bound of the search is refused, not kept.
        let edge = 1e-3 * model.dcf_bound_rad;
        if !(x > lo + edge && x < hi - edge) {
            self.refused_calibrations += 1;
            return;
        }
        if x.is_finite() && model.config.dcf_update {
            // dcf_smoothing = 1 is eq. (6) as in the paper; below 1 the new
            // estimate is blended into the previous one.
            let w = model.config.dcf_smoothing;
            model.dcf_rad = w * x + (1.0 - w) * model.dcf_rad;
        }
    }
}

impl Tedris {
    /// The rows of the joint calibration over the last `calibration_window_s`
    /// for `model` (see [`Tedris::calibrate`]). Over minutes the reference
    /// heading is far more accurate than in 30 s windows or block increments,
    /// so the numbers that decide the drift in an outage come out 10–100 times
    /// more precise.
    fn calibration_rows(&self, model: &TedrisModel, t: f64) -> CalibrationRows {
        let mut unit = model.clone();
        unit.turn_gain = 1.0;
        let lag = model.lag_samples;
        let t0 = t - model.config.calibration_window_s;
        let samples: Vec<&Sample> = self.history.iter().filter(|s| s.t_s >= t0).collect();
        let mut p = Predictor::default();
        let (mut k, mut b, mut d, mut tr) = (0.0, 0.0, 0.0, 0.0);
        let mut cum = Vec::with_capacity(samples.len());
        for s in &samples {
            let r = p.step(&unit, s.omega_m, s.dist_m, 0.0);
            // Only moving samples turn the heading (as in `push_wheel`).
            if s.moving() {
                k += 1.0;
                b += r.base_rad;
                d += s.dist_m;
                tr += r.turn_rad;
            }
            cum.push((k, b, d, tr));
        }
        let mut out = CalibrationRows::default();
        for (j, s) in samples.iter().enumerate().skip(model.config.tau_samples) {
            let Some(th) = s.theta_rad else { continue };
            let Some(src) = usize::try_from(j as i64 - lag).ok() else {
                continue;
            };
            let Some(&(ck, cb, cd, ct)) = cum.get(src) else {
                continue;
            };
            out.rows.push([ck, cd, ct, th - cb]);
            out.segments.push(s.segment);
            out.times.push(s.t_s);
        }
        out
    }

    /// The joint calibration fitted on `rows` (see [`Tedris::calibrate`]);
    /// `None` without enough support, or when an estimate reaches a physical
    /// bound (the fit is then refused, not clamped).
    fn calibration_fit(
        &self,
        model: &TedrisModel,
        rows: &[[f64; 4]],
        segments: &[u32],
    ) -> Option<Calibration> {
        if rows.len() < 200 {
            return None;
        }
        let mut cols_all: Vec<Vec<f64>> = rows.iter().map(|r| r.to_vec()).collect();
        centre_per_segment(&mut cols_all, segments);
        let col = |i: usize| cols_all.iter().map(move |r| r[i]);
        let ss = |i: usize| col(i).map(|v| v * v).sum::<f64>();
        // The distance column must differ from the sample count: speed must vary.
        let (skk, sdd) = (ss(0), ss(1));
        let skd: f64 = cols_all.iter().map(|r| r[0] * r[1]).sum();
        let use_d = skk > 0.0 && sdd > 0.0 && skd * skd / (skk * sdd) < 0.999;
        let (lo, hi) = col(2).fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
        let use_g = model.config.turn_gain && hi - lo > 1.0;
        let per_metre = model.per_metre_straight;
        // In the per-metre form the distance term is the whole straight-line rate.
        let use_d = use_d || (per_metre && sdd > 0.0);
        let mut cols = if per_metre { vec![] } else { vec![0usize] };
        if use_d {
            cols.push(1);
        }
        if use_g {
            cols.push(2);
        }
        let x: Vec<Vec<f64>> = cols_all
            .iter()
            .map(|r| cols.iter().map(|&i| r[i]).collect())
            .collect();
        // A term left out keeps its current value.
        let (old_d, old_g) = (model.dcf_distance_rad_per_m, model.turn_gain);
        let y: Vec<f64> = cols_all
            .iter()
            .map(|r| {
                r[3] - if use_d { 0.0 } else { old_d * r[1] }
                    - if use_g { 0.0 } else { (old_g - 1.0) * r[2] }
            })
            .collect();
        let mut names = if per_metre { vec![] } else { vec!["dcf"] };
        if use_d {
            names.push("dcf_distance");
        }
        if use_g {
            names.push("gain");
        }
        if names.is_empty() {
            return None;
        }
        let fit = crate::stats::ols(&x, &y, &names).ok()?;
        let beta = fit.beta();
        if !beta.iter().all(|v| v.is_finite()) {
            return None;
        }
        let b = &model.config;
        let mut c = Calibration {
            dcf_rad: if per_metre { 0.0 } else { beta[0] },
            distance_rad_per_m: None,
            gain: None,
        };
        let mut k = usize::from(!per_metre);
        if use_d {
            c.distance_rad_per_m = Some(beta[k]);
            k += 1;
        }
        if use_g {
            c.gain = Some(1.0 + beta[k]);
        }
        // Physical bounds: a fit reaching one is refused.
        let max_d = b.max_radius_mismatch / self.geometry.track_rear_m;
        let within = (per_metre || (c.dcf_rad - model.dcf0_rad).abs() <= model.dcf_bound_rad)
            && c.distance_rad_per_m.is_none_or(|d| d.abs() <= max_d)
            && c.gain.is_none_or(|g| (g - 1.0).abs() <= b.max_gain_error);
        within.then_some(c)
    }

    /// The joint calibration, the update phase of eq. (6) generalised. The
    /// model (turn gain 1, no DCF) is replayed over the last
    /// `calibration_window_s`; with n the count of moving samples, Σb, Σd, ΣT
    /// its cumulative heading, distance and turning part (γ̂(ω) − γ̂(straight
    /// line)) up to sample k − h,
    ///
    /// `θ_ref(k) − Σb = c_s + DCF·n + DCF_d·Σd + (g − 1)·ΣT`
    ///
    /// is solved by least squares with an intercept c_s per heading segment s
    /// (a course is never unwrapped across a stop or a gap): DCF (rad per
    /// moving sample), the distance term DCF_d (rad per metre: unequal rear
    /// radii) and the turn gain g. Columns without support are left out and
    /// keep their values.
    ///
    /// Nothing replaces the current values unless it is better out of sample:
    /// the fit uses the first three quarters of the window, and is accepted
    /// only when its heading residual on the last quarter (per-segment
    /// intercepts) is no larger than the current model's, after at least
    /// `min_calibration_span_s` of reference heading. With the automatic model
    /// choice the kind is chosen by the same held-back residual.
    fn calibrate(&mut self, t: f64) {
        let Some(model) = self.model.as_ref() else {
            return;
        };
        if !model.config.dcf_update {
            return;
        }
        let kinds: Vec<crate::config::ModelKind> =
            if model.config.model == crate::config::ModelChoice::Auto {
                model
                    .fits
                    .iter()
                    .map(|f| f.kind)
                    .filter(|k| model.kind_usable(*k))
                    .collect()
            } else {
                vec![model.chosen]
            };
        let mut current_rms = f64::INFINITY;
        let mut best: Option<(crate::config::ModelKind, Calibration, f64)> = None;
        let mut refused = false;
        for kind in kinds {
            let mut m = model.clone();
            m.chosen = kind;
            let rows = self.calibration_rows(&m, t);
            let (Some(&first), Some(&last)) = (rows.times.first(), rows.times.last()) else {
                return;
            };
            if last - first < model.config.min_calibration_span_s {
                return;
            }
            let split = rows
                .times
                .partition_point(|&x| x < first + 0.75 * (last - first));
            let (fit_rows, held) = rows.rows.split_at(split);
            let (fit_segs, held_segs) = rows.segments.split_at(split);
            if kind == model.chosen {
                current_rms = held_rms(
                    held,
                    held_segs,
                    model.dcf_rad,
                    model.dcf_distance_rad_per_m,
                    model.turn_gain,
                );
            }
            match self.calibration_fit(&m, fit_rows, fit_segs) {
                Some(c) => {
                    let rms = held_rms(
                        held,
                        held_segs,
                        c.dcf_rad,
                        c.distance_rad_per_m.unwrap_or(model.dcf_distance_rad_per_m),
                        c.gain.unwrap_or(model.turn_gain),
                    );
                    if rms.is_finite() && best.as_ref().is_none_or(|b| rms < b.2) {
                        best = Some((kind, c, rms));
                    }
                }
                None => refused = true,
            }
        }
        let Some((kind, c, rms)) = best else {
            if refused {
                self.refused_calibrations += 1;
            }
            return;
        };
        if rms > current_rms {
            self.refused_calibrations += 1;
            return;
        }
        let Some(model) = self.model.as_mut() else {
            return;
        };
        model.chosen = kind;
        model.dcf_rad = c.dcf_rad;
        if let Some(d) = c.distance_rad_per_m {
            model.dcf_distance_rad_per_m = d;
        }
        if let Some(g) = c.gain {
            model.turn_gain = g;
        }
    }
}

/// The rows of a joint calibration: `[n, Σd, ΣT, θ − Σb]` with each row's
/// heading segment and time.
#[derive(Debug, Default)]
struct CalibrationRows {
    rows: Vec<[f64; 4]>,
    segments: Vec<u32>,
    times: Vec<f64>,
}

/// The RMS heading residual of calibration values on `rows`, with an
/// intercept per segment; infinite without rows.
fn held_rms(rows: &[[f64; 4]], segments: &[u32], dcf: f64, dist: f64, gain: f64) -> f64 {
    if rows.is_empty() {
        return f64::INFINITY;
    }
    let mut e: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| vec![r[3] - dcf * r[0] - dist * r[1] - (gain - 1.0) * r[2]])
        .collect();
    centre_per_segment(&mut e, segments);
    (e.iter().map(|v| v[0] * v[0]).sum::<f64>() / e.len() as f64).sqrt()
}

/// The result of one joint calibration.
#[derive(Debug, Clone, Copy)]
struct Calibration {
    dcf_rad: f64,
    distance_rad_per_m: Option<f64>,
    gain: Option<f64>,
}

/// The heading offset from (t, reference − DR) pairs: their mean, or with
/// `trend` the least-squares line through them evaluated at `t_now` (the DR
/// heading may drift within the window, e.g. through a turn).
fn anchor(pairs: &VecDeque<(f64, f64)>, t_now: f64, trend: bool) -> f64 {
    let n = pairs.len() as f64;
    let mt = pairs.iter().map(|p| p.0).sum::<f64>() / n;
    let md = pairs.iter().map(|p| p.1).sum::<f64>() / n;
    if !trend || pairs.len() < 10 {
        return md;
    }
    let stt: f64 = pairs.iter().map(|p| (p.0 - mt).powi(2)).sum();
    let std: f64 = pairs.iter().map(|p| (p.0 - mt) * (p.1 - md)).sum();
    if stt <= 0.0 {
        return md;
    }
    md + std / stt * (t_now - mt)
}

/// The lag h ∈ ±`max_lag` for which the reference heading is best explained
/// (least squares) by the wheels' cumulative sums h samples earlier:
/// `θ_ref(k) ≈ c0 + a·Σω(k − h) + b·Σd(k − h) + e·k`. The per-sample
/// cross-correlation of ω with increments of a course interpolated between 4 Hz
/// fixes has a flat, noisy peak (±3 samples on the simulated car); the heading
/// itself pins the lag through the shape of every turn. `None` with fewer than
/// 200 usable samples.
pub fn heading_lag(h: &History, max_lag: usize) -> Option<i64> {
    let samples: Vec<&Sample> = h.iter().collect();
    let mut cw = Vec::with_capacity(samples.len());
    let mut cd = Vec::with_capacity(samples.len());
    let (mut w, mut d) = (0.0, 0.0);
    for s in &samples {
        w += s.omega_m;
        d += s.dist_m;
        cw.push(w);
        cd.push(d);
    }
    let ml = max_lag as i64;
    let mut best: Option<(f64, i64)> = None;
    for lag in -ml..=ml {
        // Rows [Σω, Σd, k, θ] with an intercept per heading segment.
        let mut rows = Vec::new();
        let mut segs = Vec::new();
        for (j, s) in samples.iter().enumerate() {
            let Some(th) = s.theta_rad else { continue };
            let Some(src) = usize::try_from(j as i64 - lag).ok() else {
                continue;
            };
            let Some(&w) = cw.get(src) else { continue };
            rows.push(vec![w, cd[src], j as f64, th]);
            segs.push(s.segment);
        }
        if rows.len() < 200 {
            return None;
        }
        centre_per_segment(&mut rows, &segs);
        let (x, y): (Vec<Vec<f64>>, Vec<f64>) =
            rows.into_iter().map(|r| (r[..3].to_vec(), r[3])).unzip();
        let fit = crate::stats::ols(&x, &y, &["omega", "distance", "rate"]).ok()?;
        if best.is_none_or(|b| fit.rss < b.0) {
            best = Some((fit.rss, lag));
        }
    }
    best.map(|b| b.1)
}

/// What a GNSS course is the direction of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CourseConvention {
    /// The antenna's velocity: the rear-axle heading plus atan(l·ψ̇/v).
    AntennaVelocity,
    /// The body's yaw (receivers fusing an IMU or two antennas).
    BodyYaw,
}

impl CourseConvention {
    /// True for [`CourseConvention::AntennaVelocity`].
    pub fn is_antenna(self) -> bool {
        self == CourseConvention::AntennaVelocity
    }
}

/// The convention found on a drive, with its evidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConventionFit {
    /// The convention chosen.
    pub convention: CourseConvention,
    /// Residual sum of squares of the heading fit taking the course as the
    /// body's yaw over that taking it as the antenna's (each at its best lag).
    pub rss_ratio: f64,
}

/// Which convention the synchronised headings of `h` support: the heading
/// (with the lever-arm angle taken off, as for an antenna course) is fitted on
/// the wheels' cumulative sums at the best lag within ±`max_lag` plus a column of the lever-arm
/// angle λ, with an intercept per heading segment. If the course is the
/// antenna's, λ's coefficient is 0; if it is the body's yaw, taking λ off was
/// wrong and the coefficient is −1. `None` while the data cannot tell (a
/// standard error above 0.15: too few turns at low speed).
pub fn course_convention(h: &History, max_lag: usize) -> Option<ConventionFit> {
    let samples: Vec<&Sample> = h.iter().collect();
    let (mut w, mut d) = (0.0, 0.0);
    let mut cum = Vec::with_capacity(samples.len());
    for s in &samples {
        w += s.omega_m;
        d += s.dist_m;
        cum.push((w, d));
    }
    let ml = max_lag as i64;
    // The smallest residual over the lags, for the heading as an antenna
    // course (θ, the lever angle taken off) and as a body yaw (θ + λ): the
    // heading on [Σω, Σd, k] with an intercept per segment (segments are
    // runs of consecutive samples), by the normal equations.
    let best_rss = |body: bool| -> Option<(f64, usize)> {
        let mut best: Option<(f64, usize)> = None;
        let mut rows: Vec<([f64; 4], u32)> = Vec::with_capacity(samples.len());
        for lag in -ml..=ml {
            rows.clear();
            for (j, s) in samples.iter().enumerate() {
                let Some(th) = s.theta_rad else { continue };
                let Some(&(cw, cd)) = usize::try_from(j as i64 - lag)
                    .ok()
                    .and_then(|i| cum.get(i))
                else {
                    continue;
                };
                let th = if body { th + s.lever_rad } else { th };
                rows.push(([cw, cd, j as f64, th], s.segment));
            }
            if rows.len() < 500 {
                return None;
            }
            let mut xtx = vec![vec![0.0; 3]; 3];
            let mut xty = [0.0; 3];
            let mut yty = 0.0;
            for run in rows.chunk_by(|a, b| a.1 == b.1) {
                let n = run.len() as f64;
                let mut m = [0.0; 4];
                for (r, _) in run {
                    for (a, v) in m.iter_mut().zip(r) {
                        *a += v / n;
                    }
                }
                for (r, _) in run {
                    let c = [r[0] - m[0], r[1] - m[1], r[2] - m[2], r[3] - m[3]];
                    for i in 0..3 {
                        xty[i] += c[i] * c[3];
                        for j in 0..3 {
                            xtx[i][j] += c[i] * c[j];
                        }
                    }
                    yty += c[3] * c[3];
                }
            }
            let Some(inv) = crate::stats::invert(&xtx) else {
                continue;
            };
            let beta: Vec<f64> = (0..3)
                .map(|i| (0..3).map(|j| inv[i][j] * xty[j]).sum())
                .collect();
            let rss = yty - (0..3).map(|i| beta[i] * xty[i]).sum::<f64>();
            if rss.is_finite() && best.is_none_or(|b| rss < b.0) {
                best = Some((rss, rows.len()));
            }
        }
        best
    };
    let (antenna, n) = best_rss(false)?;
    let (body, _) = best_rss(true)?;
    // Decided only on a clear difference (10 % of the residual): an antenna
    // course looks like a body yaw delayed by l/v, which a lag imitates at
    // one speed, so only speed changes in turns tell them apart.
    let ratio = body / antenna;
    if (ratio - 1.0).abs() < 0.1 || n < 500 {
        return None;
    }
    Some(ConventionFit {
        convention: if ratio < 1.0 {
            CourseConvention::BodyYaw
        } else {
            CourseConvention::AntennaVelocity
        },
        rss_ratio: ratio,
    })
}

fn ccf_peak_value(c: &crate::ccf::CrossCorrelation) -> f64 {
    c.values.iter().copied().fold(f64::MIN, f64::max)
}

/// The straight-line parameters from the blocks flagged straight; the quietest
/// tenth of the blocks (smallest |γ|) stand in when fewer than 10 are flagged.
pub fn straight_line(tuples: &[Tuple], epsilon_factor: Option<f64>) -> Option<StraightLine> {
    let flagged: Vec<f64> = tuples
        .iter()
        .filter(|t| t.straight)
        .map(|t| t.omega_m)
        .collect();
    if flagged.len() >= 10 {
        return StraightLine::from_omegas(&flagged, epsilon_factor, false);
    }
    let mut by_gamma: Vec<&Tuple> = tuples.iter().collect();
    by_gamma.sort_by(|a, b| a.gamma_rad.abs().total_cmp(&b.gamma_rad.abs()));
    let k = (tuples.len() / 10).max(3).min(tuples.len());
    let quiet: Vec<f64> = by_gamma[..k].iter().map(|t| t.omega_m).collect();
    StraightLine::from_omegas(&quiet, epsilon_factor, true)
}
