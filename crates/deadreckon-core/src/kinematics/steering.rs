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

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};

use super::ParamEstimate;
use crate::model::{V, YAW_RATE};
use crate::reference::Reference;
use crate::{Drive, Error};

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
        return Err(Error::InvalidParams(format!(
            "speed threshold must be non-negative, got {min_speed_mps}"
        )));
    }
    let l = drive.vehicle.wheelbase_m;
    let nominal = drive.vehicle.steering_ratio;
    let (mut s, mut target) = (Vec::new(), Vec::new());
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
    let fail = || format!("the fit did not converge ({:?})", report.termination);
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
        samples: n,
        rms_rad,
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
}
