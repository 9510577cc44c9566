//! comma2k19 segments: `processed_log/` streams and the `global_pose/`
//! reference trajectory (every stream a pair of extension-less NumPy files `t`
//! and `value`, times in seconds of device boot, one clock for all).
//!
//! | drive stream | source | conversion |
//! |---|---|---|
//! | `wheels` (speeds) | `CAN/wheel_speed` `[fl, fr, rl, rr]` m/s | none |
//! | `speed` | [`SpeedSource`]: by default the car's SPEED message (0xB4) in `CAN/raw_can`, or `CAN/speed` | km/h → m/s |
//! | `steering` | `CAN/steering_angle`, degrees | → rad |
//! | `yaw_rate` | [`GyroSource`]: by default `IMU/gyro_uncalibrated`, axes `[forward, right, down]` | CCW yaw rate = −gyro\[2\] |
//! | `imu.gyro` | the same gyro stream, three axes | `[forward, right, down]` → `[x forward, y left, z up]`: (g0, −g1, −g2) |
//! | `imu.accel` | `IMU/accelerometer`, m/s², axes `[forward, right, down]` | → `[x forward, y left, z up]`: (a0, −a1, −a2) |
//! | `gnss` | `GNSS/live_gnss_ublox` `[lat, lon, speed, utc_ms, alt, bearing]` | WGS84 → east/north about the origin; time − latency (default 0: log time) |
//! | `truth` | `global_pose/frame_*`: ECEF position, ECEF velocity, quaternion `[w, x, y, z]` rotating device `[forward, right, down]` axes into ECEF | ECEF → ENU; yaw of the forward axis; speed: the horizontal velocity along the horizontal heading; moved back to the rear axle |
//!
//! Decisions (also written into the [`ImportReport`] notes):
//!
//! - **Gyro**: both `gyro` and `gyro_uncalibrated` exist. `gyro` has Android's
//!   running bias estimate removed (`gyro = gyro_uncalibrated − gyro_bias`,
//!   about 0.068 rad/s on the yaw axis of this segment). The drive's yaw-rate
//!   stream is the *raw* gyro, bias included, because calibration estimates the
//!   bias itself; so `gyro_uncalibrated` is the default.
//! - **Speed**: `processed_log/CAN/speed` is not an independent sensor: it is
//!   the mean of the four wheel speeds (same timestamps, equal to 1e-12). The
//!   car's own vehicle-speed message SPEED (0xB4, 41.7 Hz) is, and it carries
//!   the speedometer scale error that calibration estimates (`a_v`), so it is
//!   the default; it is decoded from `raw_can` with the built-in DBC subset.
//! - **Truth point**: `global_pose` is the pose of the device (camera) at the
//!   top of the windshield. The truth is moved back to the rear-axle centre by
//!   [`Comma2k19Options::device_forward_m`] along the horizontal forward axis
//!   (default [`crate::profiles::RAV4_DEVICE_FORWARD_M`], an estimate).
//! - **Truth yaw**: the device's forward axis projected on the local level
//!   plane, minus the camera mount's constant yaw offset: the mean difference
//!   between that axis and the velocity heading while moving faster than 2 m/s
//!   (0.90° on this segment). Uncorrected, a dead reckoning started from the
//!   truth yaw drifts sideways by 1.6 m per 100 m.
//! - **GNSS time**: a u-blox fix is logged about 0.1 s after the instant it
//!   describes: against the reference, the RMS position difference is 1.47 m
//!   with the log time and 0.55 m with the time moved back by 0.1 s. The
//!   importer does **not** correct this: the default
//!   [`Comma2k19Options::gnss_latency_s`] is 0 (fixes at their log time), and
//!   the tool estimates the delay from the data ([`deadreckon_core::timing`]).
//!   A known latency can still be given here.
//! - **IMU**: the phone's gyro (the chosen [`GyroSource`]) and accelerometer
//!   are also kept as three-axis streams ([`deadreckon_core::drive::Imu`]), so
//!   that the phone's mounting tilt can be estimated from gravity and the
//!   angular rate projected on the vertical ([`deadreckon_core::imu`]); the
//!   drive's `yaw_rate` stays the phone's own down axis, as read.
//! - **GNSS accuracy**: `live_gnss_ublox` carries no accuracy. `std_m` is
//!   [`Comma2k19Options::gnss_std_m`], default 1.0 m (the RMS difference to the
//!   reference above is 0.55 m; 1 m leaves room for worse sky).
//! - **Origin**: `vehicle.origin` if set, else the first u-blox fix; the
//!   origin's altitude is the first fix's. The drive's vehicle gets that origin.

