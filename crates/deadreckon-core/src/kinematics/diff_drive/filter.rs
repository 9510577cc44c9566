//! A GNSS-aided extended Kalman filter of the differential drive: where an
//! outage starts from when the fixes wander.
//!
//! State (named indices below), SI units:
//!
//! | index | meaning | unit |
//! |---|---|---|
//! | [`X`], [`Y`] | the base (axle centre), east and north of the fixes' origin | m |
//! | [`YAW`] | heading, counter-clockwise from east | rad |
//! | [`YAW_BIAS`] | yaw-rate bias `b_ω` subtracted from the scaled rate | rad/s |
//! | [`SPEED_SCALE`] | odometry speed scale `a_v` | 1 |
//! | [`YAW_SCALE`] | yaw-rate scale `a_ω` | 1 |
//! | [`FIX_E`], [`FIX_N`] | the fixes' slowly wandering error, east and north | m |
//!
//! Propagation over a step of `dt` with mean odometry speed `v̄` and yaw rate
//! `ω` (the kinematics of [`super`]):
//!
//! ```text
//! Δψ = (a_ω·ω − b_ω)·dt,   m = ψ + Δψ/2,   d = a_v·v̄·dt
//! x' = x + d·cos m,   y' = y + d·sin m,   ψ' = ψ + Δψ
//! b_ω' = b_ω,   a_v' = a_v,   a_ω' = a_ω,   e' = φ·e  with φ = exp(−dt/τ)
//! ```
//!
//! A fix measures the antenna `(x_a, y_a)` on the base plus the wander:
//! `z = p + R(ψ)·(x_a, y_a) + e + w`, `w` white. The wander `e` is a
//! first-order Gauss–Markov process of standard deviation `σ_e` and time
//! constant `τ` (process noise `σ_e²·(1 − φ²)` per step, so its variance
//! stays `σ_e²`). Every fix is gated by its Mahalanobis distance and counted;
//! when the gate keeps rejecting for [`FilterNoise::jump_after_s`] the fixes
//! are taken to have jumped (an SBAS correction change): the wander's
//! variance is widened and the fix taken, counted as a jump.
//!
//! The filter starts once the odometry has travelled
//! [`FilterNoise::init_path_m`]: the dead reckoning over that stretch aligned
//! to its fixes gives the pose; the bias and the scales start at the
//! parameters' values with their standard errors (or the defaults' priors).
//!
//! Through an outage the filter keeps predicting without fixes: the base is
//! dead-reckoned with the estimated bias and scales, and the wander estimate
//! at the outage's start decays as `e·exp(−t/τ)` — the part of the fixes'
//! error still expected at the fix the outage is scored against.
//!
//! The noise values live in [`FilterNoise`], each with its unit, its
//! meaning and where its default comes from.

use nalgebra::{SMatrix, SVector};

use super::{align, DiffDriveDrive, ANTENNA_X, ANTENNA_Y, N_PARAMS, SPEED_SCALE as P_SPEED};
use super::{YAW_BIAS as P_BIAS, YAW_SCALE as P_YAW};
use crate::kalman::{innovation_stats, predict_covariance, update_vector, CovarianceForm};
use crate::{Error, Rule, Value};

/// Index of the base's east coordinate, m.
pub const X: usize = 0;
/// Index of the base's north coordinate, m.
pub const Y: usize = 1;
/// Index of the heading, rad.
pub const YAW: usize = 2;
/// Index of the yaw-rate bias, rad/s.
pub const YAW_BIAS: usize = 3;
/// Index of the odometry speed scale.
pub const SPEED_SCALE: usize = 4;
/// Index of the yaw-rate scale.
pub const YAW_SCALE: usize = 5;
/// Index of the fixes' wander, east, m.
pub const FIX_E: usize = 6;
/// Index of the fixes' wander, north, m.
pub const FIX_N: usize = 7;
/// State dimension.
pub const N: usize = 8;

