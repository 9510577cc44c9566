//! Kinematic calibration against a reference: nonlinear least squares
//! (Levenberg–Marquardt, the MINPACK port of the `levenberg-marquardt`
//! crate) over relative motions in short windows.
//!
//! The drive is cut into consecutive, non-overlapping windows of
//! [`KinematicOptions::window_s`]. Each window starts at the reference pose
//! of its first sample, dead-reckons with the shape's kinematics and
//! compares the measured point's pose at its last sample with the
//! reference there: three residuals per window, `(Δx, Δy, w·Δψ)` with `w`
//! [`KinematicOptions::heading_weight_m`] metres per radian. Windows slower
//! on average than the speed threshold are left out.
//!
//! Observability is reported, not hidden. A parameter is **not estimated**
//! (it keeps its nominal value, and the result says why) when
//!
//! 1. the used windows cannot excite it at all ([`KinematicModel::unexcited`]:
//!    no windows above the speed threshold, no turns, no steering change), or
//! 2. its fit ends at or beyond a physical bound ([`KinematicModel::bounds`]),
//!    or
//! 3. its standard error exceeds [`KinematicModel::determination_tolerance`]
//!    (the drive leaves it free, usually through a correlation near ±1 with
//!    another parameter, which the reason names).
//!
//! Cases 2 and 3 remove one parameter at a time (the worst) and fit again;
//! an undetermined parameter is removed before bounds are checked (it may be
//! the one that wandered off, dragging a determined one with it).
//! Standard errors are `σ̂²(JᵀJ)⁻¹` with `σ̂² = RSS / (m − n)` at the
//! solution; `converged` is true only when the solver reports success and
//! at least one parameter was estimated.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{DMatrix, DVector, Dyn, Owned};
use serde::{Deserialize, Serialize};

use super::{KinematicModel, Pose2};
use crate::angle::wrap;
use crate::{Error, Rule};

/// Options of [`calibrate`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KinematicOptions {
    /// Window length, s (default 2: on the tricycle log, 2 s windows gave
    /// 0.27 m in-sample over 30 s outages and 0.20 / 0.59 m across halves;
    /// 5 s windows 0.27 / 0.43 / 0.77 m).
    pub window_s: f64,
    /// Windows whose mean speed (nominal wheel travel / duration) is below
    /// this are not used, m/s (default: the shape's
    /// [`super::Shape::default_min_speed_mps`]).
    pub min_speed_mps: f64,
    /// Weight of the heading residual, m per rad.
    pub heading_weight_m: f64,
}

impl Default for KinematicOptions {
    fn default() -> Self {
        KinematicOptions {
            window_s: 2.0,
            min_speed_mps: 0.05,
            heading_weight_m: 1.0,
        }
    }
}

/// One calibrated parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamEstimate {
    /// Name with unit.
    pub name: String,
    /// The value: fitted, or the nominal value when not estimated.
    pub value: f64,
    /// Standard error (only when estimated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Whether the drive determined it.
    pub estimated: bool,
    /// Why not, when not estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// The result of [`calibrate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KinematicCalibration {
    /// Every parameter of the shape, in its order.
    pub params: Vec<ParamEstimate>,
    /// Correlations between the estimated parameters (same order as
    /// `correlated`).
    pub correlation: Vec<Vec<f64>>,
    /// Names of the estimated parameters, the rows of `correlation`.
    pub correlated: Vec<String>,
    /// Windows used / cut.
    pub windows_used: usize,
    /// Windows cut from the drive (with a reference at both ends).
    pub windows_total: usize,
    /// The speed threshold applied, m/s.
    pub min_speed_mps: f64,
    /// RMS position residual at the end of the windows, m.
    pub rms_position_m: f64,
    /// RMS heading residual at the end of the windows, rad.
    /// `None` where the reference has no heading (a differential drive
    /// calibrated against GNSS positions).
    pub rms_heading_rad: Option<f64>,
    /// Residual evaluations of the solver (all fits).
    pub evaluations: usize,
    /// True only when the solver succeeded and something was estimated.
    pub converged: bool,
    /// How the last fit ended.
    pub termination: String,
    /// A differential drive's parameters chosen on held-back GNSS
    /// ([`super::diff_drive::held_back`]): each one's two figures and the
    /// decision (`None` where no such choice was made).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held_back: Option<super::diff_drive::held_back::HeldBackParams>,
}

