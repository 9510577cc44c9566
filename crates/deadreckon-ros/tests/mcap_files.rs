//! MCAP: reading a generated ROS2 (CDR) fixture, and the Foxglove writer round trip.

mod common;

use std::collections::BTreeMap;

use common::*;
use deadreckon_core::drive::{GnssFix, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::{Track, TrackPoint};
use deadreckon_ros::{list_topics_bytes, read_mcap_bytes, write_mcap, write_tracks_mcap, Mapping};

const CLEAN: Quirks = Quirks {
    duplicate_odom: false,
    zero_stamp_imu: false,
    no_fix: false,
    message_compression: None,
};
const QUIRKY: Quirks = Quirks {
    duplicate_odom: true,
    zero_stamp_imu: true,
    no_fix: true,
    message_compression: None,
};

#[test]
fn ros2_mcap_round_trip() {
    let mapping = Mapping::from_toml_str(MAPPING).unwrap();
    for chunked in [true, false] {
        let bytes = ros2_mcap(chunked, &CLEAN);
        let (drive, report) = read_mcap_bytes(&bytes, "fixture.mcap", &mapping).unwrap();
        drive.validate().unwrap();
        assert_eq!(report.format, "mcap");
        let Wheels::Speeds(s) = &drive.wheels else {
            panic!("speeds")
        };
        assert_eq!(s.len(), 401);
        assert_eq!(drive.yaw_rate.len(), 1001);
        assert_eq!(drive.gnss.len(), 21);
        assert_eq!(drive.speed.len(), 201);
        assert_eq!(drive.truth.len(), 201);
        assert_eq!(report.dropped(), 0);
        // v ∓ ω·track/2 with track 0.5.
        assert!(
            (s[7].rl_mps - (V - W * 0.25)).abs() < 1e-12
                && (s[7].rr_mps - (V + W * 0.25)).abs() < 1e-12
        );
        assert_eq!((s[7].fl_mps, s[7].fr_mps), (s[7].rl_mps, s[7].rr_mps));
        assert!((s[7].t_s - (T0 + 0.35)).abs() < 1e-6);
        assert!(drive.yaw_rate.iter().all(|y| y.value == W));
        // Fixes: east/north about the first fix (which is at the circle's start), std 2 m.
        for (k, g) in drive.gnss.iter().enumerate() {
            let (e, n, _) = circle(k as f64);
            assert!(
                (g.east_m - e).abs() < 1e-3 && (g.north_m - n).abs() < 1e-3,
                "{k}: {g:?} vs {e} {n}"
            );
            assert_eq!(g.std_m, 2.0);
        }
        let o = drive.vehicle.origin.unwrap();
        assert!((o.lat_deg - LAT0).abs() < 1e-12 && (o.lon_deg - LON0).abs() < 1e-12);
        let tr = &drive.truth[100];
        let (e, n, yaw) = circle(10.0);
        assert!(
            (tr.east_m - e).abs() < 1e-9
                && (tr.north_m - n).abs() < 1e-9
                && (tr.yaw_rad - yaw).abs() < 1e-9
        );
        let topics = list_topics_bytes(&bytes, "fixture.mcap").unwrap();
        let summary: Vec<(&str, &str, u64)> = topics
            .iter()
            .map(|t| (t.topic.as_str(), t.msg_type.as_str(), t.messages))
            .collect();
        assert_eq!(
            summary,
            [
                ("/cmd_vel", "geometry_msgs/msg/TwistStamped", 201),
                ("/gps/fix", "sensor_msgs/msg/NavSatFix", 21),
                ("/ground_truth", "geometry_msgs/msg/PoseStamped", 201),
                ("/imu", "sensor_msgs/msg/Imu", 1001),
                ("/odom", "nav_msgs/msg/Odometry", 401),
            ]
        );
        assert!(topics.iter().all(|t| t.encoding == "cdr"));
    }
}

#[test]
fn ros2_mcap_quirks_are_gated_and_counted() {
    let mapping = Mapping::from_toml_str(MAPPING).unwrap();
    let bytes = ros2_mcap(true, &QUIRKY);
    let (drive, report) = read_mcap_bytes(&bytes, "fixture.mcap", &mapping).unwrap();
    drive.validate().unwrap();
    let by_topic: BTreeMap<&str, _> = report
        .streams
        .iter()
        .map(|s| (s.topic.as_str(), s))
        .collect();
    let odom = by_topic["/odom"];
    assert_eq!(
        (odom.messages, odom.accepted, odom.non_increasing_time),
        (402, 401, 1)
    );
    let imu = by_topic["/imu"];
    // The zero stamp falls back to the log time, which is the true time here.
    assert_eq!((imu.accepted, imu.stamp_missing), (1001, 1));
    let fix = by_topic["/gps/fix"];
    assert_eq!((fix.messages, fix.accepted, fix.no_fix), (21, 20, 1));
    assert_eq!(report.dropped(), 2);
}

#[test]
fn vehicle_origin_is_used_when_given() {
    let mut mapping = Mapping::from_toml_str(MAPPING).unwrap();
    mapping.vehicle.origin = Some(Origin {
        lat_deg: LAT0 - 0.001,
        lon_deg: LON0,
        height_m: 0.0,
    });
    let (drive, _) = read_mcap_bytes(&ros2_mcap(true, &CLEAN), "fixture.mcap", &mapping).unwrap();
    // 0.001° of latitude is about 111 m.
    assert!(
        (drive.gnss[0].north_m - 111.0).abs() < 1.0 && drive.gnss[0].east_m.abs() < 1e-6,
        "{:?}",
        drive.gnss[0]
    );
}

fn track(name: &str, origin: Option<Origin>, n: usize) -> Track {
    let points = (0..n)
        .map(|k| {
            let (e, n, yaw) = circle(k as f64 * 0.1);
            TrackPoint {
                t_s: T0 + k as f64 * 0.1,
                east_m: e,
                north_m: n,
                yaw_rad: yaw,
                speed_mps: V,
                yaw_rate_rps: W,
                cov_pose: [0.25, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.01],
            }
        })
        .collect();
    Track {
        name: name.into(),
        points,
        origin,
    }
}

#[test]
fn foxglove_writer_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("tracks.mcap");
    let origin = Origin {
        lat_deg: LAT0,
        lon_deg: LON0,
        height_m: 0.0,
    };
    let tracks = [
        track("smoothed", Some(origin), 150),
        track("dead reckoned", None, 120),
    ];
    let fixes: Vec<GnssFix> = (0..20)
        .map(|k| {
            let (e, n, _) = circle(k as f64);
            GnssFix {
                t_s: T0 + k as f64,
                east_m: e,
                north_m: n,
                std_m: 2.0,
                course_deg: None,
                speed_mps: None,
            }
        })
        .collect();
    write_mcap(&path, &tracks, Some((&fixes, origin))).unwrap();
    // Nothing but the file is left in the directory (atomic write through a temporary).
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["tracks.mcap"]);

    let bytes = std::fs::read(&path).unwrap();
    let mut counts: BTreeMap<String, (String, String, String, usize)> = BTreeMap::new();
    let mut first_fix = None;
    let mut first_gnss = None;
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        let m = m.unwrap();
        let schema = m.channel.schema.as_ref().unwrap();
        let e = counts.entry(m.channel.topic.clone()).or_insert_with(|| {
            (
                schema.name.clone(),
                schema.encoding.clone(),
                m.channel.message_encoding.clone(),
                0,
            )
        });
        e.3 += 1;
        let v: serde_json::Value = serde_json::from_slice(&m.data).unwrap();
        if m.channel.topic == "/deadreckon/smoothed/fix" && first_fix.is_none() {
            first_fix = Some(v.clone());
        }
        if m.channel.topic == "/deadreckon/gnss/fix" && first_gnss.is_none() {
            first_gnss = Some(v.clone());
        }
        if m.channel.topic.ends_with("/pose") {
            assert_eq!(v["frame_id"], "enu");
            let ns = v["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
                + v["timestamp"]["nsec"].as_u64().unwrap();
            assert_eq!(ns, m.log_time);
        }
    }
    let get = |t: &str| counts[t].clone();
    let pif = (
        "foxglove.PoseInFrame".to_string(),
        "jsonschema".to_string(),
        "json".to_string(),
    );
    let lf = (
        "foxglove.LocationFix".to_string(),
        "jsonschema".to_string(),
        "json".to_string(),
    );
    assert_eq!(counts.len(), 4, "{counts:?}");
    assert_eq!(
        get("/deadreckon/smoothed/pose"),
        (pif.0.clone(), pif.1.clone(), pif.2.clone(), 150)
    );
    assert_eq!(
        get("/deadreckon/smoothed/fix"),
        (lf.0.clone(), lf.1.clone(), lf.2.clone(), 150)
    );
    assert_eq!(
        get("/deadreckon/dead_reckoned/pose"),
        (pif.0, pif.1, pif.2, 120)
    );
    assert_eq!(get("/deadreckon/gnss/fix"), (lf.0, lf.1, lf.2, 20));
    let f = first_fix.unwrap();
    assert!(
        (f["latitude"].as_f64().unwrap() - LAT0).abs() < 1e-9
            && (f["longitude"].as_f64().unwrap() - LON0).abs() < 1e-9
    );
    assert_eq!(f["position_covariance"][0], 0.25);
    // Issue 12: the covariance type said "approximated" where it is known
    // (the filter's east/north covariance), "diagonal known" for a GNSS fix.
    assert_eq!(f["position_covariance_type"], 3);
    assert_eq!(first_gnss.unwrap()["position_covariance_type"], 2);

    // The schemas are valid JSON naming the Foxglove type.
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.schemas.len(), 2);
    for s in summary.schemas.values() {
        let v: serde_json::Value = serde_json::from_slice(&s.data).unwrap();
        assert_eq!(v["title"], s.name.as_str());
        // Issue 12: the embedded schemas had no `required` fields.
        let required: Vec<&str> = v["required"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_str().unwrap())
            .collect();
        assert!(required.contains(&"timestamp") && required.contains(&"frame_id"));
        for (name, p) in v["properties"].as_object().unwrap() {
            assert!(required.contains(&name.as_str()), "{} lacks {name}", s.name);
            if p["type"] == "object" {
                assert!(
                    p["required"].is_array(),
                    "{}.{name} has no `required`",
                    s.name
                );
            }
        }
    }
    // Issue 12: the chunks were written uncompressed.
    assert!(!summary.chunk_indexes.is_empty());
    for c in &summary.chunk_indexes {
        assert_eq!(c.compression, "zstd");
        assert!(c.compressed_size < c.uncompressed_size);
    }
    // A track with the same topic name as another is refused, and nothing is written.
    let p2 = dir.path().join("bad.mcap");
    let e = write_tracks_mcap(&p2, &[track("a b", None, 3), track("a_b", None, 3)]).unwrap_err();
    assert!(e.to_string().contains("a_b"), "{e}");
    assert!(!p2.exists());
    // Negative times cannot be MCAP timestamps: an error, and the old file stays.
    let mut neg = track("neg", None, 3);
    neg.points[0].t_s = -1.0;
    assert!(write_tracks_mcap(&path, &[neg]).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["tracks.mcap"]);
}

