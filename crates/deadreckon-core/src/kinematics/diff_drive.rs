//! The differential drive (left/right wheels, or the odometry twist they
//! give), calibrated against GNSS positions.
//!
//! Between two odometry samples the base moves `a_v · v̄ · dt` along its
//! heading (taken at the middle of the step) and turns by
//! `(a_ω · ω − b_ω) · dt`, with `v̄` the mean odometry speed (signed:
//! reversing is negative) and `ω` the yaw rate of the chosen [`YawSource`]:
//! the odometry's `(v_R − v_L) / track`, or the gyro averaged over the step.
//! The GNSS antenna sits at `(x, y)` on the base. The five parameters are
//! `[speed_scale, yaw_scale, yaw_bias_rps, antenna_x_m, antenna_y_m]`.
//!
//! GNSS gives positions, not headings, so nothing can start from a reference
//! pose. The calibration ([`calibrate_diff_drive`]) cuts the drive into
//! windows, gives each its own start pose (three nuisance parameters), and
//! fits everything by Levenberg–Marquardt on the antenna positions at the
//! fixes. The outage evaluation ([`evaluate_diff_drive`]) starts each outage
//! from the state of a GNSS-aided filter ([`filter`]: pose, bias, scales and
//! the fixes' slowly wandering error, which it carries into the outage) or,
//! the baseline, from the rigid alignment (closed-form Procrustes) of the
//! preceding dead-reckoned stretch to its fixes — what a user does without a
//! filter — and scores the dead-reckoned antenna against the last hidden fix
//! at or before the outage's end.

use crate::drive::Wheels;
use crate::{Drive, DriveFault, Error, Input, Task};

/// Index of the odometry speed scale.
pub const SPEED_SCALE: usize = 0;
/// Index of the yaw-rate scale.
pub const YAW_SCALE: usize = 1;
/// Index of the yaw-rate bias, rad/s.
pub const YAW_BIAS: usize = 2;
/// Index of the antenna's x on the base, m.
pub const ANTENNA_X: usize = 3;
/// Index of the antenna's y on the base, m.
pub const ANTENNA_Y: usize = 4;
/// Number of parameters.
pub const N_PARAMS: usize = 5;
/// Parameter names with units.
pub const NAMES: [&str; N_PARAMS] = [
    "speed_scale",
    "yaw_scale",
    "yaw_bias_rps",
    "antenna_x_m",
    "antenna_y_m",
];

/// Which yaw rate the dead reckoning integrates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum YawSource {
    /// The odometry's `(v_R − v_L) / track` (skid-steer robots slip in turns).
    Odometry,
    /// The gyro, averaged over each odometry step.
    Gyro,
}

/// Standard errors above which a parameter counts as not determined.
const TOLERANCE: [f64; N_PARAMS] = [0.02, 0.05, 0.005, 0.5, 0.5];

/// d(antenna x, y)/d(parameters): two rows.
type AntennaJacobian = [[f64; N_PARAMS]; 2];
/// A dead-reckoned antenna position in the start frame, its Jacobian and its time.
type LocalPoint = ([f64; 2], AntennaJacobian, f64);

/// One odometry step's inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DiffDriveSample {
    /// Time, s.
    pub t_s: f64,
    /// Forward speed, m/s (signed).
    pub v_mps: f64,
    /// Yaw rate from the chosen source over the step ending here, rad/s.
    pub yaw_rate_rps: f64,
}

/// A differential-drive drive: odometry samples and GNSS fixes (local
/// east/north), in time order.
#[derive(Debug, Clone, PartialEq)]
pub struct DiffDriveDrive {
    /// Odometry samples.
    pub samples: Vec<DiffDriveSample>,
    /// GNSS fixes `(t_s, east_m, north_m)`.
    pub fixes: Vec<(f64, f64, f64)>,
    /// The yaw source the samples carry.
    pub yaw_source: YawSource,
}

