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
//! derivative) from x and the centripetal acceleration, speed × (gyro z −
//! its bias), from y. The bias comes from the GNSS course
//! ([`gyro_bias_from_course`]): a phone's raw gyro carries tens of mrad/s
//! (0.068 rad/s on the comma2k19 segment), and left in the centripetal term
//! at 15 m/s it reads as a 6° roll. What is left of a drive's accelerations
//! and road slopes averages out over its one-second blocks; the vertical
//! found is the drive's mean one, its mean grade and bank included.
//!
//! **Standard error**: of each horizontal component of the vertical, in
//! quadrature: the scatter of the one-second block means divided by
//! √blocks (vibration and correlated noise count); the accelerometer's own
//! error, which gravity alone cannot tell from a tilt, taken as large across
//! as it is along the vertical (`| |f| − γ |`, γ the normal gravity at the
//! drive's origin, [`normal_gravity`]); and, driving, the bias's standard
//! error times the mean speed (y only). On comma2k19 the accelerometer reads
//! |f| 0.12 m/s² short, and against the reference's specific force it is
//! (−0.075, +0.076, +0.142) m/s² off in (forward, right, down): the tilt is
//! 3.75° ± 0.77° where the reference's mean vertical in the camera's axes is
//! 3.46° (pitch −3.67° ± 0.77° against −3.22°, roll +0.81° ± 0.73° against
//! +1.24°).
//!
//! **Status**: not estimated without an accelerometer and three-axis gyro,
//! with fewer than [`MIN_BLOCKS`] blocks, without standstill and without a
//! GNSS course to take the gyro bias from (fewer than [`MIN_COURSE_BLOCKS`]
//! blocks of [`COURSE_BLOCK_S`]), when the mean specific force is not gravity
//! (|f| more than [`MAX_GRAVITY_ERROR_MPS2`] from it: units or axes wrong),
//! or when the tilt is above [`MAX_TILT_DEG`] (axes not as documented):
//! rejected, never clamped.

use crate::drive::{Axes, Drive, Scalar};
use crate::series::interp;
use crate::status::Status;

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
/// Largest difference between the mean specific force and gravity accepted,
/// m/s² (more is units or axes wrong, not a sensor's bias).
pub const MAX_GRAVITY_ERROR_MPS2: f64 = 0.5;
/// Slowest GNSS speed at which its course is used for the gyro bias, m/s
/// (the course is noisy below; [`crate::gyro_scale::MIN_SPEED_MPS`]).
pub const COURSE_MIN_SPEED_MPS: f64 = crate::gyro_scale::MIN_SPEED_MPS;
/// Largest time between two courses whose change is used, s.
pub const COURSE_MAX_GAP_S: f64 = 2.0;
/// Block of driving with a course over which one bias is taken, s.
pub const COURSE_BLOCK_S: f64 = 5.0;
/// Fewest such blocks for a gyro bias (and so a tilt while driving).
pub const MIN_COURSE_BLOCKS: usize = 2;

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
    /// Its standard error, rad.
    pub pitch_std_rad: f64,
    /// Left-side-up part: asin(up · y), rad.
    pub roll_rad: f64,
    /// Its standard error, rad.
    pub roll_std_rad: f64,
    /// The part of the x and y components' standard errors from the scatter
    /// of the one-second blocks alone, rad.
    pub std_blocks_rad: [f64; 2],
    /// The mean specific force's magnitude minus normal gravity, m/s²: the
    /// accelerometer's error along the vertical (its error across, the same
    /// size presumably, is in the standard errors).
    pub accel_error_mps2: f64,
    /// While driving: the gyro z bias removed from the centripetal
    /// acceleration (from the GNSS course).
    pub gyro_bias: Option<CourseBias>,
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

/// The mean speed of the present wheels, `(t, m/s)`.
pub(crate) fn wheel_speed(d: &Drive) -> Vec<(f64, f64)> {
    let present: Vec<usize> = (0..4).filter(|&i| d.vehicle.wheels_present[i]).collect();
    if present.is_empty() {
        return Vec::new();
    }
    // From the rows borrowed, not consumed: a collect in place would keep
    // the rows' allocation (40 B a row) under the 16 B ones (issue 30).
    crate::plausibility::wheel_rows(d)
        .iter()
        .map(|&(t, w)| {
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
        pitch_std_rad: f64::NAN,
        roll_rad: f64::NAN,
        roll_std_rad: f64::NAN,
        std_blocks_rad: [f64::NAN; 2],
        accel_error_mps2: f64::NAN,
        gyro_bias: None,
        source: TiltSource::Driving,
        blocks: 0,
        status: Status::NotEstimated(reason),
    }
}

/// The gyro z axis's bias while driving, from the GNSS course.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CourseBias {
    /// Bias, rad/s: the gyro's mean reading minus the course's rate of change.
    pub bias_rps: f64,
    /// Its standard error, rad/s.
    pub std_rps: f64,
    /// Driving time with a course, s.
    pub span_s: f64,
}

