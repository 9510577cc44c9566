//! The rear-axle side-slip gradient g from a drive with GNSS.
//!
//! With side slip the rear-axle centre M moves at `β_r = −g·a_y` to the body
//! axis ([`crate::model`]), `a_y = v·ψ̇`. Dead-reckoning M with the speed v
//! along the heading ψ turning at ψ̇ over a block `[a, b]` gives
//!
//! ```text
//! D(g) = ∫ v·(cos ψ − tan β sin ψ, sin ψ + tan β cos ψ) dt
//!      ≈ D₀ + g·J,   D₀ = ∫ v·(cos ψ, sin ψ) dt,   J = ∫ v|v|ψ̇·(sin ψ, −cos ψ) dt
//! ```
//!
//! (`tan β ≈ β`: 0.03 % off at β = 1.7°). The fixes' displacement F over the
//! block (antenna fixes with the lever arm removed, the mean over the
//! [`END_S`] either side of each end, less the dead reckoning at the same
//! fixes: every fix is used, each at one block end) then obeys, block by
//! block,
//!
//! ```text
//! F − D₀ = g·J + s·D₀ + r_w·R₉₀D₀ + e
//! ```
//!
//! with nuisance parameters: a distance-scale residual `s` for the drive
//! (the wheels' scale against the fixes', which the RTS calibration's
//! chords check too) and a yaw offset `r_w` for each window of
//! [`YAW_WINDOW_S`]. The three (or more) are solved by least squares over
//! the 2·n equations of the n blocks of [`BLOCK_S`] that move at least
//! [`MIN_BLOCK_M`].
//!
//! **The heading is the gyro's**, integrated (less the calibrated bias)
//! from the smoothed yaw at the start, with the gyro's yaw rate for a_y; v
//! is the smoothed speed. J is lateral, and in a steady turn it is
//! `a_y·R₉₀D₀`-like: a turn's slip looks like a heading error of that
//! block. A heading that the fixes helped to set takes it in: the smoothed
//! yaw of the (g = 0) filter followed the slip through the turns and added
//! a lag of its own, and against it g read −0.0010 to −0.0018 on family
//! cars with true gradients of 0.0040–0.0058 (−0.0016 to −0.0021 on the
//! kinematic world, where g = 0), while along the gyro's heading 0.0042 to
//! 0.0062. The gyro cannot follow a turn's slip; what it drifts by (its
//! bias error, its noise) is slow and goes into the windows' offsets, which
//! are determined because a_y changes sign between left and right turns and
//! vanishes on straights. A yaw lag of τ reads as `g ≈ −τ/v`: 5 ms at
//! 15 m/s is 0.0003, so the gyro's stamps matter (a stamp mid-interval, not
//! at its start, in the tests). Without a gyro the smoothed yaw and yaw
//! rate are used, with that bias.
//!
//! The fixes' time alignment is confounded with g the same way: a fix
//! late by τ against the wheels moves a turn's chord sideways by about
//! `τ·v·Δψ`, against the slip's `g·v²·Δψ`. On the built-in calibration
//! scenario (kinematic, g = 0; `deadreckon calibrate`) g read 0.0013 ±
//! 0.0007 with `--corrections none` and 0.0024 ± 0.0009 with the default
//! corrections (a GNSS delay of −12.7 ms and a gyro scale error of
//! +0.36 % applied). Fitting the delay beside g separates them only
//! through the turns' speeds, and on the unit tests' drive it multiplied
//! g's standard error by 4.4 (3.1e-5 → 1.35e-4): not done.
//!
//! The standard error is the sandwich form with the neighbouring blocks'
//! products (blocks share their end fixes: the end noise enters two blocks
//! with opposite signs), floored at the plain `σ̂²(AᵀA)⁻¹`. g is "not
//! estimated" (with why) with fewer than [`MIN_BLOCKS`] blocks or when its
//! standard error is above [`MAX_STD_RAD_PER_MPS2`]: a drive without turns
//! at speed, or a receiver whose wander hides them (on the family cars,
//! 1200 s drives: ±0.0002–0.0008 with white fixes of 0.3–1.5 m, ±0.001–0.0035
//! with their wander of up to 1.5 m; `crates/deadreckon-sim/tests/side_slip.rs`).

