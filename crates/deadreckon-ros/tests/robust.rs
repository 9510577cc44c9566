//! Truncated, corrupted and arbitrary inputs give errors, never panics.

mod common;

use common::*;
use deadreckon_ros::{list_topics_bytes, read_mcap_bytes, read_rosbag_bytes, Mapping, RosError};
use proptest::prelude::*;

const CLEAN: Quirks = Quirks {
    duplicate_odom: false,
    zero_stamp_imu: false,
    no_fix: false,
    message_compression: None,
};

fn husky() -> Vec<u8> {
    std::fs::read(HUSKY).unwrap()
}

fn lenient(mut m: Mapping) -> Mapping {
    m.require_topics = false;
    m
}

/// Offsets spread over the whole input, plus the first few bytes.
fn offsets(len: usize, n: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (0..20).collect();
    v.extend((1..n).map(|k| k * len / n));
    v.push(len - 1);
    v
}

#[test]
fn truncated_bag_is_an_error_with_an_offset() {
    let bag = husky();
    let m = Mapping::husky();
    for cut in offsets(bag.len(), 40) {
        let r = read_rosbag_bytes(&bag[..cut], "cut.bag", &m);
        let e = r
            .err()
            .unwrap_or_else(|| panic!("bag cut at {cut} was accepted"));
        assert!(
            matches!(e, RosError::Format { .. } | RosError::Compression { .. }),
            "cut {cut}: {e}"
        );
        let s = e.to_string();
        assert!(
            s.starts_with("cut.bag") && (cut < 13 || s.contains("byte")),
            "cut {cut}: {s}"
        );
        assert!(list_topics_bytes(&bag[..cut], "cut.bag").is_err());
    }
}

#[test]
fn corrupted_bag_never_panics() {
    let bag = husky();
    let m = lenient(Mapping::husky());
    let mut errors = 0;
    for (i, at) in offsets(bag.len(), 30).into_iter().enumerate() {
        let mut b = bag.clone();
        b[at] ^= 0xff ^ (i as u8);
        if read_rosbag_bytes(&b, "flip.bag", &m).is_err() {
            errors += 1;
        }
        let _ = list_topics_bytes(&b, "flip.bag");
    }
    assert!(errors > 10, "{errors}");
}

#[test]
fn truncated_mcap_is_an_error() {
    let m = Mapping::from_toml_str(MAPPING).unwrap();
    for chunked in [true, false] {
        let f = ros2_mcap(chunked, &CLEAN);
        for cut in offsets(f.len(), 50) {
            let e = read_mcap_bytes(&f[..cut], "cut.mcap", &m).err();
            let e = e.unwrap_or_else(|| panic!("mcap cut at {cut} was accepted"));
            assert!(e.to_string().starts_with("cut.mcap"), "{e}");
            assert!(list_topics_bytes(&f[..cut], "cut.mcap").is_err());
        }
    }
}

#[test]
fn corrupted_mcap_never_panics() {
    let m = lenient(Mapping::from_toml_str(MAPPING).unwrap());
    for chunked in [true, false] {
        let f = ros2_mcap(chunked, &CLEAN);
        for (i, at) in offsets(f.len(), 300).into_iter().enumerate() {
            let mut b = f.clone();
            b[at] ^= 0x5a ^ (i as u8);
            let _ = read_mcap_bytes(&b, "flip.mcap", &m);
            let _ = list_topics_bytes(&b, "flip.mcap");
        }
    }
}

#[test]
fn decode_error_names_topic_and_offset() {
    // A chunk-free bag whose odometry message is one byte short.
    let bag = tiny_bag(&[0u8; 10]);
    let mut m = lenient(Mapping::husky());
    m.streams.truncate(1);
    let e = read_rosbag_bytes(&bag, "tiny.bag", &m)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("tiny.bag")
            && e.contains("/husky_velocity_controller/odom")
            && e.contains("byte"),
        "{e}"
    );
}

proptest! {
    // Seeded (issue 33); `PROPTEST_RNG_SEED=<n>` runs another seed.
    #![proptest_config(ProptestConfig { cases: 512, rng_seed: proptest::test_runner::RngSeed::Fixed(std::env::var("PROPTEST_RNG_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(106)), ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(tail in proptest::collection::vec(any::<u8>(), 0..600), which in 0u8..3) {
        let prefix: &[u8] = match which { 0 => b"#ROSBAG V2.0\n", 1 => b"\x89MCAP0\r\n", _ => b"" };
        let bytes = [prefix, &tail].concat();
        let m = lenient(Mapping::husky());
        let _ = read_rosbag_bytes(&bytes, "p", &m);
        let _ = read_mcap_bytes(&bytes, "p", &m);
        let _ = list_topics_bytes(&bytes, "p");
    }

    #[test]
    fn mutated_fixtures_never_panic(seed_edits in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..8), mcap in any::<bool>()) {
        let (mut bytes, m) = if mcap {
            (ros2_mcap(true, &CLEAN), lenient(Mapping::from_toml_str(MAPPING).unwrap()))
        } else {
            (tiny_bag(&[0u8; 700]), lenient(Mapping::husky()))
        };
        for (i, v) in seed_edits {
            let k = i.index(bytes.len());
            bytes[k] = v;
        }
        let _ = read_rosbag_bytes(&bytes, "p", &m);
        let _ = read_mcap_bytes(&bytes, "p", &m);
        let _ = list_topics_bytes(&bytes, "p");
    }
}

