//! # deadreckon-tedris
//!
//! TedriS, the Time Series Dead Reckoning System (Freitas, Costa, Campista et al.):
//! dead reckoning through GNSS outages from the rear wheels alone, with a
//! regression learnt, while GNSS is good, between the rear wheel difference and
//! the GNSS course increments. A streaming API ([`Tedris`], one sample at a time,
//! as on a vehicle) and batch functions over a [`deadreckon_core::Drive`]
//! ([`train`], [`run_outages`]).
//!
//! ## Reading of the paper's ω and γ (units)
//!
//! The paper's notation is loose (its ω is called a yaw rate but tabulated in
//! metres). Here, on the wheel clock (the faster one: 25 Hz wheels against 4 Hz
//! GNSS on the car; both 10 Hz on the robot):
//!
//! - **ω_t** = right − left rear wheel distance over sample t, **metres per sample**
//!   (eq. 1 times the track width times the sample period; left turns positive);
//! - **d_t** = mean rear wheel distance over sample t, metres per sample;
//! - **θ_t** = reference heading (GNSS course of the antenna converted to the
//!   rear-axle heading with the lever arm, or the integrated gyro), linearly
//!   interpolated onto the wheel clock, unwrapped (no 0/360° jump), radians
//!   counter-clockwise from east;
//! - **γ_t** = θ_t − θ_{t−1}, **radians per sample**.
//!
//! So the slope α1 is in rad/m (≈ 1/track width), α0 and the DCF in rad per
//! sample, and µ, W_L, W_H, ε in metres per sample, as in the paper's text.
//! γ_t is regressed on ω_{t−h}, h the lag of the cross-correlation peak.
//!
//! ## What runs, in the paper's order
//!
//! 1. Synchronisation (figure 3) on the wheel clock; a GNSS course (the antenna's)
//!    becomes the rear-axle heading `θ − atan(l·ψ̇/v)` with ψ̇, v from the wheels
//!    over the fix interval **centred** on the course's time (the course waits for
//!    the wheel samples after it); the course from chords between fixes or the
//!    integrated gyro (bias taken at standstill) are the other references.
//! 2. Cross-correlation of ω and γ; the lag h from the heading fit (below), or,
//!    as in the paper, at the correlation peak within ±`max_lag_s` (the
//!    shortest lag within `lag_tolerance` of the peak: the peak is flat).
//! 3. Blocks of τ samples → tuples (median ω, median d, median γ); straight
//!    blocks (reference heading change < `slt_max_change_deg` over `slt_window_s`)
//!    give µ, W_L, W_H and ε = k·(W_H − W_L); repositories R_n with min/max fill.
//! 4. Regressions of eq. (2)–(3) for every kind (paper, distance, ARX), with the
//!    coefficient table, Box–Pierce and Ljung–Box, the AR/MA correction when
//!    Ljung–Box rejects, the joint refit (table 2), the repository fits, and the
//!    automatic choice: by residual statistics (simulation BIC among
//!    white-innovation kinds) at the fit, then, with the joint calibration, the
//!    kind whose calibrated heading fits the reference best.
//! 5. Update phase: by default the joint calibration (below); eq. (6) (Brent's
//!    bounded minimisation of the heading RMSE over `update_window_s`, from DCF₀)
//!    in the paper variant.
//! 6. Prediction: eq. (4) per wheel sample, heading by cumulative sum (eq. 5),
//!    position by the rear-wheel distance along the heading; the AR/MA forecast
//!    carries the last block errors into the outage.
//!
//! ## Holding on drives it was never tuned on
//!
//! Tried on drives made independently of the simulator, the method once lost
//! 250 m in 80 s outages: receivers report random courses at low speed, and a
//! course unwrapped through every stop jumped by whole turns, which the heading
//! fits read as drift. What guards against that now:
//!
//! - **Heading segments** ([`history::Sample::segment`]): the reference is
//!   never unwrapped across a gap, a stop, an unusable course or an outage; a
//!   new segment starts on the branch nearest the dead-reckoned heading, and
//!   every heading fit (joint calibration, eq. 6, heading lag, course
//!   convention) has an intercept per segment ([`history::centre_per_segment`]).
//! - **Courses checked against the wheels**: a course is used only when its
//!   change since the previous course agrees with the wheels' turn within
//!   `course_consistency_rad`, not only above a speed; none is used while the
//!   rear wheels roll backwards (receivers then report the direction of
//!   motion, a frozen course or a random one;
//!   [`Tedris::reversing_courses`] counts them). Below
//!   [`tuning::HELD_COURSE_MAX_SPEED_MPS`] a course equal to the one before
//!   is skipped as held by the receiver (a course held since reversing
//!   points backwards while the car pulls away, and its change agrees with
//!   the wheels'; `MachineChecks::repeated_courses` counts them); faster, a
//!   repeat is a straight road in the course's resolution and kept.
//! - **Physical form** (GNSS course, the extended variant): the straight-line
//!   heading is per metre only, as unequal rear radii make it; the model turns
//!   the car only when the wheels move ([`history::moving`]); the ARX kind,
//!   whose turn lives in its feedback, is not used in this form.
//! - **The distance travelled, not the distance reported** ([`DistanceScale`],
//!   `machine/scale.rs`): the rear wheels' distance scale (their mean
//!   circumference against the nominal one) from 10 s GNSS chords, fitted,
//!   bounded and held back like the heading calibration. Without it a tyre
//!   1 % off put the car 8 m short after 800 m; on the family's cars 1–12 it
//!   took the 80 s outage mean from 3.17 m to 2.70 m.
//! - **Bounds refuse, not clamp**: a calibration reaching the radius-mismatch
//!   (`max_radius_mismatch`), turn-gain (`max_gain_error`), distance-scale
//!   (`max_distance_scale_error`) or DCF bound is
//!   refused and counted ([`Tedris::refused_calibrations`]); a heading lag at
//!   the edge of its search (`max_lag_s`) is refused for the
//!   cross-correlation peak.
//! - **Nothing replaces a model unless it is better out of sample**: a joint
//!   calibration is fitted on the first three quarters of its window and
//!   accepted only if its heading residual on the last quarter is no larger
//!   than the current model's, after `min_calibration_span_s` of reference;
//!   the automatic kind choice uses the same held-back residual. On a
//!   machine started from a trained model it leaves the incumbent kind (the
//!   trained model's, then the one each calibration installed) only when
//!   that kind, recalibrated on the same rows, has a held-back mean square
//!   larger by more than `tuning::KIND_SWITCH_MARGIN` (10 %;
//!   [`Tedris::kept_kinds`] counts the calibrations that kept it: without
//!   the margin the held kind flipped every few calibrations on tick
//!   counters and over-turned a fast turn into an outage). A refit of
//!   the regressions once trained (and the closing refit of [`train`]) is
//!   calibrated the same way beside the current regressions and refused
//!   when its held-back heading residual is worse by more than
//!   `tuning::REFIT_TEST_MARGIN` (5 % in mean square) at the one-sided level
//!   `tuning::REFIT_TEST_LEVEL` (0.01; a paired t test over batch means,
//!   batches at least two correlation times of the loss difference long),
//!   or when it cannot be calibrated within the physical bounds and the
//!   current regressions can ([`Tedris::accepted_refits`],
//!   [`Tedris::refused_refits`], in [`MachineChecks`]). It refuses harm
//!   rather than wait for a proof of improvement: accepting only refits
//!   significantly better took the family's cars 101–112 from 1.37 to
//!   1.42 m and the Husky's 60 s outages from 1.48 to 1.60 m (freezing the
//!   regressions once trained: 1.45 m, 1.60 m). What it can see is small:
//!   the joint calibration absorbs a regression's linear part, so once
//!   calibrated a refit has the current regressions' held-back residual to
//!   1e-9 in 95 % of 344 refits on the family's cars 1–12, and blocks with
//!   γ offset in one repository (3·10⁻³ rad on left turns, 3·10⁻⁴ rad on
//!   straights) leave it unchanged. On the clean drives measured (family
//!   cars 1–12 and 101–112, the simulated car and robot, the Husky with the
//!   gyro) it refused no refit by the test and changed no outage; it
//!   refuses refits the calibration cannot follow within its bounds (4 on
//!   the Husky, all on the fix-track reference; blocks whose γ was shuffled,
//!   ω slope 0.64 → 0.15 unguarded).
//! - **A watchdog** ([`Tedris::model_alarms`]): in the update phase, a
//!   dead-reckoned heading drifting from the reference faster than
//!   `tuning::MAX_HEADING_DRIFT_RPS` over the anchor window counts an alarm
//!   and brings the next calibration forward. It is a noisy signal (6 alarms
//!   on trained models over 24 family test runs); a 0.01 rad/m fault is found
//!   within 25 s.
//! - **The course convention is checked on the data**
//!   ([`machine::course_convention`]): antenna velocity or body yaw, by which
//!   heading fits the wheels better at its best lag; undecided (antenna
//!   assumed) without a 10 % difference.
//! - **Wheel-tick counters** ([`blocks`], issue 35): per-sample ticks are
//!   mostly quantisation noise, and medians of whole ticks attenuated α1
//!   tenfold. When the wheel distances lie on a lattice coarse against the
//!   reference's turning, blocks are means (cumulative increments) with τ
//!   chosen so that the quantisation leaves at most 1 % attenuation; the
//!   choice and why are in the model ([`TedrisModel::blocks`]) and printed
//!   by `tedris train`. The speed kind ([`config::ModelKind::Speed`])
//!   follows the loaded outer tyres' smaller radius in turns; its
//!   errors-in-variables fit takes off the noise covariance of its ω·d²
//!   column with ω's ([`stats::ols_eiv_sum`]).
//! - **Physical acceptance** ([`acceptance`]): a kind whose turn gain
//!   (α1·track, or its equivalent) is outside [0.75, 1.33], whose block R²
//!   is not significantly above 0, the speed kind whose ω·d² term is not
//!   significant, or a cross-correlation peak far below what the data's
//!   turning should give, is refused with the failed check and what to do;
//!   the baseline kind stands in if it passes. docs/tedris.md, "Wheel-tick
//!   counters and physical acceptance", has the measurements.
//! - **A plain baseline** ([`baseline`]): least squares of course increments
//!   on wheel increments, what a user writes in an afternoon, run through the
//!   same outages.
//!
//! Measured on 12 cars of the simulator's randomized family
//! (`deadreckon_sim::family`, `tests/family_outages.rs`; GNSS latencies up to
//! 0.15 s), trained on one drive and tested on another, 24 outages of 80 s
//! (most right after a stop): mean error 3.20 m (worst 8.04 m) against 82.3 m
//! before these changes; the paper's method alone 72.1 m; the baseline 8.12 m.
//! On 12 other cars (101–112) not looked at while developing: 2.22 m (worst
//! 5.67 m), paper 49.8 m, baseline 5.16 m. The position anchor does not
//! correct the GNSS latency (about 1 m at 10 m/s and 0.1 s).
//!
//! ## Beyond the paper ([`config::Variant::Extended`], the default;
//! [`config::Variant::Paper`] and [`TedrisConfig::paper`] are the paper's
//! method alone)
//!
//! - **Joint calibration**: eq. (6) generalised.
//!   Over the last `calibration_window_s` (10 min) the reference heading is
//!   regressed on the model's cumulative heading: DCF (rad per sample), a
//!   distance term (rad per metre) and the turn gain g by linear least squares.
//!   What decides the drift in an outage is the straight-line rate at each speed
//!   (to about 10⁻⁶ rad per sample on the car) and the scale of turns; block
//!   increments of a noisy course, or 30 s windows, give these 10–100 times less
//!   precisely than the heading over minutes. This is the largest gain (car,
//!   seeds 7–12: 3.6 m → 1.4 m). Each installed value carries its standard
//!   error (`TedrisModel::dcf_std_rad`, `dcf_distance_std_rad_per_m`,
//!   `turn_gain_std`; `None`: not estimated): the residuals of a cumulative
//!   heading are random-walk-like and the OLS formula reads 18–153 times
//!   smaller on the car family, so they are taken over blocks of the residual increments
//!   ([`stats::increment_block_std`]; docs/tedris.md, "Calibrated values and
//!   their standard errors").
//! - Lag from the heading: h minimises the
//!   residual of the reference heading fitted on the wheels' cumulative sums
//!   h samples earlier ([`machine::heading_lag`]); the per-sample
//!   cross-correlation peak is flat and wandered by ±3 samples (0.12 s), which
//!   misplaces the heading anchor in turns (car: 1.6 m → 1.0 m).
//! - Centred lever-arm conversion of the course (always on): a yaw rate taken
//!   over the fix interval *before* the course lags by half an interval, skews
//!   the heading increments at every turn entry and exit and attenuated α1 by
//!   1.5 % on the simulated car (a 90° turn then loses 0.024 rad).
//! - `Distance` and `Arx` kinds (the paper's future work): the rear-radius bias
//!   grows with the distance per sample, which a constant DCF cannot follow.
//! - Errors-in-variables slope correction: block medians of ω
//!   are noisy, which attenuates an OLS slope.
//! - Gyro bias pooled over the training and the run drives' standstills
//!   ([`TedrisModel::gyro_bias`]): the gyro heading's residual bias is learnt as
//!   DCF and is the robot's limit (a 5 s standstill leaves ±3·10⁻⁴ rad/s).
//! - Without truth, the gyro heading is turned into the GNSS frame (circular
//!   mean of chord directions minus gyro heading) and the fixes anchor the
//!   position, so a real robot's run is measured against its hidden fixes.
//! - Automatic model choice by the calibrated heading (with the joint
//!   calibration): the block-level BIC prefers ARX, which drifts more in dead
//!   reckoning (car, automatic choice: 1.68 m → 0.98 m).
//! - Removed as superseded (they were switches): a straight-line dead band and
//!   a turn gain from whole-segment heading changes (remedies for white
//!   wheel-speed noise the joint calibration handles), block means, a trend in
//!   the heading anchor, freezing the DCF.
//!
//! ## Measured on the simulator (see `tests/sim_outages.rs`)
//!
//! `tedris-car` (tone-ring wheel-speed noise): model trained on seed s, 80 s
//! outages starting at 200, 350 and 500 s of the drive of seed s + 100, seeds
//! 1–6; mean position error against truth, averaged per seed then over seeds:
//!
//! | configuration | mean error | per seed |
//! |---|---|---|
//! | defaults, distance kind | 0.97 m | 0.41–1.61 m |
//! | defaults, paper kind (the distance term comes from the calibration) | 0.96 m | 0.47–1.66 m |
//! | defaults, automatic choice (by the held-back calibrated heading) | 1.00 m | 0.55–1.65 m |
//! | automatic choice by block BIC (before; ARX for 2 seeds) | 1.68 m | 1.14–2.28 m |
//! | distance kind, lag from the cross-correlation peak | 1.60 m | 0.48–2.12 m |
//! | the paper's method alone ([`TedrisConfig::paper`]) | 5.58 m | 2.77–10.15 m |
//!
//! On other windows (120–550 s) and seeds 7–12 the distance kind gives 0.83 m
//! (0.67–1.06 per seed), the automatic choice 0.86 m (1.65 m by block BIC);
//! 3.58 m without the joint calibration and the heading lag. A wheel-only dead reckoning with the
//! true radii and the true initial pose has about 0.5 m on the same windows.
//! The paper reports about 3 m (figure 6b) and 4 m (figure 6c).
//!
//! `tedris-robot` (gyro reference, error aligned at the outage start, 90 s
//! outages every 30 s from 30 to 240 s, seeds 1–6): the error stays under
//! 0.159 m for at least 60 s in 42 of 48 outages, median 90 s, shortest 42 s
//! (39 of 48 and 37 s before the heading segments and the standstill rule).
//! Before the pooled gyro bias it was 18/48 (seed 1: 8–25 s); a diagnostic run
//! with the exact gyro bias also gives 37/48.
//!
//! The real Husky bag (tests/husky_bag.rs, gyro reference, trained on the first
//! half, lag −3 samples): 30 s outages 0.63–2.10 m mean error against the
//! hidden SBAS fixes (largest 4.4 m; mean of the five 1.41 m), 60 s outages
//! 0.77–2.39 m (largest 4.7 m; mean 1.48 m). The window [125, 185) was 2.34 m
//! before the held-back calibration: it starts with a DCF of +1.17·10⁻⁵ rad per
//! sample calibrated 90 s earlier for the paper kind on data ending 150 s
//! before the outage (the refit after it set the kind back to the block BIC's
//! ARX and kept these values), the 9 calibrations after it worse than it on
//! their held-back quarter; installing every calibration fitted on the whole
//! window, as before, starts it with −1.3·10⁻⁵ (the DCF alone moves the window
//! 0.017 m per 10⁻⁵) and gives 2.34 m, but 1.42 m and 1.50 m over the 30 s and
//! 60 s outages (1.41, 1.48 m now) and a worst family outage of 6.11 m and
//! 4.94 m (cars 1–12, 101–112; 5.80 and 2.94 m now). The window's difference
//! is not significant (paired per-fix errors, 10 s batch means: +0.047 m,
//! t = 1.3 on 5 degrees of freedom). The course from chords between the fixes
//! is too noisy at 1 m/s for the block regression (cross-correlation peak
//! 0.06): 2.8–12.1 m over 30 s.
//!
//! ## Modules
//!
//! | module | concept |
//! |---|---|
//! | [`stats`] | OLS, coefficient table (estimate, standard error, t, p), median, the paired batch-means t test of the refit guard, the block standard errors of a cumulative regression (the joint calibration's) |
//! | [`baseline`] | the plain least-squares baseline TedriS is compared with |
//! | [`residuals`] | autocorrelation, Box–Pierce, Ljung–Box, AR/MA correction |
//! | [`ccf`] | cross-correlation ω/γ, lag at the peak |
//! | [`repository`] | tuples, straight-line band, repositories R_n |
//! | [`model`] | the fitted regressions of every kind, model choice, DCF₀ |
//! | [`predict`] | eq. (4) per sample: FIFO median, repository, DCF, correction |
//! | [`history`] | wheel-clock samples with the synchronised heading and its segment, block formation, per-segment centring |
//! | [`minimise`] | Brent's bounded minimisation (eq. 6) |
//! | [`machine`] | the state machine of section 3.3 (`mod.rs`), heading synchronisation (`sync.rs`: segments, consistency, convention, anchor), training (`training.rs`), calibration (`calibration.rs`: eq. 6, the joint calibration with held-back acceptance, the heading lag) |
//! | [`input`] | drive → events (wheels, reference heading, fixes), outage blanking |
//! | [`outage`] | batch training and outage runs with their errors |
//! | [`config`] | every parameter with unit and default |
//! | [`tuning`] | the internal thresholds, named and documented |
#![deny(missing_docs)]

