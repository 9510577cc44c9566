//! The tricycle: one steered, driven front wheel on the centre line, a
//! passive rear axle, a steering encoder and a traction encoder.
//!
//! Between two samples the front wheel travels
//! `ds = Ktraction · Δticks / ticks_per_rev` (signed: reversing is negative
//! ticks) at the wheel angle `φ = Ksteer · 2π·s/counts_per_rev + offset`
//! (`s` the steering encoder read as signed, averaged over the step). The base
//! (rear axle centre) then moves `ds·cos φ` along its heading (taken at the
//! middle of the step) and turns by `ds·sin φ / L`. Nothing divides by
//! `cos φ`: the integration is stable at every steering angle, ±90° (turning
//! on the spot around the rear axle) included.
//!
//! The reference measures a point mounted at `(x, y, ψ)` on the base
//! ([`Pose2`]): the seven parameters are
//! `[ktraction_m, ksteer, steer_offset_rad, axle_length_m, mount_x_m,
//! mount_y_m, mount_yaw_rad]`.

use serde::{Deserialize, Serialize};

use super::{KinematicModel, Pose2, PoseJacobian};
use crate::{DriveFault, Error, Need, Rule, Value};

/// Index of `Ktraction` (metres per traction-encoder revolution).
pub const KTRACTION: usize = 0;
/// Index of `Ksteer` (wheel angle per steering-encoder angle).
pub const KSTEER: usize = 1;
/// Index of the steering offset (wheel angle at encoder zero), rad.
pub const STEER_OFFSET: usize = 2;
/// Index of the axle length (rear axle to front wheel), m.
pub const AXLE: usize = 3;
/// Index of the measured point's x in the base frame, m.
pub const MOUNT_X: usize = 4;
/// Index of the measured point's y in the base frame, m.
pub const MOUNT_Y: usize = 5;
/// Index of the measured point's yaw in the base frame, rad.
pub const MOUNT_YAW: usize = 6;
/// Number of parameters.
pub const N_PARAMS: usize = 7;

/// Parameter names with units, in vector order.
pub const NAMES: [&str; N_PARAMS] = [
    "ktraction_m",
    "ksteer",
    "steer_offset_rad",
    "axle_length_m",
    "mount_x_m",
    "mount_y_m",
    "mount_yaw_rad",
];

/// Thresholds deciding whether a drive can determine a parameter at all
/// (before any fit), and how well a fitted one must be determined. Chosen for
/// robots of the tricycle log's size (1–2 m long, under 1 m/s).
pub mod tuning {
    /// Path the used windows must travel for the traction scale and the
    /// mounting yaw, m.
    pub const MIN_PATH_M: f64 = 1.0;
    /// A window turns when its reference heading changes by this much from
    /// its start to its end, rad (about 6°: far above the tracker's heading
    /// noise of a few mrad).
    pub const MIN_TURN_RAD: f64 = 0.1;
    /// Turning windows needed for the steering parameters, the axle length
    /// and the mounting position.
    pub const MIN_TURNING_WINDOWS: usize = 3;
    /// Spread (standard deviation) of the steering-encoder angle while moving
    /// needed to separate `Ksteer` from the offset, rad.
    pub const MIN_STEER_SPREAD_RAD: f64 = 0.02;
    /// A fitted parameter counts as determined when its standard error is
    /// below these: relative for the scales and the axle length, absolute
    /// for the offset (rad) and the mounting (m, m, rad).
    pub const MAX_REL_STD_SCALE: f64 = 0.05;
    /// Offset tolerance, rad (about 3°).
    pub const MAX_STD_OFFSET_RAD: f64 = 0.05;
    /// Mounting position tolerance, m.
    pub const MAX_STD_MOUNT_M: f64 = 0.2;
    /// Mounting yaw tolerance, rad.
    pub const MAX_STD_MOUNT_YAW_RAD: f64 = 0.05;
}

/// The fixed geometry of the encoders.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TricycleGeometry {
    /// Traction-encoder ticks per revolution (the log's 5000).
    pub ticks_per_rev: u32,
    /// Steering-encoder counts per turn (the log's 8192).
    pub steer_counts_per_rev: u32,
}