/// A ROS1-serialized `geometry_msgs/TwistStamped`: header (seq, stamp, frame_id), twist.
fn ros1_twist(seq: u32, t: f64, v: f64) -> Vec<u8> {
    let mut b = seq.to_le_bytes().to_vec();
    let sec = t.floor();
    b.extend_from_slice(&(sec as u32).to_le_bytes());
    b.extend_from_slice(&(((t - sec) * 1e9).round() as u32).to_le_bytes());
    b.extend_from_slice(&4u32.to_le_bytes());
    b.extend_from_slice(b"base");
    for x in [v, 0.0, 0.0, 0.0, 0.0, 0.3] {
        b.extend_from_slice(&f64::to_le_bytes(x));
    }
    b
}

#[test]
fn ros1_messages_in_mcap() {
    let mut w = mcap::WriteOptions::new()
        .compression(None)
        .create(std::io::Cursor::new(Vec::new()))
        .unwrap();
    let s = w
        .add_schema(
            "geometry_msgs/TwistStamped",
            "ros1msg",
            b"Header header\nTwist twist",
        )
        .unwrap();
    let c = w.add_channel(s, "/vel", "ros1", &BTreeMap::new()).unwrap();
    for k in 0..10u32 {
        let t = T0 + f64::from(k) * 0.1;
        let ns = (t * 1e9).round() as u64;
        let h = mcap::records::MessageHeader {
            channel_id: c,
            sequence: k,
            log_time: ns,
            publish_time: ns,
        };
        // The 5th message repeats the 4th's stamp: gated.
        let stamp = if k == 4 { T0 + 0.3 } else { t };
        w.write_to_known_channel(&h, &ros1_twist(k, stamp, 0.5 + f64::from(k)))
            .unwrap();
    }
    w.finish().unwrap();
    let bytes = w.into_inner().into_inner();
    let m =
        Mapping::from_toml_str("[[stream]]\ntopic = \"/vel\"\nkind = \"twist_speed\"\n").unwrap();
    let (drive, report) = read_mcap_bytes(&bytes, "ros1.mcap", &m).unwrap();
    assert_eq!(drive.speed.len(), 9);
    assert_eq!(report.streams[0].non_increasing_time, 1);
    assert_eq!(drive.speed[0].value, 0.5);
    assert!((drive.speed[1].t_s - (T0 + 0.1)).abs() < 1e-6);
    // The same topic read as odometry is refused with both types named.
    let m = Mapping::from_toml_str("[[stream]]\ntopic = \"/vel\"\nkind = \"odometry_wheels\"\n")
        .unwrap();
    let e = read_mcap_bytes(&bytes, "ros1.mcap", &m)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("nav_msgs/Odometry") && e.contains("geometry_msgs/TwistStamped"),
        "{e}"
    );
}

