//! Configuration of TedriS: every key with its unit and default.

use serde::{Deserialize, Serialize};

use crate::Error;

/// Which regression links the wheel series to the reference heading increments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// The paper's eq. (3): `γ = α0 + α1·ω` (constant offset, plus DCF).
    Paper,
    /// Multiple regression: `γ = α0 + α1·ω + α2·d`, d the distance travelled per
    /// sample. Follows the speed-proportional bias of unequal rear tyre radii.
    Distance,
    /// ARX(1,1) over consecutive blocks: `γ_k = α0 + α1·ω_k + α2·d_k + b1·ω_{k−1} + a1·γ_{k−1}`;
    /// in prediction `γ_{k−1}` is the model's own previous output.
    Arx,
    /// The plain least-squares model a user writes in an afternoon (see
    /// [`crate::baseline`]): `γ = α1·ω + α2·d`, one global fit with no
    /// intercept and no repositories, i.e. heading per metre of rear-wheel
    /// difference and per metre travelled. A candidate of the automatic choice,
    /// so that TedriS falls back to it where its richer kinds do worse.
    Baseline,
    /// The distance kind with a turn gain that falls with the square of the
    /// speed: `γ = α0 + α1·ω + α2·d + α3·ω·d²` (d per sample stands for the
    /// speed). In a turn the load moves to the outer wheels, whose loaded
    /// tyres roll on a smaller radius and count more distance: ω overstates
    /// the turn by a share that grows with the lateral acceleration v·ψ̇,
    /// i.e. with v² at a given ω per metre. Unmodelled, that share leaked
    /// into the joint calibration's heading per metre (issue 35: the
    /// dynamic family's tick cars drifted 1.1·10⁻⁴ rad/m on straights). In
    /// the extended variant only; never chosen by the block BIC, only by the
    /// held-back calibrated heading (or when fixed).
    Speed,
}

impl ModelKind {
    /// All kinds, in report order.
    pub const ALL: [ModelKind; 5] = [
        ModelKind::Paper,
        ModelKind::Distance,
        ModelKind::Arx,
        ModelKind::Baseline,
        ModelKind::Speed,
    ];

    /// Names of the regressors, in design-column order.
    pub fn regressors(self) -> &'static [&'static str] {
        match self {
            ModelKind::Paper => &["alpha0", "alpha1"],
            ModelKind::Distance => &["alpha0", "alpha1", "distance"],
            ModelKind::Arx => &["alpha0", "alpha1", "distance", "omega_prev", "gamma_prev"],
            ModelKind::Baseline => &["alpha1", "distance"],
            ModelKind::Speed => &["alpha0", "alpha1", "distance", "omega_speed"],
        }
    }

    /// The snake-case name.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Paper => "paper",
            ModelKind::Distance => "distance",
            ModelKind::Arx => "arx",
            ModelKind::Baseline => "baseline",
            ModelKind::Speed => "speed",
        }
    }
}

/// How the model is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelChoice {
    /// The kind with the smallest BIC of its simulation residuals (ARX fed its own
    /// output, as in dead reckoning) among those whose residuals, after the AR/MA
    /// correction if one was needed, pass Ljung–Box; the smallest overall otherwise.
    /// In the extended variant, each calibration then takes the kind whose
    /// calibrated heading has the smallest residual on the held-back quarter
    /// of its window (not on the data it was fitted on); in the per-metre form
    /// (a GNSS course) the paper, distance and baseline kinds are candidates.
    Auto,
    /// Always this kind.
    Fixed(ModelKind),
}

/// How each repository's regression is fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum RepositoryFit {
    /// The paper: an independent regression per repository (needs a wide spread of ω in it).
    Separate,
    /// The slopes of the global fit, with an intercept per repository (the mean of the
    /// global residuals of its tuples). Immune to the attenuation of slopes fitted
    /// on the narrow, noisy ω range of one repository.
    PooledSlopes,
}