use std::path::{Path, PathBuf};

use deadreckon_core::drive::{Axes, GnssFix, Imu, Scalar, TruthPose, WheelSpeeds, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::{Drive, Vehicle};

use crate::can::{dbc::Database, raw_can::read_raw_can};
use crate::npy::{read_npy, NpyArray};
use crate::stream::{Reject, StreamBuilder};
use crate::{profiles, Import, ImportError, ImportReport, TimeOrderPolicy};

/// Which gyro stream feeds the drive's yaw rate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GyroSource {
    /// `IMU/gyro_uncalibrated`: raw, bias included (the default).
    #[default]
    Uncalibrated,
    /// `IMU/gyro`: Android's bias estimate removed.
    Calibrated,
}

/// Which vehicle speed feeds the drive's speed stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SpeedSource {
    /// The SPEED message (0xB4) decoded from `CAN/raw_can` (the default).
    #[default]
    CanSpeedMessage,
    /// `CAN/speed` (the mean of the four wheel speeds).
    Processed,
}

/// Options of [`read_comma2k19_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct Comma2k19Options {
    /// The vehicle (default: [`profiles::toyota_rav4`]); its origin, if set, is used.
    pub vehicle: Option<Vehicle>,
    /// Gyro stream.
    pub gyro: GyroSource,
    /// Speed stream.
    pub speed: SpeedSource,
    /// Forward distance from the rear-axle centre to the device whose pose
    /// `global_pose` gives, m (default [`profiles::RAV4_DEVICE_FORWARD_M`]).
    pub device_forward_m: f64,
    /// Delay between a u-blox fix's instant and its log time, s (default 0:
    /// the tool estimates it, see [`deadreckon_core::timing`]).
    pub gnss_latency_s: f64,
    /// Standard deviation given to every u-blox fix, m (default 1.0).
    pub gnss_std_m: f64,
    /// What to do with unsorted, duplicate or non-finite samples.
    pub policy: TimeOrderPolicy,
}

impl Default for Comma2k19Options {
    fn default() -> Self {
        Comma2k19Options {
            vehicle: None,
            gyro: GyroSource::default(),
            speed: SpeedSource::default(),
            device_forward_m: profiles::RAV4_DEVICE_FORWARD_M,
            gnss_latency_s: 0.0,
            gnss_std_m: 1.0,
            policy: TimeOrderPolicy::Error,
        }
    }
}

/// Reads the segment in `dir` with the default options and `vehicle` (the
/// RAV4 profile when `None`).
pub fn read_comma2k19(dir: &Path, vehicle: Option<Vehicle>) -> Result<Drive, ImportError> {
    read_comma2k19_with(
        dir,
        &Comma2k19Options {
            vehicle,
            ..Default::default()
        },
    )
    .map(|i| i.drive)
}

/// One `t`/`value` pair of a stream directory.
struct Pair {
    dir: PathBuf,
    t: Vec<f64>,
    value: NpyArray,
}

impl Pair {
    fn read(dir: PathBuf) -> Result<Pair, ImportError> {
        let tp = dir.join("t");
        let t = read_npy(&tp)?.f64_vector(&tp)?;
        let value = read_npy(&dir.join("value"))?;
        if value.rows() != t.len() {
            return Err(ImportError::Stream {
                path: dir.clone(),
                stream: dir.display().to_string(),
                index: value.rows().min(t.len()),
                t_s: f64::NAN,
                message: format!("`value` has {} rows, `t` has {}", value.rows(), t.len()),
            });
        }
        Ok(Pair { dir, t, value })
    }

