//! Physical acceptance of a fitted model (issue 35): a model whose turn does
//! not look like a car's is refused instead of dead-reckoned with.
//!
//! Four checks, each against what the data or the physics say:
//!
//! - **Turn gain**: the heading the model gives per metre of right − left
//!   wheel distance, times the rear track: `α1·track` for the paper,
//!   distance and baseline kinds, `(α1 + β_ω,prev)/(1 − β_γ,prev)·track` (the
//!   steady state) for ARX, `(α1 + α3·d²)·track` for the speed kind at the
//!   blocks' turning-weighted mean square distance per sample d² (at rest
//!   it is an extrapolation), each times the calibrated turn gain. Rigid
//!   wheels on a rigid axle give 1; tyre deflection, a rear radius
//!   mismatch and the track's uncertainty move it by a few per cent, a
//!   skid-steered robot's scrubbing more. Outside
//!   [`MIN_TURN_GAIN`, `MAX_TURN_GAIN`] the kind is refused (the quantised
//!   ticks of issue 35 gave 0.09).
//! - **R²** of the kind's block regression near 0: not significantly above
//!   what its blocks would give without any link between ω and γ (F test
//!   at [`R_SQUARED_TEST_LEVEL`], [`min_r_squared`]): the wheels do not
//!   explain the reference's turning.
//! - **Cross-correlation peak** below [`MIN_CCF_SHARE`] of the peak the
//!   data's turning should give: the correlation of ω and γ per sample is
//!   at most the product of their turning shares (the share of each
//!   series' variance that survives a one-second mean,
//!   [`expected_ccf_peak`]); noisy wheels (ticks) lower both the measured
//!   and the expected peak, a reference that does not follow the wheels
//!   (another vehicle's course, a wrong sign, a frozen gyro) only the
//!   measured one. This refuses every kind.
//!
//! - **The speed kind's ω·d² term** not significantly different from 0
//!   (t test at [`SPEED_TERM_TEST_LEVEL`]): without loaded tyres to model it
//!   is the distance kind plus a term fitted to noise, which the held-back
//!   choice then picked by chance (the smooth-speed family's cars 101–112:
//!   1.37 m without the speed kind, 1.44 m with it).
//!
//! A chosen kind that is refused gives way to the baseline kind if that
//! passes, else to another kind that passes; when every kind is refused the
//! model is refused as a whole, with the failed checks and what the user
//! can do.

use serde::{Deserialize, Serialize};

use crate::config::ModelKind;
use crate::history::History;
use crate::model::{KindFit, TedrisModel};
use crate::tuning::{
    MAX_TURN_GAIN, MIN_CCF_SHARE, R_SQUARED_TEST_LEVEL, SPEED_TERM_TEST_LEVEL, TURN_SIGNAL_WINDOW_S,
};

/// A kind the acceptance refused, and why.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindRefusal {
    /// The kind.
    pub kind: ModelKind,
    /// Which check failed, with its numbers.
    pub reason: String,
}

/// One kind's checks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindCheck {
    /// The kind.
    pub kind: ModelKind,
    /// Its turn gain (heading per metre of ω times the rear track; 1 for
    /// rigid wheels), `None` when its slope is not defined (ARX with a
    /// feedback of 1).
    pub turn_gain: Option<f64>,
    /// R² of its block regression.
    pub r_squared: f64,
    /// The failed checks (`None`: accepted).
    pub refused: Option<String>,
}

/// The checks of a model at training.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Acceptance {
    /// The measured cross-correlation peak of ω and γ per sample.
    pub ccf_peak: f64,
    /// The peak the data's turning should give ([`expected_ccf_peak`]);
    /// `None` when too few samples tell.
    pub expected_ccf_peak: Option<f64>,
    /// Per kind.
    pub kinds: Vec<KindCheck>,
    /// The chosen kind was refused and this one used instead.
    pub fell_back_from: Option<ModelKind>,
}

impl Acceptance {
    /// The kind's check.
    pub fn kind(&self, kind: ModelKind) -> Option<&KindCheck> {
        self.kinds.iter().find(|k| k.kind == kind)
    }
}

/// Smallest accepted turn gain (see the module docs).
pub const MIN_TURN_GAIN: f64 = crate::tuning::MIN_TURN_GAIN;

fn coef(f: &KindFit, name: &str) -> Option<f64> {
    f.global
        .coefficients
        .iter()
        .find(|c| c.name == name)
        .map(|c| c.estimate)
}

