//! From decoded messages to the streams of a [`Drive`] through the shared
//! conversion ([`crate::convert`]), gating and counting every sample that
//! cannot be used (never repairing it).

use serde::Serialize;

use deadreckon_core::drive::{WheelSpeeds, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::Drive;

use crate::convert::{Converter, Message, Sample};
use crate::error::{Location, RosError};
use crate::mapping::{Mapping, StreamKind};
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

/// The import in progress: the shared conversion ([`Converter`]) and the drive
/// it fills.
pub(crate) struct Ingest {
    conv: Converter,
    pub(crate) drive: Drive,
    speeds: Vec<WheelSpeeds>,
    pub(crate) report: ImportReport,
}

impl StreamReport {
    /// The report of a stream before its first message.
    pub(crate) fn empty(topic: &str, kind: StreamKind) -> Self {
        StreamReport {
            topic: topic.to_owned(),
            kind,
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
        }
    }
}

impl Ingest {
    pub(crate) fn new(mapping: &Mapping, file: &str, format: &str) -> Self {
        Ingest {
            conv: Converter::new(mapping),
            drive: Drive::empty(mapping.vehicle.clone()),
            speeds: Vec::new(),
            report: ImportReport {
                file: file.to_owned(),
                format: format.to_owned(),
                streams: Vec::new(),
                unmapped_topics: Vec::new(),
                origin: mapping.vehicle.origin,
            },
        }
    }

    /// Checks the topics of the file against the mapping. `topics` is (topic, type) for
    /// every topic of the file. Returns for each mapped stream whether it is present.
    pub(crate) fn bind(
        &mut self,
        topics: &[(String, String)],
        at: &Location,
    ) -> Result<(), RosError> {
        let mapping = self.conv.mapping().clone();
        for (i, s) in mapping.streams.iter().enumerate() {
            let found: Vec<&(String, String)> =
                topics.iter().filter(|(t, _)| *t == s.topic).collect();
            if found.is_empty() {
                if mapping.require_topics {
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
            self.conv.reports_mut()[i].msg_type = found[0].1.clone();
        }
        let mut unmapped: Vec<String> = topics
            .iter()
            .map(|(t, _)| t.clone())
            .filter(|t| !mapping.streams.iter().any(|s| &s.topic == t))
            .collect();
        unmapped.sort();
        unmapped.dedup();
        self.report.unmapped_topics = unmapped;
        Ok(())
    }

    /// The index of the stream fed by `topic`, if any.
    pub(crate) fn stream_of(&self, topic: &str) -> Option<usize> {
        self.conv
            .mapping()
            .streams
            .iter()
            .position(|s| s.topic == topic)
    }

    /// The message type stream `i` reads.
    pub(crate) fn msg_type(&self, i: usize) -> MsgType {
        self.conv.mapping().streams[i].kind.msg_type()
    }

    /// Adds one decoded message of stream `i` received at `record_t_s`.
    pub(crate) fn push(&mut self, i: usize, record_t_s: f64, msg: Decoded) {
        match self.conv.push(i, record_t_s, &Message(msg)) {
            Some(Sample::Wheels(w)) => self.speeds.push(w),
            Some(Sample::YawRate(s)) => self.drive.yaw_rate.push(s),
            Some(Sample::Speed(s)) => self.drive.speed.push(s),
            Some(Sample::Truth(p)) => self.drive.truth.push(p),
            Some(Sample::Gnss(g)) => self.drive.gnss.push(g),
            None => {}
        }
    }

    /// The drive and the report.
    pub(crate) fn finish(mut self) -> (Drive, ImportReport) {
        self.drive.wheels = Wheels::Speeds(std::mem::take(&mut self.speeds));
        if let Some(o) = self.conv.origin() {
            self.drive.vehicle.origin = Some(o);
        }
        self.report.streams = self.conv.reports().to_vec();
        self.report.origin = self.drive.vehicle.origin;
        (self.drive, self.report)
    }
}