/// The filter's state.
pub type State = SVector<f64, N>;
/// Its covariance (and the transition Jacobian).
pub type Cov = SMatrix<f64, N, N>;
/// d(state)/d(inputs): columns `v̄` and the scaled yaw rate `a_ω·ω`.
type InputJacobian = SMatrix<f64, N, 2>;
/// d(fix)/d(state).
type FixJacobian = SMatrix<f64, 2, N>;

/// The filter's noise model, in one place: every value with its unit, its
/// meaning and where its default comes from.
///
/// The kinematic values are set by a physical argument (stated with each).
/// The fixes' error model (`fix_white_m`, `fix_wander_m`,
/// `fix_wander_tau_s`) was identified by maximising the likelihood of the
/// fixes' innovations ([`fix_log_likelihood`]) on the first half of the
/// Husky bag only (its first 197.7 s, nominal parameters, the grid of
/// `examples/diff_drive_fix_model.rs`): never on outage errors, and never
/// on the second half.
///
/// The three `*_prior` values are the standard deviations of the kinematic
/// parameters the filter refines, used for a parameter whose source states
/// none (nominal values, or not estimated); a calibrated parameter starts
/// with its calibration's standard error instead
/// ([`FilterNoise::with_param_std`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FilterNoise {
    /// Odometry speed white noise as a random walk of the distance
    /// travelled, m/√s. Default 0.02: wheel-encoder speed of a 1 m/s robot
    /// is good to a few cm/s sample to sample (quantisation, skid in
    /// turns); over one second of 10 Hz samples that is 0.02 m.
    pub speed_noise_m_per_sqrt_s: f64,
    /// Yaw-rate white noise as a random walk of the heading (angle random
    /// walk), rad/√s. Default 0.005 (0.29°/√s): an order above a MEMS
    /// gyro's data-sheet ARW (about 0.5 mrad/√s) for vibration on a
    /// skid-steer base and for the odometry yaw rate's slip.
    pub yaw_noise_rad_per_sqrt_s: f64,
    /// Standard deviation of the yaw-rate bias at the start when the
    /// parameters state none, rad/s. Default 0.001 (0.06°/s): the residual
    /// bias of a consumer MEMS gyro after its driver's start-up zeroing.
    pub yaw_bias_prior_rps: f64,
    /// Standard deviation of the speed scale at the start when the
    /// parameters state none. Default 0.03: tyre wear, pressure and the
    /// skid of a four-wheel skid-steer base, 3%.
    pub speed_scale_prior: f64,
    /// Standard deviation of the yaw-rate scale at the start when the
    /// parameters state none. Default 0.05: a MEMS gyro's scale-factor
    /// error (1–3%) and the cosine of a few degrees of mounting tilt; for
    /// the odometry yaw rate, skid-steer slip in turns.
    pub yaw_scale_prior: f64,
    /// Random walk of the yaw-rate bias, rad/s/√s. Default 3e-6: a MEMS
    /// gyro's in-run bias instability (about 10°/h, 5e-5 rad/s) reached
    /// over some five minutes — constant within an outage.
    pub yaw_bias_walk_rps_per_sqrt_s: f64,
    /// Random walk of the speed scale, 1/√s. Default 1e-5: the scale is a
    /// property of the tyres, 0.03% over ten minutes.
    pub speed_scale_walk_per_sqrt_s: f64,
    /// Random walk of the yaw-rate scale, 1/√s. Default 1e-5, as the speed
    /// scale's.
    pub yaw_scale_walk_per_sqrt_s: f64,
    /// White noise of a fix, per axis, m. Default 0.05: on the first half
    /// of the Husky bag the likelihood rises as this falls to the grid's
    /// floor (log-likelihood per fix 0.292 at 0.05 m, 0.327 at 0.01 m: the
    /// wander explains everything), so it is not identified; 0.05 m is kept
    /// as the output noise of a carrier-smoothed receiver (the outage
    /// errors differ by a few millimetres between the two).
    pub fix_white_m: f64,
    /// Standard deviation of the fixes' wander, per axis, m. Default 3.0:
    /// with the white noise at 0.05 m, the likelihood's maximum on the
    /// first half of the Husky bag (the receiver reports σ = 0.9 m, which
    /// the fixes' drift against the odometry exceeds).
    pub fix_wander_m: f64,
    /// Time constant of the wander, s. Default 180, with `fix_wander_m`
    /// the likelihood's maximum on the first half of the Husky bag. The
    /// likelihood is flat along σ²/τ ≈ 0.05 m²/s (2.5 m with 120 s and 4 m
    /// with 300 s are within 0.002 per fix; 1.5 m with 45 s within 0.005):
    /// over a 30 s outage the wander moves like a random walk of that
    /// diffusion, and a half of the bag (200 s) does not tell σ from τ.
    pub fix_wander_tau_s: f64,
    /// χ² threshold of the Mahalanobis gate on a fix (2 degrees of
    /// freedom). Default 13.82, the 99.9% quantile.
    pub gate_chi2: f64,
    /// How long the gate may keep rejecting fixes before the filter takes
    /// them to have jumped, s: the wander's variance is then widened by
    /// `fix_wander_m²` and the fix taken (counted as a jump). Default 2: a
    /// multipath spike lasts a fix or two; a shift that persists for 2 s
    /// (5 fixes at 2.5 Hz) while the odometry runs smoothly is a new level
    /// of the fixes' error (an SBAS correction or satellite change), not
    /// motion, and the fixes an outage is scored against keep it.
    pub jump_after_s: f64,
    /// Path over which the first pose is taken by aligning the dead
    /// reckoning to the fixes, m. Default 10: the heading then starts
    /// within about 0.2 rad (σ = 2·the fixes' error across the stretch /
    /// its length; the wander common to the stretch only shifts it),
    /// inside the filter's linear range.
    pub init_path_m: f64,
}