/// The bias of `gz` (`(t, rad/s)`, the sensor's z axis, counter-clockwise
/// seen from above) while driving: between consecutive GNSS fixes with a
/// course, at least [`COURSE_MIN_SPEED_MPS`] and at most
/// [`COURSE_MAX_GAP_S`] apart, the gyro's integral against the course change.
/// Summed, the course changes telescope to the course at the ends of each run
/// of fixes, so the course's noise enters once per run. Standard error from
/// the scatter of [`COURSE_BLOCK_S`] blocks; `None` with fewer than
/// [`MIN_COURSE_BLOCKS`] blocks.
pub fn gyro_bias_from_course(drive: &Drive, gz: &[(f64, f64)]) -> Option<CourseBias> {
    if gz.len() < 2 {
        return None;
    }
    let mut cum = Vec::with_capacity(gz.len());
    let mut acc = 0.0;
    cum.push((gz[0].0, 0.0));
    for w in gz.windows(2) {
        acc += 0.5 * (w[0].1 + w[1].1) * (w[1].0 - w[0].0);
        cum.push((w[1].0, acc));
    }
    let v = wheel_speed(drive);
    let fixes: Vec<(f64, f64, f64)> = drive
        .gnss
        .iter()
        .filter_map(|f| {
            let c = f.course_yaw_rad()?;
            let speed = f.speed_mps.or_else(|| interp(&v, f.t_s))?;
            let h = interp(&cum, f.t_s)?;
            (speed >= COURSE_MIN_SPEED_MPS).then_some((f.t_s, c, h))
        })
        .collect();
    // Blocks of (time, gyro integral − course change).
    let mut blocks: Vec<(f64, f64)> = Vec::new();
    let mut cur = (0.0, 0.0);
    for w in fixes.windows(2) {
        let (a, b) = (w[0], w[1]);
        let dt = b.0 - a.0;
        if !(dt > 0.0 && dt <= COURSE_MAX_GAP_S) {
            continue;
        }
        cur.0 += dt;
        cur.1 += (b.2 - a.2) - crate::angle::wrap(b.1 - a.1);
        if cur.0 >= COURSE_BLOCK_S {
            blocks.push(cur);
            cur = (0.0, 0.0);
        }
    }
    if cur.0 > 0.0 {
        match blocks.last_mut() {
            // A short remainder joins the last block.
            Some(last) if cur.0 < 0.5 * COURSE_BLOCK_S => {
                last.0 += cur.0;
                last.1 += cur.1;
            }
            _ => blocks.push(cur),
        }
    }
    let n = blocks.len();
    if n < MIN_COURSE_BLOCKS {
        return None;
    }
    let span: f64 = blocks.iter().map(|b| b.0).sum();
    let bias = blocks.iter().map(|b| b.1).sum::<f64>() / span;
    // The time-weighted mean of the block rates, and its standard error.
    let var = blocks
        .iter()
        .map(|b| (b.1 - bias * b.0).powi(2))
        .sum::<f64>()
        / (span * span)
        * n as f64
        / (n - 1) as f64;
    Some(CourseBias {
        bias_rps: bias,
        std_rps: var.sqrt(),
        span_s: span,
    })
}

