//! Calibration while the reference is good: eq. (6) and the joint
//! calibration (DCF, heading per metre, turn gain) with an intercept per
//! heading segment, refused at physical bounds and accepted only when better
//! on held-back data; the heading lag.

use super::*;
use crate::stats::{correlation_time, increment_block_std, paired_batch_test, PairedTest};
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
        let tau = model.tau();
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
            // Eq. (6) gives no standard error.
            model.dcf_std_rad = None;
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
        for (j, s) in samples.iter().enumerate().skip(model.tau()) {
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
            x,
            y,
            fit,
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
        let kinds = calibration_kinds(model);
        let mut current_rms = f64::INFINITY;
        // Every kind that calibrates within the bounds, with its held-back
        // residuals.
        let mut candidates: Vec<Candidate> = Vec::new();
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
                    let held_residuals = held_residuals(
                        held,
                        held_segs,
                        c.dcf_rad,
                        c.distance_rad_per_m.unwrap_or(model.dcf_distance_rad_per_m),
                        c.gain.unwrap_or(model.turn_gain),
                    );
                    let rms = rms_of(&held_residuals);
                    if rms.is_finite() {
                        candidates.push(Candidate {
                            kind,
                            calibration: c,
                            rms,
                            fit_part: (fit_segs.to_vec(), rows.times[..split].to_vec()),
                            held_residuals,
                        });
                    }
                }
                None => refused = true,
            }
        }
        let Some(best) = candidates
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.rms.total_cmp(&b.1.rms))
            .map(|b| b.0)
        else {
            if refused {
                self.refused_calibrations += 1;
            }
            return;
        };
        // On a machine started from a trained model, a kind switch needs
        // clear evidence: the incumbent (the trained model's kind, then the
        // kind each calibration installed), itself recalibrated on the same
        // rows, must have a held-back mean square larger than the best
        // kind's by more than a margin ([`kind_switch_evidence`]); otherwise
        // the incumbent, recalibrated, is kept. While training from scratch
        // (no incumbent), and where the incumbent does not calibrate, the
        // best kind is taken.
        let mut pick = best;
        if let Some(incumbent) = self.calibrated_kind.filter(|&k| k != candidates[best].kind) {
            if let Some(cur) = candidates.iter().position(|c| c.kind == incumbent) {
                let (cu, be) = (&candidates[cur], &candidates[best]);
                if !kind_switch_evidence(&cu.held_residuals, &be.held_residuals) {
                    self.kept_kinds += 1;
                    pick = cur;
                }
            }
        }
        let Candidate {
            kind,
            calibration: c,
            rms,
            fit_part,
            ..
        } = candidates.swap_remove(pick);
        if rms > current_rms {
            self.refused_calibrations += 1;
            return;
        }
        let installed = InstalledCalibration::new(&c, &fit_part, t);
        let Some(model) = self.model.as_mut() else {
            return;
        };
        // The standard errors of the values installed; a term left out keeps
        // its value and the standard error it came with.
        let std = installed.std_error.as_ref();
        let se = |name: &str| {
            let j = installed.names.iter().position(|n| n == name)?;
            std.map(|s| s[j])
        };
        model.chosen = kind;
        // Only a machine started from a trained model holds an incumbent.
        if self.calibrated_kind.is_some() {
            self.calibrated_kind = Some(kind);
        }
        model.dcf_rad = c.dcf_rad;
        model.dcf_std_rad = se("dcf");
        if let Some(d) = c.distance_rad_per_m {
            model.dcf_distance_rad_per_m = d;
            model.dcf_distance_std_rad_per_m = se("dcf_distance");
        }
        if let Some(g) = c.gain {
            model.turn_gain = g;
            model.turn_gain_std = se("gain");
        }
        self.last_calibration = Some(installed);
    }
}

/// The kinds a joint calibration tries: every usable kind with the
/// automatic choice, else the chosen one.
fn calibration_kinds(model: &TedrisModel) -> Vec<crate::config::ModelKind> {
    if model.config.model == crate::config::ModelChoice::Auto {
        model
            .fits
            .iter()
            .map(|f| f.kind)
            .filter(|k| model.kind_usable(*k))
            .collect()
    } else {
        vec![model.chosen]
    }
}

/// What the refit guard decided ([`Tedris::refit_verdict`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum RefitVerdict {
    /// Not significantly worse out of sample than the current regressions.
    Accepted(PairedTest),
    /// Significantly worse out of sample (the test), or not calibratable
    /// within the physical bounds where the current regressions are.
    Refused(Option<PairedTest>),
    /// The test could not be made (too little held-back reference heading,
    /// no calibration of either within the bounds); the refit is installed
    /// as the paper does.
    Untested,
}

/// A model's heading residuals on the held-back part of the calibration
/// window, calibrated as [`Tedris::calibrate`] does on the part before.
#[derive(Debug)]
struct HeldBack {
    times: Vec<f64>,
    /// About each heading segment's mean, rad.
    residuals: Vec<f64>,
}