#[test]
fn per_message_compression_of_rosbag2_was_not_plain_cdr() {
    // rosbag2 with `compression_mode: message` stores each message as one
    // zstd (or lz4) frame: it failed with "encapsulation 28b5 is not plain CDR".
    let mapping = Mapping::from_toml_str(MAPPING).unwrap();
    let (want, _) = read_mcap_bytes(&ros2_mcap(true, &CLEAN), "plain.mcap", &mapping).unwrap();
    for c in ["zstd", "lz4"] {
        let q = Quirks {
            message_compression: Some(c),
            ..CLEAN
        };
        let bytes = ros2_mcap(true, &q);
        let (got, _) = read_mcap_bytes(&bytes, "packed.mcap", &mapping).unwrap();
        assert_eq!(got, want, "{c}");
    }
    // A damaged frame: an error naming the file, the topic and the compression.
    let mut m = ros2_mcap(
        false,
        &Quirks {
            message_compression: Some("zstd"),
            ..CLEAN
        },
    );
    let at = m
        .windows(4)
        .rposition(|w| w == [0x28, 0xb5, 0x2f, 0xfd])
        .unwrap();
    for b in &mut m[at + 4..at + 12] {
        *b = 0xff;
    }
    let e = read_mcap_bytes(&m, "bad.mcap", &mapping)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("bad.mcap") && e.contains("per-message zstd"),
        "{e}"
    );
}

