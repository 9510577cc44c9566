//! Which topic feeds which stream of the drive: the mapping file.
//!
//! ```toml
//! # Optional: the vehicle (same keys as vehicle.toml). Default: the Husky profile,
//! # with its track replaced by the odometry stream's track_m when that is given.
//! # [vehicle]
//! # wheelbase_m = 0.01
//! # ...
//!
//! # Optional, default true: a mapped topic missing from the file is an error.
//! require_topics = true
//!
//! [[stream]]
//! topic = "/husky_velocity_controller/odom"
//! kind = "odometry_wheels"   # nav_msgs/Odometry -> wheel speeds (m/s)
//! track_m = 0.555            # wheel separation used to split (v, ω) into left/right, m
//!
//! [[stream]]
//! topic = "/imu/data"
//! kind = "imu_yaw_rate"      # sensor_msgs/Imu -> yaw rate (rad/s, counter-clockwise)
//! yaw_axis = "y"             # which signed IMU axis is the vehicle's up axis (default "z")
//!
//! [[stream]]
//! topic = "/fix"
//! kind = "navsatfix_gnss"    # sensor_msgs/NavSatFix -> GNSS fixes in local east/north
//! fallback_std_m = 5.0       # std when the fix has no covariance, m (default 5.0)
//!
//! # kind = "twist_speed"     geometry_msgs/TwistStamped -> speed (twist.linear.x, m/s)
//! # kind = "pose_truth"      geometry_msgs/PoseStamped  -> reference poses (x east, y north)
//! # Every stream also takes time = "header" (default: header.stamp, or the
//! # record time when the stamp is zero) or time = "record" (the bag/MCAP log time).
//! ```

use serde::Deserialize;

use deadreckon_core::vehicle::Noise;
use deadreckon_core::Vehicle;

use crate::error::RosError;
use crate::msgs::MsgType;

/// What a topic feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StreamKind {
    /// `nav_msgs/Odometry` of a differential-drive robot → wheel speeds, front = rear:
    /// v_l = v − ω·track/2, v_r = v + ω·track/2.
    OdometryWheels,
    /// `sensor_msgs/Imu` angular velocity on `yaw_axis` → yaw rate.
    ImuYawRate,
    /// `sensor_msgs/NavSatFix` → GNSS fixes (east/north about the origin).
    NavsatfixGnss,
    /// `geometry_msgs/TwistStamped` twist.linear.x → speed.
    TwistSpeed,
    /// `geometry_msgs/PoseStamped` → reference trajectory.
    PoseTruth,
}

impl StreamKind {
    /// The snake-case name used in mapping files.
    pub fn name(self) -> &'static str {
        match self {
            StreamKind::OdometryWheels => "odometry_wheels",
            StreamKind::ImuYawRate => "imu_yaw_rate",
            StreamKind::NavsatfixGnss => "navsatfix_gnss",
            StreamKind::TwistSpeed => "twist_speed",
            StreamKind::PoseTruth => "pose_truth",
        }
    }
    pub(crate) fn msg_type(self) -> MsgType {
        match self {
            StreamKind::OdometryWheels => MsgType::Odometry,
            StreamKind::ImuYawRate => MsgType::Imu,
            StreamKind::NavsatfixGnss => MsgType::NavSatFix,
            StreamKind::TwistSpeed => MsgType::TwistStamped,
            StreamKind::PoseTruth => MsgType::PoseStamped,
        }
    }
    /// The ROS1 name of the message type the kind reads.
    pub fn msg_type_name(self) -> &'static str {
        match self {
            StreamKind::OdometryWheels => "nav_msgs/Odometry",
            StreamKind::ImuYawRate => "sensor_msgs/Imu",
            StreamKind::NavsatfixGnss => "sensor_msgs/NavSatFix",
            StreamKind::TwistSpeed => "geometry_msgs/TwistStamped",
            StreamKind::PoseTruth => "geometry_msgs/PoseStamped",
        }
    }
}