/// The seven tricycle parameters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TricycleParams {
    /// Metres the front wheel travels per traction-encoder revolution.
    pub ktraction_m: f64,
    /// Wheel angle per steering-encoder angle.
    pub ksteer: f64,
    /// Wheel angle at steering-encoder zero, rad.
    pub steer_offset_rad: f64,
    /// Rear axle to front wheel, m.
    pub axle_length_m: f64,
    /// Pose of the measured point in the base frame.
    pub mount: Pose2,
}

impl TricycleParams {
    /// The parameter vector, in [`NAMES`] order.
    pub fn to_vec(&self) -> Vec<f64> {
        vec![
            self.ktraction_m,
            self.ksteer,
            self.steer_offset_rad,
            self.axle_length_m,
            self.mount.x_m,
            self.mount.y_m,
            self.mount.yaw_rad,
        ]
    }

    /// From a vector in [`NAMES`] order.
    pub fn from_slice(p: &[f64]) -> Result<TricycleParams, Error> {
        if p.len() != N_PARAMS {
            return Err(Error::param(
                "tricycle parameters",
                Value::Count(p.len()),
                Rule::FiniteCount(N_PARAMS),
            ));
        }
        let t = TricycleParams {
            ktraction_m: p[KTRACTION],
            ksteer: p[KSTEER],
            steer_offset_rad: p[STEER_OFFSET],
            axle_length_m: p[AXLE],
            mount: Pose2::new(p[MOUNT_X], p[MOUNT_Y], p[MOUNT_YAW]),
        };
        t.validate()?;
        Ok(t)
    }

    /// Checks that the parameters are finite and the axle length positive.
    pub fn validate(&self) -> Result<(), Error> {
        if self.to_vec().iter().any(|v| !v.is_finite()) {
            return Err(Error::param(
                "tricycle parameters",
                Value::Numbers(self.to_vec()),
                Rule::Finite,
            ));
        }
        if self.axle_length_m <= 0.0 {
            return Err(Error::param(
                "axle_length_m",
                self.axle_length_m,
                Rule::Positive,
            ));
        }
        Ok(())
    }
}

/// One sample of a tricycle drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TricycleSample {
    /// Time, s.
    pub t_s: f64,
    /// Cumulative traction ticks since the first sample (unwrapped, signed).
    pub ticks: i64,
    /// Steering encoder, read as signed counts (`-counts/2 .. counts/2`).
    pub steer_counts: i64,
    /// The reference pose of the measured point, if measured at this sample.
    pub reference: Option<Pose2>,
}

/// A tricycle drive: geometry, nominal parameters and samples in time order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TricycleDrive {
    /// Encoder geometry.
    pub geometry: TricycleGeometry,
    /// The nominal parameters (the vehicle description).
    pub nominal: TricycleParams,
    /// Samples, strictly increasing in time.
    pub samples: Vec<TricycleSample>,
}

/// What one step contributes: wheel travel, wheel angle and their
/// derivatives with respect to the parameters they depend on.
struct Step {
    ds: f64,
    dds_dktr: f64,
    phi: f64,
    /// dφ/dKsteer (the encoder angle); dφ/doffset is 1.
    dphi_dks: f64,
}

impl TricycleDrive {
    /// Checks the geometry, the parameters and that time strictly increases.
    pub fn validate(&self) -> Result<(), Error> {
        if self.geometry.ticks_per_rev == 0 {
            return Err(Error::vehicle(
                "ticks_per_rev",
                Value::Count(0),
                Rule::Positive,
            ));
        }
        if self.geometry.steer_counts_per_rev < 2 {
            return Err(Error::vehicle(
                "steer_counts_per_rev",
                Value::Count(self.geometry.steer_counts_per_rev as usize),
                Rule::AtLeast {
                    min: 2.0,
                    why: None,
                },
            ));
        }
        self.nominal.validate()?;
        for (i, w) in self.samples.windows(2).enumerate() {
            if w[1].t_s.partial_cmp(&w[0].t_s) != Some(std::cmp::Ordering::Greater) {
                return Err(Error::drive(
                    "tricycle",
                    DriveFault::NotIncreasing {
                        index: i + 1,
                        t_s: w[1].t_s,
                        previous_t_s: w[0].t_s,
                    },
                ));
            }
        }
        Ok(())
    }

