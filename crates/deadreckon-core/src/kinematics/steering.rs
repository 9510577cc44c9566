//! The four-wheel car's steering: steering ratio `r_s` and steering-wheel
//! offset `s₀` against a reference trajectory (truth or smoothed states).
//!
//! The kinematic bicycle model turns with curvature `κ = tan δ / l` at the
//! virtual front-wheel angle `δ = (s − s₀) / r_s` (`s` the steering-wheel
//! reading, `l` the wheelbase). The reference gives `κ = ψ̇ / v` at each
//! steering reading; the residual, in radians of steering wheel, is
//!
//! ```text
//! e = s − s₀ − r_s · atan(l · ψ̇ / v)
//! ```
//!
//! over readings where the reference moves faster than the speed threshold
//! (below it `ψ̇ / v` is noise), fitted by Levenberg–Marquardt with the
//! analytic Jacobian `∂e/∂r_s = −atan(l·ψ̇/v)`, `∂e/∂s₀ = −1`. The noise is
//! in the reading, so the reading is the side the residual is measured on:
//! the other way round (`(s − s₀)/r_s − δ`) the reading's noise sits in the
//! regressor and biases the ratio upwards (on the simulated calibration
//! drive, 19.0 for a true 16.5). The
//! wheelbase is taken as known: with small wheel angles only `r_s · l` is
//! determined. A drive that does not turn (wheel-angle spread below
//! [`MIN_WHEEL_ANGLE_SPREAD_RAD`]) determines the offset but not the ratio,
//! and says so. Standard errors are `σ̂²(JᵀJ)⁻¹`; consecutive readings are
//! correlated through the reference's smoothing, so they are optimistic.
//!
//! ## With understeer (the RTS calibration's fit)
//!
//! A real car's front tyres slip more than its rear ones in a turn: the
//! road-wheel angle is `atan(l·κ) + K_us·a_y` with the understeer gradient
//! K_us and the lateral acceleration `a_y = v·ψ̇`, so the reading is
//!
//! ```text
//! s = s₀ + r_s·atan(l·ψ̇/v) + k·|v|·ψ̇,   k = r_s·K_us
//! ```
//!
//! (`|v|·ψ̇` is a_y forwards; reversing, the front tyre's slip angle turns
//! round with the velocity, as in the simulator's single-track model, so
//! the term keeps the sign of the turn's curvature).
//!
//! linear in `(r_s, s₀, k)`: [`calibrate_steering_understeer`] solves it by
//! linear least squares. Without the `k` column the understeer goes into the
//! ratio (a truth fit on a dynamic world read 15.79 for a true 15.3). The
//! column is determined only when the drive turns at several speeds: at one
//! speed `a_y ∝ atan(l·ψ̇/v)` and k and r_s are one. K_us is estimated when
//! `a_y` spreads by at least [`MIN_LATERAL_ACCEL_SPREAD_MPS2`] about its
//! least-squares prediction from `[1, atan(l·ψ̇/v)]` and its standard error
//! is at most [`MAX_UNDERSTEER_STD_RAD_PER_MPS2`], else not estimated (and
//! the two-parameter fit above is reported). `K_us = k/r_s`, its
//! standard error by the delta method. Standard errors here are inflated
//! for the residuals' lag-1 autocorrelation ρ₁ (effective sample size
//! `n·(1−ρ₁)/(1+ρ₁)`, as the RTS calibration's least squares).

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::ParamEstimate;
use crate::model::{V, YAW_RATE};
use crate::reference::Reference;
use crate::{Drive, Error, Rule};

/// Readings needed for a fit.
pub const MIN_SAMPLES: usize = 20;
/// Spread (standard deviation) of the reference wheel angle needed to
/// determine the ratio, rad (about 0.6°).
pub const MIN_WHEEL_ANGLE_SPREAD_RAD: f64 = 0.01;

