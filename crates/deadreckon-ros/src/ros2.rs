//! ROS2 message types as serde structs, CDR-encoded as in MCAP files recorded by
//! `ros2 bag record` (message encoding `cdr`).
//!
//! A CDR message starts with a 4-byte encapsulation header: `00 01 00 00` for
//! little-endian CDR, `00 00 00 00` for big-endian. The body aligns every
//! primitive to its own size (counted from the end of the header); strings are
//! (length u32 including the terminating NUL, bytes, NUL). `cdr-encoding` does
//! the alignment; these structs give the field order of the ROS2 definitions.
//! Covariances (`float64[36]`) are written as 6 × 6 nested arrays, which encode
//! to the same bytes and keep within serde's array support.

use serde::{Deserialize, Serialize};

use crate::msgs::{Decoded, MsgType};

/// `builtin_interfaces/msg/Time`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Time {
    /// Seconds since the epoch.
    pub sec: i32,
    /// Nanoseconds within the second.
    pub nanosec: u32,
}

/// `std_msgs/msg/Header`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Header {
    /// Acquisition time.
    pub stamp: Time,
    /// Frame of the data.
    pub frame_id: String,
}

/// `geometry_msgs/msg/Vector3` (also `Point`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

/// `geometry_msgs/msg/Quaternion`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
    /// w.
    pub w: f64,
}

/// `geometry_msgs/msg/Pose`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Position, m.
    pub position: Vector3,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/Twist`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Linear velocity, m/s.
    pub linear: Vector3,
    /// Angular velocity, rad/s.
    pub angular: Vector3,
}

/// A `float64[36]` covariance, row-major 6 × 6.
pub type Covariance6 = [[f64; 6]; 6];

/// `geometry_msgs/msg/PoseWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Its covariance.
    pub covariance: Covariance6,
}

/// `geometry_msgs/msg/TwistWithCovariance`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Its covariance.
    pub covariance: Covariance6,
}

/// `nav_msgs/msg/Odometry`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Odometry {
    /// Header.
    pub header: Header,
    /// Frame of the twist.
    pub child_frame_id: String,
    /// Pose in `header.frame_id`.
    pub pose: PoseWithCovariance,
    /// Twist in `child_frame_id`.
    pub twist: TwistWithCovariance,
}

/// `sensor_msgs/msg/Imu`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Imu {
    /// Header.
    pub header: Header,
    /// Orientation.
    pub orientation: Quaternion,
    /// Its covariance, row-major 3 × 3.
    pub orientation_covariance: [f64; 9],
    /// Angular velocity, rad/s.
    pub angular_velocity: Vector3,
    /// Its covariance.
    pub angular_velocity_covariance: [f64; 9],
    /// Linear acceleration, m/s².
    pub linear_acceleration: Vector3,
    /// Its covariance.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/msg/NavSatStatus`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatStatus {
    /// -1 no fix, 0 fix, 1 SBAS fix, 2 GBAS fix.
    pub status: i8,
    /// Bit set of the constellations used.
    pub service: u16,
}

/// `sensor_msgs/msg/NavSatFix`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct NavSatFix {
    /// Header.
    pub header: Header,
    /// Fix status.
    pub status: NavSatStatus,
    /// Latitude, degrees.
    pub latitude: f64,
    /// Longitude, degrees.
    pub longitude: f64,
    /// Altitude above the WGS84 ellipsoid, m.
    pub altitude: f64,
    /// Position covariance in ENU, m², row-major 3 × 3.
    pub position_covariance: [f64; 9],
    /// 0 unknown, 1 approximated, 2 diagonal known, 3 known.
    pub position_covariance_type: u8,
}

/// `geometry_msgs/msg/TwistStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct TwistStamped {
    /// Header.
    pub header: Header,
    /// The twist.
    pub twist: Twist,
}

/// `geometry_msgs/msg/PoseStamped`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct PoseStamped {
    /// Header.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}

/// Encodes a message as little-endian CDR with its encapsulation header, as
/// ROS2 writes it.
pub fn encode_cdr<T: Serialize>(msg: &T) -> Result<Vec<u8>, String> {
    let body =
        cdr_encoding::to_vec::<T, byteorder::LittleEndian>(msg).map_err(|e| e.to_string())?;
    let mut out = Vec::with_capacity(body.len() + 4);
    out.extend_from_slice(&[0, 1, 0, 0]);
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decodes a CDR message (with its encapsulation header) as `T`.
pub fn decode_cdr<T: serde::de::DeserializeOwned>(data: &[u8]) -> Result<T, String> {
    let (kind, body) = match data {
        [_, k, _, _, body @ ..] => (*k, body),
        _ => {
            return Err(format!(
                "{} bytes: shorter than the CDR encapsulation header",
                data.len()
            ))
        }
    };
    if data[0] != 0 {
        return Err(format!(
            "encapsulation {:02x}{:02x} is not plain CDR",
            data[0], data[1]
        ));
    }
    let (msg, used) = match kind {
        1 => cdr_encoding::from_bytes::<T, byteorder::LittleEndian>(body),
        0 => cdr_encoding::from_bytes::<T, byteorder::BigEndian>(body),
        k => return Err(format!("encapsulation 00{k:02x} is not plain CDR")),
    }
    .map_err(|e| e.to_string())?;
    // ROS2 pads a message to a multiple of 4 bytes; more left over means a wrong type.
    if body.len().saturating_sub(used) > 3 {
        return Err(format!(
            "{} bytes left over after the message (wrong type?)",
            body.len() - used
        ));
    }
    Ok(msg)
}

/// Decodes a CDR message of type `t` into the importer's form, through the
/// conversion the live node uses ([`crate::convert::Message`]).
pub(crate) fn decode(t: MsgType, data: &[u8]) -> Result<Decoded, String> {
    use crate::convert::Message;
    let m = match t {
        MsgType::Odometry => Message::from(&decode_cdr::<Odometry>(data)?),
        MsgType::Imu => Message::from(&decode_cdr::<Imu>(data)?),
        MsgType::NavSatFix => Message::from(&decode_cdr::<NavSatFix>(data)?),
        MsgType::TwistStamped => Message::from(&decode_cdr::<TwistStamped>(data)?),
        MsgType::PoseStamped => Message::from(&decode_cdr::<PoseStamped>(data)?),
    };
    Ok(m.0)
}
