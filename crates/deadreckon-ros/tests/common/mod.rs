//! Fixtures shared by the tests: a ROS2 MCAP written with the `mcap` crate.
#![allow(dead_code)]

use std::collections::BTreeMap;
use std::io::Cursor;

use deadreckon_ros::ros2::{
    encode_cdr, Header, Imu, NavSatFix, NavSatStatus, Odometry, PoseStamped, Quaternion, Time,
    TwistStamped, Vector3,
};

pub const HUSKY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/husky-gps-bag/husky_gps.bag"
);

/// Origin of the fixture's fixes.
pub const LAT0: f64 = 42.0;
pub const LON0: f64 = -71.0;
/// Start time of the fixture, s since the epoch.
pub const T0: f64 = 1_700_000_000.0;
/// Constant speed and yaw rate of the fixture's circle.
pub const V: f64 = 1.0;
pub const W: f64 = 0.1;
/// Duration, s.
pub const DURATION: f64 = 20.0;

pub const MAPPING: &str = r#"
[[stream]]
topic = "/odom"
kind = "odometry_wheels"
track_m = 0.5

[[stream]]
topic = "/imu"
kind = "imu_yaw_rate"
yaw_axis = "z"

[[stream]]
topic = "/gps/fix"
kind = "navsatfix_gnss"

[[stream]]
topic = "/cmd_vel"
kind = "twist_speed"

[[stream]]
topic = "/ground_truth"
kind = "pose_truth"
"#;

fn header(t: f64) -> Header {
    let sec = t.floor();
    Header {
        stamp: Time {
            sec: sec as i32,
            nanosec: ((t - sec) * 1e9).round() as u32,
        },
        frame_id: "base_link".into(),
    }
}

fn ns(t: f64) -> u64 {
    (t * 1e9).round() as u64
}

/// What the fixture holds beyond the clean samples.
pub struct Quirks {
    /// An odometry message repeating the previous stamp (must be gated).
    pub duplicate_odom: bool,
    /// An IMU message with a zero stamp (falls back to the log time).
    pub zero_stamp_imu: bool,
    /// A fix with status -1 (dropped, counted).
    pub no_fix: bool,
    /// Each message's data compressed on its own (`lz4` or `zstd`), as rosbag2
    /// writes with `compression_mode: message`.
    pub message_compression: Option<&'static str>,
}

/// `data` as one frame of `compression` (`lz4` or `zstd`).
pub fn compress_frame(data: &[u8], compression: &str) -> Vec<u8> {
    match compression {
        "lz4" => {
            let mut e = lz4_flex::frame::FrameEncoder::new(Vec::new());
            std::io::Write::write_all(&mut e, data).unwrap();
            e.finish().unwrap()
        }
        "zstd" => {
            ruzstd::encoding::compress_to_vec(data, ruzstd::encoding::CompressionLevel::Fastest)
        }
        c => panic!("{c}"),
    }
}

/// Position on the fixture's circle at time `t` after T0 (east, north, yaw).
pub fn circle(t: f64) -> (f64, f64, f64) {
    let r = V / W;
    let yaw = W * t;
    (r * yaw.sin(), r * (1.0 - yaw.cos()), yaw)
}

/// An MCAP with CDR Odometry (20 Hz), Imu (50 Hz), NavSatFix (1 Hz), TwistStamped
/// (10 Hz) and PoseStamped (10 Hz) messages of a robot driving a circle.
pub fn ros2_mcap(chunked: bool, q: &Quirks) -> Vec<u8> {
    ros2_mcap_for(chunked, q, DURATION)
}

