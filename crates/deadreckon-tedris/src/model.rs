//! The fitted TedriS model: the regressions of eq. (2)–(3) for each model kind,
//! their residual analysis and AR/MA correction, the repository regressions, and
//! the evaluation of the heading increment γ̂ of eq. (4).
//!
//! All regressions are on block medians in per-sample units: ω and d in metres per
//! wheel sample, γ in radians per wheel sample. Because they are linear, a fit on
//! block medians applies sample by sample: eq. (4) is evaluated at each wheel sample
//! with that sample's ω and d, the repository being chosen by the median of the
//! last τ samples of ω.

use std::collections::BTreeMap;

use serde::{Deserialize, Serialize};

use crate::ccf::CrossCorrelation;
use crate::config::{ModelChoice, ModelKind, RepositoryFit, TedrisConfig};
use crate::repository::{Repositories, StraightLine, Tuple};
use crate::residuals::{
    box_pierce, ljung_box, select_correction, Correction, CorrectionFit, Portmanteau,
};
use crate::stats::{mean, ols, ols_eiv_sum, OlsFit};
use crate::Error;

/// The design row of a tuple for a kind (`None` when ARX lacks the previous block).
pub fn design_row(kind: ModelKind, t: &Tuple) -> Option<Vec<f64>> {
    Some(match kind {
        ModelKind::Paper => vec![1.0, t.omega_m],
        ModelKind::Distance => vec![1.0, t.omega_m, t.dist_m],
        ModelKind::Arx => {
            let (wp, gp) = t.prev?;
            vec![1.0, t.omega_m, t.dist_m, wp, gp]
        }
        ModelKind::Baseline => vec![t.omega_m, t.dist_m],
        ModelKind::Speed => vec![1.0, t.omega_m, t.dist_m, t.omega_m * t.dist_m * t.dist_m],
    })
}

/// How a design row moves with the noise of the block's ω (∂row/∂ω) and,
/// independently, of the previous block's ω (ARX), `None` for the latter
/// when the kind has no such column.
fn omega_jacobians(kind: ModelKind, t: &Tuple) -> (Vec<f64>, Option<Vec<f64>>) {
    match kind {
        ModelKind::Paper => (vec![0.0, 1.0], None),
        ModelKind::Distance => (vec![0.0, 1.0, 0.0], None),
        ModelKind::Arx => (
            vec![0.0, 1.0, 0.0, 0.0, 0.0],
            Some(vec![0.0, 0.0, 0.0, 1.0, 0.0]),
        ),
        ModelKind::Baseline => (vec![1.0, 0.0], None),
        // ω·d²: ω's noise times d² (d is far less noisy than ω), correlated
        // with the ω column's.
        ModelKind::Speed => (vec![0.0, 1.0, 0.0, t.dist_m * t.dist_m], None),
    }
}

/// The sum over the rows of `kind`'s design of the covariance of their
/// errors from ω's noise of variance `omega_noise_var` (m²): what the
/// errors-in-variables fit ([`ols_eiv_sum`]) takes off `XᵀX`. Only rows
/// [`design_row`] gives (ARX needs the previous block).
pub fn omega_noise_sum(kind: ModelKind, tuples: &[Tuple], omega_noise_var: f64) -> Vec<Vec<f64>> {
    let p = kind.regressors().len();
    let mut sum = vec![vec![0.0; p]; p];
    if !(omega_noise_var.is_finite() && omega_noise_var > 0.0) {
        return sum;
    }
    for t in tuples.iter().filter(|t| design_row(kind, t).is_some()) {
        let (g, g_prev) = omega_jacobians(kind, t);
        for g in std::iter::once(&g).chain(g_prev.as_ref()) {
            for (i, gi) in g.iter().enumerate() {
                for (j, gj) in g.iter().enumerate() {
                    sum[i][j] += gi * gj;
                }
            }
        }
    }
    // Times the variance last: n·σ² exactly for a column that is ω itself.
    for v in sum.iter_mut().flatten() {
        *v *= omega_noise_var;
    }
    sum
}

