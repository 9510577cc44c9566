//! Any bytes given to the MCAP reader: an error or a drive, never a panic.
#![no_main]

use deadreckon_ros::{list_topics_bytes, read_mcap_bytes, Mapping};
use libfuzzer_sys::fuzz_target;

const MAPPING: &str = r#"
require_topics = false
[[stream]]
topic = "/odom"
kind = "odometry_wheels"
[[stream]]
topic = "/imu"
kind = "imu_yaw_rate"
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

fuzz_target!(|data: &[u8]| {
    let m = Mapping::from_toml_str(MAPPING).expect("valid mapping");
    let _ = read_mcap_bytes(data, "fuzz.mcap", &m);
    let _ = list_topics_bytes(data, "fuzz.mcap");
});