    /// The steering-encoder angle of sample `i`, rad.
    pub fn encoder_angle(&self, i: usize) -> f64 {
        std::f64::consts::TAU * self.samples[i].steer_counts as f64
            / f64::from(self.geometry.steer_counts_per_rev)
    }

    /// The samples with `from_s ≤ t < until_s` (drive clock; `None`: open).
    pub fn time_range(&self, from_s: Option<f64>, until_s: Option<f64>) -> TricycleDrive {
        let lo = from_s.unwrap_or(f64::NEG_INFINITY);
        let hi = until_s.unwrap_or(f64::INFINITY);
        TricycleDrive {
            geometry: self.geometry,
            nominal: self.nominal,
            samples: self
                .samples
                .iter()
                .filter(|s| s.t_s >= lo && s.t_s < hi)
                .copied()
                .collect(),
        }
    }

    fn step(&self, p: &[f64], k: usize) -> Step {
        let n = (self.samples[k].ticks - self.samples[k - 1].ticks) as f64;
        let dds_dktr = n / f64::from(self.geometry.ticks_per_rev);
        let e = 0.5 * (self.encoder_angle(k - 1) + self.encoder_angle(k));
        Step {
            ds: p[KTRACTION] * dds_dktr,
            dds_dktr,
            phi: p[KSTEER] * e + p[STEER_OFFSET],
            dphi_dks: e,
        }
    }

    /// Dead reckons the base from `base` at sample `a` to every sample up to
    /// `b`: the base poses of samples `a..=b`.
    pub fn dead_reckon(
        &self,
        params: &TricycleParams,
        base: Pose2,
        a: usize,
        b: usize,
    ) -> Vec<Pose2> {
        let p = params.to_vec();
        let mut pose = base;
        let mut out = vec![pose];
        for k in a + 1..=b.min(self.samples.len().saturating_sub(1)) {
            let st = self.step(&p, k);
            let d = st.ds * st.phi.cos();
            let dpsi = st.ds * st.phi.sin() / p[AXLE];
            let mid = pose.yaw_rad + 0.5 * dpsi;
            pose.x_m += d * mid.cos();
            pose.y_m += d * mid.sin();
            pose.yaw_rad += dpsi;
            out.push(pose);
        }
        out
    }
}

impl TricycleDrive {
    /// The dead-reckoned track of the measured point from the first
    /// reference pose over the whole drive, with the base's signed speed and
    /// yaw rate per step (no covariance: `cov_pose` is NaN), and the
    /// reference as a second track.
    pub fn tracks(&self, params: &TricycleParams) -> Result<Vec<crate::Track>, Error> {
        params.validate()?;
        let Some(a) = self.samples.iter().position(|s| s.reference.is_some()) else {
            return Err(Need::ReferencePoses.into());
        };
        let start = self.samples[a]
            .reference
            .unwrap_or_default()
            .unmount(&params.mount);
        let base = self.dead_reckon(params, start, a, self.samples.len().saturating_sub(1));
        let point = |t_s: f64, p: Pose2, speed_mps: f64, yaw_rate_rps: f64| crate::TrackPoint {
            t_s,
            east_m: p.x_m,
            north_m: p.y_m,
            yaw_rad: crate::angle::wrap(p.yaw_rad),
            speed_mps,
            yaw_rate_rps,
            cov_pose: [f64::NAN; 9],
        };
        let mut dr = Vec::with_capacity(base.len());
        for (k, b) in base.iter().enumerate() {
            let i = a + k;
            let (v, w) = if k == 0 {
                (0.0, 0.0)
            } else {
                let prev = base[k - 1];
                let dt = self.samples[i].t_s - self.samples[i - 1].t_s;
                let dist = (b.x_m - prev.x_m).hypot(b.y_m - prev.y_m);
                let sign = if self.samples[i].ticks >= self.samples[i - 1].ticks {
                    1.0
                } else {
                    -1.0
                };
                (sign * dist / dt, (b.yaw_rad - prev.yaw_rad) / dt)
            };
            dr.push(point(self.samples[i].t_s, b.compose(&params.mount), v, w));
        }
        let reference = self
            .samples
            .iter()
            .filter_map(|s| Some(point(s.t_s, s.reference?, f64::NAN, f64::NAN)))
            .collect();
        Ok(vec![
            crate::Track {
                name: "dead-reckoned".into(),
                points: dr,
                origin: None,
            },
            crate::Track {
                name: "reference".into(),
                points: reference,
                origin: None,
            },
        ])
    }
}

