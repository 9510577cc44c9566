//! Which built-in mapping a ROS recording is read with (issue 33): chosen by
//! the topics the recording has, and said, where it used to be the Jackal's
//! whenever the file's name contained "jackal", silently.

use std::path::Path;

use deadreckon_api::source::{builtin_mapping, read_ros_saying};

const BAGS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/husky-gps-bag"
);

/// The two real bags under names that say the opposite of what they hold.
#[test]
fn the_jackal_mapping_was_chosen_by_the_file_name() {
    let tmp = tempfile::tempdir().unwrap();
    let husky_named_jackal = tmp.path().join("jackal_drive.bag");
    let jackal_named_robot = tmp.path().join("robot.bag");
    std::os::unix::fs::symlink(Path::new(BAGS).join("husky_gps.bag"), &husky_named_jackal).unwrap();
    std::os::unix::fs::symlink(
        Path::new(BAGS).join("jackal_no_gps.bag"),
        &jackal_named_robot,
    )
    .unwrap();

    let (d, _, said) = read_ros_saying(&husky_named_jackal, None).unwrap();
    assert!(
        said.contains("Husky") && said.contains("/husky_velocity_controller/odom"),
        "{said}"
    );
    // The Husky's track (0.555 m), not the Jackal's (0.37559 m).
    assert_eq!(d.vehicle.track_rear_m, 0.555);

    let (d, _, said) = read_ros_saying(&jackal_named_robot, None).unwrap();
    assert!(
        said.contains("Jackal") && said.contains("/jackal_velocity_controller/odom"),
        "{said}"
    );
    assert_eq!(d.vehicle.track_rear_m, 0.37559);
}

#[test]
fn a_recording_with_neither_wheel_topic_is_read_as_the_default_and_says_so() {
    let (m, said) = builtin_mapping(&["/fix", "/imu/data"]);
    assert_eq!(m, deadreckon_ros::Mapping::husky());
    assert!(
        said.contains("the default") && said.contains("neither"),
        "{said}"
    );
}
