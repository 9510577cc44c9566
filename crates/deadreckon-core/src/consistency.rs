//! Filter consistency against the truth: the normalised estimation error
//! squared (NEES) through dead-reckoning windows, with the χ² bounds of the
//! average over the windows (Bar-Shalom, Li, Kirubarajan, *Estimation with
//! Applications to Tracking and Navigation*, 2001, §5.4.2).
//!
//! The GNSS-aided filter runs once over the drive with GNSS hidden in each
//! window (as [`crate::outage::through_windows`]). At a few points of every
//! window (a quarter, half, three quarters and the end of it) the error
//! `e = x̂ − x_true` of two blocks of the state is normalised by the filter's
//! own covariance, `ε = eᵀ P⁻¹ e`:
//!
//! - the **pose** `[x, y, ψ]` (3 degrees of freedom; yaw error wrapped);
//! - the **motion** `[v, ψ̇]` (2 degrees of freedom; the truth's speed and yaw
//!   rate, derived by [`Reference::from_truth`] where `truth.csv` has none).
//!
//! For a consistent filter `ε ~ χ²(n)`; averaged over M windows, `M·ε̄ ~
//! χ²(M n)`, so ε̄ lies within `[χ²⁻¹(0.025; Mn)/M, χ²⁻¹(0.975; Mn)/M]` with
//! probability 0.95. Above the bound the filter is over-confident (its
//! covariance too small) by about `ε̄/n` in variance, below it
//! under-confident. The windows should be far enough apart for the errors of
//! two windows to be nearly independent (GNSS between them resets the pose).

use nalgebra::{Matrix2, Matrix3, Vector2, Vector3};
use serde::{Deserialize, Serialize};
use statrs::distribution::{ChiSquared, ContinuousCDF};

use crate::aided::Aided;
use crate::angle;
use crate::drive::Drive;
use crate::ekf::FilterOptions;
use crate::model::{Mat, State, V, X, Y, YAW, YAW_RATE};
use crate::reference::Reference;
use crate::vehicle::Params;
use crate::{Error, Input, Need, Task};

/// The points of each window where the NEES is taken, as fractions of it.
pub const WINDOW_POINTS: [f64; 4] = [0.25, 0.5, 0.75, 1.0];

/// Two-sided probability of the bounds.
pub const BOUND_PROBABILITY: f64 = 0.95;

/// What the averaged NEES says.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "verdict", content = "factor")]
pub enum Verdict {
    /// Within the 95 % bounds.
    Consistent,
    /// Above the upper bound: the errors are larger than the covariance says,
    /// by this factor in variance (ε̄ / n).
    OverConfident(f64),
    /// Below the lower bound: the covariance is larger than the errors, by
    /// this factor in variance (n / ε̄).
    UnderConfident(f64),
}

impl std::fmt::Display for Verdict {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Verdict::Consistent => f.write_str("consistent"),
            Verdict::OverConfident(k) => write!(f, "over-confident by ×{k:.1}"),
            Verdict::UnderConfident(k) => write!(f, "under-confident by ×{k:.1}"),
        }
    }
}

/// The averaged NEES of one block of the state at one point of the windows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct NeesPoint {
    /// Fraction of the window elapsed (0.25 … 1).
    pub fraction: f64,
    /// Windows averaged, M.
    pub windows: usize,
    /// Averaged NEES ε̄.
    pub nees: f64,
    /// Lower 95 % bound.
    pub lower: f64,
    /// Upper 95 % bound.
    pub upper: f64,
    /// Within, above or below the bounds.
    pub verdict: Verdict,
}

/// The NEES of one block of the state through the windows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockNees {
    /// `pose` or `motion`.
    pub name: String,
    /// Degrees of freedom n.
    pub dof: usize,
    /// One point per entry of [`WINDOW_POINTS`] that had windows.
    pub points: Vec<NeesPoint>,
    /// The NEES of every window at every point (for merging runs).
    pub values: Vec<Vec<f64>>,
}

