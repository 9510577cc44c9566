//! Tracks written as ROS 2 `nav_msgs/msg/Odometry` (CDR, `ros2msg` schema) in
//! MCAP, read back by the `mcap` crate with our CDR decoder and by our own
//! MCAP reader.

use deadreckon_core::drive::Wheels;
use deadreckon_core::{Track, TrackPoint};
use deadreckon_ros::ros2::{decode_cdr, Odometry};
use deadreckon_ros::ros2_out::{odometry_schema, CHILD_FRAME_ID, ODOMETRY_SCHEMA_NAME};
use deadreckon_ros::{read_mcap_bytes, write_mcap_with, Mapping, McapOptions};

const T0: f64 = 1_700_000_000.0;

fn track(name: &str, n: usize) -> Track {
    Track {
        name: name.into(),
        points: (0..n)
            .map(|k| {
                let t = k as f64 * 0.1;
                TrackPoint {
                    t_s: T0 + t,
                    east_m: 3.0 * t,
                    north_m: -1.0 + 0.5 * t * t,
                    yaw_rad: 0.3 * t - 1.0,
                    speed_mps: 3.0 + t,
                    yaw_rate_rps: 0.3,
                    cov_pose: [0.04, 0.01, 0.002, 0.01, 0.09, 0.003, 0.002, 0.003, 0.0004],
                }
            })
            .collect(),
        origin: None,
    }
}

#[test]
fn odometry_round_trips_through_mcap_and_cdr() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ros2.mcap");
    let tracks = [track("dead-reckoned", 50), track("smoothed", 40)];
    write_mcap_with(&path, &tracks, None, McapOptions::ROS2).unwrap();
    let bytes = std::fs::read(&path).unwrap();

    // A ros2-profile file: cdr channels with the QoS metadata, ros2msg schemas.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.schemas.len(), 1);
    let schema = summary.schemas.values().next().unwrap();
    assert_eq!(
        (schema.name.as_str(), schema.encoding.as_str()),
        (ODOMETRY_SCHEMA_NAME, "ros2msg")
    );
    assert_eq!(&schema.data[..], odometry_schema().as_bytes());
    let mut topics: Vec<(String, String)> = summary
        .channels
        .values()
        .map(|c| (c.topic.clone(), c.message_encoding.clone()))
        .collect();
    topics.sort();
    assert_eq!(
        topics,
        [
            ("/deadreckon/dead_reckoned/odom".into(), "cdr".into()),
            ("/deadreckon/smoothed/odom".into(), "cdr".into()),
        ]
    );
    for c in summary.channels.values() {
        assert_eq!(
            c.metadata.get("offered_qos_profiles").map(String::as_str),
            Some("")
        );
    }
    let header_profile = {
        // The header record follows the 8 magic bytes: opcode 1, length, profile string.
        let len = u32::from_le_bytes(bytes[17..21].try_into().unwrap()) as usize;
        String::from_utf8(bytes[21..21 + len].to_vec()).unwrap()
    };
    assert_eq!(header_profile, "ros2");

    let mut n = 0;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let odom: Odometry = decode_cdr(&m.data).unwrap();
        let tr = if m.channel.topic.contains("smoothed") {
            &tracks[1]
        } else {
            &tracks[0]
        };
        let p = &tr.points[m.sequence as usize];
        n += 1;
        let stamp = f64::from(odom.header.stamp.sec) + f64::from(odom.header.stamp.nanosec) * 1e-9;
        assert!((stamp - p.t_s).abs() < 1e-6, "{stamp} {}", p.t_s);
        assert_eq!(m.log_time, (p.t_s * 1e9).round() as u64);
        assert_eq!(odom.header.frame_id, "enu");
        assert_eq!(odom.child_frame_id, CHILD_FRAME_ID);
        let pos = odom.pose.pose.position;
        assert_eq!((pos.x, pos.y, pos.z), (p.east_m, p.north_m, 0.0));
        let q = odom.pose.pose.orientation;
        assert_eq!((q.x, q.y), (0.0, 0.0));
        let yaw = 2.0 * q.z.atan2(q.w);
        assert!(deadreckon_core::angle::wrap(yaw - p.yaw_rad).abs() < 1e-12);
        // (x, y, yaw) of the track at rows/columns 0, 1, 5 of (x, y, z, roll, pitch, yaw).
        let c = odom.pose.covariance;
        assert_eq!([c[0][0], c[0][1], c[0][5]], [0.04, 0.01, 0.002]);
        assert_eq!([c[1][1], c[1][5], c[5][5]], [0.09, 0.003, 0.0004]);
        assert_eq!([c[5][0], c[2][2], c[3][3], c[4][4]], [0.002, 0.0, 0.0, 0.0]);
        assert_eq!(odom.twist.twist.linear.x, p.speed_mps);
        assert_eq!(odom.twist.twist.angular.z, p.yaw_rate_rps);
    }
    assert_eq!(n, 90);

    // Our own reader takes the Odometry topic as a differential drive's wheels:
    // v ∓ ω·track/2.
    let mapping = Mapping::from_toml_str(
        "[[stream]]\ntopic = \"/deadreckon/dead_reckoned/odom\"\nkind = \"odometry_wheels\"\ntrack_m = 0.5\n",
    )
    .unwrap();
    let (drive, report) = read_mcap_bytes(&bytes, "ros2.mcap", &mapping).unwrap();
    assert_eq!(report.dropped(), 0);
    let Wheels::Speeds(s) = &drive.wheels else {
        panic!("speeds")
    };
    assert_eq!(s.len(), 50);
    for (w, p) in s.iter().zip(&tracks[0].points) {
        assert!((w.t_s - p.t_s).abs() < 1e-6);
        assert!((w.rl_mps - (p.speed_mps - 0.3 * 0.25)).abs() < 1e-12);
        assert!((w.rr_mps - (p.speed_mps + 0.3 * 0.25)).abs() < 1e-12);
    }
}