/// Which method runs: the paper's alone, or with this crate's additions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Variant {
    /// The paper's method (section 3): the lag at the cross-correlation peak,
    /// plain OLS, no turn gain, the DCF of eq. (6) over `update_window_s`.
    Paper,
    /// The paper's method with this crate's additions (see the crate docs):
    /// the lag from the heading fit, the errors-in-variables slope, the joint
    /// calibration (DCF, heading per metre and turn gain over
    /// `calibration_window_s`, accepted only when better on held-back data)
    /// and, with a GNSS course, the per-metre form (no heading at rest).
    #[default]
    Extended,
}

/// TedriS parameters. Units are in the key names: times in seconds; only
/// `tau_samples`, the paper's block length, counts wheel samples.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TedrisConfig {
    /// The method: the paper's alone, or extended (default).
    pub variant: Variant,
    /// τ: wheel samples per block, the FIFO length (paper: 6; the paper's
    /// method is defined in samples, so this one setting stays in samples).
    pub tau_samples: usize,
    /// Half-width of the lag window searched for the lag between the wheels and
    /// the reference heading, s (default 0.4: ±10 samples at 25 Hz).
    pub max_lag_s: f64,
    /// Relative tolerance on the cross-correlation peak: the shortest lag within it
    /// is taken (default 0.005; 0 = the highest peak, as in the paper).
    pub lag_tolerance: f64,
    /// Model kind, or automatic choice by the residual statistics (default auto).
    pub model: ModelChoice,
    /// Repository regression (default pooled slopes).
    pub repository_fit: RepositoryFit,
    /// k of ε = k·(W_H − W_L); `None` for ε = ∞, one repository (paper: 1.5 car,
    /// ∞ robot; default `None`: a repository's own intercept is the mean of a few
    /// dozen noisy block residuals, ±10⁻⁴ rad per sample on the simulated car,
    /// which turns into heading error in every turn; `TedrisConfig::paper` has 1.5).
    pub epsilon_factor: Option<f64>,
    /// Minimum tuples in each required repository for training to be complete (default 20).
    pub min_fill: usize,
    /// Maximum tuples per repository; the oldest is dropped beyond it (default 3000).
    pub max_fill: usize,
    /// Required repositories: R−n … Rn must reach `min_fill` (default 1).
    pub required_bins: i32,
    /// Synchronised reference heading needed before the lag and the
    /// straight-line parameters are estimated, s (default 60).
    pub init_s: f64,
    /// Smallest cross-correlation peak accepted for the first fit; below it the
    /// machine waits for more turning (or a full history) (default 0.3).
    pub min_ccf_peak: f64,
    /// Time of wheel samples kept for the lag, the straight-line parameters
    /// and the calibrations, s (default 1200).
    pub history_s: f64,
    /// Wheel speed below which the GNSS course is not trusted for training, m/s (default 1.0).
    pub min_course_speed_mps: f64,
    /// Largest disagreement between a course's change since the previous course
    /// and the wheels' turn over the same interval for the course to be used,
    /// rad (default 0.2). Catches the random courses receivers report at low
    /// speed and course jumps; the speed gate alone does not.
    pub course_consistency_rad: f64,
    /// Largest gap between two reference headings that is still interpolated, s (default 1.0).
    pub max_heading_gap_s: f64,
    /// No reference heading for this long means GNSS (or gyro) lost, s (default 1.0).
    pub reference_timeout_s: f64,
    /// Window of the heading anchor (mean reference − DR difference), s (default 10).
    pub heading_anchor_window_s: f64,
    /// Window of the position anchor (mean fix − DR difference), s (default 5).
    pub position_anchor_window_s: f64,
    /// Reference data after an outage before the update phase resumes, s (default 3).
    pub retrain_s: f64,
    /// Window of the DCF update (eq. 6), s (default 30).
    pub update_window_s: f64,
    /// Interval between DCF updates, s (default 10).
    pub update_interval_s: f64,
    /// Interval between regression refits once trained, s (default 60). In
    /// the extended variant a refit is refused when significantly worse on
    /// held-back data than the regressions it would replace (see the crate
    /// docs).
    pub refit_interval_s: f64,
    /// Weight of each new DCF estimate against the previous DCF, in (0, 1]
    /// (default 0.2; 1 is eq. (6) as in the paper, whose 30 s estimates are noisy).
    pub dcf_smoothing: f64,
    /// Half-width of the DCF search interval, in units of |α1|·(W_H − W_L) (default 2).
    pub dcf_bound_factor: f64,
    /// Window of the joint calibration, s (default 600).
    pub calibration_window_s: f64,
    /// Reference heading needed in the window before a joint calibration may
    /// replace the current values, s (default 120).
    pub min_calibration_span_s: f64,
    /// Largest rear-radius mismatch the distance term may express, relative
    /// (default 0.01: tyres of one axle are within 1 %); a fit beyond it is refused.
    pub max_radius_mismatch: f64,
    /// Largest turn gain error, relative (default 0.05); a fit beyond it is refused.
    pub max_gain_error: f64,
    /// Largest error of the rear wheels' distance scale (their mean
    /// circumference against the nominal one), relative (default 0.05: worn,
    /// soft or oversized tyres); a fit beyond it is refused.
    #[serde(default = "default_max_distance_scale_error")]
    pub max_distance_scale_error: f64,
    /// Window over which the straight-line detector measures the heading change, s (default 3).
    pub slt_window_s: f64,
    /// Largest reference heading change over `slt_window_s` on a straight line, degrees (default 1).
    pub slt_max_change_deg: f64,
    /// Autocorrelation lags of the portmanteau tests (default 10).
    pub portmanteau_lags: usize,
    /// Significance level of the Ljung–Box test that triggers a correction (default 0.05).
    pub alpha: f64,
    /// Largest AR or MA order tried (default 3).
    pub max_correction_order: usize,
}