/// How a Levenberg–Marquardt fit ended, in words for people (the solver's
/// own `Debug` text, `Converged { ftol: true, xtol: false }`, is for code).
pub fn termination_words(t: &levenberg_marquardt::TerminationReason) -> String {
    use levenberg_marquardt::TerminationReason as R;
    match t {
        R::Converged { ftol, xtol } => match (ftol, xtol) {
            (true, true) => "the cost and the parameters stopped changing".to_string(),
            (true, false) => "the cost stopped decreasing".to_string(),
            (false, true) => "the parameters stopped changing".to_string(),
            (false, false) => "converged".to_string(),
        },
        R::ResidualsZero => "the residuals are zero".to_string(),
        R::Orthogonal => "the gradient vanished (residuals orthogonal to the Jacobian)".to_string(),
        R::User(why) => format!("stopped by the model: {why}"),
        R::Numerical(why) => format!("a non-finite number in the {why}"),
        R::NoImprovementPossible(what) => {
            format!("no improvement possible within machine precision ({what} tolerance too small)")
        }
        R::LostPatience => "too many evaluations without converging".to_string(),
        R::NoParameters => "no parameter to fit".to_string(),
        R::NoResiduals => "no residual to fit".to_string(),
        R::WrongDimensions(what) => format!("wrong dimensions of the {what}"),
    }
}

impl KinematicCalibration {
    /// The parameter values (fitted or nominal), in the shape's order.
    pub fn values(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.value).collect()
    }
}

/// A window: first and last sample, the start pose and the reference at the end.
#[derive(Debug, Clone, Copy)]
struct Window {
    a: usize,
    b: usize,
    start: Pose2,
    end: Pose2,
}

/// The least-squares problem over the free parameters.
struct Problem<'a, M: KinematicModel> {
    model: &'a M,
    windows: &'a [Window],
    full: Vec<f64>,
    free: Vec<usize>,
    w: f64,
}

impl<M: KinematicModel> Problem<'_, M> {
    fn residual_vec(&self) -> DVector<f64> {
        let mut r = DVector::zeros(3 * self.windows.len());
        for (i, win) in self.windows.iter().enumerate() {
            let (p, _) = self
                .model
                .predict(&self.full, &win.start, win.a, win.b, false);
            r[3 * i] = p.x_m - win.end.x_m;
            r[3 * i + 1] = p.y_m - win.end.y_m;
            r[3 * i + 2] = self.w * wrap(p.yaw_rad - win.end.yaw_rad);
        }
        r
    }

    fn jacobian_mat(&self) -> DMatrix<f64> {
        let mut j = DMatrix::zeros(3 * self.windows.len(), self.free.len());
        for (i, win) in self.windows.iter().enumerate() {
            let (_, jw) = self
                .model
                .predict(&self.full, &win.start, win.a, win.b, true);
            let Some(jw) = jw else { continue };
            for (c, &q) in self.free.iter().enumerate() {
                j[(3 * i, c)] = jw[(0, q)];
                j[(3 * i + 1, c)] = jw[(1, q)];
                j[(3 * i + 2, c)] = self.w * jw[(2, q)];
            }
        }
        j
    }
}

impl<M: KinematicModel> LeastSquaresProblem<f64, Dyn, Dyn> for Problem<'_, M> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        for (c, &q) in self.free.iter().enumerate() {
            self.full[q] = x[c];
        }
    }

    fn params(&self) -> DVector<f64> {
        DVector::from_iterator(self.free.len(), self.free.iter().map(|&q| self.full[q]))
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        let r = self.residual_vec();
        r.iter().all(|v| v.is_finite()).then_some(r)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let j = self.jacobian_mat();
        j.iter().all(|v| v.is_finite()).then_some(j)
    }
}