/// The signed IMU axis that points up in the vehicle (its rate is the yaw rate,
/// counter-clockwise positive). IMU mounts rotate it: on the Husky bag it is `y`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, serde::Serialize)]
pub enum YawAxis {
    /// +x.
    #[serde(rename = "x")]
    X,
    /// −x.
    #[serde(rename = "-x")]
    NegX,
    /// +y.
    #[serde(rename = "y")]
    Y,
    /// −y.
    #[serde(rename = "-y")]
    NegY,
    /// +z (the REP-103 mount).
    #[serde(rename = "z")]
    Z,
    /// −z.
    #[serde(rename = "-z")]
    NegZ,
}

impl YawAxis {
    /// All six axes.
    pub const ALL: [YawAxis; 6] = [
        YawAxis::X,
        YawAxis::NegX,
        YawAxis::Y,
        YawAxis::NegY,
        YawAxis::Z,
        YawAxis::NegZ,
    ];

    /// The yaw rate from an angular velocity (x, y, z).
    pub fn pick(self, w: [f64; 3]) -> f64 {
        match self {
            YawAxis::X => w[0],
            YawAxis::NegX => -w[0],
            YawAxis::Y => w[1],
            YawAxis::NegY => -w[1],
            YawAxis::Z => w[2],
            YawAxis::NegZ => -w[2],
        }
    }
}

/// Where a sample's time comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum TimeSource {
    /// `header.stamp`; the record (log) time when the stamp is zero (counted).
    #[default]
    Header,
    /// The record time of the bag, or the log time of the MCAP message.
    Record,
}

/// One `[[stream]]` of the mapping.
#[derive(Debug, Clone, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct StreamSpec {
    /// Topic name.
    pub topic: String,
    /// What the topic feeds.
    pub kind: StreamKind,
    /// `odometry_wheels`: wheel separation, m (default: the vehicle's rear track).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub track_m: Option<f64>,
    /// `imu_yaw_rate`: the signed up axis of the IMU (default `z`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw_axis: Option<YawAxis>,
    /// `navsatfix_gnss`: std used when a fix has no usable covariance, m (default 5).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_std_m: Option<f64>,
    /// Time source (default `header`).
    #[serde(default)]
    pub time: TimeSource,
}

impl StreamSpec {
    /// A stream with default options.
    pub fn new(topic: &str, kind: StreamKind) -> Self {
        StreamSpec {
            topic: topic.to_owned(),
            kind,
            track_m: None,
            yaw_axis: None,
            fallback_std_m: None,
            time: TimeSource::Header,
        }
    }
}

/// Default GNSS standard deviation when a fix carries no covariance, m.
pub const DEFAULT_FALLBACK_STD_M: f64 = 5.0;

/// The mapping from topics to drive streams, with the vehicle.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    /// The vehicle of the drive.
    pub vehicle: Vehicle,
    /// The streams to read.
    pub streams: Vec<StreamSpec>,
    /// When true (the default), a mapped topic missing from the file is an error;
    /// when false it is reported as a stream with no messages.
    pub require_topics: bool,
}

#[derive(Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
struct MappingFile {
    #[serde(default = "yes")]
    require_topics: bool,
    #[serde(default)]
    stream: Vec<StreamSpec>,
    #[serde(default)]
    vehicle: Option<Vehicle>,
}

fn yes() -> bool {
    true
}

/// Clearpath Husky: track 0.555 m (Clearpath's Husky specification, wheel
/// separation of `husky_control`), wheel radius 0.1651 m (13-inch wheels).
/// Its wheelbase (0.512 m) is not used: a skid-steer robot's odometry gives
/// one speed per side, so front = rear and the car model's wheelbase is set small
/// (0.01 m) to make its front-wheel speeds equal the rear ones.
pub fn husky_vehicle() -> Vehicle {
    differential_vehicle(0.555, 0.1651)
}

/// Clearpath Jackal: wheel separation 0.37559 m, wheel radius 0.098 m (`jackal_control`).
pub fn jackal_vehicle() -> Vehicle {
    differential_vehicle(0.37559, 0.098)
}

