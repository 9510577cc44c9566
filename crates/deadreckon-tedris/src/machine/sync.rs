//! Heading synchronisation: reference headings (GNSS course or gyro heading)
//! turned into the rear-axle heading on the wheel clock, in heading segments
//! (never unwrapped across a gap, a stop, an unusable course or an outage),
//! checked against the wheels' turn; the course convention found on the data;
//! the heading anchor.

use super::*;
pub use crate::convention::{ConventionFit, CourseConvention};
use crate::tuning::*;

impl Tedris {
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
                .is_some_and(|q| hs.t_s - q.t_s > COURSE_QUEUE_S)
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
    pub(super) fn half_window(&self, t: f64) -> f64 {
        0.5 * self.last_heading.map_or(COURSE_INTERVAL_DEFAULT_S, |p| {
            (t - p.0).clamp(COURSE_INTERVAL_RANGE_S.0, COURSE_INTERVAL_RANGE_S.1)
        })
    }

    /// Processes the queued courses whose window is covered by wheel samples up to `t_wheel`.
    pub(super) fn flush_headings(&mut self, t_wheel: f64) {
        while let Some(q) = self.queued_headings.front().copied() {
            if t_wheel < q.t_s + self.half_window(q.t_s) {
                break;
            }
            self.queued_headings.pop_front();
            self.process_heading(q);
        }
    }

    /// The wheels' heading change over samples with `a < t ≤ b`, rad (nominal track).
    pub(super) fn wheel_turn(&self, a: f64, b: f64) -> f64 {
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

    pub(super) fn process_heading(&mut self, hs: HeadingSample) {
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
            // A course identical to the one before at low speed is no new
            // measurement: the receiver holds its last course (below its
            // speed threshold), and a course held since the car reversed
            // points backwards while the car pulls away, which the
            // consistency check cannot see (a held course does not change,
            // nor do the wheels turn much). It is skipped. Faster, a repeat
            // is a straight road in the course's resolution: kept.
            if prev.is_some_and(|p| p.2 == hs.yaw_rad) && v.abs() < HELD_COURSE_MAX_SPEED_MPS {
                self.repeated_courses += 1;
                return;
            }
            // Reversing (the rear wheels roll backwards), receivers differ: the
            // direction of motion (π from the heading), the last course at
            // speed frozen, or a random one. None is used; the consistency
            // check confirms the first course after.
            if v < 0.0 {
                usable = false;
                self.reversing_courses += 1;
            } else if v < self.config.min_course_speed_mps.max(1e-3) {
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
        // whole turns. A gyro heading is one integral over the whole drive
        // (the input integrates through gaps and outages): one segment.
        let continuing = if self.geometry.heading_is_course {
            prev.is_some_and(|p| p.4 && usable && gap_ok(&p))
        } else {
            prev.is_some()
        };
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
    pub(super) fn resolve_pairs(&mut self, t_now: f64) {
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
            self.heading_offset = anchor(&self.heading_pairs);
        }
        self.watch_heading(t_now);
    }

    /// The model's watchdog, in the update phase (a complete model, the
    /// reference good): the dead-reckoned heading must follow the reference.
    /// When their difference over the anchor window drifts faster than
    /// [`MAX_HEADING_DRIFT_RPS`], the model is off (a wrong gain or
    /// straight-line rate): the alarm is counted and a calibration is due at
    /// once (it replaces the values only if it does better on held-back
    /// data). The alarm clears below half the threshold.
    fn watch_heading(&mut self, t_now: f64) {
        if self.model.is_none() || self.phase != Phase::Update {
            return;
        }
        let pairs = &self.heading_pairs;
        let (Some(first), Some(last)) = (pairs.front(), pairs.back()) else {
            return;
        };
        if pairs.len() < WATCH_MIN_PAIRS
            || last.0 - first.0 < WATCH_MIN_SPAN * self.config.heading_anchor_window_s
        {
            return;
        }
        let n = pairs.len() as f64;
        let mt = pairs.iter().map(|p| p.0).sum::<f64>() / n;
        let md = pairs.iter().map(|p| p.1).sum::<f64>() / n;
        let stt: f64 = pairs.iter().map(|p| (p.0 - mt).powi(2)).sum();
        let std: f64 = pairs.iter().map(|p| (p.0 - mt) * (p.1 - md)).sum();
        if stt <= 0.0 {
            return;
        }
        let drift = (std / stt).abs();
        if drift > MAX_HEADING_DRIFT_RPS {
            if !self.alarm_active {
                self.alarm_active = true;
                self.model_alarms += 1;
                self.last_alarm_t = Some(t_now);
                // A calibration at the next wheel sample.
                self.last_update_t = f64::MIN;
            }
        } else if drift < 0.5 * MAX_HEADING_DRIFT_RPS {
            self.alarm_active = false;
        }
    }

    /// Decides the course convention on the history once it can
    /// ([`course_convention`]); with a body-yaw course the lever-arm angle is
    /// put back on every synchronised heading. True when the headings changed.
    pub(super) fn decide_convention(&mut self) -> bool {
        if !self.geometry.heading_is_course
            || self.geometry.lever_arm_m == 0.0
            || self.convention.is_some()
        {
            return false;
        }
        let Some(fit) = course_convention(&self.history, self.max_lag()) else {
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
}

/// The heading offset from (t, reference − DR) pairs: their mean.
pub(super) fn anchor(pairs: &VecDeque<(f64, f64)>) -> f64 {
    pairs.iter().map(|p| p.1).sum::<f64>() / pairs.len() as f64
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
            if rows.len() < MIN_CONVENTION_ROWS {
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
    if (ratio - 1.0).abs() < CONVENTION_MARGIN || n < MIN_CONVENTION_ROWS {
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
