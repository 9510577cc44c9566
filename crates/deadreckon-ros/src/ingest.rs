//! From decoded messages to the streams of a [`Drive`], gating and counting
//! every sample that cannot be used (never repairing it).

use serde::Serialize;

use deadreckon_core::drive::{GnssFix, Scalar, TruthPose, WheelSpeeds, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::Drive;

use crate::error::{Location, RosError};
use crate::mapping::{Mapping, StreamKind, StreamSpec, TimeSource, DEFAULT_FALLBACK_STD_M};
use crate::msgs::{Decoded, MsgType};

/// What happened to one mapped stream during an import.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StreamReport {
    /// Topic read.
    pub topic: String,
    /// Stream kind it fed.
    pub kind: StreamKind,
    /// Message type the file declares for the topic (empty when the topic is absent).
    pub msg_type: String,
    /// Messages on the topic.
    pub messages: u64,
    /// Samples added to the drive.
    pub accepted: u64,
    /// Dropped: time not strictly after the previous accepted sample of the stream
    /// (duplicates, out-of-order messages).
    pub non_increasing_time: u64,
    /// Dropped: non-finite time or value, or a latitude/longitude out of range.
    pub invalid_value: u64,
    /// Dropped (GNSS): `status.status` < 0 (no fix).
    pub no_fix: u64,
    /// Accepted with the record time because `header.stamp` was zero.
    pub stamp_missing: u64,
    /// Accepted (GNSS) with `fallback_std_m` because the covariance was unknown or not positive.
    pub covariance_missing: u64,
    /// Time of the first accepted sample, s.
    pub first_t_s: Option<f64>,
    /// Time of the last accepted sample, s.
    pub last_t_s: Option<f64>,
}

/// What an import read, used and dropped, stream by stream.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ImportReport {
    /// Input file.
    pub file: String,
    /// `rosbag` or `mcap`.
    pub format: String,
    /// One entry per mapped stream, in mapping order.
    pub streams: Vec<StreamReport>,
    /// Topics in the file that the mapping does not read.
    pub unmapped_topics: Vec<String>,
    /// Geodetic origin of east/north (the vehicle's, or the first accepted fix).
    pub origin: Option<Origin>,
}

impl ImportReport {
    /// Total samples dropped over all streams.
    pub fn dropped(&self) -> u64 {
        self.streams
            .iter()
            .map(|s| s.non_increasing_time + s.invalid_value + s.no_fix)
            .sum()
    }
}

impl std::fmt::Display for ImportReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        writeln!(f, "{} ({})", self.file, self.format)?;
        writeln!(
            f,
            "{:<36} {:<15} {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} {:>8}",
            "topic",
            "kind",
            "messages",
            "accepted",
            "unsorted",
            "invalid",
            "no_fix",
            "no_stamp",
            "no_cov"
        )?;
        for s in &self.streams {
            writeln!(
                f,
                "{:<36} {:<15} {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} {:>8}",
                s.topic,
                s.kind.name(),
                s.messages,
                s.accepted,
                s.non_increasing_time,
                s.invalid_value,
                s.no_fix,
                s.stamp_missing,
                s.covariance_missing
            )?;
        }
        if !self.unmapped_topics.is_empty() {
            writeln!(f, "not read: {}", self.unmapped_topics.join(", "))?;
        }
        if let Some(o) = self.origin {
            writeln!(
                f,
                "origin: {:.7} N, {:.7} E, {:.2} m above the WGS84 ellipsoid",
                o.lat_deg, o.lon_deg, o.height_m
            )?;
        }
        Ok(())
    }
}

/// The import in progress: one state per mapped stream.
pub(crate) struct Ingest<'m> {
    mapping: &'m Mapping,
    pub(crate) drive: Drive,
    speeds: Vec<WheelSpeeds>,
    pub(crate) report: ImportReport,
    last_t: Vec<f64>,
    /// Origin (lat, lon) in degrees and the altitude of the first fix.
    origin: Option<(f64, f64, Option<f64>)>,
}

