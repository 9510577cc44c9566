//! Tracks as ROS 2 `nav_msgs/msg/Odometry` messages (CDR, with a `ros2msg`
//! schema), so ROS tools read them from an MCAP file: `ros2 bag play`, the
//! `rosbags` library, `evo_traj mcap`, Foxglove.
//!
//! Per track `<name>`: `/deadreckon/<name>/odom`, with
//!
//! - `header.stamp` the pose's time (`builtin_interfaces/Time`: seconds as
//!   int32, so 0 ≤ t < 2³¹ s), `header.frame_id` [`FRAME_ID`]
//!   (the drive's local east-north-up frame), `child_frame_id` [`CHILD_FRAME_ID`];
//! - the pose: position (east, north, 0), orientation the yaw about z;
//!   covariance (x, y, z, roll, pitch, yaw, row-major) with the track's
//!   east/north/yaw block, zero elsewhere (planar: z, roll, pitch are not
//!   estimated);
//! - the twist in the child frame: linear.x the speed, angular.z the yaw rate;
//!   covariance zero (not part of a track).

use deadreckon_core::TrackPoint;

use crate::ros2::{
    Header, Odometry, Pose, PoseWithCovariance, Quaternion, Time, Twist, TwistWithCovariance,
    Vector3,
};

/// The schema name of the messages.
pub const ODOMETRY_SCHEMA_NAME: &str = "nav_msgs/msg/Odometry";

/// The frame of the poses: the local east-north-up frame of the drive
/// (the Foxglove poses' too, [`crate::foxglove`]).
pub const FRAME_ID: &str = "enu";

/// The frame the twist is in: the vehicle (rear-axle centre, REP 105's `base_link`).
pub const CHILD_FRAME_ID: &str = "base_link";

/// The `ros2msg` schema of `nav_msgs/msg/Odometry`: its definition, then each
/// type it uses after a line of 80 `=` and `MSG: package/Type` (the MCAP
/// registry's concatenated format; comments and constants left out).
pub fn odometry_schema() -> String {
    let sep = "=".repeat(80);
    let parts: [(&str, &str); 10] = [
        (
            "",
            "std_msgs/Header header\nstring child_frame_id\n\
             geometry_msgs/PoseWithCovariance pose\ngeometry_msgs/TwistWithCovariance twist\n",
        ),
        (
            "std_msgs/Header",
            "builtin_interfaces/Time stamp\nstring frame_id\n",
        ),
        ("builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"),
        (
            "geometry_msgs/PoseWithCovariance",
            "geometry_msgs/Pose pose\nfloat64[36] covariance\n",
        ),
        (
            "geometry_msgs/Pose",
            "geometry_msgs/Point position\ngeometry_msgs/Quaternion orientation\n",
        ),
        ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
        (
            "geometry_msgs/Quaternion",
            "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n",
        ),
        (
            "geometry_msgs/TwistWithCovariance",
            "geometry_msgs/Twist twist\nfloat64[36] covariance\n",
        ),
        (
            "geometry_msgs/Twist",
            "geometry_msgs/Vector3 linear\ngeometry_msgs/Vector3 angular\n",
        ),
        ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
    ];
    let mut out = String::new();
    for (name, body) in parts {
        if !name.is_empty() {
            out.push_str(&format!("{sep}\nMSG: {name}\n"));
        }
        out.push_str(body);
    }
    out
}

/// The ROS 2 stamp of a time in seconds, or `None` outside what
/// `builtin_interfaces/Time` holds (0 ≤ t < 2³¹ s here).
pub fn stamp(t_s: f64) -> Option<Time> {
    let ns = (t_s * 1e9).round();
    if !(ns.is_finite() && ns >= 0.0 && ns < f64::from(i32::MAX) * 1e9) {
        return None;
    }
    let ns = ns as u64;
    Some(Time {
        sec: i32::try_from(ns / 1_000_000_000).ok()?,
        nanosec: (ns % 1_000_000_000) as u32,
    })
}

/// The Odometry message of one track pose (see the module doc), or `None`
/// when its time has no ROS 2 stamp.
pub fn odometry(p: &TrackPoint) -> Option<Odometry> {
    odometry_in(p, FRAME_ID)
}

/// [`odometry`] with the pose in frame `frame_id` (the live node's `odom`).
pub fn odometry_in(p: &TrackPoint, frame_id: &str) -> Option<Odometry> {
    let half = 0.5 * p.yaw_rad;
    // 6 × 6 over (x, y, z, roll, pitch, yaw); the track's 3 × 3 is over (x, y, yaw).
    let mut cov = [[0.0; 6]; 6];
    let at = [0usize, 1, 5];
    for (a, &i) in at.iter().enumerate() {
        for (b, &j) in at.iter().enumerate() {
            cov[i][j] = p.cov_pose[3 * a + b];
        }
    }
    Some(Odometry {
        header: Header {
            stamp: stamp(p.t_s)?,
            frame_id: frame_id.into(),
        },
        child_frame_id: CHILD_FRAME_ID.into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: Vector3 {
                    x: p.east_m,
                    y: p.north_m,
                    z: 0.0,
                },
                orientation: Quaternion {
                    x: 0.0,
                    y: 0.0,
                    z: half.sin(),
                    w: half.cos(),
                },
            },
            covariance: cov,
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: Vector3 {
                    x: p.speed_mps,
                    y: 0.0,
                    z: 0.0,
                },
                angular: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: p.yaw_rate_rps,
                },
            },
            covariance: [[0.0; 6]; 6],
        },
    })
}