impl Tedris {
    /// The held-back residuals of `model` (see [`HeldBack`]): each kind the
    /// calibration would try is calibrated on the first `FIT_SHARE` of the
    /// window; the kind with the smallest held-back RMS gives the residuals.
    /// `None` with less than `min_calibration_span_s` of reference heading,
    /// or when no kind calibrates within the physical bounds.
    fn held_back(&self, model: &TedrisModel, t: f64) -> Option<HeldBack> {
        let mut best: Option<(f64, HeldBack)> = None;
        for kind in calibration_kinds(model) {
            let mut m = model.clone();
            m.chosen = kind;
            let rows = self.calibration_rows(&m, t);
            let (&first, &last) = (rows.times.first()?, rows.times.last()?);
            if last - first < model.config.min_calibration_span_s {
                return None;
            }
            let split = rows
                .times
                .partition_point(|&x| x < first + FIT_SHARE * (last - first));
            let (fit_rows, held) = rows.rows.split_at(split);
            let (fit_segs, held_segs) = rows.segments.split_at(split);
            let Some(c) = self.calibration_fit(&m, fit_rows, fit_segs) else {
                continue;
            };
            let (dist, gain) = (
                c.distance_rad_per_m.unwrap_or(model.dcf_distance_rad_per_m),
                c.gain.unwrap_or(model.turn_gain),
            );
            let residuals = held_residuals(held, held_segs, c.dcf_rad, dist, gain);
            let rms = rms_of(&residuals);
            if rms.is_finite() && best.as_ref().is_none_or(|b| rms < b.0) {
                let times = rows.times[split..].to_vec();
                best = Some((rms, HeldBack { times, residuals }));
            }
        }
        best.map(|b| b.1)
    }

    /// The refit guard: is `refit` (the regressions refitted on the
    /// repositories) worse out of sample than `current`? Both are
    /// calibrated on the first `FIT_SHARE` of the calibration window as
    /// the joint calibration would be (every kind it tries, the best on the
    /// held-back rest), and their squared heading residuals on the held-back
    /// rest are compared row by row: a paired t test over
    /// `REFIT_TEST_BATCHES` batch means ([`crate::stats::paired_batch_test`])
    /// of non-inferiority, the refit's squares against the current ones
    /// grown by `REFIT_TEST_MARGIN`. The refit is refused when it is worse
    /// by more than the margin at the one-sided level `REFIT_TEST_LEVEL`, or
    /// when it cannot be calibrated within the physical bounds and the
    /// current regressions can.
    ///
    /// Why refused only when significantly worse, not accepted only when
    /// significantly better: a refit adds the blocks since the last one to
    /// the same repositories, and the joint calibration absorbs the linear
    /// part of any regression, so once calibrated the two have the same
    /// held-back residual (to 1e-9 in 95 % of the refits on the family's
    /// cars 1–12): "significantly better" is never reached and would freeze
    /// the regressions after training. What the held-back stretch can show
    /// is harm: a refit that took in blocks the heading contradicts.
    pub(super) fn refit_verdict(
        &self,
        current: &TedrisModel,
        refit: &TedrisModel,
        t: f64,
    ) -> RefitVerdict {
        let (new, old) = match (self.held_back(refit, t), self.held_back(current, t)) {
            (Some(n), Some(o)) => (n, o),
            (None, Some(_)) => return RefitVerdict::Refused(None),
            _ => return RefitVerdict::Untested,
        };
        if new.times != old.times {
            return RefitVerdict::Untested;
        }
        // Non-inferiority: the refit's squared residuals against the current
        // ones grown by the margin.
        let new_sq: Vec<f64> = new.residuals.iter().map(|e| e * e).collect();
        let old_sq: Vec<f64> = old
            .residuals
            .iter()
            .map(|e| e * e * (1.0 + REFIT_TEST_MARGIN))
            .collect();
        // Batches at least REFIT_TEST_DECORRELATIONS correlation times of
        // the loss difference long, so that their means are independent.
        let d: Vec<f64> = new_sq.iter().zip(&old_sq).map(|(a, b)| a - b).collect();
        let (Some(tc), Some(&t0), Some(&t1)) = (
            correlation_time(&d, &new.times),
            new.times.first(),
            new.times.last(),
        ) else {
            return RefitVerdict::Untested;
        };
        let fit = ((t1 - t0) / (REFIT_TEST_DECORRELATIONS * tc)).floor();
        if tc <= 0.0 || fit.is_nan() || fit < REFIT_TEST_MIN_BATCHES as f64 {
            return RefitVerdict::Untested;
        }
        let batches = (fit as usize).min(REFIT_TEST_BATCHES);
        match paired_batch_test(&new_sq, &old_sq, batches) {
            Some(p) if p.p_a_larger < REFIT_TEST_LEVEL => RefitVerdict::Refused(Some(p)),
            Some(p) => RefitVerdict::Accepted(p),
            None => RefitVerdict::Untested,
        }
    }
}