impl<'m> Ingest<'m> {
    pub(crate) fn new(mapping: &'m Mapping, file: &str, format: &str) -> Self {
        let streams = mapping
            .streams
            .iter()
            .map(|s| StreamReport {
                topic: s.topic.clone(),
                kind: s.kind,
                msg_type: String::new(),
                messages: 0,
                accepted: 0,
                non_increasing_time: 0,
                invalid_value: 0,
                no_fix: 0,
                stamp_missing: 0,
                covariance_missing: 0,
                first_t_s: None,
                last_t_s: None,
            })
            .collect();
        Ingest {
            mapping,
            drive: Drive::empty(mapping.vehicle.clone()),
            speeds: Vec::new(),
            report: ImportReport {
                file: file.to_owned(),
                format: format.to_owned(),
                streams,
                unmapped_topics: Vec::new(),
                origin: mapping.vehicle.origin,
            },
            last_t: vec![f64::NEG_INFINITY; mapping.streams.len()],
            // An origin without a height (0) takes the first fix's.
            origin: mapping.vehicle.origin.map(|o| {
                (
                    o.lat_deg,
                    o.lon_deg,
                    (o.height_m != 0.0).then_some(o.height_m),
                )
            }),
        }
    }

    /// Checks the topics of the file against the mapping. `topics` is (topic, type) for
    /// every topic of the file. Returns for each mapped stream whether it is present.
    pub(crate) fn bind(
        &mut self,
        topics: &[(String, String)],
        at: &Location,
    ) -> Result<(), RosError> {
        for (i, s) in self.mapping.streams.iter().enumerate() {
            let found: Vec<&(String, String)> =
                topics.iter().filter(|(t, _)| *t == s.topic).collect();
            if found.is_empty() {
                if self.mapping.require_topics {
                    let mut names: Vec<&str> = topics.iter().map(|(t, _)| t.as_str()).collect();
                    names.dedup();
                    return Err(RosError::MissingTopic {
                        at: Box::new(at.on(&s.topic)),
                        available: names.join(", "),
                    });
                }
                continue;
            }
            for (_, ty) in &found {
                if MsgType::from_name(ty) != Some(s.kind.msg_type()) {
                    return Err(RosError::TypeMismatch {
                        at: Box::new(at.on(&s.topic)),
                        kind: s.kind.name().into(),
                        expected: s.kind.msg_type_name().into(),
                        found: ty.clone(),
                    });
                }
            }
            self.report.streams[i].msg_type = found[0].1.clone();
        }
        let mut unmapped: Vec<String> = topics
            .iter()
            .map(|(t, _)| t.clone())
            .filter(|t| !self.mapping.streams.iter().any(|s| &s.topic == t))
            .collect();
        unmapped.sort();
        unmapped.dedup();
        self.report.unmapped_topics = unmapped;
        Ok(())
    }

    /// The index of the stream fed by `topic`, if any.
    pub(crate) fn stream_of(&self, topic: &str) -> Option<usize> {
        self.mapping.streams.iter().position(|s| s.topic == topic)
    }

    /// The message type stream `i` reads.
    pub(crate) fn msg_type(&self, i: usize) -> MsgType {
        self.mapping.streams[i].kind.msg_type()
    }