/// A differential-drive robot: track `track_m`, wheels of radius `wheel_radius_m`,
/// small wheelbase (0.01 m), GNSS antenna over the axle centre (lever arm 0).
pub fn differential_vehicle(track_m: f64, wheel_radius_m: f64) -> Vehicle {
    Vehicle {
        wheelbase_m: 0.01,
        track_front_m: track_m,
        track_rear_m: track_m,
        gnss_lever_arm_m: 0.0,
        // Not used: odometry gives wheel speeds, not ticks.
        ticks_per_rev: 1,
        wheel_circumference_m: 2.0 * std::f64::consts::PI * wheel_radius_m,
        steering_ratio: 1.0,
        wheels_present: [true; 4],
        origin: None,
        noise: Noise::default(),
        vehicle_id: None,
        recorded_at: None,
        steering_offset_rad: 0.0,
        understeer_gradient_rad_per_mps2: 0.0,
        rear_slip_gradient_rad_per_mps2: 0.0,
    }
}

impl Mapping {
    /// The built-in mapping of `husky_gps.bag` (robot_localization's test bag):
    /// odometry → wheel speeds with the Husky track, IMU yaw rate on +y (the IMU is
    /// mounted rotated; the sign is chosen by correlation with the odometry yaw
    /// rate: +y gives +0.85, −y −0.85, ±z and ±x below 0.03), NavSatFix → GNSS.
    pub fn husky() -> Self {
        let mut imu = StreamSpec::new("/imu/data", StreamKind::ImuYawRate);
        imu.yaw_axis = Some(YawAxis::Y);
        Mapping {
            vehicle: husky_vehicle(),
            streams: vec![
                StreamSpec::new(
                    "/husky_velocity_controller/odom",
                    StreamKind::OdometryWheels,
                ),
                imu,
                StreamSpec::new("/fix", StreamKind::NavsatfixGnss),
            ],
            require_topics: true,
        }
    }

    /// The built-in mapping of `jackal_no_gps.bag`: odometry and IMU (frame
    /// `base_link`, so yaw on +z), no GNSS.
    pub fn jackal() -> Self {
        let mut imu = StreamSpec::new("/imu/data", StreamKind::ImuYawRate);
        imu.yaw_axis = Some(YawAxis::Z);
        Mapping {
            vehicle: jackal_vehicle(),
            streams: vec![
                StreamSpec::new(
                    "/jackal_velocity_controller/odom",
                    StreamKind::OdometryWheels,
                ),
                imu,
            ],
            require_topics: true,
        }
    }

    /// The mapping as a mapping file (with its `[vehicle]`), which
    /// [`Mapping::from_toml_str`] reads back to the same mapping.
    pub fn to_toml_string(&self) -> Result<String, RosError> {
        let f = MappingFile {
            require_topics: self.require_topics,
            stream: self.streams.clone(),
            vehicle: Some(self.vehicle.clone()),
        };
        toml::to_string(&f).map_err(|e| RosError::Mapping(e.to_string()))
    }

    /// Reads a mapping file (see the module doc) and validates it.
    pub fn from_toml_str(s: &str) -> Result<Self, RosError> {
        let f: MappingFile = toml::from_str(s).map_err(|e| RosError::Mapping(e.to_string()))?;
        let vehicle = match f.vehicle {
            Some(v) => v,
            None => {
                let mut v = husky_vehicle();
                if let Some(t) = f.stream.iter().find_map(|s| s.track_m) {
                    v.track_front_m = t;
                    v.track_rear_m = t;
                }
                v
            }
        };
        let m = Mapping {
            vehicle,
            streams: f.stream,
            require_topics: f.require_topics,
        };
        m.validate()?;
        Ok(m)
    }

