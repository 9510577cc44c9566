//! One message → one sample of a drive stream: the conversion the bag and
//! MCAP readers and the live ROS 2 node (`deadreckon-ros2`) share, so a
//! message gives the same number whether it was recorded or heard on the
//! network.
//!
//! A [`Converter`] holds what the conversion carries from message to message
//! (per mapped stream: the last accepted time, the counters of
//! [`StreamReport`]; the origin of east/north once the first fix fixed it);
//! [`Converter::push`] turns one [`Message`] of mapped stream `i` into a
//! [`Sample`], or drops and counts it. The rules are those of the crate doc
//! (time source, strictly increasing times per stream, status < 0 fixes
//! dropped, the Odometry split into left/right wheel speeds, the IMU's signed
//! yaw axis, NavSatFix about the origin).

use deadreckon_core::drive::{GnssFix, Scalar, TruthPose, WheelSpeeds};
use deadreckon_core::event::{Event, Measurement};
use deadreckon_core::vehicle::Origin;

use crate::ingest::StreamReport;
use crate::mapping::{Mapping, StreamKind, TimeSource, DEFAULT_FALLBACK_STD_M};
use crate::msgs::{Decoded, Stamp};
use crate::ros2;

/// A decoded message of one of the types a mapping reads (built from the
/// ROS 2 message structs of [`crate::ros2`], or by the readers from ROS1 and
/// CDR bytes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Message(pub(crate) Decoded);

fn stamp(h: &ros2::Header) -> Stamp {
    Stamp {
        sec: i64::from(h.stamp.sec),
        nsec: h.stamp.nanosec,
    }
}

impl From<&ros2::Odometry> for Message {
    fn from(m: &ros2::Odometry) -> Self {
        Message(Decoded::Odometry {
            stamp: stamp(&m.header),
            v_mps: m.twist.twist.linear.x,
            w_rps: m.twist.twist.angular.z,
        })
    }
}

impl From<&ros2::Imu> for Message {
    fn from(m: &ros2::Imu) -> Self {
        let g = m.angular_velocity;
        Message(Decoded::Imu {
            stamp: stamp(&m.header),
            gyro: [g.x, g.y, g.z],
        })
    }
}

impl From<&ros2::NavSatFix> for Message {
    fn from(m: &ros2::NavSatFix) -> Self {
        Message(Decoded::NavSatFix {
            stamp: stamp(&m.header),
            status: m.status.status,
            lat_deg: m.latitude,
            lon_deg: m.longitude,
            alt_m: m.altitude,
            cov: m.position_covariance,
            cov_type: m.position_covariance_type,
        })
    }
}

impl From<&ros2::TwistStamped> for Message {
    fn from(m: &ros2::TwistStamped) -> Self {
        Message(Decoded::Twist {
            stamp: stamp(&m.header),
            v_mps: m.twist.linear.x,
            w_rps: m.twist.angular.z,
        })
    }
}

impl From<&ros2::PoseStamped> for Message {
    fn from(m: &ros2::PoseStamped) -> Self {
        let (p, q) = (m.pose.position, m.pose.orientation);
        Message(Decoded::Pose {
            stamp: stamp(&m.header),
            position: [p.x, p.y, p.z],
            orientation: [q.x, q.y, q.z, q.w],
        })
    }
}

impl Message {
    /// The header stamp in seconds since the epoch (`None` for the zero stamp).
    pub fn stamp_s(&self) -> Option<f64> {
        match self.0 {
            Decoded::Odometry { stamp, .. }
            | Decoded::Imu { stamp, .. }
            | Decoded::NavSatFix { stamp, .. }
            | Decoded::Twist { stamp, .. }
            | Decoded::Pose { stamp, .. } => stamp.seconds(),
        }
    }
}

/// One sample of a drive stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Sample {
    /// A wheel-speed row (`odometry_wheels`).
    Wheels(WheelSpeeds),
    /// A yaw rate, rad/s (`imu_yaw_rate`).
    YawRate(Scalar),
    /// A speed, m/s (`twist_speed`).
    Speed(Scalar),
    /// A reference pose (`pose_truth`).
    Truth(TruthPose),
    /// A GNSS fix in east/north (`navsatfix_gnss`).
    Gnss(GnssFix),
}

