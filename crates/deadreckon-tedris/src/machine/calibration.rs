//! Calibration while the reference is good: eq. (6) and the joint
//! calibration (DCF, heading per metre, turn gain) with an intercept per
//! heading segment, refused at physical bounds and accepted only when better
//! on held-back data; the heading lag.

use super::*;
use crate::tuning::*;

impl Tedris {
    /// Eq. (6): the DCF minimising the RMSE between the reference heading and the
    /// DR heading over the last `update_window_s` (the constant offset removed).
    pub(super) fn update_dcf(&mut self, t: f64) {
        self.last_update_t = t;
        self.calibrate_scale();
        if self
            .model
            .as_ref()
            .is_some_and(|m| m.config.joint_calibration())
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
        if pairs.len() < 2 * tau.max(MIN_DCF_PAIRS) {
            return;
        }
        let segs: Vec<u32> = pairs.iter().map(|p| p.2).collect();
        // The RMS difference with an offset per heading segment.
        let cost = |dcf: f64| {
            let d: Vec<f64> = pairs
                .iter()
                .map(|&(i, th, _)| th - (cum[i].0 + dcf * cum[i].1))
                .collect();
            rms_about_segment_means(&d, &segs)
        };
        let (lo, hi) = (
            model.dcf0_rad - model.dcf_bound_rad,
            model.dcf0_rad + model.dcf_bound_rad,
        );
        let (x, _) = brent(
            cost,
            lo,
            hi,
            model.dcf_bound_rad * BRENT_TOLERANCE,
            BRENT_ITERATIONS,
        );
        // A minimum at the bound of the search is refused, not kept.
        let edge = BOUND_EDGE * model.dcf_bound_rad;
        if !(x > lo + edge && x < hi - edge) {
            self.refused_calibrations += 1;
            return;
        }
        if x.is_finite() {
            // dcf_smoothing = 1 is eq. (6) as in the paper; below 1 the new
            // estimate is blended into the previous one.
            let w = model.config.dcf_smoothing;
            model.dcf_rad = w * x + (1.0 - w) * model.dcf_rad;
        }
    }

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
        if rows.len() < MIN_HEADING_FIT_ROWS {
            return None;
        }
        let mut cols_all: Vec<Vec<f64>> = rows.iter().map(|r| r.to_vec()).collect();
        centre_per_segment(&mut cols_all, segments);
        let col = |i: usize| cols_all.iter().map(move |r| r[i]);
        let ss = |i: usize| col(i).map(|v| v * v).sum::<f64>();
        // The distance column must differ from the sample count: speed must vary.
        let (skk, sdd) = (ss(0), ss(1));
        let skd: f64 = cols_all.iter().map(|r| r[0] * r[1]).sum();
        let use_d = skk > 0.0 && sdd > 0.0 && skd * skd / (skk * sdd) < MAX_DISTANCE_COLLINEARITY;
        let (lo, hi) = col(2).fold((f64::MAX, f64::MIN), |(l, h), v| (l.min(v), h.max(v)));
        let use_g = model.config.turn_gain() && hi - lo > MIN_TURNING_RAD;
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
    pub(super) fn calibrate(&mut self, t: f64) {
        let Some(model) = self.model.as_ref() else {
            return;
        };
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
                .partition_point(|&x| x < first + FIT_SHARE * (last - first));
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
pub(super) fn held_rms(rows: &[[f64; 4]], segments: &[u32], dcf: f64, dist: f64, gain: f64) -> f64 {
    if rows.is_empty() {
        return f64::INFINITY;
    }
    let e: Vec<f64> = rows
        .iter()
        .map(|r| r[3] - dcf * r[0] - dist * r[1] - (gain - 1.0) * r[2])
        .collect();
    rms_about_segment_means(&e, segments)
}

/// The result of one joint calibration.
#[derive(Debug, Clone, Copy)]
struct Calibration {
    dcf_rad: f64,
    distance_rad_per_m: Option<f64>,
    gain: Option<f64>,
}

/// The lag h ∈ ±`max_lag` for which the reference heading is best explained
/// (least squares) by the wheels' cumulative sums h samples earlier:
/// `θ_ref(k) ≈ c0 + a·Σω(k − h) + b·Σd(k − h) + e·k`. The per-sample
/// cross-correlation of ω with increments of a course interpolated between 4 Hz
/// fixes has a flat, noisy peak (±3 samples on the simulated car); the heading
/// itself pins the lag through the shape of every turn. `None` with fewer than
/// 200 usable samples, or when the best lag is at ±`max_lag` (a fit at its
/// bound is refused, not kept).
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
        if rows.len() < MIN_HEADING_FIT_ROWS {
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
    // A lag at the edge of the search is a fit at its bound: refused (the
    // caller falls back to the cross-correlation peak).
    best.map(|b| b.1).filter(|l| l.abs() < ml)
}
