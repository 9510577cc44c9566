//! A 95 % horizontal error bound on every dead-reckoned position: the
//! filter's position covariance turned into a radius, made honest by a
//! factor fitted on the calibration drive's own held-back GNSS
//! (derivation in `docs/bound.md`).
//!
//! **The radius.** For a horizontal error `e ~ N(0, P)` (2×2, east/north)
//! with eigenvalues `λ₁ ≥ λ₂`, `|e|² = λ₁ Z₁² + λ₂ Z₂²` (a generalised χ²),
//! and the 95 % radius `r` solves `P(|e| ≤ r) = 0.95`. In polar
//! coordinates, with `a(θ) = cos²θ/λ₁ + sin²θ/λ₂`,
//!
//! ```text
//! F(r) = 1/(2π √(λ₁λ₂)) ∫₀^{2π} (1 − exp(−r² a(θ)/2)) / a(θ) dθ
//! ```
//!
//! a smooth periodic integrand, which the trapezoid rule integrates to
//! machine precision ([`radius_exact`]). `r = √λ₁ · g(√(λ₂/λ₁))`, with
//! `g(0) = 1.95996` (one axis: the normal's 97.5 % quantile) and
//! `g(1) = √(−2 ln 0.05) = 2.44775` (a circle: the Rayleigh quantile);
//! [`radius`] interpolates `g` from a table of 257 exact values (within
//! 1e-6 relative). `2.45 √trace` would be 41 % too wide on a circle.
//!
//! **The bound.** `r(k² P + F)`: `P` the filter's covariance of the
//! position, inflated by the fitted factor `k`, and `F = σ² I` the
//! receiver's floor, `σ` the declared accuracy of the last fix before
//! the outage ([`receiver_std_m`]). The filter takes the fixes as white
//! and averages their noise away, but a receiver's error is correlated
//! over tens of seconds: the position it hands over is off by about its
//! declared accuracy. `k` is not applied to `F`: no held-back fix can
//! tell the offset (the fixes carry it), so nothing fitted on them may
//! shrink it (a `k` of 0.15 on comma2k19 once did, and 5 of 7 windows
//! fell outside).
//!
//! **The factor.** A filter's covariance is not its error (the family's
//! pose NEES reads ×1.5–×250 over-confident, issue 36). `k` is fitted by
//! split conformal prediction on outage windows of the calibration drive
//! against its own hidden fixes ([`fit`]). Against a hidden fix the
//! error is the dead reckoning's, plus the offset handed over, minus the
//! hidden fix's own offset and white noise; the offsets are taken as
//! independent (a window is about as long as a receiver's correlation
//! time), so a window's score is the least `k_i ≥ 0` with
//! `|e_i| ≤ r(k_i² P_i + 2F + R)`, `R` the fixes' white noise
//! ([`fix_scatter_std_m`]) ([`crate::compared::OutageResult::final_sample`]).
//! `k` is the `⌈0.95 (n + 1)⌉`-th smallest score, which covers a new
//! exchangeable window with probability at least 95 % (the largest score
//! when `n < 19`). `k = 0` says the receiver's declaration explains every
//! window's error: the bound is then the floor. Windows overlap and are
//! not exchangeable with another drive's: the held-out coverage is
//! measured, not assumed (`docs/bound.md`).

use std::sync::OnceLock;

use nalgebra::SMatrix;

use crate::model::{X, Y, YAW};

/// The coverage the bound is for: 0.95.
pub const LEVEL: f64 = 0.95;

/// The least number of windows a factor is fitted on; with fewer the bound
/// is the filter's covariance alone ([`Method::Filter`]).
pub const MIN_WINDOWS: usize = 5;

/// A horizontal (east, north) covariance, m².
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cov2 {
    /// Var(east), m².
    pub ee_m2: f64,
    /// Cov(east, north), m².
    pub en_m2: f64,
    /// Var(north), m².
    pub nn_m2: f64,
}

impl Cov2 {
    /// A circular covariance with `std_m` per axis.
    pub fn circular(std_m: f64) -> Self {
        Cov2 {
            ee_m2: std_m * std_m,
            en_m2: 0.0,
            nn_m2: std_m * std_m,
        }
    }

