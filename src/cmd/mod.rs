//! One module per subcommand.
pub mod batch;
pub mod calibrate;
pub mod common;
pub mod compare;
pub mod demo;
pub mod evaluate;
pub mod events;
pub mod import;
pub mod kinematic;
pub mod progress;
pub mod report;
pub mod run;
pub mod simulate;
pub mod stream;
pub mod tedris;

/// The `--mapping` file given on the command line, for ROS recordings.
pub static ROS_MAPPING: std::sync::OnceLock<std::path::PathBuf> = std::sync::OnceLock::new();

/// `--skip-checks`: read drives without the cross-stream plausibility checks.
pub static SKIP_CHECKS: std::sync::OnceLock<bool> = std::sync::OnceLock::new();

/// Reads a ROS1 bag or ROS2 MCAP recording with the `--mapping` file, or the
/// built-in mapping (Husky, or Jackal when the file name says so), with the
/// reader's report of what was used, dropped and counted.
pub fn load_ros_with_report(
    path: &std::path::Path,
) -> anyhow::Result<(deadreckon_core::Drive, deadreckon_ros::ImportReport)> {
    let mapping = ROS_MAPPING.get().map(|m| m.as_path());
    Ok(deadreckon_api::read_ros(path, mapping)?)
}