/// A kind's turn gain: heading per metre of ω (steady state for ARX; for
/// the speed kind at `turn_d2_m2`, the turning-weighted mean square of the
/// distance per sample) times `calibrated_gain` times `track_m`.
pub fn turn_gain(f: &KindFit, calibrated_gain: f64, track_m: f64, turn_d2_m2: f64) -> Option<f64> {
    let a1 = coef(f, "alpha1")?;
    let slope = match f.kind {
        ModelKind::Speed => a1 + coef(f, "omega_speed")? * turn_d2_m2,
        ModelKind::Arx => {
            let (wp, gp) = (coef(f, "omega_prev")?, coef(f, "gamma_prev")?);
            if (1.0 - gp).abs() < 1e-3 {
                return None;
            }
            (a1 + wp) / (1.0 - gp)
        }
        _ => a1,
    };
    let g = slope * calibrated_gain * track_m;
    g.is_finite().then_some(g)
}

/// The smallest R² a regression of `regressors` columns besides the
/// intercept on `n` rows must reach to be significantly above 0 at
/// [`R_SQUARED_TEST_LEVEL`] (F test: R² = k·F/(k·F + n − k − 1)).
pub fn min_r_squared(n: usize, regressors: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, FisherSnedecor};
    let k = regressors.max(1) as f64;
    let dof = n as f64 - k - 1.0;
    if dof < 1.0 {
        return 1.0;
    }
    match FisherSnedecor::new(k, dof) {
        Ok(f) => {
            let q = f.inverse_cdf(1.0 - R_SQUARED_TEST_LEVEL);
            k * q / (k * q + dof)
        }
        Err(_) => 1.0,
    }
}

/// The cross-correlation peak of ω (at `lag` samples before γ) and γ that
/// the data's turning should give: √(s_ω·s_γ), each s the share of the
/// series' variance in its one-second means (minus what white noise leaves
/// in a mean of n samples), over runs of moving samples with a reference.
/// `None` with fewer than 30 one-second windows.
pub fn expected_ccf_peak(h: &History, lag: i64, period_s: f64) -> Option<f64> {
    let n = (TURN_SIGNAL_WINDOW_S / period_s).round().max(2.0) as usize;
    let mut w = Vec::new();
    let mut g = Vec::new();
    let (mut means_w, mut means_g) = (Vec::new(), Vec::new());
    let mut flush = |w: &mut Vec<f64>, g: &mut Vec<f64>| {
        for (cw, cg) in w.chunks_exact(n).zip(g.chunks_exact(n)) {
            means_w.push(cw.iter().sum::<f64>() / n as f64);
            means_g.push(cg.iter().sum::<f64>() / n as f64);
        }
        w.clear();
        g.clear();
    };
    let mut all_w = Vec::new();
    let mut all_g = Vec::new();
    for s in h.iter() {
        let src = h.get((s.idx as i64 - lag).max(0) as u64);
        match (h.gamma(s.idx), src) {
            (Some(gj), Some(src)) if s.moving() && src.moving() => {
                w.push(src.omega_m);
                g.push(gj);
                all_w.push(src.omega_m);
                all_g.push(gj);
            }
            _ => flush(&mut w, &mut g),
        }
    }
    flush(&mut w, &mut g);
    if means_w.len() < 30 {
        return None;
    }
    let var = |x: &[f64]| {
        let m = x.iter().sum::<f64>() / x.len() as f64;
        x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (x.len() - 1) as f64
    };
    let share = |all: &[f64], means: &[f64]| {
        let (v1, vn) = (var(all), var(means));
        if v1 <= 0.0 {
            return 0.0;
        }
        let k = 1.0 / n as f64;
        ((vn - k * v1) / (v1 * (1.0 - k))).clamp(0.0, 1.0)
    };
    Some((share(&all_w, &means_w) * share(&all_g, &means_g)).sqrt())
}