/// [`ros2_mcap`] over `duration_s` seconds.
pub fn ros2_mcap_for(chunked: bool, q: &Quirks, duration_s: f64) -> Vec<u8> {
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .use_chunks(chunked)
        .profile("ros2")
        .create(Cursor::new(Vec::new()))
        .unwrap();
    let meta = BTreeMap::new();
    let ch = |w: &mut mcap::Writer<_>, ty: &str, topic: &str| {
        let s = w
            .add_schema(ty, "ros2msg", b"# definition omitted in the fixture")
            .unwrap();
        w.add_channel(s, topic, "cdr", &meta).unwrap()
    };
    let odom = ch(&mut w, "nav_msgs/msg/Odometry", "/odom");
    let imu = ch(&mut w, "sensor_msgs/msg/Imu", "/imu");
    let fix = ch(&mut w, "sensor_msgs/msg/NavSatFix", "/gps/fix");
    let twist = ch(&mut w, "geometry_msgs/msg/TwistStamped", "/cmd_vel");
    let pose = ch(&mut w, "geometry_msgs/msg/PoseStamped", "/ground_truth");
    // Messages are written in time order, all topics interleaved (1 ms grid).
    let mut seq = 0u32;
    let mut put = |w: &mut mcap::Writer<_>, channel_id: u16, t: f64, data: Vec<u8>| {
        seq += 1;
        let data = match q.message_compression {
            Some(c) => compress_frame(&data, c),
            None => data,
        };
        let h = mcap::records::MessageHeader {
            channel_id,
            sequence: seq,
            log_time: ns(t),
            publish_time: ns(t),
        };
        w.write_to_known_channel(&h, &data).unwrap();
    };
    let steps = (duration_s * 1000.0) as u64;
    for k in 0..=steps {
        let dt = k as f64 / 1000.0;
        let t = T0 + dt;
        if k % 50 == 0 {
            let mut m = Odometry {
                header: header(t),
                child_frame_id: "base_link".into(),
                ..Default::default()
            };
            m.twist.twist.linear.x = V;
            m.twist.twist.angular.z = W;
            m.twist.covariance[5][5] = 0.01;
            let data = encode_cdr(&m).unwrap();
            put(&mut w, odom, t, data.clone());
            if q.duplicate_odom && k == 5000 {
                put(&mut w, odom, t, data);
            }
        }
        if k % 20 == 0 {
            let stamp = if q.zero_stamp_imu && k == 2000 {
                Header::default()
            } else {
                header(t)
            };
            let m = Imu {
                header: stamp,
                orientation: Quaternion {
                    w: 1.0,
                    ..Default::default()
                },
                angular_velocity: Vector3 {
                    x: 0.0,
                    y: 0.0,
                    z: W,
                },
                linear_acceleration: Vector3 {
                    x: 0.0,
                    y: V * W,
                    z: 9.81,
                },
                ..Default::default()
            };
            put(&mut w, imu, t, encode_cdr(&m).unwrap());
        }
        if k % 1000 == 0 {
            let (e, n, _) = circle(dt);
            let (lat, lon, alt) = map_3d::enu2geodetic(
                e,
                n,
                0.0,
                LAT0.to_radians(),
                LON0.to_radians(),
                10.0,
                map_3d::Ellipsoid::WGS84,
            );
            let status = if q.no_fix && k == 3000 { -1 } else { 0 };
            let m = NavSatFix {
                header: header(t),
                status: NavSatStatus { status, service: 1 },
                latitude: lat.to_degrees(),
                longitude: lon.to_degrees(),
                altitude: alt,
                position_covariance: [4.0, 0.0, 0.0, 0.0, 4.0, 0.0, 0.0, 0.0, 9.0],
                position_covariance_type: 2,
            };
            put(&mut w, fix, t, encode_cdr(&m).unwrap());
        }
        if k % 100 == 0 {
            let mut m = TwistStamped {
                header: header(t),
                ..Default::default()
            };
            m.twist.linear.x = V;
            put(&mut w, twist, t, encode_cdr(&m).unwrap());
            let (e, n, yaw) = circle(dt);
            let mut p = PoseStamped {
                header: header(t),
                ..Default::default()
            };
            p.pose.position = Vector3 { x: e, y: n, z: 0.0 };
            p.pose.orientation = Quaternion {
                x: 0.0,
                y: 0.0,
                z: (yaw / 2.0).sin(),
                w: (yaw / 2.0).cos(),
            };
            put(&mut w, pose, t, encode_cdr(&p).unwrap());
        }
    }
    w.finish().unwrap();
    w.into_inner().into_inner()
}