    /// The covariance of the rear axle from the state's `(X, Y, YAW)`
    /// block `p3` (row-major).
    pub fn rear_axle(p3: &[[f64; 3]; 3]) -> Self {
        Cov2 {
            ee_m2: p3[0][0],
            en_m2: 0.5 * (p3[0][1] + p3[1][0]),
            nn_m2: p3[1][1],
        }
    }

    /// The covariance of a point `lever_m` ahead of the rear axle (the
    /// antenna) at heading `yaw_rad`, from the `(X, Y, YAW)` block `p3`:
    /// `A P Aᵀ` with `A = [I₂ | l (−sin ψ, cos ψ)ᵀ]`.
    pub fn ahead(p3: &[[f64; 3]; 3], yaw_rad: f64, lever_m: f64) -> Self {
        let j = [-lever_m * yaw_rad.sin(), lever_m * yaw_rad.cos()];
        let a = |r: usize| {
            [
                if r == 0 { 1.0 } else { 0.0 },
                if r == 1 { 1.0 } else { 0.0 },
                j[r],
            ]
        };
        let q = |r: usize, c: usize| {
            let (ar, ac) = (a(r), a(c));
            let mut s = 0.0;
            for i in 0..3 {
                for l in 0..3 {
                    s += ar[i] * p3[i][l] * ac[l];
                }
            }
            s
        };
        Cov2 {
            ee_m2: q(0, 0),
            en_m2: 0.5 * (q(0, 1) + q(1, 0)),
            nn_m2: q(1, 1),
        }
    }

    /// `s · self + other`.
    pub fn scaled_plus(&self, s: f64, other: &Cov2) -> Cov2 {
        Cov2 {
            ee_m2: s * self.ee_m2 + other.ee_m2,
            en_m2: s * self.en_m2 + other.en_m2,
            nn_m2: s * self.nn_m2 + other.nn_m2,
        }
    }

    /// The covariance of the antenna a GNSS fix sees, m²: the pose's
    /// `p3` carried `lever_m` ahead at `yaw_rad`, plus the receiver's
    /// wander where the filter carries it (`wander`).
    pub(crate) fn at_fix(
        p3: &[[f64; 3]; 3],
        wander: Option<&WanderCov>,
        yaw_rad: f64,
        lever_m: f64,
    ) -> Cov2 {
        let antenna = Cov2::ahead(p3, yaw_rad, lever_m);
        match wander {
            Some(w) => w.fix_cov(antenna, yaw_rad, lever_m),
            None => antenna,
        }
    }

    /// `ln N(d; 0, self)` of an offset `d = [east, north]`, m: the 2-D
    /// Gaussian's `−ln 2π − ½ ln det Σ − ½ dᵀΣ⁻¹d` (−∞ where the
    /// covariance is not positive definite).
    pub fn log_density(&self, d: [f64; 2]) -> f64 {
        let (a, b, c) = (self.ee_m2, self.en_m2, self.nn_m2);
        let det = a * c - b * b;
        if det.is_nan() || det <= 0.0 {
            return f64::NEG_INFINITY;
        }
        let nis = (c * d[0] * d[0] - 2.0 * b * d[0] * d[1] + a * d[1] * d[1]) / det;
        -(2.0 * std::f64::consts::PI).ln() - 0.5 * det.ln() - 0.5 * nis
    }

    /// The eigenvalues, largest first, clamped at 0, m².
    pub fn eigenvalues(&self) -> (f64, f64) {
        let m = 0.5 * (self.ee_m2 + self.nn_m2);
        let d = (0.5 * (self.ee_m2 - self.nn_m2)).hypot(self.en_m2);
        ((m + d).max(0.0), (m - d).max(0.0))
    }
}

/// The receiver's wander's part of a filter covariance: its covariance
/// with `(X, Y, YAW)` (rows) and its own 2×2 block, m², m·rad.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct WanderCov {
    cross: [[f64; 2]; 3],
    block: [[f64; 2]; 2],
}