    fn value_path(&self) -> PathBuf {
        self.dir.join("value")
    }
}

fn invalid(path: &Path, source: deadreckon_core::Error) -> ImportError {
    ImportError::Invalid {
        path: path.to_path_buf(),
        source,
    }
}

/// Reads the segment in `dir`.
pub fn read_comma2k19_with(dir: &Path, o: &Comma2k19Options) -> Result<Import, ImportError> {
    let mut vehicle = o.vehicle.clone().unwrap_or_else(profiles::toyota_rav4);
    vehicle.validate().map_err(|e| invalid(dir, e))?;
    for (k, v) in [
        ("device_forward_m", o.device_forward_m),
        ("gnss_latency_s", o.gnss_latency_s),
    ] {
        if !v.is_finite() {
            return Err(invalid(
                dir,
                deadreckon_core::Error::param(k, v, deadreckon_core::Rule::Finite),
            ));
        }
    }
    if !(o.gnss_std_m.is_finite() && o.gnss_std_m > 0.0) {
        return Err(invalid(
            dir,
            deadreckon_core::Error::param(
                "gnss_std_m",
                o.gnss_std_m,
                deadreckon_core::Rule::Positive,
            ),
        ));
    }
    let mut report = ImportReport {
        format: "comma2k19".into(),
        ..Default::default()
    };
    let log = dir.join("processed_log");

    // Wheel speeds.
    let ws = Pair::read(log.join("CAN/wheel_speed"))?;
    let rows = ws.value.f64_rows::<4>(&ws.value_path())?;
    let mut b = StreamBuilder::new("wheel_speeds", &ws.dir, o.policy);
    for (i, (&t, v)) in ws.t.iter().zip(&rows).enumerate() {
        let s = WheelSpeeds {
            t_s: t,
            fl_mps: v[0],
            fr_mps: v[1],
            rl_mps: v[2],
            rr_mps: v[3],
        };
        b.push(i, t, v, s)?;
    }
    let (wheel_speeds, r) = b.finish(|s| s.t_s);
    report.streams.push(r);

    // Vehicle speed.
    let speed = match o.speed {
        SpeedSource::Processed => {
            let p = Pair::read(log.join("CAN/speed"))?;
            let v = p.value.f64_vector(&p.value_path())?;
            scalar_stream("speed", &p.dir, &p.t, &v, 1.0, o.policy, &mut report)?
        }
        SpeedSource::CanSpeedMessage => {
            let rc = log.join("CAN/raw_can");
            let frames = read_raw_can(&rc)?;
            let db = Database::parse(
                crate::can::TOYOTA_RAV4_DBC,
                Path::new("toyota_rav4_subset.dbc"),
            )?;
            let msg = db
                .message("SPEED")
                .and_then(|m| m.signal("SPEED").map(|s| (m.id, s.clone())));
            let Some((id, sig)) = msg else {
                return Err(ImportError::Dbc {
                    path: "toyota_rav4_subset.dbc".into(),
                    message: "no SPEED.SPEED".into(),
                });
            };
            let mut b = StreamBuilder::new("speed", &rc, o.policy);
            for (i, f) in frames
                .iter()
                .enumerate()
                .filter(|(_, f)| f.bus == "0" && f.id == id && !f.extended)
            {
                match sig.decode(&f.data) {
                    Some(kph) => {
                        let v = kph / 3.6;
                        b.push(
                            i,
                            f.t_s,
                            &[v],
                            Scalar {
                                t_s: f.t_s,
                                value: v,
                            },
                        )?;
                    }
                    None => b.reject(i, f.t_s, Reject::Invalid("SPEED frame too short".into()))?,
                }
            }
            let (v, r) = b.finish(|s| s.t_s);
            report.streams.push(r);
            v
        }
    };
    report.notes.push(match o.speed {
        SpeedSource::CanSpeedMessage => {
            "speed: SPEED (0xB4, bus 0) from CAN/raw_can, km/h / 3.6".into()
        }
        SpeedSource::Processed => "speed: CAN/speed (the mean of the four wheel speeds)".into(),
    });

    // Steering wheel angle.
    let st = Pair::read(log.join("CAN/steering_angle"))?;
    let v = st.value.f64_vector(&st.value_path())?;
    let steering = scalar_stream(
        "steering",
        &st.dir,
        &st.t,
        &v,
        std::f64::consts::PI / 180.0,
        o.policy,
        &mut report,
    )?;

    // Gyro.
    let gyro_dir = match o.gyro {
        GyroSource::Uncalibrated => "IMU/gyro_uncalibrated",
        GyroSource::Calibrated => "IMU/gyro",
    };
    let g = Pair::read(log.join(gyro_dir))?;
    let axes = g.value.f64_rows::<3>(&g.value_path())?;
    let down: Vec<f64> = axes.iter().map(|a| a[2]).collect();
    let yaw_rate = scalar_stream("yaw_rate", &g.dir, &g.t, &down, -1.0, o.policy, &mut report)?;
    report.notes.push(format!(
        "yaw_rate: -{gyro_dir}[2] (axes forward, right, down), bias not removed by the import"
    ));
    let imu_gyro = axes_stream("imu_gyro", &g.dir, &g.t, &axes, o.policy, &mut report)?;
    let ac = Pair::read(log.join("IMU/accelerometer"))?;
    let acc = ac.value.f64_rows::<3>(&ac.value_path())?;
    let imu_accel = axes_stream("imu_accel", &ac.dir, &ac.t, &acc, o.policy, &mut report)?;
    report.notes.push(format!(
        "imu: {gyro_dir} and IMU/accelerometer as three axes [forward, left, up] = (v0, -v1, -v2)"
    ));

    // GNSS and origin.
    let gn = Pair::read(log.join("GNSS/live_gnss_ublox"))?;
    let fixes = gn.value.f64_rows::<6>(&gn.value_path())?;
    let first_fix = fixes
        .iter()
        .find(|f| f[0].is_finite() && f[1].is_finite() && f[4].is_finite());
    let first_alt = first_fix.map_or(0.0, |f| f[4]);
    // The frame is the tangent plane at the origin at its height: a given
    // origin's, or (given without one, or taken from it) the first fix's.
    let origin = match (vehicle.origin, first_fix) {
        (Some(o), _) if o.height_m != 0.0 => o,
        (Some(o), _) => Origin {
            height_m: first_alt,
            ..o
        },
        (None, Some(f)) => Origin {
            lat_deg: f[0],
            lon_deg: f[1],
            height_m: f[4],
        },
        (None, None) => {
            return Err(ImportError::Stream {
                path: gn.dir.clone(),
                stream: "gnss".into(),
                index: 0,
                t_s: f64::NAN,
                message: "no finite u-blox fix to take the origin from (set vehicle.origin)".into(),
            })
        }
    };
    vehicle.origin = Some(origin);
    let alt0 = origin.height_m;
    let (lat0, lon0) = (origin.lat_deg.to_radians(), origin.lon_deg.to_radians());
    report.notes.push(format!(
        "origin: lat {:.8} lon {:.8} (altitude {alt0:.2} m above the WGS84 ellipsoid)",
        origin.lat_deg, origin.lon_deg
    ));
    let mut b = StreamBuilder::new("gnss", &gn.dir, o.policy);
    for (i, (&t_log, f)) in gn.t.iter().zip(&fixes).enumerate() {
        let [lat, lon, speed, _utc_ms, alt, bearing] = *f;
        let t = t_log - o.gnss_latency_s;
        let (e, n, _u) = map_3d::geodetic2enu(
            lat.to_radians(),
            lon.to_radians(),
            alt,
            lat0,
            lon0,
            alt0,
            map_3d::Ellipsoid::WGS84,
        );
        let fix = GnssFix {
            t_s: t,
            east_m: e,
            north_m: n,
            std_m: o.gnss_std_m,
            course_deg: Some(bearing),
            speed_mps: Some(speed),
        };
        b.push(i, t, &[e, n, speed, bearing], fix)?;
    }
    let (gnss, r) = b.finish(|s| s.t_s);
    report.streams.push(r);
    report.notes.push(format!(
        "gnss: live_gnss_ublox, time = log time - {} s latency, std_m = {} (u-blox gives none)",
        o.gnss_latency_s, o.gnss_std_m
    ));

    // Truth.
    let (truth, yaw_minus_course) = read_truth(dir, lat0, lon0, alt0, o, &mut report)?;
    report.notes.push(format!(
        "truth: global_pose device pose moved back {} m along the forward axis to the rear axle; \
         yaw from the device forward axis minus the camera mount's yaw offset (mean device yaw - velocity heading while moving: {:.2} deg, removed)",
        o.device_forward_m,
        yaw_minus_course.to_degrees()
    ));

    let drive = Drive {
        vehicle,
        wheels: Wheels::Speeds(wheel_speeds),
        yaw_rate,
        speed,
        steering,
        gnss,
        truth,
        imu: Imu {
            gyro: imu_gyro,
            accel: imu_accel,
        },
    };
    Import::checked(drive, report, dir)
}