use nalgebra::{DMatrix, DVector};

use crate::drive::Drive;
use crate::kinematics::ParamEstimate;
use crate::model::{V, YAW, YAW_RATE};
use crate::reference::Reference;

/// Length of a block, s: about a turn, so that a block's slip is one sign.
pub const BLOCK_S: f64 = 10.0;
/// Fixes averaged at each end of a block: those within this many seconds
/// of the end, s: half a block, so that every fix is used once at the ends
/// of two neighbouring blocks (the residual and the regressors are both
/// averaged over the same fixes, so the block is the difference of two
/// 10 s means; measured on family car 1 with dynamics: ±0.0023 rad per m/s²
/// with 0.5 s ends).
pub const END_S: f64 = 0.5 * BLOCK_S;
/// Shortest dead-reckoned displacement of a block that is used, m.
pub const MIN_BLOCK_M: f64 = 20.0;
/// The windows with a yaw offset of their own, s: the gyro's heading drifts
/// with the error of its bias (1e-5 rad/s is 0.0006 rad in a minute).
pub const YAW_WINDOW_S: f64 = 60.0;
/// Fewest blocks for an estimate.
pub const MIN_BLOCKS: usize = 10;
/// The largest standard error with which g is reported as estimated, rad
/// per m/s²: 0.001, a fifth of a car's typical 0.005. Above it the drive's
/// turns at speed do not determine g.
pub const MAX_STD_RAD_PER_MPS2: f64 = 0.001;
/// The key of g, as in vehicle.toml and params.toml.
pub const NAME: &str = "rear_slip_gradient_rad_per_mps2";

/// The side-slip gradient of a drive, with the nuisance parameters.
#[derive(Debug, Clone, PartialEq)]
pub struct SideSlip {
    /// g with its standard error, or not estimated with why (value 0).
    pub gradient: ParamEstimate,
    /// The fitted g even when not reported as estimated (NaN without a fit).
    pub fitted: f64,
    /// Its standard error (NaN without a fit).
    pub fitted_std: f64,
    /// The distance-scale residual fitted beside it (fixes over dead reckoning − 1).
    pub scale_residual: f64,
    /// The largest |yaw offset| of a window fitted beside it, rad.
    pub yaw_offset_rad: f64,
    /// Blocks used.
    pub blocks: usize,
    /// RMS lateral acceleration over the blocks used, m/s².
    pub rms_lateral_accel_mps2: f64,
}

fn not_estimated(why: String) -> ParamEstimate {
    ParamEstimate {
        name: NAME.into(),
        value: 0.0,
        std: None,
        estimated: false,
        reason: Some(why),
    }
}

/// One block's look: residual `F − D₀` and the regressors J, D₀, R₉₀D₀.
struct Look {
    y: [f64; 2],
    a: [[f64; 3]; 2],
}

/// The heading the blocks are dead-reckoned along: the gyro integrated
/// (less `gyro_bias_rps`) from the smoothed yaw at its first sample, and
/// the gyro's yaw rate; the smoothed yaw and yaw rate without a gyro.
/// Returns `(ψ, ψ̇)` at the smoothed samples (`None` outside the gyro's span).
fn headings(drive: &Drive, smoothed: &Reference, gyro_bias_rps: f64) -> Vec<Option<(f64, f64)>> {
    let (t, x) = (&smoothed.t, &smoothed.x);
    let gy = &drive.yaw_rate;
    if gy.len() < 2 {
        return x.iter().map(|s| Some((s[YAW], s[YAW_RATE]))).collect();
    }
    let mut cum = Vec::with_capacity(gy.len());
    let mut acc = 0.0;
    cum.push(0.0);
    for w in gy.windows(2) {
        acc += 0.5 * (w[0].value + w[1].value - 2.0 * gyro_bias_rps) * (w[1].t_s - w[0].t_s);
        cum.push(acc);
    }
    // (∫, rate) at `ts` by linear interpolation.
    let at = |ts: f64| -> Option<(f64, f64)> {
        let k = gy.partition_point(|g| g.t_s <= ts);
        if k == 0 || k >= gy.len() {
            return None;
        }
        let (a, b) = (&gy[k - 1], &gy[k]);
        let f = (ts - a.t_s) / (b.t_s - a.t_s);
        let rate = a.value + f * (b.value - a.value) - gyro_bias_rps;
        let integral = cum[k - 1] + 0.5 * (ts - a.t_s) * (a.value - gyro_bias_rps + rate);
        Some((integral, rate))
    };
    let mut start: Option<(f64, f64)> = None; // (smoothed ψ, ∫) at the first sample inside
    t.iter()
        .zip(x)
        .map(|(&ts, s)| {
            let (integral, rate) = at(ts)?;
            let (yaw0, int0) = *start.get_or_insert((s[YAW], integral));
            Some((yaw0 + integral - int0, rate))
        })
        .collect()
}