impl WanderCov {
    /// From a covariance whose wander starts at index `w`.
    pub(crate) fn of<const N: usize>(p: &SMatrix<f64, N, N>, w: usize) -> Self {
        let i = [X, Y, YAW];
        WanderCov {
            cross: std::array::from_fn(|r| std::array::from_fn(|c| p[(i[r], w + c)])),
            block: std::array::from_fn(|r| std::array::from_fn(|c| p[(w + r, w + c)])),
        }
    }

    /// The covariance of the fix predicted at the antenna (`lever_m` ahead
    /// of the rear axle at `yaw_rad`) plus the wander: `H P Hᵀ` with
    /// `H = [A | I₂]`, `A = [I₂ | l (−sin ψ, cos ψ)ᵀ]`; `antenna` is
    /// `A P_pose Aᵀ` ([`Cov2::ahead`]); what the outage evaluation's bound
    /// compares a hidden fix with ([`crate::outage`]).
    pub(crate) fn fix_cov(&self, antenna: Cov2, yaw_rad: f64, lever_m: f64) -> Cov2 {
        let j = [-lever_m * yaw_rad.sin(), lever_m * yaw_rad.cos()];
        // M = A · cross (2×2).
        let m = |r: usize, c: usize| self.cross[r][c] + j[r] * self.cross[2][c];
        Cov2 {
            ee_m2: antenna.ee_m2 + 2.0 * m(0, 0) + self.block[0][0],
            en_m2: antenna.en_m2 + m(0, 1) + m(1, 0) + 0.5 * (self.block[0][1] + self.block[1][0]),
            nn_m2: antenna.nn_m2 + 2.0 * m(1, 1) + self.block[1][1],
        }
    }
}

/// P(|e| ≤ r) for `e ~ N(0, diag(λ₁, λ₂))`, `λ₁ ≥ λ₂ > 0`, and its
/// derivative in `r` (the density of `|e|`), by the trapezoid rule on
/// the polar integral (module documentation) with `n` points.
fn cdf_and_density(l1: f64, l2: f64, r: f64, n: usize) -> (f64, f64) {
    let h = 2.0 * std::f64::consts::PI / n as f64;
    let norm = 1.0 / (2.0 * std::f64::consts::PI * (l1 * l2).sqrt());
    let (mut f, mut d) = (0.0, 0.0);
    for i in 0..n {
        let th = (i as f64 + 0.5) * h;
        let a = th.cos().powi(2) / l1 + th.sin().powi(2) / l2;
        let e = (-0.5 * r * r * a).exp();
        f += (1.0 - e) / a;
        d += r * e;
    }
    (f * h * norm, d * h * norm)
}

/// The radius `r` with `P(|e| ≤ r) = level` for `e ~ N(0, cov)`, m,
/// computed directly (Newton on the trapezoid-integrated CDF): about
/// 1e-12 relative; [`radius`] is the fast path for the 95 % level.
pub fn radius_exact(cov: &Cov2, level: f64) -> f64 {
    let (l1, l2) = cov.eigenvalues();
    if l1 <= 0.0 {
        return 0.0;
    }
    let one_axis = || l1.sqrt() * normal_quantile(0.5 + 0.5 * level);
    if l2 <= l1 * 1e-12 {
        return one_axis();
    }
    // The integrand's peak is √(λ₁/λ₂) times narrower than 2π.
    let n = (64.0 + 32.0 * (l1 / l2).sqrt()).min(1e6) as usize;
    // Between the one-axis and the circular radius of λ₁: start at the circle's.
    let mut r = l1.sqrt() * (-2.0 * (1.0 - level).ln()).sqrt();
    let lo = one_axis();
    for _ in 0..60 {
        let (f, d) = cdf_and_density(l1, l2, r, n);
        let step = (f - level) / d.max(1e-300);
        let next = (r - step).max(0.5 * lo).min(2.0 * r);
        if (next - r).abs() <= 1e-14 * r {
            r = next;
            break;
        }
        r = next;
    }
    r
}

/// The standard normal's quantile at `p`.
fn normal_quantile(p: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, Normal};
    Normal::standard().inverse_cdf(p)
}