/// A three-axis stream in `[forward, right, down]` axes as `[forward, left, up]`.
fn axes_stream(
    name: &'static str,
    dir: &Path,
    t: &[f64],
    v: &[[f64; 3]],
    policy: TimeOrderPolicy,
    report: &mut ImportReport,
) -> Result<Vec<Axes>, ImportError> {
    let mut b = StreamBuilder::new(name, dir, policy);
    for (i, (&t, a)) in t.iter().zip(v).enumerate() {
        let s = Axes {
            t_s: t,
            x: a[0],
            y: -a[1],
            z: -a[2],
        };
        b.push(i, t, a, s)?;
    }
    let (v, r) = b.finish(|s| s.t_s);
    report.streams.push(r);
    Ok(v)
}

fn scalar_stream(
    name: &'static str,
    dir: &Path,
    t: &[f64],
    v: &[f64],
    scale: f64,
    policy: TimeOrderPolicy,
    report: &mut ImportReport,
) -> Result<Vec<Scalar>, ImportError> {
    let mut b = StreamBuilder::new(name, dir, policy);
    for (i, (&t, &x)) in t.iter().zip(v).enumerate() {
        let value = x * scale;
        b.push(i, t, &[value], Scalar { t_s: t, value })?;
    }
    let (v, r) = b.finish(|s| s.t_s);
    report.streams.push(r);
    Ok(v)
}