impl Default for FilterNoise {
    fn default() -> Self {
        FilterNoise {
            speed_noise_m_per_sqrt_s: 0.02,
            yaw_noise_rad_per_sqrt_s: 0.005,
            yaw_bias_prior_rps: 0.001,
            speed_scale_prior: 0.03,
            yaw_scale_prior: 0.05,
            yaw_bias_walk_rps_per_sqrt_s: 3e-6,
            speed_scale_walk_per_sqrt_s: 1e-5,
            yaw_scale_walk_per_sqrt_s: 1e-5,
            fix_white_m: 0.05,
            fix_wander_m: 3.0,
            fix_wander_tau_s: 180.0,
            gate_chi2: 13.815510557964274,
            jump_after_s: 2.0,
            init_path_m: 10.0,
        }
    }
}

impl FilterNoise {
    /// The priors of the speed scale, yaw scale and yaw bias replaced by
    /// the standard errors `std` (one per parameter of [`super::NAMES`],
    /// `None` where the source states none) where they are given and
    /// positive.
    pub fn with_param_std(mut self, std: &[Option<f64>]) -> FilterNoise {
        let get = |k: usize| std.get(k).copied().flatten().filter(|v| *v > 0.0);
        if let Some(v) = get(P_SPEED) {
            self.speed_scale_prior = v;
        }
        if let Some(v) = get(P_YAW) {
            self.yaw_scale_prior = v;
        }
        if let Some(v) = get(P_BIAS) {
            self.yaw_bias_prior_rps = v;
        }
        self
    }

    /// Checks that every value is finite and positive.
    pub fn check(&self) -> Result<(), Error> {
        let v = [
            ("speed_noise_m_per_sqrt_s", self.speed_noise_m_per_sqrt_s),
            ("yaw_noise_rad_per_sqrt_s", self.yaw_noise_rad_per_sqrt_s),
            (
                "yaw_bias_walk_rps_per_sqrt_s",
                self.yaw_bias_walk_rps_per_sqrt_s,
            ),
            (
                "speed_scale_walk_per_sqrt_s",
                self.speed_scale_walk_per_sqrt_s,
            ),
            ("yaw_bias_prior_rps", self.yaw_bias_prior_rps),
            ("speed_scale_prior", self.speed_scale_prior),
            ("yaw_scale_prior", self.yaw_scale_prior),
            ("yaw_scale_walk_per_sqrt_s", self.yaw_scale_walk_per_sqrt_s),
            ("fix_white_m", self.fix_white_m),
            ("fix_wander_m", self.fix_wander_m),
            ("fix_wander_tau_s", self.fix_wander_tau_s),
            ("gate_chi2", self.gate_chi2),
            ("jump_after_s", self.jump_after_s),
            ("init_path_m", self.init_path_m),
        ];
        match v.iter().find(|(_, x)| !(x.is_finite() && *x > 0.0)) {
            Some((name, x)) => Err(Error::param(
                format!("filter noise {name}"),
                *x,
                Rule::Positive,
            )),
            None => Ok(()),
        }
    }
}