/// The result of [`calibrate_steering`].
#[derive(Debug, Clone, PartialEq)]
pub struct SteeringCalibration {
    /// `steering_ratio`: steering-wheel angle per wheel angle.
    pub ratio: ParamEstimate,
    /// `steering_offset_rad`: steering-wheel reading when going straight, rad.
    pub offset: ParamEstimate,
    /// `understeer_gradient_rad_per_mps2`: K_us, when the fit had the
    /// understeer column ([`calibrate_steering_understeer`]; `None` for
    /// [`calibrate_steering`]).
    pub understeer: Option<ParamEstimate>,
    /// Readings used.
    pub samples: usize,
    /// RMS residual in steering-wheel angle, rad.
    pub rms_rad: f64,
}

struct Problem<'a> {
    s: &'a [f64],
    target: &'a [f64],
    p: [f64; 2],
    fit_ratio: bool,
}

impl Problem<'_> {
    fn res(&self) -> DVector<f64> {
        let [r, s0] = self.p;
        DVector::from_iterator(
            self.s.len(),
            self.s.iter().zip(self.target).map(|(s, d)| s - s0 - r * d),
        )
    }
    fn jac(&self) -> DMatrix<f64> {
        let cols = if self.fit_ratio { 2 } else { 1 };
        let mut j = DMatrix::zeros(self.s.len(), cols);
        for (i, d) in self.target.iter().enumerate() {
            if self.fit_ratio {
                j[(i, 0)] = -d;
            }
            j[(i, cols - 1)] = -1.0;
        }
        j
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;
    fn set_params(&mut self, x: &DVector<f64>) {
        if self.fit_ratio {
            self.p = [x[0], x[1]];
        } else {
            self.p[1] = x[0];
        }
    }
    fn params(&self) -> DVector<f64> {
        if self.fit_ratio {
            DVector::from_row_slice(&self.p)
        } else {
            DVector::from_row_slice(&self.p[1..])
        }
    }
    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.res();
        r.iter().all(|v| v.is_finite()).then_some(r)
    }
    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let j = self.jac();
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

fn not_estimated(name: &str, value: f64, why: String) -> ParamEstimate {
    ParamEstimate {
        name: name.into(),
        value,
        std: None,
        estimated: false,
        reason: Some(why),
    }
}