impl Sample {
    /// The sample as the event [`deadreckon_core::ekf::DriveEvents`] gives for
    /// it in a drive (`None` for a reference pose, which is no measurement).
    pub fn event(&self) -> Option<Event> {
        let (t_s, measurement) = match *self {
            Sample::Wheels(w) => (w.t_s, Measurement::wheel_speeds(&w)),
            Sample::YawRate(s) => (
                s.t_s,
                Measurement::YawRate {
                    yaw_rate_rps: s.value,
                },
            ),
            Sample::Speed(s) => (s.t_s, Measurement::Speed { speed_mps: s.value }),
            Sample::Gnss(g) => (g.t_s, Measurement::gnss(&g)),
            Sample::Truth(_) => return None,
        };
        Some(Event { t_s, measurement })
    }
}

/// The conversion in progress: see the module doc.
#[derive(Debug, Clone)]
pub struct Converter {
    mapping: Mapping,
    reports: Vec<StreamReport>,
    last_t: Vec<f64>,
    /// Origin (lat, lon) in degrees and the altitude of the first fix.
    origin: Option<(f64, f64, Option<f64>)>,
    /// The origin east/north are about, once a fix has been converted.
    used_origin: Option<Origin>,
}

impl Converter {
    /// A conversion through `mapping` (its vehicle's track and origin).
    pub fn new(mapping: &Mapping) -> Self {
        Converter {
            mapping: mapping.clone(),
            reports: mapping
                .streams
                .iter()
                .map(|s| StreamReport::empty(&s.topic, s.kind))
                .collect(),
            last_t: vec![f64::NEG_INFINITY; mapping.streams.len()],
            // An origin without a height (0) takes the first fix's.
            origin: mapping.vehicle.origin.map(|o| {
                (
                    o.lat_deg,
                    o.lon_deg,
                    (o.height_m != 0.0).then_some(o.height_m),
                )
            }),
            used_origin: None,
        }
    }

    /// The mapping converted through.
    pub fn mapping(&self) -> &Mapping {
        &self.mapping
    }

    /// What happened to each mapped stream so far, in mapping order.
    pub fn reports(&self) -> &[StreamReport] {
        &self.reports
    }

    pub(crate) fn reports_mut(&mut self) -> &mut [StreamReport] {
        &mut self.reports
    }

    /// The origin east/north are about, once a fix has been converted
    /// (the vehicle's, with the first fix's height when it has none, or the
    /// first fix).
    pub fn origin(&self) -> Option<Origin> {
        self.used_origin
    }

    /// The time of message `msg` of stream `i` received at `record_t_s`: its
    /// header stamp, or `record_t_s` with `time = "record"` or a zero stamp.
    pub fn time_s(&self, i: usize, record_t_s: f64, msg: &Message) -> f64 {
        match self.mapping.streams[i].time {
            TimeSource::Record => record_t_s,
            TimeSource::Header => msg.stamp_s().unwrap_or(record_t_s),
        }
    }

    /// Converts one message of stream `i` received at `record_t_s`: the
    /// sample, or `None` when it is dropped (counted in [`Converter::reports`]).
    pub fn push(&mut self, i: usize, record_t_s: f64, msg: &Message) -> Option<Sample> {
        let spec = &self.mapping.streams[i];
        let rep = &mut self.reports[i];
        rep.messages += 1;
        if spec.time == TimeSource::Header && msg.stamp_s().is_none() {
            rep.stamp_missing += 1;
        }
        let t = self.time_s(i, record_t_s, msg);
        let rep = &mut self.reports[i];
        if !t.is_finite() {
            rep.invalid_value += 1;
            return None;
        }
        if let Decoded::NavSatFix { status, .. } = msg.0 {
            if status < 0 {
                rep.no_fix += 1;
                return None;
            }
        }
        if t <= self.last_t[i] {
            rep.non_increasing_time += 1;
            return None;
        }
        let sample = self.sample(i, t, msg.0);
        let rep = &mut self.reports[i];
        match sample {
            Some(_) => {
                self.last_t[i] = t;
                rep.accepted += 1;
                rep.first_t_s.get_or_insert(t);
                rep.last_t_s = Some(t);
            }
            None => rep.invalid_value += 1,
        }
        sample
    }