/// A ROS1 `nav_msgs/Odometry`: header, child_frame_id, pose (+ covariance), twist (+ covariance).
fn ros1_odometry(sec: u32, v: f64, w: f64) -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&7u32.to_le_bytes()); // seq
    b.extend_from_slice(&sec.to_le_bytes());
    b.extend_from_slice(&0u32.to_le_bytes());
    for s in ["odom", "base_link"] {
        b.extend_from_slice(&(s.len() as u32).to_le_bytes());
        b.extend_from_slice(s.as_bytes());
    }
    let mut f = vec![0.0; 7 + 36];
    f[6] = 1.0; // orientation w
    f.extend_from_slice(&[v, 0.0, 0.0, 0.0, 0.0, w]);
    f.extend_from_slice(&[0.0; 36]);
    for x in f {
        b.extend_from_slice(&x.to_le_bytes());
    }
    b
}

#[test]
fn lz4_and_uncompressed_bag_chunks() {
    let mut m = lenient(Mapping::husky());
    m.streams.truncate(1);
    let kinds: &[&str] = if cfg!(feature = "lz4") {
        &["none", "lz4"]
    } else {
        &["none"]
    };
    for &c in kinds {
        let bag = tiny_bag_with(&ros1_odometry(100, 1.5, 0.2), c);
        let (d, r) = read_rosbag_bytes(&bag, "tiny.bag", &m).unwrap();
        assert_eq!(r.streams[0].accepted, 1, "{c}");
        let deadreckon_core::drive::Wheels::Speeds(s) = &d.wheels else {
            panic!()
        };
        assert_eq!(
            (s[0].t_s, s[0].rl_mps, s[0].rr_mps),
            (100.0, 1.5 - 0.2 * 0.555 / 2.0, 1.5 + 0.2 * 0.555 / 2.0)
        );
    }
}

/// The fuzzing seed made by `fuzz/make_bag_seed.py` (two bz2/uncompressed chunks
/// with index and chunk-info records) is a valid bag.
#[test]
fn fuzz_seed_bag_is_valid() {
    // The seed is cut from the shared recording by the script (the project keeps
    // no copy of the shared data), here into a temporary directory.
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("seeds/rosbag")).unwrap();
    let status = std::process::Command::new("python3")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/fuzz/make_bag_seed.py"
        ))
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/husky-gps-bag/husky_gps.bag"
        ))
        .current_dir(tmp.path())
        .status()
        .expect("python3 runs");
    assert!(status.success(), "make_bag_seed.py failed");
    let b = std::fs::read(tmp.path().join("seeds/rosbag/husky_head.bag")).unwrap();
    let (drive, report) = read_rosbag_bytes(&b, "seed.bag", &Mapping::husky()).unwrap();
    assert!(report.streams.iter().all(|s| s.messages == 2), "{report:?}");
    assert_eq!(drive.wheels.len(), 2);
    // Index records that disagree with the chunks are an error.
    let mut bad = b.clone();
    let at = bad.windows(6).rposition(|w| w == b"count=").unwrap() + 6;
    bad[at] ^= 1;
    let e = read_rosbag_bytes(&bad, "seed.bag", &Mapping::husky()).unwrap_err();
    assert!(e.to_string().contains("seed.bag"), "{e}");
}

/// Fuzzing found `mcap` 0.26's chunk reader adding a record length near u64::MAX
/// to the header size with overflow (a panic with overflow checks on). Chunk
/// records are now walked by our bounds-checked walker.
#[test]
fn mcap_chunk_record_length_overflow() {
    let mut records = vec![0x05u8];
    records.extend_from_slice(&(u64::MAX - 4).to_le_bytes());
    let mut chunk = Vec::new();
    chunk.extend_from_slice(&0u64.to_le_bytes()); // message start time
    chunk.extend_from_slice(&0u64.to_le_bytes()); // message end time
    chunk.extend_from_slice(&(records.len() as u64).to_le_bytes());
    chunk.extend_from_slice(&0u32.to_le_bytes()); // no CRC
    chunk.extend_from_slice(&0u32.to_le_bytes()); // compression ""
    chunk.extend_from_slice(&(records.len() as u64).to_le_bytes());
    chunk.extend_from_slice(&records);
    let mut f = b"\x89MCAP0\r\n".to_vec();
    f.push(0x06);
    f.extend_from_slice(&(chunk.len() as u64).to_le_bytes());
    f.extend_from_slice(&chunk);
    let e = read_mcap_bytes(&f, "overflow.mcap", &lenient(Mapping::husky()))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("overflow.mcap") && e.contains("chunk at byte 8"),
        "{e}"
    );
    // The input fuzzing found, if present.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz/artifacts/mcap");
    for entry in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let b = std::fs::read(entry.path()).unwrap();
        let _ = read_mcap_bytes(&b, "artifact.mcap", &lenient(Mapping::husky()));
    }
}

/// Fuzzing found `mcap` 0.26's attachment parser slicing `body[..len - 4]` of a
/// body shorter than 4 bytes. Records the reader does not use are now skipped unparsed.
#[test]
fn mcap_short_attachment_record() {
    let mut f = b"\x89MCAP0\r\n".to_vec();
    f.push(0x09); // attachment
    f.extend_from_slice(&3u64.to_le_bytes());
    f.extend_from_slice(&[1, 2, 3]);
    f.push(0x02); // footer: summary start u64, summary offset start u64, crc u32
    f.extend_from_slice(&20u64.to_le_bytes());
    f.extend_from_slice(&[0; 20]);
    f.extend_from_slice(b"\x89MCAP0\r\n");
    let topics = list_topics_bytes(&f, "attachment.mcap").unwrap();
    assert!(topics.is_empty());
    let e = read_mcap_bytes(&f, "attachment.mcap", &Mapping::husky())
        .unwrap_err()
        .to_string();
    assert!(e.contains("topic not in the file"), "{e}");
}