/// The fit of one model kind: global regression, residual tests, correction and
/// the repository regressions.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KindFit {
    /// The kind.
    pub kind: ModelKind,
    /// The regression on all tuples (the coefficient table).
    pub global: OlsFit,
    /// Box–Pierce test of the global residuals.
    pub box_pierce: Portmanteau,
    /// Ljung–Box test of the global residuals.
    pub ljung_box: Portmanteau,
    /// The AR/MA correction, when Ljung–Box rejected white residuals.
    pub correction: Option<CorrectionFit>,
    /// The regression refitted jointly with the correction terms (the paper's table 2).
    pub corrected: Option<OlsFit>,
    /// Coefficients of each repository's regression (same columns as `global`).
    pub repositories: BTreeMap<i32, Vec<f64>>,
    /// The global coefficients, used where no repository has a fit.
    pub global_beta: Vec<f64>,
    /// BIC of the simulation residuals: for ARX, γ_{k−1} is the model's own
    /// previous output along each run of contiguous blocks, as in dead reckoning;
    /// for the static kinds it is the BIC of the fit.
    #[serde(default)]
    pub sim_bic: f64,
}

impl KindFit {
    /// The coefficients used for repository `n`: its own, else the nearest repository's, else the global ones.
    pub fn beta(&self, n: i32) -> &[f64] {
        if let Some(b) = self.repositories.get(&n) {
            return b;
        }
        let lower = self.repositories.range(..n).next_back();
        let upper = self.repositories.range(n..).next();
        match (lower, upper) {
            (Some((a, ba)), Some((b, bb))) => {
                if n - a <= b - n {
                    ba
                } else {
                    bb
                }
            }
            (Some((_, b)), None) | (None, Some((_, b))) => b,
            (None, None) => &self.global_beta,
        }
    }

    /// The correction, `None` as [`Correction::None`].
    pub fn correction(&self) -> Correction {
        self.correction
            .as_ref()
            .map_or(Correction::None, |c| c.correction.clone())
    }
}

/// Fits one kind on time-ordered tuples and the repositories.
/// `omega_noise_var` is the variance of the noise of a block median of ω (m²),
/// for the errors-in-variables correction of the ω columns (0: plain OLS).
pub fn fit_kind(
    kind: ModelKind,
    tuples: &[Tuple],
    repos: &Repositories,
    cfg: &TedrisConfig,
    omega_noise_var: f64,
    tau: usize,
) -> Result<KindFit, Error> {
    let rows: Vec<(Vec<f64>, f64)> = tuples
        .iter()
        .filter_map(|t| Some((design_row(kind, t)?, t.gamma_rad)))
        .collect();
    let (x, y): (Vec<Vec<f64>>, Vec<f64>) = rows.into_iter().unzip();
    let names = kind.regressors();
    let noise = omega_noise_sum(kind, tuples, omega_noise_var);
    let global = ols_eiv_sum(&x, &y, names, &noise)?;
    let e = global.residuals(&x, &y);
    let lags = cfg.portmanteau_lags.min(e.len() / 4).max(1);
    let bp = box_pierce(&e, lags, 0);
    let lb = ljung_box(&e, lags, 0);
    let correction = if e.len() > 60 {
        select_correction(&e, lags, cfg.alpha, cfg.max_correction_order)
    } else {
        None
    };
    let corrected = correction
        .as_ref()
        .and_then(|c| joint_refit(&x, &y, &e, &c.correction, names));
    let beta_g = global.beta();
    let mut repositories = BTreeMap::new();
    // The baseline is one global fit: no repositories.
    let bins = if kind == ModelKind::Baseline {
        None
    } else {
        Some(&repos.bins)
    };
    for (&n, q) in bins.into_iter().flatten() {
        let tq: Vec<&Tuple> = q.iter().collect();
        let rows: Vec<(Vec<f64>, f64)> = tq
            .iter()
            .filter_map(|t| Some((design_row(kind, t)?, t.gamma_rad)))
            .collect();
        if rows.len() < 3 {
            continue;
        }
        let beta = match cfg.repository_fit {
            RepositoryFit::PooledSlopes => {
                let offs: Vec<f64> = rows.iter().map(|(r, yv)| yv - dot(&beta_g, r)).collect();
                let mut b = beta_g.clone();
                b[0] += mean(&offs);
                b
            }
            RepositoryFit::Separate => {
                if rows.len() < names.len() + 3 {
                    continue;
                }
                let (rx, ry): (Vec<Vec<f64>>, Vec<f64>) = rows.into_iter().unzip();
                let q: Vec<Tuple> = tq.iter().map(|t| **t).collect();
                let noise = omega_noise_sum(kind, &q, omega_noise_var);
                match ols_eiv_sum(&rx, &ry, names, &noise) {
                    Ok(f) => f.beta(),
                    Err(_) => continue,
                }
            }
        };
        repositories.insert(n, beta);
    }
    let sim_bic = simulation_bic(kind, tuples, &beta_g, tau as u64, global.bic);
    Ok(KindFit {
        kind,
        global,
        sim_bic,
        box_pierce: bp,
        ljung_box: lb,
        correction,
        corrected,
        repositories,
        global_beta: beta_g,
    })
}

