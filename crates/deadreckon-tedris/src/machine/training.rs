//! Training: the first fit (lag, blocks, straight line, repositories), the
//! refits, and the turn gain of module `gain` (without the joint calibration).

use super::*;
use crate::tuning::*;

impl Tedris {
    /// Forms blocks and fits, after new samples were synchronised.
    pub(super) fn train(&mut self, t: f64) {
        let final_upto = self.pending_from.saturating_sub(1);
        if self.model.is_none() {
            if t - self.last_init_try_t >= INIT_RETRY_S {
                let n = self.history.gamma_count();
                let need = (self.config.init_s / self.sample_period()).round() as usize;
                if n >= need {
                    self.last_init_try_t = t;
                    self.init(t, final_upto);
                } else {
                    self.untrained_because = Some(format!(
                        "{:.1} s of wheel samples have a synchronised reference heading on both sides; init_s needs {}",
                        n as f64 * self.sample_period(),
                        self.config.init_s
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
        while self.recent.len() > RECENT_BLOCKS {
            self.recent.pop_front();
        }
        if !model.complete && model.repositories.complete(model.config.required_bins) {
            self.refit(t);
        }
    }

    /// The reference heading's turning in the history: the sum of |Δθ| over
    /// one-second steps within heading segments, rad.
    pub(super) fn reference_turning(&self) -> f64 {
        let step = (1.0 / self.sample_period()).round().max(1.0) as usize;
        let pts: Vec<(f64, u32)> = self
            .history
            .iter()
            .step_by(step)
            .filter_map(|s| Some((s.theta_rad?, s.segment)))
            .collect();
        pts.windows(2)
            .filter(|w| w[0].1 == w[1].1)
            .map(|w| (w[1].0 - w[0].0).abs())
            .sum()
    }

    /// `max_lag_s` in wheel samples.
    pub(super) fn max_lag(&self) -> usize {
        (self.config.max_lag_s / self.sample_period()).round() as usize
    }

    pub(super) fn sample_period(&self) -> f64 {
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
            DEFAULT_SAMPLE_PERIOD_S
        }
    }

    /// First fit: the lag from the cross-correlation over the history, the blocks,
    /// the straight-line band and the repositories. Waits (returns) while the
    /// cross-correlation peak is below `min_ccf_peak` and, in the extended
    /// variant, the reference has turned less than `MIN_TRAINING_TURN_RAD`
    /// (too little turning yet).
    pub(super) fn init(&mut self, t: f64, final_upto: u64) {
        let ccf = masked_ccf(&self.history, self.max_lag());
        let peak = ccf_peak_value(&ccf);
        let full = self.history.full();
        // The extended variant asks for turning itself (rate-independent);
        // the per-sample correlation peak falls with the wheel rate's noise.
        let turned = self.config.variant == crate::config::Variant::Extended
            && self.reference_turning() >= MIN_TRAINING_TURN_RAD;
        if peak < self.config.min_ccf_peak && !full && !turned {
            let turning = if self.config.variant == crate::config::Variant::Extended {
                format!(
                    ", and the reference turned {:.2} rad of the {:.2} that would do instead",
                    self.reference_turning(),
                    MIN_TRAINING_TURN_RAD
                )
            } else {
                String::new()
            };
            self.untrained_because = Some(format!(
                "the cross-correlation peak of ω and γ is {peak:.3}; min_ccf_peak needs {}{turning} (too little turning yet)",
                self.config.min_ccf_peak
            ));
            return;
        }
        let ccf = if self.decide_convention() {
            masked_ccf(&self.history, self.max_lag())
        } else {
            ccf
        };
        self.rebuild(t, final_upto, ccf);
    }

    /// Rebuilds the repositories from the history with the lag of `ccf`.
    pub(super) fn rebuild(
        &mut self,
        t: f64,
        final_upto: u64,
        ccf: crate::ccf::CrossCorrelation,
    ) -> bool {
        let lag = self.choose_lag(&ccf);
        let period = self.sample_period();
        let extended = self.config.variant == crate::config::Variant::Extended;
        let blocks = if extended {
            self.quantised_blocks(period)
        } else {
            None
        };
        let c = &self.config;
        let tau = blocks.map_or(c.tau_samples, |b| b.tau_samples);
        let slt_window = (c.slt_window_s / period).round().max(1.0) as u64;
        let start = self.history.span().map_or(0, |s| s.0);
        let mut former = BlockFormer::new(
            tau,
            lag,
            slt_window,
            c.slt_max_change_deg.to_radians(),
            start,
        );
        former.mean = blocks.is_some();
        let tuples = former.form(&self.history, final_upto);
        let Some(straight) = straight_line(&tuples, c.epsilon_factor) else {
            self.untrained_because = Some(format!(
                "{} blocks of tau = {} samples are too few for the straight-line parameters",
                tuples.len(),
                tau
            ));
            return false;
        };
        let mut repos = Repositories::new(straight, c.min_fill, c.max_fill);
        for tu in &tuples {
            repos.insert(*tu);
        }
        // The per-metre form cannot use the ARX kind: a user who fixes ARX
        // gets the per-sample form instead (what the model reports).
        let per_metre = c.per_metre_straight()
            && c.joint_calibration()
            && self.geometry.heading_is_course
            && c.model != crate::config::ModelChoice::Fixed(crate::config::ModelKind::Arx);
        match TedrisModel::fit(c.clone(), period, lag, ccf, repos, blocks) {
            Ok(mut model) => {
                model.per_metre_straight = per_metre;
                // A rebuilt model keeps the scale (the tyres did not change).
                if let Some(old) = &self.model {
                    model.distance_scale = old.distance_scale;
                }
                model.course_convention = self
                    .model
                    .as_ref()
                    .and_then(|m| m.course_convention)
                    .or(self.pending_convention);
                model.settle_kind();
                if let Err(why) = self.accept(&mut model) {
                    if self.model.is_none() {
                        self.untrained_because = Some(why);
                    }
                    return false;
                }
                self.recent = tuples
                    .iter()
                    .rev()
                    .take(RECENT_BLOCKS)
                    .rev()
                    .copied()
                    .collect();
                self.model = Some(model);
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

    /// The lag h: from the heading fit ([`heading_lag`]) in the extended variant
    /// when it has the data, else at the cross-correlation peak.
    pub(super) fn choose_lag(&self, ccf: &crate::ccf::CrossCorrelation) -> i64 {
        let from_ccf = ccf.peak_lag_within(self.config.lag_tolerance);
        if self.config.lag_from_heading() {
            heading_lag(&self.history, self.max_lag()).unwrap_or(from_ccf)
        } else {
            from_ccf
        }
    }

    /// Refit. Until training first completes, the lag is re-estimated on the
    /// history, and a different lag with a higher correlation peak rebuilds the
    /// repositories from the history; otherwise (and always once complete) the
    /// regressions are refitted on the repositories as they are.
    pub(super) fn refit(&mut self, t: f64) {
        self.last_refit_t = t;
        if self.convention.is_none() && self.decide_convention() {
            // The history's headings changed: rebuild the blocks on them.
            let final_upto = self.pending_from.saturating_sub(1);
            let ccf = masked_ccf(&self.history, self.max_lag());
            if self.rebuild(t, final_upto, ccf) {
                return;
            }
        }
        let Some(old) = &self.model else { return };
        let ccf = masked_ccf(&self.history, self.max_lag());
        let better =
            self.config.lag_from_heading() || ccf_peak_value(&ccf) > ccf_peak_value(&old.ccf);
        if !old.complete && self.choose_lag(&ccf) != old.lag_samples && better {
            let final_upto = self.pending_from.saturating_sub(1);
            if self.rebuild(t, final_upto, ccf) {
                return;
            }
        }
        let Some(old) = &self.model else { return };
        let guarded = old.complete && old.config.joint_calibration();
        let convention = old.course_convention;
        let scale = old.distance_scale;
        let (gain, per_metre, dist, dcf, joint) = (
            old.turn_gain,
            old.per_metre_straight,
            old.dcf_distance_rad_per_m,
            old.dcf_rad,
            old.config.joint_calibration(),
        );
        let (gain_std, dist_std, dcf_std) = (
            old.turn_gain_std,
            old.dcf_distance_std_rad_per_m,
            old.dcf_std_rad,
        );
        if let Ok(mut m) = old.refit() {
            m.turn_gain = gain;
            m.turn_gain_std = gain_std;
            m.distance_scale = scale;
            m.per_metre_straight = per_metre;
            m.course_convention = convention;
            m.settle_kind();
            if joint {
                // The calibrated values stand until a calibration beats them.
                m.dcf_distance_rad_per_m = dist;
                m.dcf_rad = dcf;
                m.dcf_distance_std_rad_per_m = dist_std;
                m.dcf_std_rad = dcf_std;
            }
            if self.accept(&mut m).is_err() {
                // A refit the physical acceptance refuses never replaces
                // the current model.
                self.refused_refits += 1;
            } else if self.guard_refit(&m, guarded, t) {
                self.model = Some(m);
            }
        }
        self.update_dcf(t);
    }
}

impl Tedris {
    /// The blocks for quantised wheel ticks in the history
    /// ([`crate::blocks`]; `None`: the configuration's τ and medians).
    pub(super) fn quantised_blocks(&self, period: f64) -> Option<crate::blocks::QuantisedBlocks> {
        let q = crate::blocks::wheel_resolution(self.history.iter())?;
        let signal =
            crate::blocks::turn_signal_m(self.history.iter(), self.geometry.track_rear_m, period)?;
        crate::blocks::choose(q, signal, period, self.config.tau_samples)
    }

    /// The physical acceptance of a fitted model ([`crate::acceptance`]) in
    /// the extended variant (the paper variant is the paper's alone):
    /// `Err` with the failed checks when the model is refused.
    pub(crate) fn accept(&self, model: &mut TedrisModel) -> Result<(), String> {
        if model.config.variant != crate::config::Variant::Extended {
            return Ok(());
        }
        let expected = crate::acceptance::expected_ccf_peak(
            &self.history,
            model.lag_samples,
            model.sample_period_s,
        );
        let acc = crate::acceptance::check(model, self.geometry.track_rear_m, expected);
        crate::acceptance::apply(model, acc)
    }

    /// The refit at the end of a training drive ([`crate::train`]), guarded
    /// like every refit once trained: false when refused (counted).
    pub(crate) fn closing_refit_accepted(&mut self, refit: &TedrisModel) -> bool {
        let (Some(t), Some(m)) = (self.last_t, self.model.as_ref()) else {
            return true;
        };
        let guarded = m.complete && m.config.joint_calibration();
        self.guard_refit(refit, guarded, t)
    }

    /// Whether the refit `m` may replace the current model: unguarded
    /// (before training completes, or without the joint calibration, as in
    /// the paper) always; guarded, unless [`Tedris::refit_verdict`] refuses
    /// it. Counts the verdict.
    pub(super) fn guard_refit(&mut self, m: &TedrisModel, guarded: bool, t: f64) -> bool {
        let Some(current) = self.model.as_ref().filter(|_| guarded) else {
            return true;
        };
        let accept = !matches!(
            self.refit_verdict(current, m, t),
            super::calibration::RefitVerdict::Refused(_)
        );
        if accept {
            self.accepted_refits += 1;
        } else {
            self.refused_refits += 1;
        }
        accept
    }
}

pub(super) fn ccf_peak_value(c: &crate::ccf::CrossCorrelation) -> f64 {
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
    if flagged.len() >= MIN_STRAIGHT_BLOCKS {
        return StraightLine::from_omegas(&flagged, epsilon_factor, false);
    }
    let mut by_gamma: Vec<&Tuple> = tuples.iter().collect();
    by_gamma.sort_by(|a, b| a.gamma_rad.abs().total_cmp(&b.gamma_rad.abs()));
    let k = (tuples.len() / 10).max(MIN_QUIET_BLOCKS).min(tuples.len());
    let quiet: Vec<f64> = by_gamma[..k].iter().map(|t| t.omega_m).collect();
    StraightLine::from_omegas(&quiet, epsilon_factor, true)
}
