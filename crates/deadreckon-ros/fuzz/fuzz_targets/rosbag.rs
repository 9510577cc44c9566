//! Any bytes given to the ROS1 bag reader: an error or a drive, never a panic.
#![no_main]

use deadreckon_ros::{list_topics_bytes, read_rosbag_bytes, Mapping, StreamKind, StreamSpec};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let mut m = Mapping::husky();
    m.require_topics = false;
    m.streams.push(StreamSpec::new("/cmd_vel", StreamKind::TwistSpeed));
    m.streams.push(StreamSpec::new("/pose", StreamKind::PoseTruth));
    let _ = read_rosbag_bytes(data, "fuzz.bag", &m);
    let _ = list_topics_bytes(data, "fuzz.bag");
});