/// See [`KindFit::sim_bic`].
fn simulation_bic(kind: ModelKind, tuples: &[Tuple], beta: &[f64], tau: u64, bic: f64) -> f64 {
    if kind != ModelKind::Arx {
        return bic;
    }
    let mut rss = 0.0;
    let mut n = 0usize;
    let mut last: Option<(u64, f64, f64)> = None;
    for t in tuples {
        let Some((wp, gp)) = t.prev else {
            last = None;
            continue;
        };
        let gp = match last {
            Some((seq, _, g)) if seq + tau == t.seq => g,
            _ => gp,
        };
        let pred = beta[0] + beta[1] * t.omega_m + beta[2] * t.dist_m + beta[3] * wp + beta[4] * gp;
        rss += (t.gamma_rad - pred).powi(2);
        n += 1;
        last = Some((t.seq, t.omega_m, pred));
    }
    if n == 0 {
        return f64::MAX;
    }
    let p = beta.len() as f64;
    n as f64 * (rss.max(f64::MIN_POSITIVE) / n as f64).ln() + p * (n as f64).ln()
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Regression with the correction terms as extra columns (lagged residuals for
/// AR, lagged long-AR innovations for MA), as in the paper's table 2.
fn joint_refit(
    x: &[Vec<f64>],
    y: &[f64],
    e: &[f64],
    c: &Correction,
    names: &[&str],
) -> Option<OlsFit> {
    let (extra, label, start): (Vec<f64>, &str, usize) = match c {
        Correction::None => return None,
        Correction::Ar { phi } => (e.to_vec(), "ar", phi.len()),
        Correction::Ma { theta } => {
            let m = (theta.len() * 3).max(6);
            let u = crate::residuals::long_ar_innovations(e, m).ok()?;
            (u, "ma", m + theta.len())
        }
    };
    let order = c.order();
    let mut all_names: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    all_names.extend((1..=order).map(|i| format!("{label}{i}")));
    let refs: Vec<&str> = all_names.iter().map(String::as_str).collect();
    let rows: Vec<Vec<f64>> = (start..x.len())
        .map(|t| {
            let mut r = x[t].clone();
            r.extend((1..=order).map(|i| extra[t - i]));
            r
        })
        .collect();
    ols(&rows, &y[start..], &refs).ok()
}

/// A trained TedriS model: what `tedris train` writes and `tedris run` reads.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TedrisModel {
    /// The configuration it was trained with.
    pub config: TedrisConfig,
    /// Wheel sample period, s (median).
    pub sample_period_s: f64,
    /// h: lag of the cross-correlation peak, samples (γ_t responds to ω_{t−h}).
    pub lag_samples: i64,
    /// The cross-correlation of ω and γ over the lag window.
    pub ccf: CrossCorrelation,
    /// The training repositories (tuples and binning: µ, W_L, W_H, ε).
    pub repositories: Repositories,
    /// The fit of every kind, in [`ModelKind::ALL`] order.
    pub fits: Vec<KindFit>,
    /// The kind used for prediction.
    pub chosen: ModelKind,
    /// DCF₀: the dynamic correction factor's starting value, rad per sample
    /// (the straight-line mean residual: µ carried into heading units).
    pub dcf0_rad: f64,
    /// DCF: the dynamic correction factor of eq. (4), rad per sample.
    pub dcf_rad: f64,
    /// Distance term of the DCF, rad per metre: γ̂ gains `dcf_distance_rad_per_m · d`
    /// (estimated by the joint calibration; 0 otherwise).
    #[serde(default)]
    pub dcf_distance_rad_per_m: f64,
    /// Half-width of the DCF search interval, rad per sample.
    pub dcf_bound_rad: f64,
    /// The expected ω on a straight line, `c0 + c1·d` (m per sample): an OLS of the
    /// straight blocks' ω on their d (the tyre-radius bias grows with speed).
    pub straight_omega: (f64, f64),
    /// Robust standard deviation (1.4826 × MAD) of the straight blocks' ω about
    /// `straight_omega`, m per sample: the noise of the block medians, used by
    /// the errors-in-variables slope correction.
    pub straight_sigma_m: f64,
    /// The gyro bias of the training drive's standstills (rad/s, gyro samples), when
    /// trained on the gyro reference: the same gyro's bias, pooled with the
    /// standstills of the drive it runs on (a 5 s standstill alone leaves an error
    /// of about 3·10⁻⁴ rad/s on the simulated robot, which becomes heading drift).
    #[serde(default)]
    pub gyro_bias: Option<(f64, usize)>,
    /// The straight-line part of γ̂ is heading per metre only (`dcf_distance_rad_per_m`),
    /// with no per-sample rate: what wheels physically do (unequal radii turn the
    /// car per metre; at rest nothing turns). Set for a GNSS course reference
    /// in the extended variant; a gyro reference keeps the
    /// per-sample DCF (its bias is per unit time).
    #[serde(default)]
    pub per_metre_straight: bool,
    /// The course convention found on the training data (None: a gyro
    /// reference, no lever arm, or too few turns at low speed to tell; the
    /// course is then taken as the antenna's).
    #[serde(default)]
    pub course_convention: Option<crate::convention::ConventionFit>,
    /// Every required repository reached its minimum fill.
    pub complete: bool,
    /// g: gain on the turning part of γ̂ (1 = the regression as fitted),
    /// estimated by the joint calibration (the extended variant; 1 in the
    /// paper variant, where it is not estimated).
    #[serde(default = "one")]
    pub turn_gain: f64,
    /// Standard error of the installed `dcf_rad`, rad per sample, from the
    /// joint calibration that set it (autocorrelation-robust:
    /// [`crate::stats::increment_block_std`]). `None`: not estimated (never
    /// calibrated jointly, the per-metre form which has no DCF, the paper's
    /// eq. (6), or too little reference heading to tell).
    #[serde(default)]
    pub dcf_std_rad: Option<f64>,
    /// Standard error of the installed `dcf_distance_rad_per_m`, rad per
    /// metre (as `dcf_std_rad`; `None` also while the term was never fitted).
    #[serde(default)]
    pub dcf_distance_std_rad_per_m: Option<f64>,
    /// Standard error of the installed `turn_gain` (as `dcf_std_rad`; `None`
    /// also while the gain was never fitted).
    #[serde(default)]
    pub turn_gain_std: Option<f64>,
    /// The rear wheels' distance scale (see [`DistanceScale`]).
    #[serde(default)]
    pub distance_scale: DistanceScale,
    /// The blocks chosen for quantised wheel ticks ([`crate::blocks`]):
    /// τ and block means in place of `config.tau_samples` and medians.
    /// `None`: the configuration's τ with medians (wheel speeds, or ticks
    /// fine against the turning).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub blocks: Option<crate::blocks::QuantisedBlocks>,
    /// The kinds the physical acceptance refused ([`crate::acceptance`]),
    /// with why: never chosen, never tried by the calibration.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub refused_kinds: Vec<crate::acceptance::KindRefusal>,
    /// The physical acceptance's checks at training (not kept in the model
    /// file: for the summary `tedris train` prints).
    #[serde(skip)]
    pub acceptance: Option<crate::acceptance::Acceptance>,
    /// The timing and mounting corrections the training drive had applied
    /// (a params.toml's delays, IMU tilt and gyro scale; `None`: none). A
    /// drive run through the model needs the same ones.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub corrections: Option<deadreckon_core::timing::KnownCorrections>,
}

/// The rear wheels' distance scale: metres travelled per metre the rear
/// wheels report (their mean circumference against the nominal one),
/// estimated from GNSS chords (the extended variant). It scales the position
/// only: the heading model is fitted on the wheels' own distances.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DistanceScale {
    /// The scale (1 until estimated).
    pub value: f64,
    /// Chords of the fit that set it; 0: not estimated (the paper variant,
    /// or too few chords yet), and `value` is then the nominal 1.
    pub chords: usize,
}