impl Default for TedrisConfig {
    fn default() -> Self {
        TedrisConfig {
            variant: Variant::Extended,
            tau_samples: 6,
            max_lag_s: 0.4,
            lag_tolerance: 0.005,
            model: ModelChoice::Auto,
            repository_fit: RepositoryFit::PooledSlopes,
            epsilon_factor: None,
            min_fill: 20,
            max_fill: 3000,
            required_bins: 1,
            init_s: 60.0,
            min_ccf_peak: 0.3,
            history_s: 1200.0,
            min_course_speed_mps: 1.0,
            course_consistency_rad: 0.2,
            max_heading_gap_s: 1.0,
            reference_timeout_s: 1.0,
            heading_anchor_window_s: 10.0,
            position_anchor_window_s: 5.0,
            retrain_s: 3.0,
            update_window_s: 30.0,
            update_interval_s: 10.0,
            refit_interval_s: 60.0,
            dcf_smoothing: 0.2,
            dcf_bound_factor: 2.0,
            calibration_window_s: 600.0,
            min_calibration_span_s: 120.0,
            max_radius_mismatch: 0.01,
            max_gain_error: 0.05,
            max_distance_scale_error: default_max_distance_scale_error(),
            slt_window_s: 3.0,
            slt_max_change_deg: 1.0,
            portmanteau_lags: 10,
            alpha: 0.05,
            max_correction_order: 3,
        }
    }
}

impl TedrisConfig {
    /// The paper's robot settings: ε = ∞ (one repository), no course speed gate,
    /// only R0 required, 60 s of reference to start; the DCF by the joint
    /// calibration (or, in the paper variant, eq. (6) unsmoothed: the gyro
    /// reference is smooth enough).
    pub fn robot() -> Self {
        TedrisConfig {
            epsilon_factor: None,
            min_course_speed_mps: 0.0,
            required_bins: 0,
            init_s: 60.0,
            dcf_smoothing: 1.0,
            ..Self::default()
        }
    }