/// Rotation matrix (row-major) of the unit quaternion `[w, x, y, z]`, or `None`
/// if it is not finite or far from unit norm.
fn rotation(q: [f64; 4]) -> Option<[[f64; 3]; 3]> {
    let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
    if !n.is_finite() || (n - 1.0).abs() > 0.01 {
        return None;
    }
    let [w, x, y, z] = q.map(|c| c / n);
    Some([
        [
            1.0 - 2.0 * (y * y + z * z),
            2.0 * (x * y - z * w),
            2.0 * (x * z + y * w),
        ],
        [
            2.0 * (x * y + z * w),
            1.0 - 2.0 * (x * x + z * z),
            2.0 * (y * z - x * w),
        ],
        [
            2.0 * (x * z - y * w),
            2.0 * (y * z + x * w),
            1.0 - 2.0 * (x * x + y * y),
        ],
    ])
}

/// The truth poses and the mean (device yaw − velocity heading), rad.
fn read_truth(
    dir: &Path,
    lat0: f64,
    lon0: f64,
    alt0: f64,
    o: &Comma2k19Options,
    report: &mut ImportReport,
) -> Result<(Vec<TruthPose>, f64), ImportError> {
    let gp = dir.join("global_pose");
    let load = |name: &str| {
        let p = gp.join(name);
        read_npy(&p).map(|a| (a, p))
    };
    let (a, p) = load("frame_times")?;
    let times = a.f64_vector(&p)?;
    let (a, p) = load("frame_positions")?;
    let pos = a.f64_rows::<3>(&p)?;
    let (a, p) = load("frame_orientations")?;
    let quat = a.f64_rows::<4>(&p)?;
    let (a, p) = load("frame_velocities")?;
    let vel = a.f64_rows::<3>(&p)?;
    for (name, len) in [
        ("frame_positions", pos.len()),
        ("frame_orientations", quat.len()),
        ("frame_velocities", vel.len()),
    ] {
        if len != times.len() {
            return Err(ImportError::Stream {
                path: gp.join(name),
                stream: "truth".into(),
                index: len.min(times.len()),
                t_s: f64::NAN,
                message: format!("{len} rows, frame_times has {}", times.len()),
            });
        }
    }
    let mut b = StreamBuilder::new("truth", &gp, o.policy);
    let (mut diff_sum, mut diff_n) = (0.0, 0usize);
    for (i, (((&t, p), q), v)) in times.iter().zip(&pos).zip(&quat).zip(&vel).enumerate() {
        let Some(r) = rotation(*q) else {
            b.reject(
                i,
                t,
                Reject::Invalid(format!("orientation {q:?} is not a unit quaternion")),
            )?;
            continue;
        };
        let (e, n, _u) =
            map_3d::ecef2enu(p[0], p[1], p[2], lat0, lon0, alt0, map_3d::Ellipsoid::WGS84);
        let (fe, fn_, _fu) = map_3d::uvw2enu(r[0][0], r[1][0], r[2][0], lat0, lon0);
        let h = fe.hypot(fn_);
        if h < 0.5 {
            b.reject(
                i,
                t,
                Reject::Invalid("device forward axis is closer to vertical than to level".into()),
            )?;
            continue;
        }
        let yaw = fn_.atan2(fe);
        let (ve, vn, _vu) = map_3d::uvw2enu(v[0], v[1], v[2], lat0, lon0);
        // The horizontal speed along the horizontal heading: the track is
        // two-dimensional. (Along the device's own forward axis, tipped down
        // 3–4° on this segment, it read 0.17 % slow.)
        let speed = (ve * fe + vn * fn_) / h;
        let pose = TruthPose {
            t_s: t,
            east_m: e - o.device_forward_m * yaw.cos(),
            north_m: n - o.device_forward_m * yaw.sin(),
            yaw_rad: deadreckon_core::angle::wrap(yaw),
            speed_mps: Some(speed),
        };
        if b.push(i, t, &[pose.east_m, pose.north_m, yaw, speed], pose)? && ve.hypot(vn) > 2.0 {
            diff_sum += deadreckon_core::angle::wrap(yaw - vn.atan2(ve));
            diff_n += 1;
        }
    }
    let (mut v, r) = b.finish(|s| s.t_s);
    report.streams.push(r);
    let mount = if diff_n > 0 {
        diff_sum / diff_n as f64
    } else {
        0.0
    };
    // The vehicle's heading is the direction of travel: remove the camera
    // mount's constant yaw offset (measured while moving), and move the pose
    // back along the corrected axis.
    for pose in &mut v {
        let device_yaw = pose.yaw_rad;
        let (e, n) = (
            pose.east_m + o.device_forward_m * device_yaw.cos(),
            pose.north_m + o.device_forward_m * device_yaw.sin(),
        );
        let yaw = deadreckon_core::angle::wrap(device_yaw - mount);
        pose.yaw_rad = yaw;
        pose.east_m = e - o.device_forward_m * yaw.cos();
        pose.north_m = n - o.device_forward_m * yaw.sin();
    }
    Ok((v, mount))
}