/// Calibrates the steering ratio and offset of `drive` against `reference`
/// (see the module doc), from the drive's nominal ratio and a zero offset.
pub fn calibrate_steering(
    drive: &Drive,
    reference: &Reference,
    min_speed_mps: f64,
) -> Result<SteeringCalibration, Error> {
    if !(min_speed_mps.is_finite() && min_speed_mps >= 0.0) {
        return Err(Error::param(
            "min_speed_mps",
            min_speed_mps,
            Rule::NonNegative { zero_means: None },
        ));
    }
    let l = drive.vehicle.wheelbase_m;
    let nominal = drive.vehicle.steering_ratio;
    // At most one of each per reading: allocated once (a growing vector
    // holds up to three times its length while it moves).
    let n_max = drive.steering.len();
    let (mut s, mut target) = (Vec::with_capacity(n_max), Vec::with_capacity(n_max));
    for m in &drive.steering {
        let Some(x) = reference.state_at(m.t_s) else {
            continue;
        };
        if x[V].abs() >= min_speed_mps && x[V].abs() > 0.0 {
            s.push(m.value);
            target.push((l * x[YAW_RATE] / x[V]).atan());
        }
    }
    let n = s.len();
    if n < MIN_SAMPLES {
        let why = format!(
            "{n} steering readings with the reference above {min_speed_mps} m/s (needs {MIN_SAMPLES})"
        );
        return Ok(SteeringCalibration {
            ratio: not_estimated("steering_ratio", nominal, why.clone()),
            offset: not_estimated("steering_offset_rad", 0.0, why),
            understeer: None,
            samples: n,
            rms_rad: f64::NAN,
        });
    }
    let mean = target.iter().sum::<f64>() / n as f64;
    let spread = (target.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    let fit_ratio = spread >= MIN_WHEEL_ANGLE_SPREAD_RAD;
    let problem = Problem {
        s: &s,
        target: &target,
        p: [nominal, 0.0],
        fit_ratio,
    };
    let (solved, report) = LevenbergMarquardt::new().minimize(problem);
    let r = solved.res();
    let j = solved.jac();
    let dof = n.saturating_sub(j.ncols()).max(1) as f64;
    let s2 = r.norm_squared() / dof;
    let cov = (j.transpose() * &j).cholesky().map(|c| c.inverse() * s2);
    let rms_rad = (r.norm_squared() / n as f64).sqrt();
    let std = |k: usize| cov.as_ref().map(|c| c[(k, k)].max(0.0).sqrt());
    let ok = report.termination.was_successful() && cov.is_some();
    let [ratio, offset] = solved.p;
    let fail = || {
        format!(
            "the fit did not converge ({})",
            crate::kinematics::calibrate::termination_words(&report.termination)
        )
    };
    let ratio = if !fit_ratio {
        not_estimated(
            "steering_ratio",
            nominal,
            format!(
                "no turns: the reference wheel angle spreads {spread:.4} rad (needs {MIN_WHEEL_ANGLE_SPREAD_RAD})"
            ),
        )
    } else if !ok {
        not_estimated("steering_ratio", nominal, fail())
    } else if ratio.is_nan() || ratio <= 0.0 {
        not_estimated(
            "steering_ratio",
            nominal,
            format!("rejected: the fit went to {ratio}, not a positive ratio"),
        )
    } else {
        ParamEstimate {
            name: "steering_ratio".into(),
            value: ratio,
            std: std(0),
            estimated: true,
            reason: None,
        }
    };
    let offset = if ok {
        ParamEstimate {
            name: "steering_offset_rad".into(),
            value: offset,
            std: std(if fit_ratio { 1 } else { 0 }),
            estimated: true,
            reason: None,
        }
    } else {
        not_estimated("steering_offset_rad", 0.0, fail())
    };
    Ok(SteeringCalibration {
        ratio,
        offset,
        understeer: None,
        samples: n,
        rms_rad,
    })
}

/// Spread of the lateral acceleration about its prediction from the wheel
/// angle that determines the understeer gradient, m/s²: turns taken at
/// speeds that differ enough that `a_y` is not one multiple of the angle.
pub const MIN_LATERAL_ACCEL_SPREAD_MPS2: f64 = 0.1;
/// The largest standard error with which K_us is reported as estimated,
/// rad per m/s²: 0.0005, a fifth of a car's typical 0.0025.
pub const MAX_UNDERSTEER_STD_RAD_PER_MPS2: f64 = 0.0005;
/// The lowest speed of the smoothed states the RTS calibration fits the
/// steering at, m/s (above its own threshold of 2 m/s): below it the
/// smoothed `ψ̇/v` is noisy, and noise in the regressor pulls the ratio
/// down and pushes K_us up. On the dynamic family's cars 1–10 (side slip
/// and steering offset, 1200 s drives), at 2 m/s car 9 (RMS a_y 0.38
/// m/s²) read a ratio of 14.65 ± 0.09 for 16 and K_us 0.0068 ± 0.0005 for
/// 0.0015, and car 1 15.96 and 0.00331 for 0.00303; at 5 m/s car 9's K_us
/// is not estimated and car 1 reads 16.02 and 0.00303.
pub const SMOOTHED_MIN_SPEED_MPS: f64 = 5.0;
/// The key of K_us (vehicle.toml, params.toml `[steering]`).
pub const UNDERSTEER_NAME: &str = "understeer_gradient_rad_per_mps2";

/// Ratio, offset and understeer gradient of `drive`'s steering against
/// `reference` (the smoothed states of the RTS calibration, or the truth):
/// see the module doc. Falls back to [`calibrate_steering`] (the understeer
/// not estimated, with why) when the drive does not determine K_us.
pub fn calibrate_steering_understeer(
    drive: &Drive,
    reference: &Reference,
    min_speed_mps: f64,
) -> Result<SteeringCalibration, Error> {
    let two = calibrate_steering(drive, reference, min_speed_mps)?;
    let nominal_k = drive.vehicle.understeer_gradient_rad_per_mps2;
    let without = |why: String| SteeringCalibration {
        understeer: Some(not_estimated(UNDERSTEER_NAME, nominal_k, why)),
        ..two.clone()
    };
    if !two.ratio.estimated {
        return Ok(without(format!(
            "the ratio is not estimated: {}",
            two.ratio.reason.as_deref().unwrap_or("")
        )));
    }
    let l = drive.vehicle.wheelbase_m;
    let n_max = drive.steering.len();
    let (mut s, mut rows) = (Vec::with_capacity(n_max), Vec::with_capacity(n_max));
    for m in &drive.steering {
        let Some(x) = reference.state_at(m.t_s) else {
            continue;
        };
        if x[V].abs() >= min_speed_mps && x[V].abs() > 0.0 {
            s.push(m.value);
            // |v|·ψ̇: a_y forwards; reversing, the front slip angle turns
            // round with the velocity (the simulator's single-track model).
            rows.push([
                (l * x[YAW_RATE] / x[V]).atan(),
                1.0,
                x[V].abs() * x[YAW_RATE],
            ]);
        }
    }
    let n = s.len();
    let a = DMatrix::from_fn(n, 3, |i, j| rows[i][j]);
    drop(rows);
    let y = DVector::from_column_slice(&s);
    drop(s);
    // How far a_y is from a multiple of the angle (plus a constant); the
    // residual in a_y's own column, the copies dropped once it is known
    // (the peak of `--corrections none` on the bench's hour: issue 30).
    let a2 = a.columns(0, 2).into_owned();
    let mut ay_resid = a.column(2).into_owned();
    let Some(ata2) = (a2.transpose() * &a2).try_inverse() else {
        return Ok(without("the wheel angles are singular".into()));
    };
    ay_resid -= &a2 * (&ata2 * (a2.transpose() * &ay_resid));
    drop(a2);
    let spread = (ay_resid.norm_squared() / n as f64).sqrt();
    drop(ay_resid);
    let few_speeds = |detail: String| {
        without(format!(
            "the turns were taken at too few speeds: the lateral acceleration spreads {spread:.3} m/s² about a multiple of the wheel angle{detail}"
        ))
    };
    if spread < MIN_LATERAL_ACCEL_SPREAD_MPS2 {
        return Ok(few_speeds(format!(
            " (needs {MIN_LATERAL_ACCEL_SPREAD_MPS2})"
        )));
    }
    let ata = a.transpose() * &a;
    let Some(inv) = ata.clone().try_inverse() else {
        return Ok(without("the fit is singular".into()));
    };
    let theta = &inv * (a.transpose() * &y);
    let r = &y - &a * &theta;
    let dof = n.saturating_sub(3).max(1) as f64;
    let s2 = r.norm_squared() / dof;
    // Lag-1 autocorrelation of the residuals (readings in time order).
    let rho = if n > 2 {
        let num: f64 = (1..n).map(|i| r[i] * r[i - 1]).sum();
        (num / r.norm_squared()).clamp(0.0, 0.99)
    } else {
        0.0
    };
    let cov = inv * (s2 * (1.0 + rho) / (1.0 - rho));
    let (ratio, offset, k) = (theta[0], theta[1], theta[2]);
    if !(ratio.is_finite() && ratio > 0.0 && k.is_finite() && offset.is_finite()) {
        return Ok(without(format!(
            "rejected: the fit went to ratio {ratio}, k {k}"
        )));
    }
    let sd = |i: usize| cov[(i, i)].max(0.0).sqrt();
    // K = k/r: ∂K/∂k = 1/r, ∂K/∂r = −k/r².
    let kus = k / ratio;
    let var_k = cov[(2, 2)] / (ratio * ratio) + k * k * cov[(0, 0)] / ratio.powi(4)
        - 2.0 * k * cov[(0, 2)] / ratio.powi(3);
    let sd_k = var_k.max(0.0).sqrt();
    if sd_k > MAX_UNDERSTEER_STD_RAD_PER_MPS2 {
        return Ok(few_speeds(format!(
            ", which determines K_us only to ±{sd_k:.5} rad per m/s² (needs ±{MAX_UNDERSTEER_STD_RAD_PER_MPS2})"
        )));
    }
    let est = |name: &str, value: f64, std: f64| ParamEstimate {
        name: name.into(),
        value,
        std: Some(std),
        estimated: true,
        reason: None,
    };
    Ok(SteeringCalibration {
        ratio: est("steering_ratio", ratio, sd(0)),
        offset: est("steering_offset_rad", offset, sd(1)),
        understeer: Some(est(UNDERSTEER_NAME, kus, sd_k)),
        samples: n,
        rms_rad: (r.norm_squared() / n as f64).sqrt(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jacobian_matches_finite_differences() {
        let s = [0.3, -1.2, 2.0, 0.05];
        let target = [0.01, -0.07, 0.12, 0.0];
        let p = Problem {
            s: &s,
            target: &target,
            p: [14.0, 0.02],
            fit_ratio: true,
        };
        let j = p.jac();
        for k in 0..2 {
            let h = 1e-6;
            let mut hi = Problem { p: p.p, ..p };
            hi.p[k] += h;
            let mut lo = Problem { p: p.p, ..p };
            lo.p[k] -= h;
            let fd = (hi.res() - lo.res()) / (2.0 * h);
            for i in 0..s.len() {
                assert!((j[(i, k)] - fd[i]).abs() < 1e-8, "{k} {i}");
            }
        }
    }

    /// A reference turning at speeds from 5 to 25 m/s (or at 8 m/s), and steering
    /// readings from `s = s₀ + r·(atan(l·ψ̇/v) + K·v·ψ̇)` plus seeded noise.
    fn understeering(k_us: f64, speeds_vary: bool) -> (Drive, Reference) {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(11);
        let vehicle = crate::Vehicle::paper_car();
        let (r, s0, l) = (15.3, 0.024, vehicle.wheelbase_m);
        let mut d = Drive::empty(vehicle);
        let (mut ts, mut xs) = (Vec::new(), Vec::new());
        for k in 0..30_000 {
            let t = k as f64 * 0.02;
            let v = if speeds_vary {
                15.0 + 10.0 * (t / 47.0).sin()
            } else {
                8.0
            };
            // Curvature up to 0.02 1/m: a_y up to 12.5 m/s² at 25 m/s is
            // too much; scale the curvature down with speed (≤ 4 m/s²).
            let kappa = 0.02 * (t / 7.0).sin() * (25.0 / (v * v)).min(1.0);
            let x = crate::model::State::from([0.0, 0.0, 0.0, v, v * kappa]);
            ts.push(t);
            xs.push(x);
            let noise: f64 = StandardNormal.sample(&mut rng);
            d.steering.push(crate::drive::Scalar {
                t_s: t,
                value: s0 + r * ((l * kappa).atan() + k_us * v * v * kappa) + 0.005 * noise,
            });
        }
        (d, Reference::from_states(ts, xs))
    }

    #[test]
    fn understeer_is_fitted_beside_the_ratio_and_offset() {
        let (d, reference) = understeering(0.0025, true);
        let c = calibrate_steering_understeer(&d, &reference, 2.0).unwrap();
        let u = c.understeer.clone().unwrap();
        assert!(u.estimated, "{c:?}");
        for (p, truth) in [(&c.ratio, 15.3), (&c.offset, 0.024), (&u, 0.0025)] {
            eprintln!("{}: {} ± {:?} (truth {truth})", p.name, p.value, p.std);
            let sd = p.std.unwrap();
            assert!((p.value - truth).abs() < 3.0 * sd, "{p:?} vs {truth}");
        }
        // Without the column the understeer goes into the ratio.
        let plain = calibrate_steering(&d, &reference, 2.0).unwrap();
        assert!(plain.ratio.value > 15.3 + 0.5, "{plain:?}");
    }

    #[test]
    fn understeer_at_one_speed_is_not_estimated() {
        let (d, reference) = understeering(0.0025, false);
        let c = calibrate_steering_understeer(&d, &reference, 2.0).unwrap();
        let u = c.understeer.unwrap();
        assert!(!u.estimated, "{u:?}");
        assert!(
            u.reason.as_deref().unwrap().contains("too few speeds"),
            "{u:?}"
        );
        assert!(c.ratio.estimated);
    }
}
