//! # deadreckon-ros
//!
//! ROS recordings in and out of deadreckon: ROS1 bags (format 2.0) and ROS2
//! MCAP files (`cdr` messages, or `ros1` ones) are read into a [`Drive`] through
//! a [`Mapping`] that says which topic feeds which stream, with an
//! [`ImportReport`] of what was used and dropped; [`list_topics`] lists what a
//! file holds; estimated [`Track`]s are written to MCAP with Foxglove's JSON
//! schemas (`foxglove.PoseInFrame`, `foxglove.LocationFix`, see [`foxglove`])
//! and, for ROS tools, as ROS 2 `nav_msgs/msg/Odometry` in CDR ([`ros2_out`]).
//!
//! Readers take a path, any `Read`, or a byte slice. The containers are decoded
//! here with every length checked; `mcap` parses MCAP record bodies and writes
//! MCAP; chunk decompression is pure Rust: bz2 always, lz4 (feature `lz4`) and
//! zstd (feature `zstd`, the `ros2 bag record` default) on by default.
//!
//! ## Conventions
//!
//! - Time: `header.stamp` of each message in seconds since the Unix epoch (the
//!   record/log time when the stamp is zero, counted in the report). Each stream
//!   must be strictly increasing: a sample not after the previous accepted one is
//!   dropped and counted in [`ImportReport`], never reordered or nudged. Messages
//!   are visited in record-time order, as `rosbag play` does.
//! - `nav_msgs/Odometry` of a differential robot gives wheel speeds from
//!   v = twist.linear.x and ω = twist.angular.z: v_l = v − ω·track/2,
//!   v_r = v + ω·track/2, front = rear ([`Wheels::Speeds`](deadreckon_core::drive::Wheels)).
//! - `sensor_msgs/Imu`: the yaw rate is the angular velocity on the mapping's
//!   signed `yaw_axis`. On `husky_gps.bag` the IMU is mounted rotated and the yaw
//!   rate is **+y**: the correlation of ω_y with the odometry yaw rate is +0.855
//!   (−y: −0.855, ±x: 0.03, ±z: 0.01), see the `husky_imu_axis` test. On
//!   `jackal_no_gps.bag` (IMU in `base_link`) it is +z (0.53: that robot's
//!   skid-steer odometry overstates its turns several times).
//! - `sensor_msgs/NavSatFix`: east/north by `map_3d` about the vehicle's origin, or
//!   else the first accepted fix (then stored as the drive's origin); std_m is the
//!   square root of the mean of the east and north variances; fixes with
//!   `status < 0` are dropped and counted.
//! - Errors name the file, the topic and the byte offset of the record
//!   ([`RosError`]); no input makes a reader panic (fuzzed, property-tested).
//!
//! ```no_run
//! use deadreckon_ros::{read_rosbag, Mapping};
//! let (drive, report) = read_rosbag("husky_gps.bag", &Mapping::husky())?;
//! println!("{} wheel epochs, {} samples dropped", drive.wheels.len(), report.dropped());
//! # Ok::<(), deadreckon_ros::RosError>(())
//! ```
#![deny(missing_docs)]

mod bag;
mod compress;
pub mod convert;
mod error;
pub mod foxglove;
mod ingest;
pub mod mapping;
mod mcap_read;
mod msgs;
pub mod ros2;
pub mod ros2_out;
mod rosbag;

use std::path::Path;

use serde::Serialize;

pub use convert::{Converter, Message, Sample};
pub use deadreckon_core::{Drive, Track};
pub use error::{Location, RosError};
pub use foxglove::{write_mcap, write_mcap_with, write_tracks_mcap, McapOptions};
pub use ingest::{ImportReport, StreamReport};
pub use mapping::{Mapping, StreamKind, StreamSpec, TimeSource, YawAxis};
pub use mcap_read::{list_mcap_topics_bytes, read_mcap_bytes};
pub use rosbag::{list_rosbag_topics_bytes, read_rosbag_bytes};

/// One topic of a recording.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TopicInfo {
    /// Topic name.
    pub topic: String,
    /// Message type (ROS1 connection type, or MCAP schema name).
    pub msg_type: String,
    /// Message encoding: `ros1`, `cdr`, `json`, ...
    pub encoding: String,
    /// MD5 sum of the definition (ROS1 only).
    pub md5sum: Option<String>,
    /// Number of messages.
    pub messages: u64,
    /// Record time of the first message, s.
    pub first_t_s: Option<f64>,
    /// Record time of the last message, s.
    pub last_t_s: Option<f64>,
}

impl TopicInfo {
    fn add(&mut self, t_s: f64) {
        self.messages += 1;
        self.first_t_s = Some(self.first_t_s.map_or(t_s, |f| f.min(t_s)));
        self.last_t_s = Some(self.last_t_s.map_or(t_s, |l| l.max(t_s)));
    }

    /// Mean message rate, Hz (None with fewer than two messages).
    pub fn rate_hz(&self) -> Option<f64> {
        match (self.first_t_s, self.last_t_s) {
            (Some(a), Some(b)) if b > a && self.messages > 1 => {
                Some((self.messages - 1) as f64 / (b - a))
            }
            _ => None,
        }
    }
}

/// The two container formats read.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Format {
    /// ROS1 bag, format 2.0.
    Rosbag,
    /// MCAP.
    Mcap,
}

impl Format {
    /// The format of a file from its first bytes.
    pub fn detect(bytes: &[u8]) -> Option<Format> {
        if bytes.starts_with(b"#ROSBAG") {
            Some(Format::Rosbag)
        } else if bytes.starts_with(mcap_read::MAGIC) {
            Some(Format::Mcap)
        } else {
            None
        }
    }
}