/// One propagation step's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepInput {
    /// Step length, s.
    pub dt_s: f64,
    /// Mean odometry speed over the step (raw), m/s.
    pub v_mps: f64,
    /// Yaw rate over the step (raw), rad/s.
    pub yaw_rate_rps: f64,
}

/// The propagated state and its Jacobians with respect to the state (`F`)
/// and to the inputs `(v̄, a_ω·ω)` (`G`).
pub fn propagate(x: &State, u: &StepInput, tau_s: f64) -> (State, Cov, InputJacobian) {
    let dt = u.dt_s;
    let dpsi = (x[YAW_SCALE] * u.yaw_rate_rps - x[YAW_BIAS]) * dt;
    let mid = x[YAW] + 0.5 * dpsi;
    let (sm, cm) = mid.sin_cos();
    let d = x[SPEED_SCALE] * u.v_mps * dt;
    let phi = (-dt / tau_s).exp();
    let mut xn = *x;
    xn[X] += d * cm;
    xn[Y] += d * sm;
    xn[YAW] += dpsi;
    xn[FIX_E] *= phi;
    xn[FIX_N] *= phi;

    let mut f = Cov::identity();
    // ∂m/∂ψ = 1, ∂m/∂b_ω = −dt/2, ∂m/∂a_ω = ω·dt/2.
    f[(X, YAW)] = -d * sm;
    f[(Y, YAW)] = d * cm;
    f[(X, YAW_BIAS)] = d * sm * 0.5 * dt;
    f[(Y, YAW_BIAS)] = -d * cm * 0.5 * dt;
    f[(YAW, YAW_BIAS)] = -dt;
    f[(X, YAW_SCALE)] = -d * sm * 0.5 * u.yaw_rate_rps * dt;
    f[(Y, YAW_SCALE)] = d * cm * 0.5 * u.yaw_rate_rps * dt;
    f[(YAW, YAW_SCALE)] = u.yaw_rate_rps * dt;
    f[(X, SPEED_SCALE)] = u.v_mps * dt * cm;
    f[(Y, SPEED_SCALE)] = u.v_mps * dt * sm;
    f[(FIX_E, FIX_E)] = phi;
    f[(FIX_N, FIX_N)] = phi;

    let mut g = InputJacobian::zeros();
    // ∂d/∂v̄ = a_v·dt; with r = a_ω·ω the scaled rate, ∂m/∂r = dt/2, ∂Δψ/∂r = dt.
    g[(X, 0)] = x[SPEED_SCALE] * dt * cm;
    g[(Y, 0)] = x[SPEED_SCALE] * dt * sm;
    g[(X, 1)] = -d * sm * 0.5 * dt;
    g[(Y, 1)] = d * cm * 0.5 * dt;
    g[(YAW, 1)] = dt;
    (xn, f, g)
}

/// The fix the state predicts (antenna plus wander) and its Jacobian.
pub fn predicted_fix(x: &State, antenna: [f64; 2]) -> (SVector<f64, 2>, FixJacobian) {
    let (s, c) = x[YAW].sin_cos();
    let [ax, ay] = antenna;
    let z = SVector::<f64, 2>::new(
        x[X] + c * ax - s * ay + x[FIX_E],
        x[Y] + s * ax + c * ay + x[FIX_N],
    );
    let mut h = FixJacobian::zeros();
    h[(0, X)] = 1.0;
    h[(1, Y)] = 1.0;
    h[(0, YAW)] = -s * ax - c * ay;
    h[(1, YAW)] = c * ax - s * ay;
    h[(0, FIX_E)] = 1.0;
    h[(1, FIX_N)] = 1.0;
    (z, h)
}