/// The checks of every kind of `model` (rear track `track_m`, the expected
/// peak from [`expected_ccf_peak`]).
pub fn check(model: &TedrisModel, track_m: f64, expected_ccf_peak: Option<f64>) -> Acceptance {
    let ccf_peak = model
        .ccf
        .values
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max);
    let ccf_failed = expected_ccf_peak
        .filter(|e| ccf_peak < MIN_CCF_SHARE * e)
        .map(|e| {
            format!(
                "cross-correlation peak {ccf_peak:.3} is below {MIN_CCF_SHARE} of the {e:.3} the data's turning should give"
            )
        });
    // The speed at which the blocks turned: Σω²d²/Σω² (the speed kind's
    // gain there; at rest it is an extrapolation).
    let tuples = model.repositories.all_sorted();
    let (sw, swd) = tuples.iter().fold((0.0, 0.0), |(a, b), t| {
        let w2 = t.omega_m * t.omega_m;
        (a + w2, b + w2 * t.dist_m * t.dist_m)
    });
    let turn_d2 = if sw > 0.0 { swd / sw } else { 0.0 };
    let kinds = model
        .fits
        .iter()
        .map(|f| {
            let g = turn_gain(f, model.turn_gain, track_m, turn_d2);
            let r2 = f.global.r_squared;
            let mut why = Vec::new();
            match g {
                Some(g) if !(MIN_TURN_GAIN..=MAX_TURN_GAIN).contains(&g) => why.push(format!(
                    "turn gain {g:.3} (heading per metre of right − left wheel distance × track) is outside the physical [{MIN_TURN_GAIN}, {MAX_TURN_GAIN}]"
                )),
                Some(_) => {}
                None => why.push("turn gain not defined (ARX feedback of 1)".to_string()),
            }
            let k = f
                .global
                .coefficients
                .iter()
                .filter(|c| c.name != "alpha0")
                .count();
            let min_r2 = min_r_squared(f.global.n, k);
            if r2 < min_r2 {
                why.push(format!(
                    "R² {r2:.3} of {} blocks is not significantly above 0 (needs {min_r2:.3})",
                    f.global.n
                ));
            }
            if f.kind == ModelKind::Speed {
                if let Some(c) = f.global.coefficients.iter().find(|c| c.name == "omega_speed") {
                    if c.p_value.is_nan() || c.p_value >= SPEED_TERM_TEST_LEVEL {
                        why.push(format!(
                            "its speed term ω·d² is not significantly different from 0 (t = {:.2}, p = {:.3} ≥ {SPEED_TERM_TEST_LEVEL}): the distance kind without a term fitted to noise",
                            c.t_value, c.p_value
                        ));
                    }
                }
            }
            if let Some(c) = &ccf_failed {
                why.push(c.clone());
            }
            KindCheck {
                kind: f.kind,
                turn_gain: g,
                r_squared: r2,
                refused: (!why.is_empty()).then(|| why.join("; ")),
            }
        })
        .collect();
    Acceptance {
        ccf_peak,
        expected_ccf_peak,
        kinds,
        fell_back_from: None,
    }
}

/// What the user can do when a model is refused.
pub const REMEDY: &str = "check track_rear_m, wheel_circumference_m and ticks_per_rev in vehicle.toml against the car, that the reference heading belongs to this vehicle (tedris train --reference), and train on a drive with more turns; --model baseline fits the plain model alone";

/// Applies the checks to `model`: the refused kinds are recorded, a refused
/// chosen kind gives way to the baseline kind if that passes, else to the
/// first other kind (in [`ModelKind::ALL`]'s order) that passes and the
/// model's form can use. `Err` with the failed checks and [`REMEDY`] when
/// every kind is refused.
pub fn apply(model: &mut TedrisModel, mut acc: Acceptance) -> Result<(), String> {
    model.refused_kinds = acc
        .kinds
        .iter()
        .filter_map(|k| {
            Some(KindRefusal {
                kind: k.kind,
                reason: k.refused.clone()?,
            })
        })
        .collect();
    let refused = |k: ModelKind| model.refused_kinds.iter().find(|r| r.kind == k);
    if let Some(r) = refused(model.chosen) {
        // The baseline kind first, then any other kind that passes.
        let order = std::iter::once(ModelKind::Baseline).chain(ModelKind::ALL);
        let fallback = order
            .into_iter()
            .find(|&k| model.fits.iter().any(|f| f.kind == k) && model.kind_usable(k));
        let Some(fallback) = fallback else {
            let why = format!(
                "the {} model was refused: {}{}; what to do: {REMEDY}",
                model.chosen.name(),
                r.reason,
                match refused(ModelKind::Baseline) {
                    Some(b) if model.chosen != ModelKind::Baseline =>
                        format!(", and the baseline model: {}", b.reason),
                    _ => String::new(),
                }
            );
            model.acceptance = Some(acc);
            return Err(why);
        };
        acc.fell_back_from = Some(model.chosen);
        model.chosen = fallback;
    }
    model.acceptance = Some(acc);
    Ok(())
}