    /// Checks the mapping: a valid vehicle, at least one stream, at most one stream
    /// per drive field, options only on the kinds they belong to, positive numbers.
    pub fn validate(&self) -> Result<(), RosError> {
        self.vehicle
            .validate()
            .map_err(|e| RosError::Mapping(e.to_string()))?;
        if self.streams.is_empty() {
            return Err(RosError::Mapping("no [[stream]]".into()));
        }
        for (i, s) in self.streams.iter().enumerate() {
            let bad =
                |what: &str| RosError::Mapping(format!("stream {} ({}): {what}", i + 1, s.topic));
            if s.topic.is_empty() {
                return Err(bad("empty topic"));
            }
            if let Some(j) = self.streams[..i].iter().position(|o| o.kind == s.kind) {
                return Err(bad(&format!(
                    "kind {} is already fed by stream {} ({}): one topic per stream",
                    s.kind.name(),
                    j + 1,
                    self.streams[j].topic
                )));
            }
            let wrong = |key: &str, kind: StreamKind| {
                bad(&format!("{key} applies to kind {} only", kind.name()))
            };
            if s.track_m.is_some() && s.kind != StreamKind::OdometryWheels {
                return Err(wrong("track_m", StreamKind::OdometryWheels));
            }
            if s.yaw_axis.is_some() && s.kind != StreamKind::ImuYawRate {
                return Err(wrong("yaw_axis", StreamKind::ImuYawRate));
            }
            if s.fallback_std_m.is_some() && s.kind != StreamKind::NavsatfixGnss {
                return Err(wrong("fallback_std_m", StreamKind::NavsatfixGnss));
            }
            for (k, v) in [("track_m", s.track_m), ("fallback_std_m", s.fallback_std_m)] {
                if let Some(v) = v {
                    if !(v.is_finite() && v > 0.0) {
                        return Err(bad(&format!("{k} must be a positive number, got {v}")));
                    }
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_documented_example_parses() {
        let doc: String = include_str!("mapping.rs")
            .lines()
            .skip_while(|l| !l.starts_with("//! ```toml"))
            .skip(1)
            .take_while(|l| !l.starts_with("//! ```"))
            .map(|l| l.trim_start_matches("//!").trim_start_matches(' '))
            .collect::<Vec<_>>()
            .join("\n");
        let m = Mapping::from_toml_str(&doc).unwrap();
        assert_eq!(m.streams.len(), 3);
        assert_eq!(m.streams[1].yaw_axis, Some(YawAxis::Y));
        assert_eq!(m.vehicle, husky_vehicle());
        assert!(m.require_topics);
    }

    #[test]
    fn track_m_sets_the_default_vehicle_track() {
        let m = Mapping::from_toml_str(
            "[[stream]]\ntopic = \"/odom\"\nkind = \"odometry_wheels\"\ntrack_m = 0.4\n",
        )
        .unwrap();
        assert_eq!(
            (m.vehicle.track_front_m, m.vehicle.track_rear_m),
            (0.4, 0.4)
        );
    }

    #[test]
    fn bad_mappings_are_refused() {
        for (toml, needle) in [
            ("", "no [[stream]]"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"imu_yaw_rate\"\n[[stream]]\ntopic = \"/b\"\nkind = \"imu_yaw_rate\"\n", "already fed"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"imu_yaw_rate\"\ntrack_m = 0.5\n", "track_m applies"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"imu_yaw_rate\"\nyaw_axis = \"w\"\n", "unknown variant"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"odometry_wheels\"\ntrack_m = -1.0\n", "positive"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"lidar\"\n", "unknown variant"),
            ("[[stream]]\ntopic = \"/a\"\nkind = \"imu_yaw_rate\"\nyaw = \"z\"\n", "unknown field"),
            ("[[stream]]\ntopic = \"\"\nkind = \"imu_yaw_rate\"\n", "empty topic"),
        ] {
            let e = Mapping::from_toml_str(toml).unwrap_err().to_string();
            assert!(e.contains(needle), "{toml:?}: {e}");
        }
    }

    #[test]
    fn mappings_round_trip_through_toml() {
        for m in [Mapping::husky(), Mapping::jackal()] {
            let text = m.to_toml_string().unwrap();
            assert_eq!(Mapping::from_toml_str(&text).unwrap(), m, "{text}");
        }
    }

    #[test]
    fn yaw_axes_pick_signed_components() {
        let w = [1.0, 2.0, 3.0];
        let got: Vec<f64> = YawAxis::ALL.iter().map(|a| a.pick(w)).collect();
        assert_eq!(got, [1.0, -1.0, 2.0, -2.0, 3.0, -3.0]);
    }
}
