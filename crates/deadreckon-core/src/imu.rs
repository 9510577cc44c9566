//! The mounting tilt of a three-axis IMU (a phone on a windshield, an ECU not
//! quite level) and the yaw rate as the angular rate about the vertical.
//!
//! A one-axis yaw-rate gyro mounted with a tilt θ measures `ψ̇·cos θ` plus
//! roll and pitch rates leaking in; with three axes and an accelerometer the
//! vertical can be found in the sensor's own axes from gravity and the angular
//! rate projected on it.
//!
//! **Gravity**: the mean specific force. At standstill (all present wheels
//! below [`STANDSTILL_MPS`] for at least [`MIN_STANDSTILL_S`] in total) it is
//! gravity alone. Without such stops (a highway segment) the vehicle's own
//! acceleration is removed first: the forward acceleration (the wheel speed's
//! derivative) from x and the centripetal acceleration (speed × gyro z rate)
//! from y; what is left of a drive's accelerations and road slopes averages
//! out over its one-second blocks.
//!
//! **Standard error**: the tilt from the block means of one second each
//! (their scatter, divided by √blocks), so vibration and correlated noise count.
//!
//! **Status**: not estimated without an accelerometer and three-axis gyro,
//! with fewer than [`MIN_BLOCKS`] blocks, when the mean specific force is not
//! gravity (|f| outside 9.81 ± 0.5 m/s²: units or axes wrong), or when the
//! tilt is above [`MAX_TILT_DEG`] (axes not as documented): rejected, never
//! clamped.

use crate::drive::{Axes, Drive, Scalar};
use crate::timing::Status;

/// Standard gravity, m/s².
pub const GRAVITY_MPS2: f64 = 9.80665;
/// Wheel speed below which the vehicle stands still, m/s.
pub const STANDSTILL_MPS: f64 = 0.05;
/// Standstill time needed to use standstill only, s.
pub const MIN_STANDSTILL_S: f64 = 2.0;
/// Fewest one-second blocks for an estimate.
pub const MIN_BLOCKS: usize = 5;
/// Largest tilt accepted, degrees.
pub const MAX_TILT_DEG: f64 = 30.0;

/// Where the gravity estimate came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TiltSource {
    /// Specific force while standing still.
    Standstill,
    /// Specific force while driving, minus the wheel-derived acceleration.
    Driving,
}

impl TiltSource {
    /// `standstill` or `driving`.
    pub fn name(self) -> &'static str {
        match self {
            TiltSource::Standstill => "standstill",
            TiltSource::Driving => "driving",
        }
    }
}

/// The estimated tilt of the IMU.
#[derive(Debug, Clone, PartialEq)]
pub struct Tilt {
    /// The unit vertical (up) in the sensor's axes.
    pub up: [f64; 3],
    /// Angle between the sensor's z axis and the vertical, rad.
    pub tilt_rad: f64,
    /// Its standard error, rad.
    pub std_rad: f64,
    /// Nose-up part: asin(up · x), rad.
    pub pitch_rad: f64,
    /// Left-side-up part: asin(up · y), rad.
    pub roll_rad: f64,
    /// Standstill or driving.
    pub source: TiltSource,
    /// One-second blocks used.
    pub blocks: usize,
    /// Estimated, or why not.
    pub status: Status,
}

impl Tilt {
    /// True when estimated (and so applied).
    pub fn is_estimated(&self) -> bool {
        self.status.is_estimated()
    }
}

/// Linear interpolation of `(t, v)` samples sorted by time; `None` outside.
pub(crate) fn interp(s: &[(f64, f64)], t: f64) -> Option<f64> {
    let n = s.len();
    if n == 0 || !(t >= s[0].0 && t <= s[n - 1].0) {
        return None;
    }
    let i = s.partition_point(|p| p.0 <= t);
    if i >= n {
        return Some(s[n - 1].1);
    }
    let i = i.max(1);
    let (a, b) = (s[i - 1], s[i]);
    let w = if b.0 > a.0 {
        (t - a.0) / (b.0 - a.0)
    } else {
        0.0
    };
    Some(a.1 * (1.0 - w) + b.1 * w)
}

/// The mean speed of the present wheels, `(t, m/s)`.
pub(crate) fn wheel_speed(d: &Drive) -> Vec<(f64, f64)> {
    let present: Vec<usize> = (0..4).filter(|&i| d.vehicle.wheels_present[i]).collect();
    if present.is_empty() {
        return Vec::new();
    }
    crate::plausibility::wheel_rows(d)
        .into_iter()
        .map(|(t, w)| {
            (
                t,
                present.iter().map(|&i| w[i]).sum::<f64>() / present.len() as f64,
            )
        })
        .collect()
}

fn not_estimated(reason: String) -> Tilt {
    Tilt {
        up: [0.0, 0.0, 1.0],
        tilt_rad: f64::NAN,
        std_rad: f64::NAN,
        pitch_rad: f64::NAN,
        roll_rad: f64::NAN,
        source: TiltSource::Driving,
        blocks: 0,
        status: Status::NotEstimated(reason),
    }
}