impl BlockNees {
    fn from_values(name: &str, n: usize, values: Vec<Vec<f64>>) -> Result<BlockNees, Error> {
        let points = WINDOW_POINTS
            .iter()
            .zip(&values)
            .filter(|(_, v)| !v.is_empty())
            .map(|(f, v)| point(*f, n, v))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(BlockNees {
            name: name.into(),
            dof: n,
            points,
            values,
        })
    }

    /// The windows of two runs together (e.g. several drives: M grows).
    pub fn merged(&self, other: &BlockNees) -> Result<BlockNees, Error> {
        let values = self
            .values
            .iter()
            .zip(&other.values)
            .map(|(a, b)| a.iter().chain(b).copied().collect())
            .collect();
        BlockNees::from_values(&self.name, self.dof, values)
    }

    /// The verdict over every point: consistent when all are; otherwise the
    /// point farthest from its bounds (in factor).
    pub fn verdict(&self) -> Verdict {
        let factor = |v: &Verdict| match v {
            Verdict::Consistent => 1.0,
            Verdict::OverConfident(k) | Verdict::UnderConfident(k) => *k,
        };
        self.points
            .iter()
            .map(|p| p.verdict)
            .max_by(|a, b| factor(a).total_cmp(&factor(b)))
            .unwrap_or(Verdict::Consistent)
    }
}

/// The consistency of a filter through dead-reckoning windows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Consistency {
    /// Window length, s.
    pub outage_s: f64,
    /// The pose `[x, y, ψ]`.
    pub pose: BlockNees,
    /// The motion `[v, ψ̇]`.
    pub motion: BlockNees,
}

impl Consistency {
    /// The windows of two runs together (several drives averaged).
    pub fn merged(&self, other: &Consistency) -> Result<Consistency, Error> {
        Ok(Consistency {
            outage_s: self.outage_s.max(other.outage_s),
            pose: self.pose.merged(&other.pose)?,
            motion: self.motion.merged(&other.motion)?,
        })
    }

    /// `pose: consistent; motion: over-confident by ×2.3`.
    pub fn summary(&self) -> String {
        format!(
            "pose: {}; motion: {}",
            self.pose.verdict(),
            self.motion.verdict()
        )
    }
}

/// The 95 % bounds of the average of `m` NEES values of `n` degrees of freedom.
pub fn averaged_nees_bounds(n: usize, m: usize) -> Result<(f64, f64), Error> {
    let k = (n * m) as f64;
    let chi = ChiSquared::new(k).map_err(|_| Error::from(Need::DegreesOfFreedom { dof: k }))?;
    let a = 0.5 * (1.0 - BOUND_PROBABILITY);
    Ok((
        chi.inverse_cdf(a) / m as f64,
        chi.inverse_cdf(1.0 - a) / m as f64,
    ))
}

fn point(fraction: f64, n: usize, values: &[f64]) -> Result<NeesPoint, Error> {
    let m = values.len();
    let nees = values.iter().sum::<f64>() / m as f64;
    let (lower, upper) = averaged_nees_bounds(n, m)?;
    let verdict = if nees > upper {
        Verdict::OverConfident(nees / n as f64)
    } else if nees < lower {
        Verdict::UnderConfident(n as f64 / nees)
    } else {
        Verdict::Consistent
    };
    Ok(NeesPoint {
        fraction,
        windows: m,
        nees,
        lower,
        upper,
        verdict,
    })
}

/// Windows of `outage_s` every `step_s` from `warmup_s` after the drive's
/// first wheel row to the end of the truth.
pub fn windows(drive: &Drive, outage_s: f64, step_s: f64, warmup_s: f64) -> Vec<(f64, f64)> {
    let (false, Some(last)) = (drive.wheels.is_empty(), drive.truth.last()) else {
        return Vec::new();
    };
    let first = drive.wheels.t_s(0);
    let mut out = Vec::new();
    let mut a = first + warmup_s;
    while a + outage_s <= last.t_s - 1.0 && step_s > 0.0 {
        out.push((a, a + outage_s));
        a += step_s;
    }
    out
}