impl Default for DistanceScale {
    fn default() -> Self {
        DistanceScale {
            value: 1.0,
            chords: 0,
        }
    }
}

impl DistanceScale {
    /// The scale when estimated, `None` when not.
    pub fn estimated(&self) -> Option<f64> {
        (self.chords > 0).then_some(self.value)
    }
}

fn one() -> f64 {
    1.0
}

impl TedrisModel {
    /// [`TedrisModel::fit`] again on this model's own settings, lag,
    /// cross-correlation and repositories: the regressions fitted anew, the
    /// calibrated values (turn gain, DCF, distance scale) not carried over.
    pub fn refit(&self) -> Result<Self, Error> {
        TedrisModel::fit(
            self.config.clone(),
            self.sample_period_s,
            self.lag_samples,
            self.ccf.clone(),
            self.repositories.clone(),
            self.blocks,
        )
    }

    /// τ of the blocks: the quantised blocks' ([`TedrisModel::blocks`]) or
    /// the configuration's `tau_samples`.
    pub fn tau(&self) -> usize {
        self.blocks
            .map_or(self.config.tau_samples, |b| b.tau_samples)
            .max(1)
    }

    /// Blocks (and the predictor's repository choice) by means instead of
    /// medians: with quantised blocks.
    pub fn block_means(&self) -> bool {
        self.blocks.is_some()
    }