/// Normal gravity on the WGS 84 ellipsoid at latitude `lat_deg` and
/// ellipsoidal height `height_m`, m/s²: Somigliana's formula (NIMA TR8350.2,
/// 3rd ed., eq. 4-1, with its constants γe = 9.7803253359 m/s²,
/// k = 0.00193185265241, e² = 0.00669437999013) and the free-air gradient
/// −3.086·10⁻⁶ s⁻² (ibid. eq. 4-3's first-order term).
pub fn normal_gravity(lat_deg: f64, height_m: f64) -> f64 {
    let s2 = lat_deg.to_radians().sin().powi(2);
    9.780_325_335_9 * (1.0 + 0.001_931_852_652_41 * s2) / (1.0 - 0.006_694_379_990_13 * s2).sqrt()
        - 3.086e-6 * height_m
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
    // Samples at standstill, and samples while driving with the forward
    // acceleration removed (and the speed and gyro z rate kept for the
    // centripetal acceleration).
    let mut still: Vec<(f64, [f64; 3])> = Vec::new();
    let mut moving: Vec<(f64, [f64; 3], f64, f64)> = Vec::new();
    for a in acc {
        let (Some(sp), Some(ax), Some(w)) = (interp(&v, a.t_s), accel_x(a.t_s), interp(&wz, a.t_s))
        else {
            continue;
        };
        if sp.abs() < STANDSTILL_MPS && ax.abs() < 0.05 {
            still.push((a.t_s, a.xyz()));
        } else {
            moving.push((a.t_s, [a.x - ax, a.y, a.z], sp, w));
        }
    }
    let span = |t: &[f64]| -> f64 {
        // Time covered: count samples times the median sampling interval.
        if t.len() < 2 {
            return 0.0;
        }
        let mut dt: Vec<f64> = t.windows(2).map(|p| p[1] - p[0]).collect();
        dt.sort_by(f64::total_cmp);
        dt[dt.len() / 2] * t.len() as f64
    };
    let still_t: Vec<f64> = still.iter().map(|s| s.0).collect();
    // The gyro bias enters the centripetal term `speed × (gyro z − bias)`:
    // with a phone's raw gyro (0.07 rad/s on the comma2k19 segment) at
    // 15 m/s, left in, it reads as a 6° roll.
    let (samples, source, bias) = if span(&still_t) >= MIN_STANDSTILL_S {
        (still, TiltSource::Standstill, None)
    } else {
        let Some(b) = gyro_bias_from_course(drive, &wz) else {
            return Some(not_estimated(format!(
                "no standstill of {MIN_STANDSTILL_S} s, and too little driving with a GNSS course \
                 ({MIN_COURSE_BLOCKS} blocks of {COURSE_BLOCK_S} s) to take the gyro's bias from: \
                 the centripetal acceleration cannot be removed"
            )));
        };
        let s = moving
            .iter()
            .map(|&(t, f, sp, w)| (t, [f[0], f[1] - sp * (w - b.bias_rps), f[2]]))
            .collect();
        (s, TiltSource::Driving, Some(b))
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
    let gravity = drive
        .vehicle
        .origin
        .map_or(GRAVITY_MPS2, |o| normal_gravity(o.lat_deg, o.height_m));
    let mean = [0, 1, 2].map(|k| blocks.iter().map(|b| b[k]).sum::<f64>() / nb as f64);
    let norm = mean.iter().map(|c| c * c).sum::<f64>().sqrt();
    if (norm - gravity).abs() > MAX_GRAVITY_ERROR_MPS2 {
        return Some(not_estimated(format!(
            "mean specific force {norm:.2} m/s² is not gravity ({gravity:.2}): accelerometer units or axes wrong"
        )));
    }
    let up = mean.map(|c| c / norm);
    let tilt = up[2].clamp(-1.0, 1.0).acos();
    // Standard errors of the horizontal components of the unit vertical:
    // the scatter of the block means; the accelerometer's own error, which
    // gravity alone cannot tell from a tilt, taken as large as its error
    // along the vertical (|f| against normal gravity); and, driving, the
    // gyro bias's error times the mean speed.
    let accel_error = (norm - gravity).abs() / norm;
    let bias_error = bias.map_or(0.0, |b| {
        let mean_speed = moving.iter().map(|m| m.2.abs()).sum::<f64>() / moving.len() as f64;
        mean_speed * b.std_rps / norm
    });
    let comp = |k: usize| -> f64 {
        let m = up[k];
        let var = blocks
            .iter()
            .map(|b| (b[k] / norm - m).powi(2))
            .sum::<f64>()
            / (nb - 1) as f64;
        var / nb as f64
    };
    let (bx, by) = (comp(0), comp(1));
    let sx = (bx + accel_error.powi(2)).sqrt();
    let sy = (by + accel_error.powi(2) + bias_error.powi(2)).sqrt();
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
    let asin_std = |s: f64, u: f64| s / (1.0 - u * u).sqrt().max(1e-9);
    Some(Tilt {
        up,
        tilt_rad: tilt,
        std_rad: std,
        pitch_rad: up[0].asin(),
        pitch_std_rad: asin_std(sx, up[0]),
        roll_rad: up[1].asin(),
        roll_std_rad: asin_std(sy, up[1]),
        std_blocks_rad: [bx.sqrt(), by.sqrt()],
        accel_error_mps2: norm - gravity,
        gyro_bias: bias,
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
    (levelled(drive, tilt.as_ref()), tilt)
}

/// The drive [`level`] returns with the tilt it estimated, `tilt`: a copy
/// of `drive` with the yaw rate about `tilt`'s vertical when it is
/// estimated, bit for bit [`level`]'s (without estimating the tilt again:
/// [`crate::timing::prepare_with`] makes the levelled drive again rather
/// than hold a copy of it through the GNSS delay's calibrations).
pub fn levelled(drive: &Drive, tilt: Option<&Tilt>) -> Drive {
    let mut d = drive.clone();
    level_in_place(&mut d, tilt);
    d
}

/// [`levelled`] in place (no copy).
pub fn level_in_place(d: &mut Drive, tilt: Option<&Tilt>) {
    if let Some(t) = tilt {
        if t.is_estimated() {
            d.yaw_rate = vertical_rate(&d.imu.gyro, t.up);
        }
    }
}

/// The drive with the yaw rate projected on a known vertical `up` (sensor
/// axes), e.g. a tilt from params.toml; unchanged without three-axis gyro data.
pub fn level_with(drive: &Drive, up: [f64; 3]) -> Drive {
    let mut d = drive.clone();
    level_with_in_place(&mut d, up);
    d
}

/// [`level_with`] in place (no copy).
pub fn level_with_in_place(d: &mut Drive, up: [f64; 3]) {
    if !d.imu.gyro.is_empty() {
        d.yaw_rate = vertical_rate(&d.imu.gyro, up);
    }
}