impl DiffDriveDrive {
    /// From a drive with wheel speeds (left = `fl`, right = `fr`, as the
    /// odometry readers write them), the gyro if `source` asks for it, and
    /// GNSS; cut to `[from_s, until_s)`.
    pub fn from_drive(
        drive: &Drive,
        source: YawSource,
        from_s: Option<f64>,
        until_s: Option<f64>,
    ) -> Result<DiffDriveDrive, Error> {
        let Wheels::Speeds(w) = &drive.wheels else {
            return Err(Error::drive("wheel_ticks", DriveFault::TicksNotSpeeds));
        };
        let track = drive.vehicle.track_front_m;
        let (lo, hi) = (
            from_s.unwrap_or(f64::NEG_INFINITY),
            until_s.unwrap_or(f64::INFINITY),
        );
        let gyro = &drive.yaw_rate;
        if source == YawSource::Gyro && gyro.is_empty() {
            return Err(Error::needs(Task::GyroYaw, Input::Gyro));
        }
        let mut samples = Vec::new();
        let mut prev_t = f64::NEG_INFINITY;
        for r in w.iter().filter(|r| r.t_s >= lo && r.t_s < hi) {
            let yaw_rate_rps = match source {
                YawSource::Odometry => (r.fr_mps - r.fl_mps) / track,
                YawSource::Gyro => {
                    let a = gyro.partition_point(|g| g.t_s <= prev_t);
                    let b = gyro.partition_point(|g| g.t_s <= r.t_s);
                    if b > a {
                        gyro[a..b].iter().map(|g| g.value).sum::<f64>() / (b - a) as f64
                    } else {
                        gyro[a.min(gyro.len() - 1)].value
                    }
                }
            };
            samples.push(DiffDriveSample {
                t_s: r.t_s,
                v_mps: 0.5 * (r.fl_mps + r.fr_mps),
                yaw_rate_rps,
            });
            prev_t = r.t_s;
        }
        let fixes = drive
            .gnss
            .iter()
            .filter(|g| g.t_s >= lo && g.t_s < hi)
            .map(|g| (g.t_s, g.east_m, g.north_m))
            .collect();
        Ok(DiffDriveDrive {
            samples,
            fixes,
            yaw_source: source,
        })
    }

    /// The nominal parameters: scales 1, no bias, antenna over the axle centre.
    pub fn nominal() -> Vec<f64> {
        vec![1.0, 1.0, 0.0, 0.0, 0.0]
    }

    /// Dead-reckons from the zero pose at sample `a` through sample `b`:
    /// the antenna in the start frame at each sample and, if asked, its
    /// Jacobian (2 × [`N_PARAMS`]) with respect to the parameters.
    fn local_track(
        &self,
        p: &[f64],
        a: usize,
        b: usize,
        jac: bool,
    ) -> Vec<([f64; 2], [[f64; N_PARAMS]; 2], f64)> {
        let (mut x, mut y, mut psi) = (0.0, 0.0, 0.0);
        let mut jx = [0.0; N_PARAMS];
        let mut jy = [0.0; N_PARAMS];
        let mut jpsi = [0.0; N_PARAMS];
        let (mx, my) = (p[ANTENNA_X], p[ANTENNA_Y]);
        let mut out = Vec::with_capacity(b + 1 - a);
        for k in a..=b {
            if k > a {
                let (s0, s1) = (&self.samples[k - 1], &self.samples[k]);
                let dt = s1.t_s - s0.t_s;
                let raw_d = 0.5 * (s0.v_mps + s1.v_mps) * dt;
                let d = p[SPEED_SCALE] * raw_d;
                let dpsi = (p[YAW_SCALE] * s1.yaw_rate_rps - p[YAW_BIAS]) * dt;
                let mid = psi + 0.5 * dpsi;
                let (sm, cm) = mid.sin_cos();
                if jac {
                    let mut dd = [0.0; N_PARAMS];
                    let mut ddpsi = [0.0; N_PARAMS];
                    dd[SPEED_SCALE] = raw_d;
                    ddpsi[YAW_SCALE] = s1.yaw_rate_rps * dt;
                    ddpsi[YAW_BIAS] = -dt;
                    for q in 0..N_PARAMS {
                        let dmid = jpsi[q] + 0.5 * ddpsi[q];
                        jx[q] += dd[q] * cm - d * sm * dmid;
                        jy[q] += dd[q] * sm + d * cm * dmid;
                        jpsi[q] += ddpsi[q];
                    }
                }
                x += d * cm;
                y += d * sm;
                psi += dpsi;
            }
            let (s, c) = psi.sin_cos();
            let ant = [x + c * mx - s * my, y + s * mx + c * my];
            let mut j = [[0.0; N_PARAMS]; 2];
            if jac {
                for q in 0..N_PARAMS {
                    j[0][q] = jx[q] + (-s * mx - c * my) * jpsi[q];
                    j[1][q] = jy[q] + (c * mx - s * my) * jpsi[q];
                }
                j[0][ANTENNA_X] += c;
                j[0][ANTENNA_Y] -= s;
                j[1][ANTENNA_X] += s;
                j[1][ANTENNA_Y] += c;
            }
            out.push((ant, j, self.samples[k].t_s));
        }
        out
    }
}