    /// Fits every kind on the repositories and chooses one. `blocks`: the
    /// quantised blocks the repositories were formed with (`None`: the
    /// configuration's τ and medians).
    pub fn fit(
        config: TedrisConfig,
        sample_period_s: f64,
        lag_samples: i64,
        ccf: CrossCorrelation,
        repositories: Repositories,
        blocks: Option<crate::blocks::QuantisedBlocks>,
    ) -> Result<Self, Error> {
        let tuples = repositories.all_sorted();
        // Compare the kinds on the same tuples: those with a contiguous previous block.
        let common: Vec<Tuple> = tuples
            .iter()
            .filter(|t| t.prev.is_some())
            .copied()
            .collect();
        let base = if common.len() > 20 { &common } else { &tuples };
        let (straight_omega, straight_sigma_m) = straight_stats(&repositories);
        // Quantised blocks: the quantisation variance is the noise's floor
        // (the straight blocks' spread also has the road's and the tyres').
        let noise_var = if config.eiv_correction() {
            let q = blocks.map_or(0.0, |b| b.quantisation_var_m2());
            (straight_sigma_m * straight_sigma_m).max(q)
        } else {
            0.0
        };
        let tau = blocks.map_or(config.tau_samples, |b| b.tau_samples);
        let mut fits = Vec::new();
        for kind in ModelKind::ALL {
            // The speed kind is the extended variant's.
            if kind == ModelKind::Speed && config.variant != crate::config::Variant::Extended {
                continue;
            }
            match fit_kind(kind, base, &repositories, &config, noise_var, tau) {
                Ok(f) => fits.push(f),
                Err(e) if kind == ModelKind::Paper => return Err(e),
                Err(_) => {}
            }
        }
        let chosen = match config.model {
            ModelChoice::Fixed(k) if fits.iter().any(|f| f.kind == k) => k,
            ModelChoice::Fixed(k) => {
                return Err(Error::Regression(format!(
                    "the {} model could not be fitted",
                    k.name()
                )))
            }
            ModelChoice::Auto => choose(&fits),
        };
        let mut m = TedrisModel {
            complete: repositories.complete(config.required_bins),
            config,
            sample_period_s,
            lag_samples,
            ccf,
            repositories,
            fits,
            chosen,
            dcf0_rad: 0.0,
            dcf_rad: 0.0,
            dcf_distance_rad_per_m: 0.0,
            gyro_bias: None,
            per_metre_straight: false,
            course_convention: None,
            dcf_bound_rad: 0.0,
            straight_omega,
            straight_sigma_m,
            turn_gain: 1.0,
            dcf_std_rad: None,
            dcf_distance_std_rad_per_m: None,
            turn_gain_std: None,
            distance_scale: DistanceScale::default(),
            blocks,
            refused_kinds: Vec::new(),
            acceptance: None,
            corrections: None,
        };
        m.set_dcf0();
        Ok(m)
    }