/// The NEES of pose and motion through `windows` (GNSS hidden in each, `base`
/// otherwise), against the drive's truth, with the filter's own covariance
/// ([`WindowErrors::consistency`] with [`Reported::FILTER`]).
///
/// The filter is the one the vehicle's noise settings call for
/// ([`crate::aided`]), as in the outage evaluation
/// ([`crate::outage::evaluate`]): with
/// `noise.gnss_wander_std_m` above 0 it carries the receiver's wander
/// ([`crate::gnss_error`]), with `noise.gyro_bias_walk_rps_per_sqrt_s`
/// above 0 a walking gyro bias ([`crate::gyro_drift`]); the NEES is taken
/// on its car block. (Before issue 36's second stop it always ran the
/// five-state filter, whatever the vehicle declared.)
pub fn nees_through_windows(
    drive: &Drive,
    params: &Params,
    windows: &[(f64, f64)],
    base: &FilterOptions,
) -> Result<Consistency, Error> {
    errors_through_windows(drive, params, windows, base)?.consistency(&Reported::FILTER)
}

/// The covariance a dead-reckoned pose is reported with: the filter's
/// `P` inflated by `k²`, plus the receiver's floor on the position (per
/// axis, m²): `k² P + diag(F, F, 0)` on `[x, y, ψ]`, `k² P` on the motion.
/// The error bound's construction (docs/bound.md, [`crate::bound`]) as a
/// covariance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reported {
    /// The factor on the filter's standard deviations.
    pub k: f64,
    /// The receiver's floor per axis, m² (0: none).
    pub floor_m2: f64,
}

impl Reported {
    /// The filter's own covariance.
    pub const FILTER: Reported = Reported {
        k: 1.0,
        floor_m2: 0.0,
    };
}

/// One point of one window: the errors of pose and motion against the
/// truth and the filter's covariance of each block.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PointError {
    /// Index into [`WINDOW_POINTS`].
    pub point: usize,
    /// `[x, y, ψ]` estimate minus truth (yaw wrapped).
    pub pose: Vector3<f64>,
    /// The filter's covariance of the pose.
    pub pose_cov: Matrix3<f64>,
    /// `[v, ψ̇]` estimate minus truth.
    pub motion: Vector2<f64>,
    /// The filter's covariance of the motion.
    pub motion_cov: Matrix2<f64>,
}

/// The errors at every point of every window ([`errors_through_windows`]),
/// from which the NEES under any reported covariance is computed without
/// running the filter again.
#[derive(Debug, Clone, PartialEq)]
pub struct WindowErrors {
    /// Longest window, s.
    pub outage_s: f64,
    /// Per window, its points that had an epoch inside it and a truth.
    pub windows: Vec<Vec<PointError>>,
}

impl WindowErrors {
    /// The NEES of pose and motion with the covariance `reported` says.
    ///
    /// A covariance that cannot be inverted (the bound's with `k` = 0 has
    /// no heading variance) claims an error of zero in some direction: its
    /// NEES is +∞, over-confident without limit, unless the whole error is
    /// exactly zero (0). Such a point is counted, never left out: a
    /// block whose every point was left out used to read "consistent".
    pub fn consistency(&self, reported: &Reported) -> Result<Consistency, Error> {
        let k2 = reported.k * reported.k;
        let mut pose = vec![Vec::new(); WINDOW_POINTS.len()];
        let mut motion = vec![Vec::new(); WINDOW_POINTS.len()];
        for pe in self.windows.iter().flatten() {
            let mut p3 = pe.pose_cov * k2;
            p3[(0, 0)] += reported.floor_m2;
            p3[(1, 1)] += reported.floor_m2;
            pose[pe.point].push(nees(&pe.pose, p3));
            motion[pe.point].push(nees(&pe.motion, pe.motion_cov * k2));
        }
        Ok(Consistency {
            outage_s: self.outage_s,
            pose: BlockNees::from_values("pose", 3, pose)?,
            motion: BlockNees::from_values("motion", 2, motion)?,
        })
    }
}