/// One kind calibrated by [`Tedris::calibrate`].
struct Candidate {
    kind: crate::config::ModelKind,
    calibration: Calibration,
    /// RMS of `held_residuals`, rad.
    rms: f64,
    /// The fit rows' segments and times (for the standard errors).
    fit_part: FitRows,
    /// Heading residuals on the held-back stretch, about each segment's
    /// mean, rad.
    held_residuals: Vec<f64>,
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
    rms_of(&held_residuals(rows, segments, dcf, dist, gain))
}

/// The heading residuals of calibration values on `rows`, about each
/// heading segment's mean, rad.
fn held_residuals(rows: &[[f64; 4]], segments: &[u32], dcf: f64, dist: f64, gain: f64) -> Vec<f64> {
    let mut e: Vec<Vec<f64>> = rows
        .iter()
        .map(|r| vec![r[3] - dcf * r[0] - dist * r[1] - (gain - 1.0) * r[2]])
        .collect();
    centre_per_segment(&mut e, segments);
    e.into_iter().map(|r| r[0]).collect()
}

/// The RMS of `e`; infinite without values.
fn rms_of(e: &[f64]) -> f64 {
    if e.is_empty() {
        return f64::INFINITY;
    }
    (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
}

/// Whether the held-back residuals justify leaving the incumbent kind for
/// a challenger, both recalibrated on the same rows: the challenger's mean
/// squared residual grown by `KIND_SWITCH_MARGIN` must still be below the
/// incumbent's.
fn kind_switch_evidence(incumbent: &[f64], challenger: &[f64]) -> bool {
    let ms = |e: &[f64]| e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64;
    incumbent.len() == challenger.len()
        && !incumbent.is_empty()
        && ms(challenger) * (1.0 + KIND_SWITCH_MARGIN) < ms(incumbent)
}

/// The heading segments and times of a calibration's fit rows.
type FitRows = (Vec<u32>, Vec<f64>);

/// The result of one joint calibration.
#[derive(Debug, Clone)]
struct Calibration {
    dcf_rad: f64,
    distance_rad_per_m: Option<f64>,
    gain: Option<f64>,
    /// The design and response (centred per heading segment) and the fit,
    /// for the standard errors of the values it installs.
    x: Vec<Vec<f64>>,
    y: Vec<f64>,
    fit: crate::stats::OlsFit,
}

/// The joint calibration last installed ([`Tedris::last_calibration`]):
/// what its values rest on and their standard errors, with the OLS ones for
/// comparison.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InstalledCalibration {
    /// When it was made (the machine's time), s.
    pub t_s: f64,
    /// Rows of the fit (samples with a reference heading on the first
    /// `FIT_SHARE` of the calibration window).
    pub rows: usize,
    /// The fitted columns: `dcf` (rad per moving sample), `dcf_distance`
    /// (rad per metre), `gain` (turn gain − 1, whose standard error is the
    /// gain's).
    pub names: Vec<String>,
    /// The estimates, in `names` order.
    pub estimates: Vec<f64>,
    /// The autocorrelation-robust standard errors
    /// ([`crate::stats::increment_block_std`]), in `names` order; `None`:
    /// not estimated, for the reason in `not_estimated_because`.
    pub std_error: Option<Vec<f64>>,
    /// Why `std_error` is `None`.
    pub not_estimated_because: Option<String>,
    /// Blocks of the robust standard errors (0 when not estimated).
    pub blocks: usize,
    /// Correlation time of the heading residual increments, s (`None`
    /// when not estimated).
    pub correlation_time_s: Option<f64>,
    /// The ordinary least-squares standard errors, in `names` order: they
    /// take the cumulative heading's residuals as independent, which they
    /// are not (random-walk-like), and come out several times too small.
    /// Kept for comparison only; never installed.
    pub ols_std_error: Vec<f64>,
}

impl InstalledCalibration {
    fn new(c: &Calibration, (segments, times): &FitRows, t: f64) -> Self {
        let robust = increment_block_std(
            &c.x,
            &c.fit.residuals(&c.x, &c.y),
            segments,
            times,
            CALIBRATION_STD_BLOCKS,
            CALIBRATION_STD_DECORRELATIONS,
        );
        let (std_error, not_estimated_because, blocks, correlation_time_s) = match robust {
            Ok(b) => (
                Some(b.std_error),
                None,
                b.blocks,
                Some(b.correlation_time_s),
            ),
            Err(e) => (None, Some(e.to_string()), 0, None),
        };
        let co = &c.fit.coefficients;
        InstalledCalibration {
            t_s: t,
            rows: c.x.len(),
            names: co.iter().map(|k| k.name.clone()).collect(),
            estimates: co.iter().map(|k| k.estimate).collect(),
            std_error,
            not_estimated_because,
            blocks,
            correlation_time_s,
            ols_std_error: co.iter().map(|k| k.std_error).collect(),
        }
    }
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

#[cfg(test)]
mod tests;