/// The filter over one differential drive: state, covariance, the time it
/// stands at, and its fix counts.
#[derive(Debug, Clone)]
pub struct DiffDriveFilter<'a> {
    d: &'a DiffDriveDrive,
    noise: FilterNoise,
    antenna: [f64; 2],
    /// State.
    pub x: State,
    /// Covariance.
    pub p: Cov,
    /// The time the state stands at, s.
    pub t_s: f64,
    /// The first odometry sample after `t_s`.
    next: usize,
    /// Fixes used.
    pub fixes_used: usize,
    /// Fixes rejected by the gate.
    pub fixes_rejected: usize,
    /// Jumps of the fixes' error: fixes taken after the gate rejected
    /// fixes for [`FilterNoise::jump_after_s`], the wander widened.
    pub fix_jumps: usize,
    /// When the current run of rejected fixes began, s.
    rejecting_since: Option<f64>,
}

impl<'a> DiffDriveFilter<'a> {
    /// Starts the filter once the odometry has travelled `init_path_m` with
    /// at least three fixes: the dead reckoning over that stretch aligned to
    /// its fixes gives the pose, the parameters the yaw bias and the speed
    /// scale, the wander starts at zero. The aligned position carries the
    /// stretch's mean fix error, so its error is the wander's with the
    /// opposite sign (covariance `−σ_e²`): the fix it predicts is as good as
    /// the mean of the stretch's fixes. `None` when the drive never travels
    /// that far with fixes.
    pub fn start(
        d: &'a DiffDriveDrive,
        params: &[f64],
        noise: &FilterNoise,
    ) -> Result<Option<DiffDriveFilter<'a>>, Error> {
        noise.check()?;
        if params.len() != N_PARAMS || params.iter().any(|v| !v.is_finite()) {
            return Err(Error::param(
                "parameters",
                Value::Numbers(params.to_vec()),
                Rule::FiniteCount(N_PARAMS),
            ));
        }
        let antenna = [params[ANTENNA_X], params[ANTENNA_Y]];
        let Some(first) = d.samples.first() else {
            return Ok(None);
        };
        // Dead reckoning from the zero pose, the antenna at each fix.
        let mut x = State::zeros();
        x[YAW_BIAS] = params[P_BIAS];
        x[SPEED_SCALE] = params[P_SPEED];
        x[YAW_SCALE] = params[P_YAW];
        let mut path = 0.0;
        let mut t = first.t_s;
        let mut fi = d.fixes.partition_point(|f| f.0 < t);
        let (mut p_loc, mut q_fix) = (Vec::new(), Vec::new());
        for k in 1..d.samples.len() {
            let (s0, s1) = (&d.samples[k - 1], &d.samples[k]);
            while fi < d.fixes.len() && d.fixes[fi].0 <= s1.t_s {
                let (tf, fe, fn_) = d.fixes[fi];
                let u = step_input(s0, s1, t, tf);
                x = propagate(&x, &u, noise.fix_wander_tau_s).0;
                t = tf;
                let (z, _) = predicted_fix(&x, antenna);
                p_loc.push([z[0], z[1]]);
                q_fix.push([fe, fn_]);
                fi += 1;
            }
            let u = step_input(s0, s1, t, s1.t_s);
            x = propagate(&x, &u, noise.fix_wander_tau_s).0;
            path += (0.5 * (s0.v_mps + s1.v_mps) * (s1.t_s - s0.t_s)).abs();
            t = s1.t_s;
            if path >= noise.init_path_m && q_fix.len() >= 3 {
                let Some((th, tr)) = align(&p_loc, &q_fix) else {
                    continue;
                };
                let (s, c) = th.sin_cos();
                let (bx, by) = (x[X], x[Y]);
                x[X] = tr[0] + c * bx - s * by;
                x[Y] = tr[1] + s * bx + c * by;
                x[YAW] += th;
                let n = q_fix.len() as f64;
                let wander = noise.fix_wander_m.powi(2);
                // The heading comes from the fixes' error across the
                // stretch: their white noise and how far the wander moved
                // in its duration (what is common to the stretch only
                // shifts it), over its length.
                let dur = t - first.t_s;
                let moved = wander * (1.0 - (-2.0 * dur / noise.fix_wander_tau_s).exp());
                let across = (moved + noise.fix_white_m.powi(2)).sqrt();
                let mut p = Cov::zeros();
                for (pos, fix) in [(X, FIX_E), (Y, FIX_N)] {
                    p[(pos, pos)] = wander + noise.fix_white_m.powi(2) / n;
                    p[(fix, fix)] = wander;
                    p[(pos, fix)] = -wander;
                    p[(fix, pos)] = -wander;
                }
                p[(YAW, YAW)] = (2.0 * across / path).powi(2);
                p[(YAW_BIAS, YAW_BIAS)] = noise.yaw_bias_prior_rps.powi(2);
                p[(SPEED_SCALE, SPEED_SCALE)] = noise.speed_scale_prior.powi(2);
                p[(YAW_SCALE, YAW_SCALE)] = noise.yaw_scale_prior.powi(2);
                return Ok(Some(DiffDriveFilter {
                    d,
                    noise: *noise,
                    antenna,
                    x,
                    p,
                    t_s: t,
                    next: k + 1,
                    fixes_used: 0,
                    fixes_rejected: 0,
                    fix_jumps: 0,
                    rejecting_since: None,
                }));
            }
        }
        Ok(None)
    }

    /// Predicts to time `t_s` (no earlier than the filter's time) through
    /// the odometry samples in between.
    pub fn predict_to(&mut self, t_s: f64) {
        let samples = &self.d.samples;
        while self.t_s < t_s && self.next < samples.len() {
            let (s0, s1) = (&samples[self.next - 1], &samples[self.next]);
            let t_end = s1.t_s.min(t_s);
            let u = step_input(s0, s1, self.t_s, t_end);
            self.predict(&u);
            self.t_s = t_end;
            if t_end >= s1.t_s {
                self.next += 1;
            }
        }
    }

    /// One propagation step, eq. (11)–(12), with the process noise of
    /// [`FilterNoise`].
    fn predict(&mut self, u: &StepInput) {
        let n = &self.noise;
        let dt = u.dt_s;
        if dt <= 0.0 {
            return;
        }
        let (x, f, g) = propagate(&self.x, u, n.fix_wander_tau_s);
        // Input noise as densities: var(v̄)·dt² = q_d·dt, var(a_ω·ω)·dt² = q_ψ·dt.
        let var_v = n.speed_noise_m_per_sqrt_s.powi(2) / dt;
        let var_w = n.yaw_noise_rad_per_sqrt_s.powi(2) / dt;
        let qu = SMatrix::<f64, 2, 2>::new(var_v, 0.0, 0.0, var_w);
        let mut q = g * qu * g.transpose();
        q[(YAW_BIAS, YAW_BIAS)] += n.yaw_bias_walk_rps_per_sqrt_s.powi(2) * dt;
        q[(SPEED_SCALE, SPEED_SCALE)] += n.speed_scale_walk_per_sqrt_s.powi(2) * dt;
        q[(YAW_SCALE, YAW_SCALE)] += n.yaw_scale_walk_per_sqrt_s.powi(2) * dt;
        let phi2 = (-2.0 * dt / n.fix_wander_tau_s).exp();
        q[(FIX_E, FIX_E)] += n.fix_wander_m.powi(2) * (1.0 - phi2);
        q[(FIX_N, FIX_N)] += n.fix_wander_m.powi(2) * (1.0 - phi2);
        self.x = x;
        self.p = predict_covariance(&self.p, &f, &q);
    }

    /// Updates with the fix `(east, north)` at the filter's time, gated by
    /// its Mahalanobis distance; after [`FilterNoise::jump_after_s`] of
    /// rejections the wander's variance is widened by `fix_wander_m²` and
    /// the fix taken (a jump). Returns whether the fix was used.
    pub fn update_fix(&mut self, east_m: f64, north_m: f64) -> Result<bool, Error> {
        let (z, h) = predicted_fix(&self.x, self.antenna);
        let y = SVector::<f64, 2>::new(east_m - z[0], north_m - z[1]);
        let r = SMatrix::<f64, 2, 2>::identity() * self.noise.fix_white_m.powi(2);
        let (_, _, nis) = innovation_stats(&self.p, &y, &h, &r, self.t_s)?;
        if nis > self.noise.gate_chi2 {
            let since = *self.rejecting_since.get_or_insert(self.t_s);
            if self.t_s - since < self.noise.jump_after_s {
                self.fixes_rejected += 1;
                return Ok(false);
            }
            // A persistent shift: the fixes' error jumped.
            let widen = self.noise.fix_wander_m.powi(2);
            self.p[(FIX_E, FIX_E)] += widen;
            self.p[(FIX_N, FIX_N)] += widen;
            self.fix_jumps += 1;
        }
        self.rejecting_since = None;
        update_vector(
            &mut self.x,
            &mut self.p,
            &y,
            &h,
            &r,
            CovarianceForm::Joseph,
            self.t_s,
        )?;
        self.fixes_used += 1;
        Ok(true)
    }

    /// The fix the state predicts now, with its covariance (the state's
    /// part, without the fix's white noise).
    pub fn predicted_fix(&self) -> (SVector<f64, 2>, SMatrix<f64, 2, 2>) {
        let (z, h) = predicted_fix(&self.x, self.antenna);
        (z, h * self.p * h.transpose())
    }
}