    /// Adds one decoded message of stream `i` received at `record_t_s`.
    pub(crate) fn push(&mut self, i: usize, record_t_s: f64, msg: Decoded) {
        let mapping: &'m Mapping = self.mapping;
        let spec: &StreamSpec = &mapping.streams[i];
        let rep = &mut self.report.streams[i];
        rep.messages += 1;
        let stamp = match msg {
            Decoded::Odometry { stamp, .. }
            | Decoded::Imu { stamp, .. }
            | Decoded::NavSatFix { stamp, .. }
            | Decoded::Twist { stamp, .. }
            | Decoded::Pose { stamp, .. } => stamp,
        };
        let t = match spec.time {
            TimeSource::Record => record_t_s,
            TimeSource::Header => match stamp.seconds() {
                Some(t) => t,
                None => {
                    rep.stamp_missing += 1;
                    record_t_s
                }
            },
        };
        if !t.is_finite() {
            rep.invalid_value += 1;
            return;
        }
        if let Decoded::NavSatFix { status, .. } = msg {
            if status < 0 {
                rep.no_fix += 1;
                return;
            }
        }
        if t <= self.last_t[i] {
            rep.non_increasing_time += 1;
            return;
        }
        let accepted = match msg {
            Decoded::Odometry { v_mps, w_rps, .. } => {
                let track = spec.track_m.unwrap_or(mapping.vehicle.track_rear_m);
                let (l, r) = (v_mps - w_rps * track / 2.0, v_mps + w_rps * track / 2.0);
                let ok = l.is_finite() && r.is_finite();
                if ok {
                    self.speeds.push(WheelSpeeds {
                        t_s: t,
                        fl_mps: l,
                        fr_mps: r,
                        rl_mps: l,
                        rr_mps: r,
                    });
                }
                ok
            }
            Decoded::Imu { gyro, .. } => {
                let value = spec
                    .yaw_axis
                    .unwrap_or(crate::mapping::YawAxis::Z)
                    .pick(gyro);
                let ok = value.is_finite();
                if ok {
                    self.drive.yaw_rate.push(Scalar { t_s: t, value });
                }
                ok
            }
            Decoded::Twist { v_mps, .. } => {
                let ok = v_mps.is_finite();
                if ok {
                    self.drive.speed.push(Scalar {
                        t_s: t,
                        value: v_mps,
                    });
                }
                ok
            }
            Decoded::Pose {
                position,
                orientation: [x, y, z, w],
                ..
            } => {
                // Yaw of a quaternion: atan2(2(wz + xy), 1 − 2(y² + z²)).
                let yaw_rad = (2.0 * (w * z + x * y)).atan2(1.0 - 2.0 * (y * y + z * z));
                let ok = position[0].is_finite() && position[1].is_finite() && yaw_rad.is_finite();
                if ok {
                    self.drive.truth.push(TruthPose {
                        t_s: t,
                        east_m: position[0],
                        north_m: position[1],
                        yaw_rad,
                        speed_mps: None,
                    });
                }
                ok
            }
            Decoded::NavSatFix {
                lat_deg,
                lon_deg,
                alt_m,
                cov,
                cov_type,
                ..
            } => {
                let alt_m = if alt_m.is_finite() { alt_m } else { 0.0 };
                let geodetic_ok = lat_deg.is_finite()
                    && lon_deg.is_finite()
                    && lat_deg.abs() <= 90.0
                    && lon_deg.abs() <= 360.0;
                if geodetic_ok {
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
                    // The drive's origin with the height its frame is about,
                    // so writers convert back at the same height.
                    let o = Origin {
                        lat_deg: lat0,
                        lon_deg: lon0,
                        height_m: alt0,
                    };
                    self.drive.vehicle.origin = Some(o);
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
                    let std_m = if cov_type > 0 && var.is_finite() && var > 0.0 {
                        var.sqrt()
                    } else {
                        rep.covariance_missing += 1;
                        spec.fallback_std_m.unwrap_or(DEFAULT_FALLBACK_STD_M)
                    };
                    let ok = e.is_finite() && n.is_finite();
                    if ok {
                        self.drive.gnss.push(GnssFix {
                            t_s: t,
                            east_m: e,
                            north_m: n,
                            std_m,
                            course_deg: None,
                            speed_mps: None,
                        });
                    }
                    ok
                } else {
                    false
                }
            }
        };
        if accepted {
            self.last_t[i] = t;
            rep.accepted += 1;
            rep.first_t_s.get_or_insert(t);
            rep.last_t_s = Some(t);
        } else {
            rep.invalid_value += 1;
        }
    }

    /// The drive and the report.
    pub(crate) fn finish(mut self) -> (Drive, ImportReport) {
        self.drive.wheels = Wheels::Speeds(std::mem::take(&mut self.speeds));
        self.report.origin = self.drive.vehicle.origin;
        (self.drive, self.report)
    }
}