impl KinematicModel for TricycleDrive {
    fn names(&self) -> &'static [&'static str] {
        &NAMES
    }

    fn nominal(&self) -> Vec<f64> {
        self.nominal.to_vec()
    }

    fn bounds(&self) -> Vec<(f64, f64)> {
        use std::f64::consts::FRAC_PI_2;
        let k = self.nominal.ktraction_m.abs();
        vec![
            // A traction scale that flips sign or is 10× off is a broken fit.
            (0.0, 10.0 * k),
            (-50.0, 50.0),
            (-FRAC_PI_2, FRAC_PI_2),
            (0.05, 20.0),
            (-20.0, 20.0),
            (-20.0, 20.0),
            (-std::f64::consts::PI, std::f64::consts::PI),
        ]
    }

    fn determination_tolerance(&self, p: &[f64]) -> Vec<f64> {
        use tuning::*;
        vec![
            MAX_REL_STD_SCALE * p[KTRACTION].abs().max(1e-9),
            MAX_REL_STD_SCALE * p[KSTEER].abs().max(1e-3),
            MAX_STD_OFFSET_RAD,
            MAX_REL_STD_SCALE * p[AXLE].abs().max(0.05),
            MAX_STD_MOUNT_M,
            MAX_STD_MOUNT_M,
            MAX_STD_MOUNT_YAW_RAD,
        ]
    }

    fn len(&self) -> usize {
        self.samples.len()
    }

    fn time(&self, i: usize) -> f64 {
        self.samples[i].t_s
    }

    fn reference(&self, i: usize) -> Option<Pose2> {
        self.samples[i].reference
    }

    fn path_m(&self, a: usize, b: usize) -> f64 {
        let per_tick = self.nominal.ktraction_m.abs() / f64::from(self.geometry.ticks_per_rev);
        (a + 1..=b)
            .map(|k| (self.samples[k].ticks - self.samples[k - 1].ticks).unsigned_abs() as f64)
            .sum::<f64>()
            * per_tick
    }

    fn predict(
        &self,
        p: &[f64],
        start: &Pose2,
        a: usize,
        b: usize,
        jacobian: bool,
    ) -> (Pose2, Option<PoseJacobian>) {
        let m = Pose2::new(p[MOUNT_X], p[MOUNT_Y], p[MOUNT_YAW]);
        let mut pose = start.unmount(&m);
        // J: d(base pose)/d(params), rows x, y, ψ.
        let mut j = PoseJacobian::zeros(N_PARAMS);
        if jacobian {
            // base ψ = ψ_s − m_ψ; base p = p_s − R(ψ)·m.
            let (s, c) = pose.yaw_rad.sin_cos();
            j[(2, MOUNT_YAW)] = -1.0;
            j[(0, MOUNT_X)] = -c;
            j[(0, MOUNT_Y)] = s;
            j[(0, MOUNT_YAW)] = -(s * m.x_m + c * m.y_m);
            j[(1, MOUNT_X)] = -s;
            j[(1, MOUNT_Y)] = -c;
            j[(1, MOUNT_YAW)] = c * m.x_m - s * m.y_m;
        }
        let l = p[AXLE];
        for k in a + 1..=b {
            let st = self.step(p, k);
            let (sphi, cphi) = st.phi.sin_cos();
            let d = st.ds * cphi;
            let dpsi = st.ds * sphi / l;
            let mid = pose.yaw_rad + 0.5 * dpsi;
            let (sm, cm) = mid.sin_cos();
            if jacobian {
                // ∂d and ∂Δψ with respect to each parameter (zero for the mounting).
                let mut dd = [0.0; N_PARAMS];
                let mut ddpsi = [0.0; N_PARAMS];
                dd[KTRACTION] = st.dds_dktr * cphi;
                ddpsi[KTRACTION] = st.dds_dktr * sphi / l;
                dd[KSTEER] = -st.ds * sphi * st.dphi_dks;
                ddpsi[KSTEER] = st.ds * cphi * st.dphi_dks / l;
                dd[STEER_OFFSET] = -st.ds * sphi;
                ddpsi[STEER_OFFSET] = st.ds * cphi / l;
                ddpsi[AXLE] = -dpsi / l;
                for q in 0..N_PARAMS {
                    let dmid = j[(2, q)] + 0.5 * ddpsi[q];
                    j[(0, q)] += dd[q] * cm - d * sm * dmid;
                    j[(1, q)] += dd[q] * sm + d * cm * dmid;
                    j[(2, q)] += ddpsi[q];
                }
            }
            pose.x_m += d * cm;
            pose.y_m += d * sm;
            pose.yaw_rad += dpsi;
        }
        let out = pose.compose(&m);
        if !jacobian {
            return (out, None);
        }
        // measured ψ = ψ_b + m_ψ; measured p = p_b + R(ψ_b)·m.
        let (s, c) = pose.yaw_rad.sin_cos();
        let mut jo = j.clone();
        for q in 0..N_PARAMS {
            // ∂R(ψ)m/∂ψ = (−s·mx − c·my, c·mx − s·my).
            jo[(0, q)] += (-s * m.x_m - c * m.y_m) * j[(2, q)];
            jo[(1, q)] += (c * m.x_m - s * m.y_m) * j[(2, q)];
        }
        jo[(0, MOUNT_X)] += c;
        jo[(0, MOUNT_Y)] -= s;
        jo[(1, MOUNT_X)] += s;
        jo[(1, MOUNT_Y)] += c;
        jo[(2, MOUNT_YAW)] += 1.0;
        (out, Some(jo))
    }

    fn unexcited(&self, windows: &[(usize, usize)], k: usize) -> Option<String> {
        use tuning::*;
        let path: f64 = windows.iter().map(|&(a, b)| self.path_m(a, b)).sum();
        // Windows in which the reference turns clearly (net, start to end:
        // robust to the reference's heading noise, which a sum of |Δψ| over
        // samples would add up).
        let turning = windows
            .iter()
            .filter_map(|&(a, b)| Some((self.reference(a)?, self.reference(b)?)))
            .filter(|(r0, r1)| crate::angle::wrap(r1.yaw_rad - r0.yaw_rad).abs() >= MIN_TURN_RAD)
            .count();
        if path < MIN_PATH_M {
            return Some(format!(
                "the used windows travel {path:.2} m (needs {MIN_PATH_M} m)"
            ));
        }
        let needs_turns = matches!(k, KSTEER | STEER_OFFSET | AXLE | MOUNT_X | MOUNT_Y);
        if needs_turns && turning < MIN_TURNING_WINDOWS {
            return Some(format!(
                "no turns: {turning} of the used windows turn by {MIN_TURN_RAD} rad or more (needs {MIN_TURNING_WINDOWS})"
            ));
        }
        if k == KSTEER {
            let e: Vec<f64> = windows
                .iter()
                .flat_map(|&(a, b)| a + 1..=b)
                .filter(|&i| self.samples[i].ticks != self.samples[i - 1].ticks)
                .map(|i| self.encoder_angle(i))
                .collect();
            let n = e.len().max(1) as f64;
            let mean = e.iter().sum::<f64>() / n;
            let spread = (e.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n).sqrt();
            if spread < MIN_STEER_SPREAD_RAD {
                return Some(format!(
                    "the steering hardly moves while driving (encoder spread {spread:.3} rad, needs {MIN_STEER_SPREAD_RAD} rad)"
                ));
            }
        }
        None
    }
}

#[cfg(test)]
mod tests;