/// Cuts the drive into consecutive windows of `window_s` with a reference at
/// both ends; returns them and how many there were before the speed filter.
fn cut_windows<M: KinematicModel>(m: &M, o: &KinematicOptions) -> (Vec<Window>, usize, f64) {
    let mut out = Vec::new();
    let mut total = 0;
    let mut fastest: f64 = 0.0;
    let n = m.len();
    let mut a = (0..n).find(|&i| m.reference(i).is_some());
    while let Some(ai) = a {
        let t_end = m.time(ai) + o.window_s;
        let Some(bi) = (ai + 1..n).find(|&i| m.time(i) >= t_end && m.reference(i).is_some()) else {
            break;
        };
        total += 1;
        let (Some(start), Some(end)) = (m.reference(ai), m.reference(bi)) else {
            break;
        };
        let speed = m.path_m(ai, bi) / (m.time(bi) - m.time(ai));
        fastest = fastest.max(speed);
        if speed >= o.min_speed_mps {
            out.push(Window {
                a: ai,
                b: bi,
                start,
                end,
            });
        }
        a = Some(bi);
    }
    (out, total, fastest)
}

/// Covariance of the free parameters at the solution, or `None` if `JᵀJ`
/// is singular.
fn covariance(j: &DMatrix<f64>, r: &DVector<f64>) -> Option<DMatrix<f64>> {
    let (m, n) = j.shape();
    if m <= n {
        return None;
    }
    let s2 = r.norm_squared() / (m - n) as f64;
    let jtj = j.transpose() * j;
    let inv = jtj.cholesky()?.inverse();
    Some(inv * s2)
}