/// Linear interpolation of a local track (and its Jacobian) at time `t`.
fn at(track: &[LocalPoint], t: f64) -> ([f64; 2], AntennaJacobian) {
    let i = track
        .partition_point(|e| e.2 <= t)
        .clamp(1, track.len().max(2) - 1);
    if track.len() < 2 {
        return (track[0].0, track[0].1);
    }
    let (a, b) = (&track[i - 1], &track[i]);
    let f = ((t - a.2) / (b.2 - a.2)).clamp(0.0, 1.0);
    let mut j = [[0.0; N_PARAMS]; 2];
    for ((row, ra), rb) in j.iter_mut().zip(&a.1).zip(&b.1) {
        for ((v, va), vb) in row.iter_mut().zip(ra).zip(rb) {
            *v = va + f * (vb - va);
        }
    }
    (
        [
            a.0[0] + f * (b.0[0] - a.0[0]),
            a.0[1] + f * (b.0[1] - a.0[1]),
        ],
        j,
    )
}

/// The rigid transform (rotation θ, translation t) minimising
/// `Σ |R(θ)·p + t − q|²` (closed-form Procrustes in the plane), or `None`
/// with fewer than two pairs.
pub fn align(p: &[[f64; 2]], q: &[[f64; 2]]) -> Option<(f64, [f64; 2])> {
    let n = p.len().min(q.len());
    if n < 2 {
        return None;
    }
    let nf = n as f64;
    let (mut pc, mut qc) = ([0.0; 2], [0.0; 2]);
    for i in 0..n {
        for k in 0..2 {
            pc[k] += p[i][k] / nf;
            qc[k] += q[i][k] / nf;
        }
    }
    let (mut sc, mut ss) = (0.0, 0.0);
    for i in 0..n {
        let (a, b) = (
            [p[i][0] - pc[0], p[i][1] - pc[1]],
            [q[i][0] - qc[0], q[i][1] - qc[1]],
        );
        sc += a[0] * b[0] + a[1] * b[1];
        ss += a[0] * b[1] - a[1] * b[0];
    }
    let th = ss.atan2(sc);
    let (s, c) = th.sin_cos();
    Some((
        th,
        [
            qc[0] - (c * pc[0] - s * pc[1]),
            qc[1] - (s * pc[0] + c * pc[1]),
        ],
    ))
}

/// A calibration window: samples `a..=b` and the fixes `fa..fb` inside.
#[derive(Debug, Clone, Copy)]
struct Window {
    a: usize,
    b: usize,
    fa: usize,
    fb: usize,
}

mod calibration;
pub mod filter;
pub mod held_back;
mod outages;

pub use calibration::{calibrate_diff_drive, DiffDriveOptions, NOT_FITTED};
pub use filter::{DiffDriveFilter, FilterNoise};
pub use held_back::{calibrate_held_back, HeldBackParams, JudgedParam};
pub use outages::{evaluate_diff_drive, DiffDriveOutages, OutageStart, DEFAULT_WARMUP_S};

#[cfg(test)]
mod filter_tests;
#[cfg(test)]
mod held_back_tests;
#[cfg(test)]
mod tests;