    fn set_dcf0(&mut self) {
        let f = self.chosen_fit();
        let straight: Vec<f64> = self
            .repositories
            .all_sorted()
            .iter()
            .filter(|t| t.straight)
            .filter_map(|t| {
                let t = *t;
                let r = design_row(f.kind, &t)?;
                let n = self.repositories.straight.bin(t.omega_m)?;
                Some(t.gamma_rad - dot(f.beta(n), &r))
            })
            .collect();
        let slope = f
            .global
            .coefficients
            .iter()
            .find(|c| c.name == "alpha1")
            .map_or(0.0, |c| c.estimate.abs());
        self.dcf0_rad = if straight.is_empty() {
            0.0
        } else {
            crate::stats::median(&straight)
        };
        let s = &self.repositories.straight;
        self.dcf_bound_rad =
            (self.config.dcf_bound_factor * slope * (s.w_high_m - s.w_low_m)).max(1e-6);
        self.dcf_rad = self.dcf0_rad;
        self.dcf_std_rad = None;
    }

    /// The expected ω on a straight line at `dist_m` per sample, m per sample
    /// (`c0 + c1·d`; µ for the Paper kind, which knows no speed).
    pub fn straight_centre(&self, dist_m: f64) -> f64 {
        match self.chosen {
            ModelKind::Paper => self.repositories.straight.mu_m,
            _ => self.straight_omega.0 + self.straight_omega.1 * dist_m,
        }
    }

    /// False for a kind the model's form cannot use — the ARX kind in the
    /// per-metre form (its turn is spread over the feedback of previous
    /// blocks, which the per-metre form's "turn from ω = 0" would cut) —
    /// or one the physical acceptance refused ([`TedrisModel::refused_kinds`]).
    pub fn kind_usable(&self, kind: ModelKind) -> bool {
        let arx_per_metre = self.per_metre_straight && kind == ModelKind::Arx;
        let refused = self.refused_kinds.iter().any(|r| r.kind == kind);
        !(arx_per_metre || refused)
    }