/// Calibrates `model`'s parameters against its reference (see the module doc).
pub fn calibrate<M: KinematicModel>(
    model: &M,
    o: &KinematicOptions,
) -> Result<KinematicCalibration, Error> {
    if !(o.window_s.is_finite() && o.window_s > 0.0) {
        return Err(Error::param("window_s", o.window_s, Rule::Positive));
    }
    if !(o.min_speed_mps.is_finite() && o.min_speed_mps >= 0.0) {
        return Err(Error::param(
            "min_speed_mps",
            o.min_speed_mps,
            Rule::NonNegative { zero_means: None },
        ));
    }
    if !(o.heading_weight_m.is_finite() && o.heading_weight_m > 0.0) {
        return Err(Error::param(
            "heading_weight_m",
            o.heading_weight_m,
            Rule::Positive,
        ));
    }
    let names = model.names();
    let nominal = model.nominal();
    let bounds = model.bounds();
    let np = names.len();
    let (windows, total, fastest) = cut_windows(model, o);
    let mut reason: Vec<Option<String>> = vec![None; np];
    if windows.is_empty() {
        let why = if total == 0 {
            format!(
                "no window of {} s with a reference at both ends",
                o.window_s
            )
        } else {
            format!(
                "0 of {total} windows above the speed threshold {} m/s (the fastest moves at {fastest:.3} m/s)",
                o.min_speed_mps
            )
        };
        reason.iter_mut().for_each(|r| *r = Some(why.clone()));
    } else {
        let spans: Vec<(usize, usize)> = windows.iter().map(|w| (w.a, w.b)).collect();
        for (k, r) in reason.iter_mut().enumerate() {
            *r = model.unexcited(&spans, k);
        }
    }
    let mut full = nominal.clone();
    let mut evaluations = 0;
    let mut termination = String::from("not run");
    let mut success;
    let mut cov: Option<DMatrix<f64>>;
    let mut free: Vec<usize>;
    loop {
        free = (0..np).filter(|&k| reason[k].is_none()).collect();
        for k in 0..np {
            if reason[k].is_some() {
                full[k] = nominal[k];
            }
        }
        if free.is_empty() || windows.is_empty() {
            cov = None;
            success = false;
            break;
        }
        let problem = Problem {
            model,
            windows: &windows,
            full: full.clone(),
            free: free.clone(),
            w: o.heading_weight_m,
        };
        let (solved, report) = LevenbergMarquardt::new()
            .with_patience(200)
            .minimize(problem);
        evaluations += report.number_of_evaluations;
        termination = termination_words(&report.termination);
        success = report.termination.was_successful();
        full = solved.full.clone();
        // Angles are kept in (−π, π].
        if let Some(k) = names.iter().position(|n| *n == "mount_yaw_rad") {
            full[k] = wrap(full[k]);
        }
        let fit = Problem {
            model,
            windows: &windows,
            full: full.clone(),
            free: free.clone(),
            w: o.heading_weight_m,
        };
        let j = fit.jacobian_mat();
        let r = fit.residual_vec();
        cov = covariance(&j, &r);
        let tol = model.determination_tolerance(&full);
        let worst = match &cov {
            None => free
                .iter()
                .enumerate()
                .min_by(|a, b| {
                    let na = j.column(a.0).norm();
                    let nb = j.column(b.0).norm();
                    na.total_cmp(&nb)
                })
                .map(|(c, &k)| (c, k, f64::INFINITY)),
            Some(c) => free
                .iter()
                .enumerate()
                .map(|(ci, &k)| (ci, k, c[(ci, ci)].max(0.0).sqrt() / tol[k]))
                .filter(|x| x.2 > 1.0)
                .max_by(|a, b| a.2.total_cmp(&b.2)),
        };
        let Some((ci, k, _)) = worst else {
            // A fit at or beyond a physical bound is rejected.
            let at_bound = free.iter().copied().find(|&k| {
                let (lo, hi) = bounds[k];
                let margin = 1e-6 * (hi - lo);
                !(full[k] > lo + margin && full[k] < hi - margin)
            });
            if let Some(k) = at_bound {
                let (lo, hi) = bounds[k];
                reason[k] = Some(format!(
                    "rejected: the fit went to {:.6}, at or beyond the physical bound [{lo}, {hi}]",
                    full[k]
                ));
                continue;
            }
            break;
        };
        let detail = match &cov {
            None => "the normal equations are singular".to_string(),
            Some(c) => {
                let sd = c[(ci, ci)].sqrt();
                let partner = free
                    .iter()
                    .enumerate()
                    .filter(|(cj, _)| *cj != ci)
                    .map(|(cj, &q)| (q, c[(ci, cj)] / (sd * c[(cj, cj)].sqrt())))
                    .max_by(|a, b| a.1.abs().total_cmp(&b.1.abs()));
                let mut s = format!("standard error {sd:.4} above the tolerance {:.4}", tol[k]);
                if let Some((q, rho)) = partner {
                    s += &format!(", correlation {rho:.3} with {}", names[q]);
                }
                s
            }
        };
        reason[k] = Some(format!("not determined by this drive: {detail}"));
    }
    let (rms_p, rms_h) = if windows.is_empty() {
        (f64::NAN, f64::NAN)
    } else {
        let fit = Problem {
            model,
            windows: &windows,
            full: full.clone(),
            free: free.clone(),
            w: o.heading_weight_m,
        };
        let r = fit.residual_vec();
        let n = windows.len() as f64;
        let p2: f64 = (0..windows.len())
            .map(|i| r[3 * i].powi(2) + r[3 * i + 1].powi(2))
            .sum();
        let h2: f64 = (0..windows.len()).map(|i| r[3 * i + 2].powi(2)).sum();
        ((p2 / n).sqrt(), (h2 / n).sqrt() / o.heading_weight_m)
    };
    let params = (0..np)
        .map(|k| {
            let ci = free.iter().position(|&q| q == k);
            let std = match (&cov, ci) {
                (Some(c), Some(ci)) => Some(c[(ci, ci)].sqrt()),
                _ => None,
            };
            ParamEstimate {
                name: names[k].to_string(),
                value: full[k],
                std,
                estimated: reason[k].is_none() && std.is_some(),
                reason: reason[k].clone(),
            }
        })
        .collect();
    let correlation = match &cov {
        Some(c) => (0..free.len())
            .map(|i| {
                (0..free.len())
                    .map(|j| c[(i, j)] / (c[(i, i)] * c[(j, j)]).sqrt())
                    .collect()
            })
            .collect(),
        None => Vec::new(),
    };
    Ok(KinematicCalibration {
        params,
        correlation,
        correlated: if cov.is_some() {
            free.iter().map(|&k| names[k].to_string()).collect()
        } else {
            Vec::new()
        },
        windows_used: windows.len(),
        windows_total: total,
        min_speed_mps: o.min_speed_mps,
        rms_position_m: rms_p,
        rms_heading_rad: Some(rms_h),
        evaluations,
        converged: success && cov.is_some() && !free.is_empty(),
        termination,
        held_back: None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::PoseJacobian;

    /// A toy shape moving along x at speed `p0 + p1` (so only the sum is
    /// determined), with a reference moving at `true_speed`.
    struct Toy {
        true_speed: f64,
        bounds: Vec<(f64, f64)>,
        n_params: usize,
    }

    impl KinematicModel for Toy {
        fn names(&self) -> &'static [&'static str] {
            &["a_mps", "b_mps"][..self.n_params]
        }
        fn nominal(&self) -> Vec<f64> {
            vec![0.5; self.n_params]
        }
        fn bounds(&self) -> Vec<(f64, f64)> {
            self.bounds.clone()
        }
        fn determination_tolerance(&self, _: &[f64]) -> Vec<f64> {
            vec![0.01; self.n_params]
        }
        fn len(&self) -> usize {
            500
        }
        fn time(&self, i: usize) -> f64 {
            i as f64 * 0.1
        }
        fn reference(&self, i: usize) -> Option<Pose2> {
            // A deterministic wiggle as "noise".
            let noise = 0.01 * ((i * 7919) % 13) as f64 / 13.0;
            Some(Pose2::new(self.true_speed * self.time(i) + noise, 0.0, 0.0))
        }
        fn path_m(&self, a: usize, b: usize) -> f64 {
            0.5 * (self.time(b) - self.time(a))
        }
        fn predict(
            &self,
            p: &[f64],
            start: &Pose2,
            a: usize,
            b: usize,
            jac: bool,
        ) -> (Pose2, Option<PoseJacobian>) {
            let dt = self.time(b) - self.time(a);
            let v: f64 = p.iter().sum();
            let out = Pose2::new(start.x_m + v * dt, start.y_m, start.yaw_rad);
            let j = jac.then(|| {
                let mut j = PoseJacobian::zeros(self.n_params);
                for q in 0..self.n_params {
                    j[(0, q)] = dt;
                }
                j
            });
            (out, j)
        }
        fn unexcited(&self, _: &[(usize, usize)], _: usize) -> Option<String> {
            None
        }
    }

    #[test]
    fn a_fit_beyond_a_physical_bound_is_rejected_not_reported() {
        let toy = Toy {
            true_speed: -1.0,
            bounds: vec![(0.0, 10.0)],
            n_params: 1,
        };
        let c = calibrate(&toy, &KinematicOptions::default()).unwrap();
        let p = &c.params[0];
        assert!(!p.estimated && p.std.is_none(), "{p:?}");
        assert!(
            p.reason.as_deref().unwrap().contains("physical bound"),
            "{p:?}"
        );
        assert_eq!(p.value, 0.5, "the nominal value is kept");
        assert!(!c.converged);
    }

    #[test]
    fn a_parameter_the_drive_cannot_separate_is_not_estimated() {
        let toy = Toy {
            true_speed: 1.2,
            bounds: vec![(-10.0, 10.0); 2],
            n_params: 2,
        };
        let c = calibrate(&toy, &KinematicOptions::default()).unwrap();
        let est: Vec<_> = c.params.iter().filter(|p| p.estimated).collect();
        assert_eq!(est.len(), 1, "{c:?}");
        let other = c.params.iter().find(|p| !p.estimated).unwrap();
        assert!(
            other.reason.as_deref().unwrap().contains("not determined"),
            "{other:?}"
        );
        // The one left carries the sum: 1.2 − 0.5.
        assert!((est[0].value - 0.7).abs() < 1e-3, "{c:?}");
        assert!(c.converged);
    }

    #[test]
    fn bad_options_are_errors() {
        let toy = Toy {
            true_speed: 1.0,
            bounds: vec![(-10.0, 10.0)],
            n_params: 1,
        };
        for o in [
            KinematicOptions {
                window_s: 0.0,
                ..Default::default()
            },
            KinematicOptions {
                min_speed_mps: f64::NAN,
                ..Default::default()
            },
            KinematicOptions {
                heading_weight_m: -1.0,
                ..Default::default()
            },
        ] {
            assert!(calibrate(&toy, &o).is_err(), "{o:?}");
        }
    }
}