pub mod acceptance;
pub mod baseline;
pub mod blocks;
pub mod ccf;
pub mod config;
pub mod convention;
pub mod history;
pub mod input;
pub mod machine;
pub mod minimise;
pub mod model;
pub mod outage;
pub mod predict;
pub mod repository;
pub mod residuals;
pub mod stats;
pub mod tuning;

pub use config::{ModelChoice, ModelKind, RepositoryFit, TedrisConfig, Variant};
pub use input::ReferenceSource;
pub use machine::{
    Estimate, Geometry, HeadingSample, MachineChecks, Phase, PositionFix, Tedris, WheelSample,
};
pub use model::{DistanceScale, TedrisModel};
pub use outage::{
    run_outages, run_outages_with, train, Outage, OutageError, OutageReport, RunOptions,
};

/// Errors of TedriS.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A configuration value is not usable.
    #[error("invalid configuration: {0}")]
    Config(String),
    /// A regression could not be fitted (too few rows, singular design, non-finite data).
    #[error("regression failed: {0}")]
    Regression(String),
    /// A loaded model is inconsistent.
    #[error("invalid model: {0}")]
    Model(String),
    /// A sample was rejected (non-finite, or time not increasing).
    #[error("invalid input: {0}")]
    Input(String),
    /// JSON (de)serialisation failed.
    #[error("JSON: {0}")]
    Json(String),
    /// The data cannot support the request (no reference heading, too short to train).
    #[error("insufficient data: {0}")]
    Insufficient(String),
    /// The drive breaks an invariant.
    #[error(transparent)]
    Drive(#[from] deadreckon_core::Error),
}