/// The mean log-likelihood per fix of the fixes' innovations,
/// `−ln 2π − ½·ln det S − ½·yᵀS⁻¹y` (2-D Gaussian), with every fix taken
/// (no gate: the likelihood of the model itself), and the number of fixes
/// it averages: how well `noise` describes the fixes given the odometry —
/// what the fix-error model is identified by. `None` when the filter
/// cannot start or no fix follows its start.
pub fn fix_log_likelihood(
    d: &DiffDriveDrive,
    params: &[f64],
    noise: &FilterNoise,
) -> Result<Option<(f64, usize)>, Error> {
    let Some(mut f) = DiffDriveFilter::start(d, params, noise)? else {
        return Ok(None);
    };
    f.noise.gate_chi2 = f64::INFINITY;
    let (mut sum, mut n) = (0.0, 0usize);
    let t_start = f.t_s;
    for &(t, east, north) in d.fixes.iter().filter(|x| x.0 > t_start) {
        f.predict_to(t);
        let (z, h) = predicted_fix(&f.x, f.antenna);
        let y = SVector::<f64, 2>::new(east - z[0], north - z[1]);
        let r = SMatrix::<f64, 2, 2>::identity() * f.noise.fix_white_m.powi(2);
        let (s, _, nis) = innovation_stats(&f.p, &y, &h, &r, t)?;
        sum += -(2.0 * std::f64::consts::PI).ln() - 0.5 * s.determinant().ln() - 0.5 * nis;
        n += 1;
        f.update_fix(east, north)?;
    }
    Ok((n > 0).then(|| (sum / n as f64, n)))
}

/// The inputs of the step from `t0` to `t1` inside the odometry interval
/// `s0 → s1`: the mean of the linearly interpolated speed, and `s1`'s rate.
fn step_input(
    s0: &super::DiffDriveSample,
    s1: &super::DiffDriveSample,
    t0: f64,
    t1: f64,
) -> StepInput {
    let span = s1.t_s - s0.t_s;
    let v_at = |t: f64| {
        if span > 0.0 {
            s0.v_mps + (s1.v_mps - s0.v_mps) * ((t - s0.t_s) / span).clamp(0.0, 1.0)
        } else {
            s1.v_mps
        }
    };
    StepInput {
        dt_s: t1 - t0,
        v_mps: 0.5 * (v_at(t0) + v_at(t1)),
        yaw_rate_rps: s1.yaw_rate_rps,
    }
}