    /// Moves the automatic choice off a kind the form cannot use (ARX in the
    /// per-metre form) to the distance kind, else the paper kind. (A kind the
    /// user fixed is never in that case: fixing ARX keeps the per-sample form.)
    pub fn settle_kind(&mut self) {
        if self.kind_usable(self.chosen) {
            return;
        }
        for k in [ModelKind::Distance, ModelKind::Paper] {
            if self.fits.iter().any(|f| f.kind == k) && self.kind_usable(k) {
                self.chosen = k;
                return;
            }
        }
    }

    /// The fit of the chosen kind.
    pub fn chosen_fit(&self) -> &KindFit {
        self.fits
            .iter()
            .find(|f| f.kind == self.chosen)
            .unwrap_or(&self.fits[0])
    }

    /// The straight-line parameters.
    pub fn straight(&self) -> &StraightLine {
        &self.repositories.straight
    }

    /// A model from its JSON (what `tedris train --out` writes), checked
    /// ([`TedrisModel::validate`]): the one way every command and the Python
    /// bindings load a model (the report and `compare` did not check it).
    pub fn from_json(text: &str) -> Result<TedrisModel, Error> {
        let m: TedrisModel = serde_json::from_str(text).map_err(|e| Error::Json(e.to_string()))?;
        m.validate()?;
        Ok(m)
    }

    /// Checks a loaded model is usable (non-empty fits, finite numbers).
    pub fn validate(&self) -> Result<(), Error> {
        self.config.validate()?;
        if let Some(c) = &self.corrections {
            c.validate()
                .map_err(|e| Error::Model(format!("the stored corrections: {e}")))?;
        }
        if self.fits.is_empty() || !self.fits.iter().any(|f| f.kind == self.chosen) {
            return Err(Error::Model(
                "the model has no fit for its chosen kind".into(),
            ));
        }
        let p = |f: &KindFit| f.kind.regressors().len();
        let consistent = self.fits.iter().all(|f| {
            f.global.coefficients.iter().all(|c| c.estimate.is_finite())
                && f.global_beta.len() == p(f)
                && f.global_beta.iter().all(|v| v.is_finite())
                && f.repositories.values().flatten().all(|v| v.is_finite())
                && f.repositories
                    .values()
                    .all(|b| b.len() == f.kind.regressors().len())
                && f.global.coefficients.len() == f.kind.regressors().len()
        });
        let scalars = [
            self.dcf_rad,
            self.dcf_distance_rad_per_m,
            self.dcf0_rad,
            self.dcf_bound_rad,
            self.straight_sigma_m,
            self.straight_omega.0,
            self.straight_omega.1,
        ];
        // A standard error is finite and non-negative, or not estimated (null).
        for (name, s) in [
            ("dcf_std_rad", self.dcf_std_rad),
            (
                "dcf_distance_std_rad_per_m",
                self.dcf_distance_std_rad_per_m,
            ),
            ("turn_gain_std", self.turn_gain_std),
        ] {
            if let Some(s) = s.filter(|s| !(s.is_finite() && *s >= 0.0)) {
                return Err(Error::Model(format!(
                    "{name} = {s} is not a standard error (finite, not negative; null when not estimated)"
                )));
            }
        }
        let ok = consistent
            && scalars.iter().all(|v| v.is_finite())
            && self.sample_period_s.is_finite()
            && self.sample_period_s > 0.0
            && self.turn_gain.is_finite()
            && self.turn_gain > 0.0
            && self.distance_scale.value.is_finite()
            && self.distance_scale.value > 0.0;
        if !ok {
            return Err(Error::Model(
                "the model holds non-finite or inconsistent values".into(),
            ));
        }
        if self.lag_samples.unsigned_abs() > 10_000 {
            return Err(Error::Model(format!(
                "lag {} is out of range",
                self.lag_samples
            )));
        }
        Ok(())
    }
}