#[test]
fn both_carries_foxglove_and_ros2_messages_and_bad_stamps_are_errors() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("both.mcap");
    write_mcap_with(&path, &[track("dead-reckoned", 5)], None, McapOptions::BOTH).unwrap();
    let bytes = std::fs::read(&path).unwrap();
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    let mut topics: Vec<&str> = summary
        .channels
        .values()
        .map(|c| c.topic.as_str())
        .collect();
    topics.sort();
    assert_eq!(
        topics,
        [
            "/deadreckon/dead_reckoned/odom",
            "/deadreckon/dead_reckoned/pose"
        ]
    );
    assert_eq!(summary.stats.unwrap().message_count, 10);

    // Beyond int32 seconds (2038): no ROS 2 stamp, an error naming the track
    // and the time, and nothing written.
    let late = dir.path().join("late.mcap");
    let mut t = track("late", 3);
    t.points[2].t_s = 2_200_000_000.0;
    let e = write_mcap_with(&late, &[t], None, McapOptions::ROS2)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("late.mcap") && e.contains("2200000000") && e.contains("`late`"),
        "{e}"
    );
    assert!(!late.exists());
    let e = write_mcap_with(
        &late,
        &[track("x", 3)],
        None,
        McapOptions {
            foxglove: false,
            ros2_odometry: false,
        },
    )
    .unwrap_err();
    assert!(e.to_string().contains("needs Foxglove or ROS 2"), "{e}");
}

#[test]
fn the_schema_names_every_type_it_uses() {
    let s = odometry_schema();
    let sections: Vec<&str> = s.split(&format!("{}\n", "=".repeat(80))).collect();
    assert_eq!(sections.len(), 10);
    let defined: Vec<&str> = sections[1..]
        .iter()
        .map(|sec| sec.lines().next().unwrap().strip_prefix("MSG: ").unwrap())
        .collect();
    // Every non-primitive field type is defined once.
    for sec in &sections {
        for line in sec.lines().filter(|l| !l.starts_with("MSG: ")) {
            let ty = line.split(' ').next().unwrap().trim_end_matches("[36]");
            if ty.contains('/') {
                assert_eq!(defined.iter().filter(|d| **d == ty).count(), 1, "{ty}");
            }
        }
    }
}