#[test]
fn compressed_chunks() {
    let mapping = Mapping::from_toml_str(MAPPING).unwrap();
    let plain = ros2_mcap(true, &CLEAN);
    let (want, _) = read_mcap_bytes(&plain, "plain.mcap", &mapping).unwrap();
    let kinds = [
        ("lz4", cfg!(feature = "lz4")),
        ("zstd", cfg!(feature = "zstd")),
    ];
    for (c, enabled) in kinds {
        let packed = recompress_mcap(&plain, c);
        if !enabled {
            let e = read_mcap_bytes(&packed, "packed.mcap", &mapping).unwrap_err();
            assert!(e.to_string().contains(&format!("`{c}` feature")), "{e}");
            continue;
        }
        assert!(
            packed.len() < plain.len() / 2,
            "{c}: {} vs {}",
            packed.len(),
            plain.len()
        );
        let (got, _) = read_mcap_bytes(&packed, "packed.mcap", &mapping).unwrap();
        assert_eq!(got, want, "{c}");
        // A flipped byte in the compressed data: a decompression or CRC error naming the chunk.
        let mut bad = packed.clone();
        let at = packed.len() / 3;
        bad[at] ^= 0x10;
        match read_mcap_bytes(&bad, "bad.mcap", &mapping) {
            Err(e) => assert!(e.to_string().starts_with("bad.mcap"), "{e}"),
            Ok((d, _)) => assert_ne!(d, want, "{c}: corruption went unnoticed"),
        }
    }
}

#[test]
fn a_rosbag2_directory_is_read_through_its_mcap_file() {
    let mapping = Mapping::from_toml_str(MAPPING).unwrap();
    let bytes = ros2_mcap(true, &CLEAN);
    let (want, _) = read_mcap_bytes(&bytes, "plain.mcap", &mapping).unwrap();
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("run1");
    std::fs::create_dir(&dir).unwrap();
    // Not a bag yet: no metadata.yaml.
    let e = deadreckon_ros::read_log(&dir, &mapping)
        .unwrap_err()
        .to_string();
    assert!(e.contains("metadata.yaml"), "{e}");
    std::fs::write(dir.join("metadata.yaml"), "rosbag2_bagfile_information:\n").unwrap();
    let e = deadreckon_ros::read_log(&dir, &mapping)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no .mcap"), "{e}");
    std::fs::write(dir.join("run1_0.mcap"), &bytes).unwrap();
    let (got, _) = deadreckon_ros::read_log(&dir, &mapping).unwrap();
    assert_eq!(got, want);
    std::fs::write(dir.join("run1_1.mcap"), &bytes).unwrap();
    let e = deadreckon_ros::read_log(&dir, &mapping)
        .unwrap_err()
        .to_string();
    assert!(e.contains("split over 2"), "{e}");
}

/// docs/ros.md's mapping example is a mapping this crate reads, equal to the
/// one in the `mapping` module's documentation.
#[test]
fn the_mapping_in_docs_ros_md_parses() {
    let doc = include_str!("../../../docs/ros.md");
    let toml: String = doc
        .lines()
        .skip_while(|l| *l != "```toml")
        .skip(1)
        .take_while(|l| *l != "```")
        .collect::<Vec<_>>()
        .join("\n");
    let m = Mapping::from_toml_str(&toml).unwrap();
    assert_eq!(m.streams.len(), 3);
    assert_eq!(m.streams[0].topic, "/husky_velocity_controller/odom");
    assert!(m.require_topics);
}