/// Rewrites every chunk of an uncompressed MCAP with `compression` (`lz4` or
/// `zstd`), as a writer with compression would have stored it. The summary's
/// chunk indexes are left stale: the reader walks the data section.
pub fn recompress_mcap(f: &[u8], compression: &str) -> Vec<u8> {
    let mut out = f[..8].to_vec();
    let mut pos = 8;
    while pos < f.len() - 8 {
        let op = f[pos];
        let len = u64::from_le_bytes(f[pos + 1..pos + 9].try_into().unwrap()) as usize;
        let body = &f[pos + 9..pos + 9 + len];
        if op == 0x06 {
            // Chunk: start u64, end u64, uncompressed size u64, crc u32, compression string, records (u64 length).
            let fixed = &body[..28];
            let clen = u32::from_le_bytes(body[28..32].try_into().unwrap()) as usize;
            assert_eq!(clen, 0, "fixture chunks are uncompressed");
            let rlen_at = 32 + clen;
            let records = &body[rlen_at + 8..];
            let packed = match compression {
                "lz4" => {
                    let mut e = lz4_flex::frame::FrameEncoder::new(Vec::new());
                    std::io::Write::write_all(&mut e, records).unwrap();
                    e.finish().unwrap()
                }
                "zstd" => ruzstd::encoding::compress_to_vec(
                    records,
                    ruzstd::encoding::CompressionLevel::Fastest,
                ),
                c => panic!("{c}"),
            };
            let mut b = fixed.to_vec();
            b.extend_from_slice(&(compression.len() as u32).to_le_bytes());
            b.extend_from_slice(compression.as_bytes());
            b.extend_from_slice(&(packed.len() as u64).to_le_bytes());
            b.extend_from_slice(&packed);
            out.push(op);
            out.extend_from_slice(&(b.len() as u64).to_le_bytes());
            out.extend_from_slice(&b);
        } else {
            out.extend_from_slice(&f[pos..pos + 9 + len]);
        }
        pos += 9 + len;
    }
    out.extend_from_slice(&f[pos..]);
    out
}

/// One ROS1 bag record: header fields (`name=value`) and data, with lengths.
pub fn record(fields: &[(&str, &[u8])], data: &[u8]) -> Vec<u8> {
    let mut h = Vec::new();
    for (k, v) in fields {
        h.extend_from_slice(&((k.len() + 1 + v.len()) as u32).to_le_bytes());
        h.extend_from_slice(k.as_bytes());
        h.push(b'=');
        h.extend_from_slice(v);
    }
    let mut r = (h.len() as u32).to_le_bytes().to_vec();
    r.extend_from_slice(&h);
    r.extend_from_slice(&(data.len() as u32).to_le_bytes());
    r.extend_from_slice(data);
    r
}

/// A bag with a bag header, one uncompressed chunk holding a connection and
/// one message of `payload`.
pub fn tiny_bag(payload: &[u8]) -> Vec<u8> {
    tiny_bag_with(payload, "none")
}

/// [`tiny_bag`] with its chunk stored with `compression` (`none` or `lz4`).
pub fn tiny_bag_with(payload: &[u8], compression: &str) -> Vec<u8> {
    let mut conn_hdr = Vec::new();
    for (k, v) in [
        ("topic", "/husky_velocity_controller/odom"),
        ("type", "nav_msgs/Odometry"),
        ("md5sum", "cd5e73d190d741a2f92e81eda573aca7"),
    ] {
        conn_hdr.extend_from_slice(&((k.len() + 1 + v.len()) as u32).to_le_bytes());
        conn_hdr.extend_from_slice(format!("{k}={v}").as_bytes());
    }
    let conn = record(
        &[
            ("op", &[7]),
            ("conn", &0u32.to_le_bytes()),
            ("topic", b"/husky_velocity_controller/odom"),
        ],
        &conn_hdr,
    );
    let time = [1u32.to_le_bytes(), 0u32.to_le_bytes()].concat();
    let msg = record(
        &[("op", &[2]), ("conn", &0u32.to_le_bytes()), ("time", &time)],
        payload,
    );
    let inner = [conn, msg].concat();
    let stored = match compression {
        "none" => inner.clone(),
        "lz4" => {
            let mut e = lz4_flex::frame::FrameEncoder::new(Vec::new());
            std::io::Write::write_all(&mut e, &inner).unwrap();
            e.finish().unwrap()
        }
        c => panic!("{c}"),
    };
    let chunk = record(
        &[
            ("op", &[5]),
            ("compression", compression.as_bytes()),
            ("size", &(inner.len() as u32).to_le_bytes()),
        ],
        &stored,
    );
    let mut out = b"#ROSBAG V2.0\n".to_vec();
    let header = |index_pos: u64| {
        record(
            &[
                ("op", &[3]),
                ("index_pos", &index_pos.to_le_bytes()),
                ("conn_count", &1u32.to_le_bytes()),
                ("chunk_count", &1u32.to_le_bytes()),
            ],
            &[],
        )
    };
    // The bag ends after the chunk: index_pos points at the end (an empty index).
    let h = header((13 + header(0).len() + chunk.len()) as u64);
    out.extend_from_slice(&h);
    out.extend_from_slice(&chunk);
    out
}