fn read_file(path: &Path) -> Result<(Vec<u8>, String), RosError> {
    let file = path.display().to_string();
    let bytes = std::fs::read(path).map_err(|source| RosError::Io {
        file: file.clone(),
        source,
    })?;
    Ok((bytes, file))
}

/// Reads everything from `reader` (e.g. a file or a `Cursor`) into memory.
fn read_all(mut reader: impl std::io::Read, file: &str) -> Result<Vec<u8>, RosError> {
    let mut bytes = Vec::new();
    reader
        .read_to_end(&mut bytes)
        .map_err(|source| RosError::Io {
            file: file.into(),
            source,
        })?;
    Ok(bytes)
}

/// Reads a ROS1 bag into a drive, with the report of what was used and dropped.
pub fn read_rosbag(
    path: impl AsRef<Path>,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    let (bytes, file) = read_file(path.as_ref())?;
    read_rosbag_bytes(&bytes, &file, mapping)
}

/// Reads a ROS1 bag from any reader; `file` names it in errors.
pub fn read_rosbag_from(
    reader: impl std::io::Read,
    file: &str,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    read_rosbag_bytes(&read_all(reader, file)?, file, mapping)
}

/// Reads an MCAP file into a drive, with the report of what was used and dropped.
pub fn read_mcap(
    path: impl AsRef<Path>,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    let (bytes, file) = read_file(path.as_ref())?;
    read_mcap_bytes(&bytes, &file, mapping)
}

/// Reads an MCAP file from any reader; `file` names it in errors.
pub fn read_mcap_from(
    reader: impl std::io::Read,
    file: &str,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    read_mcap_bytes(&read_all(reader, file)?, file, mapping)
}

/// Reads a bag or an MCAP file, whichever `path` holds, or the MCAP file of a
/// rosbag2 directory ([`rosbag2_storage`]).
pub fn read_log(
    path: impl AsRef<Path>,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    let (bytes, file) = log_bytes(path.as_ref())?;
    read_log_bytes(&bytes, &file, mapping)
}

/// The bytes of the recording [`read_log`] reads at `path` (a bag, an MCAP
/// file, or a rosbag2 directory's MCAP file), and its name for errors: for a
/// caller that looks at it ([`list_topics_bytes`]) before reading it, once.
pub fn log_bytes(path: &Path) -> Result<(Vec<u8>, String), RosError> {
    if path.is_dir() {
        read_file(&rosbag2_storage(path)?)
    } else {
        read_file(path)
    }
}

/// [`read_log`] of a recording held in memory; `file` names it in errors.
pub fn read_log_bytes(
    bytes: &[u8],
    file: &str,
    mapping: &Mapping,
) -> Result<(Drive, ImportReport), RosError> {
    match Format::detect(bytes) {
        Some(Format::Rosbag) => read_rosbag_bytes(bytes, file, mapping),
        Some(Format::Mcap) => read_mcap_bytes(bytes, file, mapping),
        None => Err(RosError::format(
            Location::file(file).at(0),
            "neither a ROS bag nor an MCAP file",
        )),
    }
}

/// The storage file of a rosbag2 directory (a `metadata.yaml` beside the
/// recorded files): its one `.mcap` file. A bag stored in SQLite (`.db3`) or
/// split over several files is refused, saying so.
pub fn rosbag2_storage(dir: &Path) -> Result<std::path::PathBuf, RosError> {
    let name = dir.display().to_string();
    let refuse = |what: String| RosError::format(Location::file(&name).at(0), what);
    if !dir.join("metadata.yaml").is_file() {
        return Err(refuse(
            "a directory without metadata.yaml is not a rosbag2 bag".into(),
        ));
    }
    let entries = std::fs::read_dir(dir).map_err(|source| RosError::Io {
        file: name.clone(),
        source,
    })?;
    let mut mcap = Vec::new();
    let mut db3 = 0;
    for e in entries {
        let p = e
            .map_err(|source| RosError::Io {
                file: name.clone(),
                source,
            })?
            .path();
        match p.extension().and_then(|x| x.to_str()) {
            Some("mcap") => mcap.push(p),
            Some("db3") => db3 += 1,
            _ => {}
        }
    }
    match (mcap.len(), db3) {
        (1, _) => Ok(mcap.remove(0)),
        (0, n) if n > 0 => Err(refuse(
            "a rosbag2 bag stored in SQLite (.db3) is not read: convert it with \
             `ros2 bag convert` to the mcap storage"
                .into(),
        )),
        (0, _) => Err(refuse("the rosbag2 directory holds no .mcap file".into())),
        (n, _) => Err(refuse(format!(
            "a rosbag2 bag split over {n} .mcap files is not read: merge them with \
             `ros2 bag convert` into one file"
        ))),
    }
}

/// The topics of a bag or an MCAP file held in memory, sorted by name.
pub fn list_topics_bytes(bytes: &[u8], file: &str) -> Result<Vec<TopicInfo>, RosError> {
    match Format::detect(bytes) {
        Some(Format::Rosbag) => list_rosbag_topics_bytes(bytes, file),
        Some(Format::Mcap) => list_mcap_topics_bytes(bytes, file),
        None => Err(RosError::format(
            Location::file(file).at(0),
            "neither a ROS bag nor an MCAP file",
        )),
    }
}

/// The topics of a bag or an MCAP file (the format is detected), sorted by name.
pub fn list_topics(path: impl AsRef<Path>) -> Result<Vec<TopicInfo>, RosError> {
    let (bytes, file) = read_file(path.as_ref())?;
    list_topics_bytes(&bytes, &file)
}