    /// The paper's method alone, for comparison: the paper's regression (eq. 3)
    /// on block medians, ε = 1.5·(W_H − W_L) with a separate regression per
    /// repository, plain OLS, no dead band, no turn gain, and the DCF of eq. (6)
    /// over 30 s windows, unsmoothed. (The synchronisation improvements, e.g. the
    /// centred lever-arm conversion, stay.)
    pub fn paper() -> Self {
        TedrisConfig {
            variant: Variant::Paper,
            model: ModelChoice::Fixed(ModelKind::Paper),
            repository_fit: RepositoryFit::Separate,
            epsilon_factor: Some(1.5),
            dcf_smoothing: 1.0,
            ..Self::default()
        }
    }

    /// The lag from the heading fit instead of the cross-correlation peak
    /// (the extended variant).
    pub fn lag_from_heading(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// The errors-in-variables correction of the ω slope (the extended variant).
    pub fn eiv_correction(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// The joint calibration of the DCF, heading per metre and turn gain
    /// (the extended variant); eq. (6) otherwise.
    pub fn joint_calibration(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// The rear wheels' distance scale is estimated from GNSS chords (the
    /// extended variant).
    pub fn distance_scale(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// The turn gain is estimated (by the joint calibration: the extended variant).
    pub fn turn_gain(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// The per-metre form with a GNSS course (the extended variant).
    pub fn per_metre_straight(&self) -> bool {
        self.variant == Variant::Extended
    }

    /// Checks every value is usable.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |k: &str, v: String| Err(Error::Config(format!("{k} = {v} is not valid")));
        if self.tau_samples == 0 {
            return bad("tau_samples", "0".into());
        }
        if let Some(k) = self.epsilon_factor {
            if !(k.is_finite() && k > 0.0) {
                return bad("epsilon_factor", k.to_string());
            }
        }
        if self.min_fill < 3 || self.max_fill < self.min_fill {
            return bad(
                "min_fill/max_fill",
                format!("{}/{}", self.min_fill, self.max_fill),
            );
        }
        if self.required_bins < 0 {
            return bad("required_bins", self.required_bins.to_string());
        }
        if !(self.init_s.is_finite() && self.init_s >= 2.0) {
            return bad("init_s", self.init_s.to_string());
        }
        for (k, v) in [
            ("max_heading_gap_s", self.max_heading_gap_s),
            ("max_lag_s", self.max_lag_s),
            ("history_s", self.history_s),
            ("reference_timeout_s", self.reference_timeout_s),
            ("heading_anchor_window_s", self.heading_anchor_window_s),
            ("position_anchor_window_s", self.position_anchor_window_s),
            ("update_window_s", self.update_window_s),
            ("update_interval_s", self.update_interval_s),
            ("refit_interval_s", self.refit_interval_s),
            ("dcf_bound_factor", self.dcf_bound_factor),
            ("calibration_window_s", self.calibration_window_s),
            ("slt_window_s", self.slt_window_s),
            ("slt_max_change_deg", self.slt_max_change_deg),
            ("course_consistency_rad", self.course_consistency_rad),
            ("min_calibration_span_s", self.min_calibration_span_s),
            ("max_radius_mismatch", self.max_radius_mismatch),
            ("max_gain_error", self.max_gain_error),
            ("max_distance_scale_error", self.max_distance_scale_error),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(k, v.to_string());
            }
        }
        if !(self.min_course_speed_mps.is_finite()
            && self.min_course_speed_mps >= 0.0
            && self.retrain_s >= 0.0)
        {
            return bad(
                "min_course_speed_mps/retrain_s",
                format!("{}/{}", self.min_course_speed_mps, self.retrain_s),
            );
        }
        if !(self.dcf_smoothing > 0.0 && self.dcf_smoothing <= 1.0) {
            return bad("dcf_smoothing", self.dcf_smoothing.to_string());
        }
        if !(self.alpha > 0.0 && self.alpha < 1.0) || self.portmanteau_lags == 0 {
            return bad(
                "alpha/portmanteau_lags",
                format!("{}/{}", self.alpha, self.portmanteau_lags),
            );
        }
        Ok(())
    }
}

fn default_max_distance_scale_error() -> f64 {
    0.05
}