/// Estimates g from `drive`'s fixes against the dead reckoning of the
/// smoothed speed along the gyro's heading (bias `gyro_bias_rps`; see the
/// module doc).
pub fn estimate(drive: &Drive, smoothed: &Reference, gyro_bias_rps: f64) -> SideSlip {
    let (t, x) = (&smoothed.t, &smoothed.x);
    let empty = |why: String| SideSlip {
        gradient: not_estimated(why),
        fitted: f64::NAN,
        fitted_std: f64::NAN,
        scale_residual: f64::NAN,
        yaw_offset_rad: f64::NAN,
        blocks: 0,
        rms_lateral_accel_mps2: f64::NAN,
    };
    if t.len() < 2 || drive.gnss.len() < 2 {
        return empty("no smoothed states or GNSS fixes".into());
    }
    let heading = headings(drive, smoothed, gyro_bias_rps);
    // Cumulative D₀ and J at the smoothed samples (trapezoid on the
    // integrands), and ∫a_y² dt for the RMS lateral acceleration; `None`
    // before the heading starts.
    let integrand = |v: f64, (yaw, rate): (f64, f64)| {
        let (sn, cs) = yaw.sin_cos();
        let k = v * v.abs() * rate;
        [v * cs, v * sn, k * sn, -k * cs, (v * rate).powi(2)]
    };
    let mut cum: Vec<Option<[f64; 5]>> = Vec::with_capacity(t.len());
    let mut acc = [0.0; 5];
    let mut prev: Option<[f64; 5]> = None;
    for k in 0..t.len() {
        let Some(h) = heading[k] else {
            cum.push(None);
            prev = None;
            continue;
        };
        let q = integrand(x[k][V], h);
        if let Some(p) = prev {
            let dt = t[k] - t[k - 1];
            for i in 0..5 {
                acc[i] += 0.5 * dt * (p[i] + q[i]);
            }
        }
        prev = Some(q);
        cum.push(Some(acc));
    }
    let cum_at = |ts: f64| -> Option<[f64; 5]> {
        let k = t.partition_point(|&s| s <= ts);
        if k == 0 || k >= t.len() {
            return None;
        }
        let (a, b) = (cum[k - 1]?, cum[k]?);
        let f = (ts - t[k - 1]) / (t[k] - t[k - 1]);
        Some(std::array::from_fn(|i| a[i] + f * (b[i] - a[i])))
    };
    let lever = drive.vehicle.gnss_lever_arm_m;
    // At one end: the mean of (fix at M − D₀) and the mean cumulative integrals.
    let end = |at: f64| -> Option<([f64; 2], [f64; 5])> {
        let i = drive.gnss.partition_point(|g| g.t_s < at - END_S);
        let (mut m, mut c, mut n) = ([0.0; 2], [0.0; 5], 0.0);
        for g in drive.gnss[i..].iter().take_while(|g| g.t_s <= at + END_S) {
            let (Some(s), Some(q)) = (smoothed.state_at(g.t_s), cum_at(g.t_s)) else {
                continue;
            };
            m[0] += g.east_m - lever * s[YAW].cos() - q[0];
            m[1] += g.north_m - lever * s[YAW].sin() - q[1];
            for i in 0..5 {
                c[i] += q[i];
            }
            n += 1.0;
        }
        (n > 0.0).then(|| ([m[0] / n, m[1] / n], c.map(|v| v / n)))
    };
    let (t0, t1) = (t[0], t[t.len() - 1]);
    // (window, look): the window's yaw offset is a nuisance of its own.
    let mut looks: Vec<(usize, Look)> = Vec::new();
    let (mut ay2, mut time) = (0.0, 0.0);
    let mut a = t0 + END_S;
    let mut prev_end = end(a);
    while a + BLOCK_S <= t1 - END_S {
        let b = a + BLOCK_S;
        let next = end(b);
        if let (Some((ma, ca)), Some((mb, cb))) = (prev_end, next) {
            let d = [cb[0] - ca[0], cb[1] - ca[1]];
            if d[0].hypot(d[1]) >= MIN_BLOCK_M {
                let j = [cb[2] - ca[2], cb[3] - ca[3]];
                let window = ((a - t0) / YAW_WINDOW_S) as usize;
                looks.push((
                    window,
                    Look {
                        y: [mb[0] - ma[0], mb[1] - ma[1]],
                        a: [[j[0], d[0], -d[1]], [j[1], d[1], d[0]]],
                    },
                ));
                ay2 += cb[4] - ca[4];
                time += BLOCK_S;
            }
        }
        prev_end = next;
        a = b;
    }
    let n = looks.len();
    let rms_ay = if time > 0.0 {
        (ay2 / time).sqrt()
    } else {
        f64::NAN
    };
    if n < MIN_BLOCKS {
        return SideSlip {
            rms_lateral_accel_mps2: rms_ay,
            blocks: n,
            ..empty(format!(
                "{n} blocks of {BLOCK_S} s moving at least {MIN_BLOCK_M} m with GNSS at both ends (needs {MIN_BLOCKS})"
            ))
        };
    }
    // Columns: g, the scale, one yaw offset per window that has blocks.
    let mut windows: Vec<usize> = looks.iter().map(|l| l.0).collect();
    windows.dedup();
    let p = 2 + windows.len();
    let col = |w: usize| 2 + windows.binary_search(&w).unwrap_or(0);
    let rows_of = |(w, l): &(usize, Look)| -> [(DVector<f64>, f64); 2] {
        std::array::from_fn(|r| {
            let mut row = DVector::zeros(p);
            row[0] = l.a[r][0];
            row[1] = l.a[r][1];
            row[col(*w)] = l.a[r][2];
            (row, l.y[r])
        })
    };
    let mut ata = DMatrix::zeros(p, p);
    let mut aty = DVector::zeros(p);
    for l in &looks {
        for (row, y) in rows_of(l) {
            ata += &row * row.transpose();
            aty += &row * y;
        }
    }
    let Some(inv) = ata.try_inverse() else {
        return SideSlip {
            rms_lateral_accel_mps2: rms_ay,
            blocks: n,
            ..empty(
                "no turns at speed: the slip regressor is collinear with the scale and yaw offsets"
                    .into(),
            )
        };
    };
    let theta = &inv * aty;
    // Per-block score contributions Aᵢᵀeᵢ.
    let mut rss = 0.0;
    let scores: Vec<DVector<f64>> = looks
        .iter()
        .map(|l| {
            let mut s = DVector::zeros(p);
            for (row, y) in rows_of(l) {
                let e = y - row.dot(&theta);
                rss += e * e;
                s += row * e;
            }
            s
        })
        .collect();
    let dof = (2 * n).saturating_sub(p).max(1) as f64;
    let plain = inv[(0, 0)] * (rss / dof);
    let mut meat = DMatrix::zeros(p, p);
    for (i, s) in scores.iter().enumerate() {
        meat += s * s.transpose();
        if i > 0 {
            let c = s * scores[i - 1].transpose();
            meat += &c + c.transpose();
        }
    }
    let sandwich = (&inv * meat * &inv)[(0, 0)] * (2.0 * n as f64 / dof);
    let var = sandwich.max(plain);
    let (g, sd) = (theta[0], var.max(0.0).sqrt());
    let gradient = if !(g.is_finite() && sd.is_finite()) {
        not_estimated("the fit is not finite".into())
    } else if sd > MAX_STD_RAD_PER_MPS2 {
        not_estimated(format!(
            "the drive's turns at speed determine g only to ±{sd:.4} rad per m/s² (needs ±{MAX_STD_RAD_PER_MPS2}; RMS lateral acceleration {rms_ay:.2} m/s² over {n} blocks)"
        ))
    } else {
        ParamEstimate {
            name: NAME.into(),
            value: g,
            std: Some(sd),
            estimated: true,
            reason: None,
        }
    };
    let yaw_offsets = theta.rows(2, p - 2);
    SideSlip {
        gradient,
        fitted: g,
        fitted_std: sd,
        scale_residual: theta[1],
        yaw_offset_rad: yaw_offsets.iter().map(|v| v.abs()).fold(0.0, f64::max),
        blocks: n,
        rms_lateral_accel_mps2: rms_ay,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::GnssFix;
    use crate::model::{evolve_slipping, State};
    use crate::vehicle::Vehicle;

    /// A figure-of-eight-like drive: straights, left and right turns at
    /// varying speed, integrated with slip `g`; fixes every 0.1 s at the
    /// antenna with seeded white noise `noise_m`; the smoothed states are
    /// the true ones (yaw along the body, not the course).
    fn drive_with_slip(g: f64, noise_m: f64, turning: bool) -> (Drive, Reference) {
        use rand::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
        let mut vehicle = Vehicle::paper_car();
        vehicle.gnss_lever_arm_m = 1.2;
        let dt = 0.01;
        let mut x = State::from([0.0, 0.0, 0.3, 12.0, 0.0]);
        let (mut ts, mut xs, mut fixes, mut gyro) =
            (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        for k in 0..60_000 {
            let t = k as f64 * dt;
            x[V] = 12.0 + 6.0 * (t / 37.0).sin();
            x[YAW_RATE] = if turning {
                0.25 * (t / 9.0).sin() * (t / 23.0).cos()
            } else {
                // A lane's wander: far below a turn.
                0.003 * (t / 9.0).sin()
            };
            ts.push(t);
            xs.push(x);
            // The rate over [t, t + dt] (the step integrates it), stamped mid-step.
            gyro.push(crate::drive::Scalar {
                t_s: t + 0.5 * dt,
                value: x[YAW_RATE] + 0.002,
            });
            if k % 10 == 0 {
                let gauss = |r: &mut rand_pcg::Pcg64| -> f64 { StandardNormal.sample(r) };
                fixes.push(GnssFix {
                    t_s: t,
                    east_m: x[0] + 1.2 * x[YAW].cos() + noise_m * gauss(&mut rng),
                    north_m: x[1] + 1.2 * x[YAW].sin() + noise_m * gauss(&mut rng),
                    std_m: noise_m.max(0.01),
                    course_deg: None,
                    speed_mps: None,
                });
            }
            x = evolve_slipping(&x, dt, g);
        }
        let mut d = Drive::empty(vehicle);
        d.gnss = fixes;
        d.yaw_rate = gyro;
        (d, Reference::from_states(ts, xs))
    }

    #[test]
    fn the_gradient_is_recovered_from_turns_at_speed() {
        for g in [0.0, 0.004, 0.007] {
            let (d, r) = drive_with_slip(g, 0.3, true);
            let s = estimate(&d, &r, 0.002);
            assert!(s.gradient.estimated, "{:?}", s.gradient);
            let sd = s.gradient.std.unwrap();
            eprintln!(
                "g {g}: {:.6} ± {sd:.6} ({} blocks, s {:.2e}, r {:.2e})",
                s.gradient.value, s.blocks, s.scale_residual, s.yaw_offset_rad
            );
            // Measured on this drive (600 s, 59 blocks, white fixes 0.3 m):
            // g 0 → −5.8e-5, 0.004 → 0.003942, 0.007 → 0.006943, each ± 7.1e-5.
            assert!((s.gradient.value - g).abs() < 3.0 * sd, "{g}: {s:?}");
            assert!(sd < 1e-4, "{s:?}");
            assert!(s.scale_residual.abs() < 1e-3 && s.yaw_offset_rad.abs() < 1e-3);
        }
    }

    #[test]
    fn a_drive_without_turns_does_not_determine_the_gradient() {
        let (d, r) = drive_with_slip(0.005, 0.3, false);
        let s = estimate(&d, &r, 0.002);
        assert!(!s.gradient.estimated, "{s:?}");
        assert!(
            s.gradient
                .reason
                .as_deref()
                .unwrap()
                .contains("turns at speed"),
            "{s:?}"
        );
    }
}