/// The straight-line ω model `c0 + c1·d` (OLS over the straight blocks; µ and 0
/// when fewer than 10) and the robust standard deviation about it (1.4826 × MAD).
fn straight_stats(repos: &Repositories) -> ((f64, f64), f64) {
    let st: Vec<Tuple> = repos
        .all_sorted()
        .into_iter()
        .filter(|t| t.straight)
        .collect();
    let x: Vec<Vec<f64>> = st.iter().map(|t| vec![1.0, t.dist_m]).collect();
    let y: Vec<f64> = st.iter().map(|t| t.omega_m).collect();
    let (c0, c1) = match ols(&x, &y, &["c0", "c1"]) {
        Ok(f) if st.len() >= 10 => (f.coefficients[0].estimate, f.coefficients[1].estimate),
        _ => (repos.straight.mu_m, 0.0),
    };
    let dev: Vec<f64> = st
        .iter()
        .map(|t| (t.omega_m - c0 - c1 * t.dist_m).abs())
        .collect();
    let sigma = if dev.len() >= 10 {
        1.4826 * crate::stats::median(&dev)
    } else {
        0.25 * (repos.straight.w_high_m - repos.straight.w_low_m)
    };
    ((c0, c1), sigma)
}

/// The automatic choice: smallest simulation BIC among kinds whose final
/// innovations pass Ljung–Box (p ≥ 0.01), else smallest simulation BIC.
fn choose(fits: &[KindFit]) -> ModelKind {
    let white = |f: &KindFit| match &f.correction {
        None => true,
        Some(c) => c.ljung_box.p_value >= 0.01,
    };
    // The speed kind is chosen only by the held-back calibrated heading.
    let best = |pred: &dyn Fn(&KindFit) -> bool| {
        fits.iter()
            .filter(|f| f.kind != ModelKind::Speed && pred(f))
            .min_by(|a, b| a.sim_bic.total_cmp(&b.sim_bic))
            .map(|f| f.kind)
    };
    best(&white)
        .or_else(|| best(&|_| true))
        .unwrap_or(ModelKind::Paper)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::repository::StraightLine;

    /// γ = 0.66·ω + 2.4e-3·d exactly (no intercept), on blocks at several
    /// speeds and turn rates, binned into repositories.
    fn tuples() -> (Vec<Tuple>, Repositories) {
        let straight = StraightLine::from_omegas(&[-0.001, 0.001], Some(1.5), false).unwrap();
        let mut repos = Repositories::new(straight, 3, 1000);
        let mut out = Vec::new();
        for k in 0..200u64 {
            let omega_m = 0.02 * ((k % 17) as f64 - 8.0) / 8.0;
            let dist_m = 0.1 + 0.05 * (k % 5) as f64;
            let t = Tuple {
                seq: 10 * k,
                omega_m,
                dist_m,
                gamma_rad: 0.66 * omega_m + 2.4e-3 * dist_m,
                prev: None,
                straight: omega_m.abs() < 1e-3,
            };
            repos.insert(t);
            out.push(t);
        }
        (out, repos)
    }

    #[test]
    fn the_baseline_kind_is_one_global_fit_without_intercept() {
        let (t, repos) = tuples();
        assert!(repos.bins.len() > 1, "the tuples fill several repositories");
        let f = fit_kind(
            ModelKind::Baseline,
            &t,
            &repos,
            &TedrisConfig::default(),
            0.0,
            6,
        )
        .unwrap();
        assert!(f.repositories.is_empty());
        assert_eq!(f.global_beta.len(), 2);
        assert!(
            (f.global_beta[0] - 0.66).abs() < 1e-9,
            "{:?}",
            f.global_beta
        );
        assert!(
            (f.global_beta[1] - 2.4e-3).abs() < 1e-9,
            "{:?}",
            f.global_beta
        );
        // Every repository falls back to the global coefficients.
        assert_eq!(f.beta(3), &f.global_beta[..]);
        assert_eq!(
            design_row(ModelKind::Baseline, &t[5]),
            Some(vec![t[5].omega_m, t[5].dist_m])
        );
    }
}