    /// The sample of a message at time `t`, or `None` for a non-finite value.
    fn sample(&mut self, i: usize, t: f64, msg: Decoded) -> Option<Sample> {
        let spec = &self.mapping.streams[i];
        let finite = |v: &[f64]| v.iter().all(|x| x.is_finite());
        match (spec.kind, msg) {
            (StreamKind::OdometryWheels, Decoded::Odometry { v_mps, w_rps, .. }) => {
                let track = spec.track_m.unwrap_or(self.mapping.vehicle.track_rear_m);
                let (l, r) = (v_mps - w_rps * track / 2.0, v_mps + w_rps * track / 2.0);
                finite(&[l, r]).then_some(Sample::Wheels(WheelSpeeds {
                    t_s: t,
                    fl_mps: l,
                    fr_mps: r,
                    rl_mps: l,
                    rr_mps: r,
                }))
            }
            (StreamKind::ImuYawRate, Decoded::Imu { gyro, .. }) => {
                let value = spec
                    .yaw_axis
                    .unwrap_or(crate::mapping::YawAxis::Z)
                    .pick(gyro);
                value
                    .is_finite()
                    .then_some(Sample::YawRate(Scalar { t_s: t, value }))
            }
            (StreamKind::TwistSpeed, Decoded::Twist { v_mps, .. }) => {
                v_mps.is_finite().then_some(Sample::Speed(Scalar {
                    t_s: t,
                    value: v_mps,
                }))
            }
            (
                StreamKind::PoseTruth,
                Decoded::Pose {
                    position,
                    orientation: [x, y, z, w],
                    ..
                },
            ) => {
                // Yaw of a quaternion: atan2(2(wz + xy), 1 − 2(y² + z²)).
                let yaw_rad = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
                finite(&[position[0], position[1], yaw_rad]).then_some(Sample::Truth(TruthPose {
                    t_s: t,
                    east_m: position[0],
                    north_m: position[1],
                    yaw_rad,
                    speed_mps: None,
                }))
            }
            (
                StreamKind::NavsatfixGnss,
                Decoded::NavSatFix {
                    lat_deg,
                    lon_deg,
                    alt_m,
                    cov,
                    cov_type,
                    ..
                },
            ) => self.fix(i, t, lat_deg, lon_deg, alt_m, &cov, cov_type),
            // The readers decode each stream as its kind's type; a live
            // message of another type is no sample of this stream.
            _ => None,
        }
    }

    /// A NavSatFix in east/north about the origin, fixing the origin (and
    /// its height) on the first fix that needs it.
    #[allow(clippy::too_many_arguments)]
    fn fix(
        &mut self,
        i: usize,
        t: f64,
        lat_deg: f64,
        lon_deg: f64,
        alt_m: f64,
        cov: &[f64; 9],
        cov_type: u8,
    ) -> Option<Sample> {
        let alt_m = if alt_m.is_finite() { alt_m } else { 0.0 };
        let geodetic_ok = lat_deg.is_finite()
            && lon_deg.is_finite()
            && lat_deg.abs() <= 90.0
            && lon_deg.abs() <= 360.0;
        if !geodetic_ok {
            return None;
        }
        let (lat0, lon0, alt0) = match self.origin {
            Some((a, b, Some(h))) => (a, b, h),
            Some((a, b, None)) => {
                self.origin = Some((a, b, Some(alt_m)));
                (a, b, alt_m)
            }
            None => {
                self.origin = Some((lat_deg, lon_deg, Some(alt_m)));
                (lat_deg, lon_deg, alt_m)
            }
        };
        // The drive's origin with the height its frame is about, so writers
        // convert back at the same height.
        self.used_origin = Some(Origin {
            lat_deg: lat0,
            lon_deg: lon0,
            height_m: alt0,
        });
        let (e, n, _) = map_3d::geodetic2enu(
            lat_deg.to_radians(),
            lon_deg.to_radians(),
            alt_m,
            lat0.to_radians(),
            lon0.to_radians(),
            alt0,
            map_3d::Ellipsoid::WGS84,
        );
        // Horizontal std: sqrt of the mean of the east and north variances.
        let var = 0.5 * (cov[0] + cov[4]);
        let spec = &self.mapping.streams[i];
        let std_m = if cov_type > 0 && var.is_finite() && var > 0.0 {
            var.sqrt()
        } else {
            self.reports[i].covariance_missing += 1;
            spec.fallback_std_m.unwrap_or(DEFAULT_FALLBACK_STD_M)
        };
        (e.is_finite() && n.is_finite()).then_some(Sample::Gnss(GnssFix {
            t_s: t,
            east_m: e,
            north_m: n,
            std_m,
            course_deg: None,
            speed_mps: None,
        }))
    }
}