/// `g(s)` at `s = 0, 1/256, …, 1` (module documentation), for [`LEVEL`].
fn table() -> &'static [f64; 257] {
    static TABLE: OnceLock<[f64; 257]> = OnceLock::new();
    TABLE.get_or_init(|| {
        let mut t = [0.0; 257];
        for (i, g) in t.iter_mut().enumerate() {
            let s = i as f64 / 256.0;
            *g = radius_exact(
                &Cov2 {
                    ee_m2: 1.0,
                    en_m2: 0.0,
                    nn_m2: s * s,
                },
                LEVEL,
            );
        }
        t
    })
}

/// The 95 % radius of `e ~ N(0, cov)`, m: `√λ₁ · g(√(λ₂/λ₁))` with `g`
/// interpolated (cubic) from 257 exact values.
pub fn radius(cov: &Cov2) -> f64 {
    let (l1, l2) = cov.eigenvalues();
    if l1 <= 0.0 || !l1.is_finite() {
        return if l1.is_finite() { 0.0 } else { f64::NAN };
    }
    let s = (l2 / l1).sqrt().clamp(0.0, 1.0) * 256.0;
    let t = table();
    let i = (s.floor() as usize).min(255);
    let u = s - i as f64;
    // Catmull–Rom through the neighbours (ends extended linearly).
    let at = |k: isize| -> f64 {
        if k < 0 {
            2.0 * t[0] - t[1]
        } else if k > 256 {
            2.0 * t[256] - t[255]
        } else {
            t[k as usize]
        }
    };
    let i = i as isize;
    let (p0, p1, p2, p3) = (at(i - 1), at(i), at(i + 1), at(i + 2));
    let g = p1
        + 0.5
            * u
            * (p2 - p0
                + u * (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3 + u * (3.0 * (p1 - p2) + p3 - p0)));
    l1.sqrt() * g
}

/// How the bound is made from the filter's covariance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// `k` fitted by split conformal prediction on the calibration drive's
    /// outage windows against its hidden fixes.
    Conformal,
    /// The filter's covariance alone (`k = 1`): no fit (too few windows,
    /// no fixes, or parameters without a `[bound]` table).
    Filter,
}

impl Method {
    /// `conformal` or `filter`, as params.toml and `--json` write it.
    pub fn name(self) -> &'static str {
        match self {
            Method::Conformal => "conformal",
            Method::Filter => "filter",
        }
    }

    /// The method named `name`.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "conformal" => Some(Method::Conformal),
            "filter" => Some(Method::Filter),
            _ => None,
        }
    }
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Method::Conformal => {
                "the filter's covariance inflated by a factor fitted on held-back fixes"
            }
            Method::Filter => "the filter's covariance alone (not calibrated)",
        })
    }
}

/// The bound's inflation: `bound = r(k² P + F)` ([`BoundFit::floored_bound_m`]).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BoundFit {
    /// How `k` was found.
    pub method: Method,
    /// The factor on the filter's covariance (`k² P`; with no floor, the
    /// factor on its 95 % radius).
    pub k: f64,
    /// Windows it was fitted on (0 for [`Method::Filter`]).
    pub windows: usize,
    /// The windows' length, s (0 when not fitted).
    pub outage_s: f64,
    /// The step between windows, s (0 when not fitted).
    pub step_s: f64,
}

impl BoundFit {
    /// The filter's covariance alone.
    pub const FILTER: BoundFit = BoundFit {
        method: Method::Filter,
        k: 1.0,
        windows: 0,
        outage_s: 0.0,
        step_s: 0.0,
    };

    /// The 95 % bound of a position whose filter covariance is `cov` and
    /// has no receiver's floor (the differential drive's), m: `k · r(P)`.
    pub fn bound_m(&self, cov: &Cov2) -> f64 {
        self.k * radius(cov)
    }

    /// The 95 % bound of a position whose filter covariance is `cov`, over
    /// a receiver's offset of covariance `floor` that the factor does not
    /// inflate: `r(k² P + F)`, m.
    pub fn floored_bound_m(&self, cov: &Cov2, floor: &Cov2) -> f64 {
        radius(&cov.scaled_plus(self.k * self.k, floor))
    }

    /// The 95 % bound of what is compared with a reference of covariance
    /// `reference` (a fix's own noise; zero for the truth), m.
    pub fn compared_bound_m(&self, cov: &Cov2, reference: &Cov2) -> f64 {
        radius(&cov.scaled_plus(self.k * self.k, reference))
    }
}