/// `eᵀ P⁻¹ e`; +∞ where `P` cannot be inverted and `e` is not zero.
fn nees<const D: usize>(e: &nalgebra::SVector<f64, D>, p: nalgebra::SMatrix<f64, D, D>) -> f64 {
    match p.try_inverse() {
        Some(inv) => (e.transpose() * inv * e)[0],
        None if e.iter().all(|v| *v == 0.0) => 0.0,
        None => f64::INFINITY,
    }
}

/// The errors of pose and motion at [`WINDOW_POINTS`] of `windows` (GNSS
/// hidden in each, `base` otherwise) against the drive's truth, with the
/// filter's covariances; the filter as in [`nees_through_windows`].
pub fn errors_through_windows(
    drive: &Drive,
    params: &Params,
    windows: &[(f64, f64)],
    base: &FilterOptions,
) -> Result<WindowErrors, Error> {
    let truth = Reference::from_truth(&drive.truth)
        .ok_or_else(|| Error::needs(Task::Nees, Input::Truth { min_poses: 0 }))?;
    if windows.is_empty() {
        return Err(Error::needs(Task::Nees, Input::Window));
    }
    let opts = FilterOptions {
        gnss_outages: windows.to_vec(),
        record_epochs: false,
        ..base.clone()
    };
    // The points where each window is looked at, in time order; each gets
    // the last epoch at or before it as the run passes (not every epoch
    // kept: 248 B per wheel epoch).
    let at: Vec<f64> = windows
        .iter()
        .flat_map(|&(a, b)| WINDOW_POINTS.iter().map(move |frac| a + frac * (b - a)))
        .collect();
    let mut order: Vec<usize> = (0..at.len()).collect();
    order.sort_by(|&i, &j| at[i].total_cmp(&at[j]));
    let mut seen: Vec<Option<(f64, State, Mat)>> = vec![None; at.len()];
    let (mut next, mut last) = (0, None);
    Aided::run(drive, params, &opts, &mut |e| {
        while let Some(&i) = order.get(next).filter(|&&i| at[i] < e.t_s) {
            seen[i] = last;
            next += 1;
        }
        last = Some((e.t_s, e.x, e.p));
    })?;
    for &i in &order[next..] {
        seen[i] = last;
    }
    let mut out = Vec::with_capacity(windows.len());
    for (w, &(a, _)) in windows.iter().enumerate() {
        let mut points = Vec::new();
        for j in 0..WINDOW_POINTS.len() {
            // The last epoch at or before the point, inside the window.
            let Some((ts, x, p)) = &seen[w * WINDOW_POINTS.len() + j] else {
                continue;
            };
            if *ts < a {
                continue;
            }
            let Some(r) = truth.state_at(*ts) else {
                continue;
            };
            points.push(PointError {
                point: j,
                pose: Vector3::new(x[X] - r[X], x[Y] - r[Y], angle::diff(x[YAW], r[YAW])),
                pose_cov: p.fixed_view::<3, 3>(0, 0).into_owned(),
                motion: Vector2::new(x[V] - r[V], x[YAW_RATE] - r[YAW_RATE]),
                motion_cov: p.fixed_view::<2, 2>(V, V).into_owned(),
            });
        }
        out.push(points);
    }
    let outage_s = windows.iter().map(|w| w.1 - w.0).fold(0.0, f64::max);
    Ok(WindowErrors {
        outage_s,
        windows: out,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_averaged_bounds_match_tabulated_chi_square_quantiles() {
        // χ²(3): 0.2158 and 9.3484 at 2.5 % and 97.5 %.
        let (lo, hi) = averaged_nees_bounds(3, 1).unwrap();
        assert!((lo - 0.2158).abs() < 1e-3 && (hi - 9.3484).abs() < 1e-3);
        // 50 runs of 2 dof: χ²(100) 74.22 and 129.56, over 50.
        let (lo, hi) = averaged_nees_bounds(2, 50).unwrap();
        assert!((lo - 1.4844).abs() < 1e-3 && (hi - 2.5912).abs() < 1e-3);
    }

    #[test]
    fn the_verdict_says_which_way_and_by_how_much() {
        let p = point(1.0, 2, &[8.0; 50]).unwrap();
        assert_eq!(p.verdict, Verdict::OverConfident(4.0));
        assert_eq!(p.verdict.to_string(), "over-confident by ×4.0");
        let p = point(1.0, 2, &[0.5; 50]).unwrap();
        assert_eq!(p.verdict, Verdict::UnderConfident(4.0));
        let p = point(1.0, 2, &[2.0; 50]).unwrap();
        assert_eq!(p.verdict, Verdict::Consistent);
    }

    #[test]
    fn the_reported_covariance_scales_and_floors_the_nees() {
        // One point: pose error (3, 4, 0.1) with P = diag(1, 1, 0.01), motion
        // error (1, 0) with P = I: NEES 25 + 1 = 26 and 1.
        let pe = PointError {
            point: 3,
            pose: Vector3::new(3.0, 4.0, 0.1),
            pose_cov: Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 0.01)),
            motion: Vector2::new(1.0, 0.0),
            motion_cov: Matrix2::identity(),
        };
        let e = WindowErrors {
            outage_s: 30.0,
            windows: vec![vec![pe]],
        };
        let nees = |r: &Reported| {
            let c = e.consistency(r).unwrap();
            (c.pose.values[3][0], c.motion.values[3][0])
        };
        let (p, m) = nees(&Reported::FILTER);
        assert!((p - 26.0).abs() < 1e-9 && (m - 1.0).abs() < 1e-9);
        // k = 2: every variance ×4.
        let (p, m) = nees(&Reported {
            k: 2.0,
            floor_m2: 0.0,
        });
        assert!((p - 6.5).abs() < 1e-9 && (m - 0.25).abs() < 1e-9);
        // A floor of 4 m² on the position only: 25/5 + 1 = 6; motion as is.
        let (p, m) = nees(&Reported {
            k: 1.0,
            floor_m2: 4.0,
        });
        assert!((p - 6.0).abs() < 1e-9 && (m - 1.0).abs() < 1e-9);
        // The other points saw no window.
        assert!(e.consistency(&Reported::FILTER).unwrap().pose.values[0].is_empty());
    }

    #[test]
    fn a_covariance_without_heading_variance_read_as_consistent() {
        // The bound's covariance with k = 0: a floor on the position and
        // nothing on the heading. Its points were left out, and a block
        // without points read "consistent"; a heading error against zero
        // variance is over-confident without limit.
        let pe = |yaw: f64| PointError {
            point: 3,
            pose: Vector3::new(0.5, -0.5, yaw),
            pose_cov: Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, 0.01)),
            motion: Vector2::new(0.1, 0.0),
            motion_cov: Matrix2::identity(),
        };
        let zero_k = Reported {
            k: 0.0,
            floor_m2: 1.0,
        };
        let e = WindowErrors {
            outage_s: 30.0,
            windows: vec![vec![pe(0.02)], vec![pe(-0.01)]],
        };
        let c = e.consistency(&zero_k).unwrap();
        assert_eq!(c.pose.points.len(), 1);
        assert_eq!(c.pose.points[0].windows, 2);
        assert_eq!(c.pose.verdict(), Verdict::OverConfident(f64::INFINITY));
        assert_eq!(c.motion.verdict(), Verdict::OverConfident(f64::INFINITY));
        // Only an error of exactly zero costs nothing against no variance.
        let exact = WindowErrors {
            outage_s: 30.0,
            windows: vec![vec![PointError {
                motion: Vector2::zeros(),
                ..pe(0.0)
            }]],
        };
        let c = exact.consistency(&zero_k).unwrap();
        assert_eq!(c.pose.values[3][0], f64::INFINITY);
        assert_eq!(c.motion.values[3][0], 0.0);
    }
}