/// Estimates the IMU's tilt; `None` when the drive has no accelerometer and
/// three-axis gyro.
pub fn estimate_tilt(drive: &Drive) -> Option<Tilt> {
    let (acc, gyr) = (&drive.imu.accel, &drive.imu.gyro);
    if acc.is_empty() || gyr.is_empty() {
        return None;
    }
    let v = wheel_speed(drive);
    if v.len() < 3 {
        return Some(not_estimated("too few wheel epochs".into()));
    }
    let wz: Vec<(f64, f64)> = gyr.iter().map(|g| (g.t_s, g.z)).collect();
    // Forward acceleration: the wheel speed's difference over ±0.25 s.
    let accel_x = |t: f64| -> Option<f64> {
        let h = 0.25;
        Some((interp(&v, t + h)? - interp(&v, t - h)?) / (2.0 * h))
    };
    // Samples at standstill, and samples while driving with the vehicle's
    // acceleration removed.
    let mut still: Vec<(f64, [f64; 3])> = Vec::new();
    let mut moving: Vec<(f64, [f64; 3])> = Vec::new();
    for a in acc {
        let (Some(sp), Some(ax), Some(w)) = (interp(&v, a.t_s), accel_x(a.t_s), interp(&wz, a.t_s))
        else {
            continue;
        };
        if sp.abs() < STANDSTILL_MPS && ax.abs() < 0.05 {
            still.push((a.t_s, a.xyz()));
        } else {
            moving.push((a.t_s, [a.x - ax, a.y - sp * w, a.z]));
        }
    }
    let span = |s: &[(f64, [f64; 3])]| -> f64 {
        // Time covered: count samples times the median sampling interval.
        if s.len() < 2 {
            return 0.0;
        }
        let mut dt: Vec<f64> = s.windows(2).map(|p| p[1].0 - p[0].0).collect();
        dt.sort_by(f64::total_cmp);
        dt[dt.len() / 2] * s.len() as f64
    };
    let (samples, source) = if span(&still) >= MIN_STANDSTILL_S {
        (still, TiltSource::Standstill)
    } else {
        (moving, TiltSource::Driving)
    };
    // One-second block means.
    let mut blocks: Vec<[f64; 3]> = Vec::new();
    let mut i = 0;
    while i < samples.len() {
        let t0 = samples[i].0;
        let mut sum = [0.0; 3];
        let mut n = 0usize;
        while i < samples.len() && samples[i].0 < t0 + 1.0 {
            for (s, v) in sum.iter_mut().zip(samples[i].1) {
                *s += v;
            }
            n += 1;
            i += 1;
        }
        if n >= 5 {
            blocks.push(sum.map(|s| s / n as f64));
        }
    }
    let nb = blocks.len();
    if nb < MIN_BLOCKS {
        return Some(not_estimated(format!(
            "{nb} one-second blocks of accelerometer data, need {MIN_BLOCKS}"
        )));
    }
    let mean = [0, 1, 2].map(|k| blocks.iter().map(|b| b[k]).sum::<f64>() / nb as f64);
    let norm = mean.iter().map(|c| c * c).sum::<f64>().sqrt();
    if (norm - GRAVITY_MPS2).abs() > 0.5 {
        return Some(not_estimated(format!(
            "mean specific force {norm:.2} m/s² is not gravity (9.81): accelerometer units or axes wrong"
        )));
    }
    let up = mean.map(|c| c / norm);
    let tilt = up[2].clamp(-1.0, 1.0).acos();
    // Standard errors of the horizontal components of the unit vertical, from
    // the scatter of the block means.
    let comp = |k: usize| -> f64 {
        let m = up[k];
        let var = blocks
            .iter()
            .map(|b| (b[k] / norm - m).powi(2))
            .sum::<f64>()
            / (nb - 1) as f64;
        (var / nb as f64).sqrt()
    };
    let (sx, sy) = (comp(0), comp(1));
    let h = (up[0] * up[0] + up[1] * up[1]).sqrt();
    let std = if h > 1e-12 {
        ((up[0] * sx).powi(2) + (up[1] * sy).powi(2)).sqrt() / h / up[2].abs().max(1e-9)
    } else {
        // At zero tilt the angle's error is the length of the component errors.
        (sx * sx + sy * sy).sqrt()
    };
    let status = if tilt.to_degrees() > MAX_TILT_DEG {
        Status::NotEstimated(format!(
            "tilt {:.1}° above {MAX_TILT_DEG}°: the sensor's axes are not x forward, y left, z up",
            tilt.to_degrees()
        ))
    } else {
        Status::Estimated
    };
    Some(Tilt {
        up,
        tilt_rad: tilt,
        std_rad: std,
        pitch_rad: up[0].asin(),
        roll_rad: up[1].asin(),
        source,
        blocks: nb,
        status,
    })
}

/// The angular rate about the vertical `up` (sensor axes): the yaw rate a
/// level gyro would measure, bias included.
pub fn vertical_rate(gyro: &[Axes], up: [f64; 3]) -> Vec<Scalar> {
    gyro.iter()
        .map(|g| Scalar {
            t_s: g.t_s,
            value: g.x * up[0] + g.y * up[1] + g.z * up[2],
        })
        .collect()
}

/// The drive with its yaw rate replaced by the angular rate about the
/// estimated vertical when the tilt is estimated, and the tilt (`None`
/// without three-axis IMU data). An unestimated tilt leaves the drive as it is.
pub fn level(drive: &Drive) -> (Drive, Option<Tilt>) {
    let tilt = estimate_tilt(drive);
    let mut d = drive.clone();
    if let Some(t) = &tilt {
        if t.is_estimated() {
            d.yaw_rate = vertical_rate(&drive.imu.gyro, t.up);
        }
    }
    (d, tilt)
}

/// The drive with the yaw rate projected on a known vertical `up` (sensor
/// axes), e.g. a tilt from params.toml; unchanged without three-axis gyro data.
pub fn level_with(drive: &Drive, up: [f64; 3]) -> Drive {
    let mut d = drive.clone();
    if !drive.imu.gyro.is_empty() {
        d.yaw_rate = vertical_rate(&drive.imu.gyro, up);
    }
    d
}