/// One window's end for the fit: the error against the hidden fix, the
/// filter's covariance of the compared point, and the fix's own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// The error, m.
    pub error_m: f64,
    /// The filter's covariance of the compared point, m².
    pub cov: Cov2,
    /// The reference's own covariance, m².
    pub reference: Cov2,
}

impl Sample {
    /// The least `k ≥ 0` with `error ≤ r(k² P + R)` (bisection on `k`,
    /// to 1e-6 relative); infinite when `P` is zero and the error exceeds
    /// `r(R)`.
    pub fn score(&self) -> f64 {
        let covered =
            |k: f64| self.error_m <= radius(&self.cov.scaled_plus(k * k, &self.reference));
        if covered(0.0) {
            return 0.0;
        }
        let mut hi = 1.0;
        while !covered(hi) {
            hi *= 2.0;
            if hi > 1e12 {
                return f64::INFINITY;
            }
        }
        let mut lo = 0.0;
        while hi - lo > 1e-6 * hi {
            let mid = 0.5 * (lo + hi);
            if covered(mid) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        hi
    }
}

/// The conformal factor of `samples` (module documentation):
/// the `⌈0.95 (n + 1)⌉`-th smallest score (the largest when `n < 19`);
/// [`BoundFit::FILTER`] with fewer than [`MIN_WINDOWS`] samples.
pub fn fit(samples: &[Sample], outage_s: f64, step_s: f64) -> BoundFit {
    let mut scores: Vec<f64> = samples
        .iter()
        .map(Sample::score)
        .filter(|s| !s.is_nan())
        .collect();
    if scores.len() < MIN_WINDOWS {
        return BoundFit::FILTER;
    }
    scores.sort_by(f64::total_cmp);
    let n = scores.len();
    let rank = ((LEVEL * (n + 1) as f64).ceil() as usize).min(n);
    let k = scores[rank - 1];
    if !k.is_finite() {
        return BoundFit::FILTER;
    }
    BoundFit {
        method: Method::Conformal,
        k,
        windows: n,
        outage_s,
        step_s,
    }
}

/// The fixes' own white noise per axis, as their scatter shows it, m: the
/// second differences `d = x(k+1) − 2 x(k) + x(k−1)` of consecutive fixes
/// (east and north pooled) have variance `6 σ²` for white noise of `σ` and
/// little else at receiver rates (a 2.5 m/s² turn moves `d` by 0.16 m at
/// 4 Hz), so `σ = 1.4826 · MAD(d) / √6` (robust to jumps). A receiver's
/// declared `std_m` is not used: comma2k19's u-blox declares 1 m on every
/// fix while its fixes scatter by centimetres, and charging 1 m of noise to
/// each fix explained every outage error away (a factor of 0). Slow wander
/// does not show in second differences; against hidden fixes it is part of
/// what the dead reckoning is charged with. 0 with fewer than 10 fixes.
pub fn fix_scatter_std_m(gnss: &[crate::drive::GnssFix]) -> f64 {
    if gnss.len() < 10 {
        return 0.0;
    }
    let mut d: Vec<f64> = gnss
        .windows(3)
        .flat_map(|w| {
            [
                w[2].east_m - 2.0 * w[1].east_m + w[0].east_m,
                w[2].north_m - 2.0 * w[1].north_m + w[0].north_m,
            ]
        })
        .filter(|v| v.is_finite())
        .collect();
    if d.is_empty() {
        return 0.0;
    }
    let median = |v: &mut Vec<f64>| {
        let m = v.len() / 2;
        *v.select_nth_unstable_by(m, f64::total_cmp).1
    };
    let mid = median(&mut d);
    let mut dev: Vec<f64> = d.iter().map(|v| (v - mid).abs()).collect();
    1.4826 * median(&mut dev) / 6f64.sqrt()
}

/// A fix's declared horizontal accuracy per axis, m (its `std_m`; 0 when
/// not finite): the floor of the bound of a position handed over from it.
pub fn receiver_std_m(fix: &crate::drive::GnssFix) -> f64 {
    if fix.std_m.is_finite() && fix.std_m > 0.0 {
        fix.std_m
    } else {
        0.0
    }
}

/// The length of the calibration drive's outage windows the factor is
/// fitted on, at most, s: 30 (the issue's held-out outages).
pub const FIT_OUTAGE_S: f64 = 30.0;

/// The windows [`fit_on_drive`] uses on a drive whose fixes span `span_s`
/// after the warm-up: `(length, step)`, s. At most [`FIT_OUTAGE_S`] long
/// and a third of the span (a short drive still gives windows), stepped
/// so that about 20 fit (19 is the fewest with which the conformal rank
/// is not the largest score), at least 1 s and at most a third of the
/// length apart.
pub fn fit_windows(span_s: f64) -> (f64, f64) {
    let length = FIT_OUTAGE_S.min(span_s / 3.0).max(1.0);
    let step = ((span_s - length) / 20.0).clamp(1.0, (length / 3.0).max(1.0));
    (length, step)
}

/// The GNSS-aided time before the first fit window, s: 5 (`evaluate`'s
/// default warm-up).
pub const FIT_WARMUP_S: f64 = 5.0;

/// Fits the bound's factor on `drive` with `params` (the calibration's):
/// sliding outages ([`fit_windows`]) against the hidden fixes, truth or
/// not ([`crate::outage::evaluate_against_fixes`]), each window's end a
/// [`Sample`]. [`BoundFit::FILTER`] when the drive has too few fixes or
/// windows.
pub fn fit_on_drive(
    drive: &crate::Drive,
    params: &crate::Params,
    base: &crate::ekf::FilterOptions,
) -> BoundFit {
    fit_on_drive_with_windows(drive, params, base).0
}

/// [`fit_on_drive`] with the windows it was fitted on (`None` when none
/// could be evaluated).
pub fn fit_on_drive_with_windows(
    drive: &crate::Drive,
    params: &crate::Params,
    base: &crate::ekf::FilterOptions,
) -> (BoundFit, Option<crate::outage::OutageEvaluation>) {
    let (Some(first), Some(last)) = (drive.gnss.first(), drive.gnss.last()) else {
        return (BoundFit::FILTER, None);
    };
    let (length, step) = fit_windows(last.t_s - first.t_s - FIT_WARMUP_S);
    match crate::outage::evaluate_against_fixes(drive, params, length, step, FIT_WARMUP_S, base) {
        Ok(ev) => (fit(&samples(&ev), length, step), Some(ev)),
        Err(_) => (BoundFit::FILTER, None),
    }
}

/// When the bound reaches `alert_m` over a drive's windows: the medians of
/// the time (s) and distance (m) into the outage over the windows where it
/// does, their count, and the windows' median speed, m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reach {
    /// The alert limit, m.
    pub alert_m: f64,
    /// Median time into the outage, s.
    pub time_s: f64,
    /// Median distance into the outage, m (NaN when not known).
    pub distance_m: f64,
    /// Windows where the bound reaches the limit.
    pub windows: usize,
    /// Windows in all.
    pub of: usize,
    /// The windows' median speed (distance over length), m/s.
    pub speed_mps: f64,
}

/// [`Reach`] of `fit`'s bound at `alert_m` over `ev`'s windows (`None`
/// when it reaches it in none).
pub fn reach(ev: &crate::outage::OutageEvaluation, fit: &BoundFit, alert_m: f64) -> Option<Reach> {
    use crate::metrics::Summary;
    let r: Vec<(f64, Option<f64>)> = ev
        .windows
        .iter()
        .filter_map(|w| w.bound_reaches(fit, alert_m))
        .collect();
    if r.is_empty() {
        return None;
    }
    let d: Vec<f64> = r.iter().filter_map(|x| x.1).collect();
    let speeds: Vec<f64> = ev
        .windows
        .iter()
        .map(|w| w.distance_m / (w.end_s - w.start_s))
        .filter(|v| v.is_finite())
        .collect();
    Some(Reach {
        alert_m,
        time_s: Summary::of(&r.iter().map(|x| x.0).collect::<Vec<_>>()).median,
        distance_m: if d.is_empty() {
            f64::NAN
        } else {
            Summary::of(&d).median
        },
        windows: r.len(),
        of: ev.windows.len(),
        speed_mps: Summary::of(&speeds).median,
    })
}

/// Each window's end of `ev` (the settled ones) as a [`Sample`]
/// ([`crate::compared::OutageResult::final_sample`]).
pub fn samples(ev: &crate::outage::OutageEvaluation) -> Vec<Sample> {
    ev.windows.iter().filter_map(|w| w.final_sample()).collect()
}

impl crate::compared::OutageResult {
    /// The 95 % bound at each error, m (empty when the estimator gave no
    /// covariance): [`BoundFit::floored_bound_m`] of the estimator's
    /// covariance and the receiver's floor.
    pub fn bounds_95_m(&self, fit: &BoundFit) -> Vec<f64> {
        self.covariances_m2
            .iter()
            .map(|c| fit.floored_bound_m(c, &self.floor_m2))
            .collect()
    }

    /// The 95 % bound at the window's end (the last error), m.
    pub fn bound_95_m(&self, fit: &BoundFit) -> Option<f64> {
        let i = self.covariances_m2.len().checked_sub(1)?;
        Some(fit.floored_bound_m(&self.covariances_m2[i], &self.floor_m2))
    }

    /// The sample the final error makes for [`fit`] and the coverage: the
    /// inflated part is the estimator's covariance `P`; the rest is what
    /// the receiver adds. Against the truth that is the floor `F` (the
    /// offset of the position handed over). Against a hidden fix it is
    /// `2F + R`: the offset handed over and the hidden fix's own offset,
    /// taken as independent, plus the fix's white noise `R` (the
    /// reference's covariance). `None` without covariances.
    pub fn final_sample(&self) -> Option<Sample> {
        let i = self.covariances_m2.len().checked_sub(1)?;
        let floor = self.floor_m2;
        let reference = match self.against {
            crate::compared::Against::Gnss => floor.scaled_plus(2.0, &self.reference_m2),
            _ => floor,
        };
        Some(Sample {
            error_m: self.final_m(),
            cov: self.covariances_m2[i],
            reference,
        })
    }

    /// Whether the final error is within the bound of what was compared
    /// (`r(k² P + R)`, `R` the reference part of [`Self::final_sample`]):
    /// against the truth, the bound itself ([`Self::bound_95_m`]).
    pub fn within_bound(&self, fit: &BoundFit) -> Option<bool> {
        let s = self.final_sample()?;
        Some(s.error_m <= fit.compared_bound_m(&s.cov, &s.reference))
    }

    /// When the bound first reaches `alert_m`: time from the outage start,
    /// s, and distance travelled, m (`None` for the distance when not
    /// known); `None` when it never does in the window.
    pub fn bound_reaches(&self, fit: &BoundFit, alert_m: f64) -> Option<(f64, Option<f64>)> {
        let i = self.bounds_95_m(fit).iter().position(|b| *b >= alert_m)?;
        Some((self.errors[i].0, self.travelled_m.get(i).copied()))
    }
}

impl crate::outage::OutageEvaluation {
    /// The share of windows whose final error is within the bound
    /// ([`crate::compared::OutageResult::within_bound`]); `None` without
    /// covariances.
    pub fn bound_coverage(&self, fit: &BoundFit) -> Option<f64> {
        let v: Vec<bool> = self
            .windows
            .iter()
            .filter_map(|w| w.within_bound(fit))
            .collect();
        (!v.is_empty()).then(|| v.iter().filter(|b| **b).count() as f64 / v.len() as f64)
    }

    /// The bound's sharpness: the median bound at the windows' ends over
    /// the median final error (1 is as sharp as a bound that knew the
    /// error's median; `None` without covariances).
    pub fn bound_sharpness(&self, fit: &BoundFit) -> Option<f64> {
        let b: Vec<f64> = self
            .windows
            .iter()
            .filter_map(|w| w.bound_95_m(fit))
            .collect();
        if b.is_empty() {
            return None;
        }
        Some(crate::metrics::Summary::of(&b).median / self.final_error().median)
    }
}

#[cfg(test)]
#[path = "bound_tests.rs"]
mod tests;
