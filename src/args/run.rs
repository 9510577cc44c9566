//! The arguments of `deadreckon run`.

use std::path::PathBuf;

use clap::Args;
use deadreckon_core::evo;

/// Arguments of `run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The drive directory (or a recording read directly).
    pub dir: PathBuf,
    /// `nominal` or a params.toml. Without it, the parameters are calibrated
    /// on the drive itself, as `evaluate` does (RTS for a car, against the
    /// tracker for a tricycle).
    #[arg(long)]
    pub params: Option<String>,
    /// Without --params: the timing and mounting corrections estimated and
    /// applied before calibrating on the drive (as `evaluate --corrections`).
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::Auto)]
    pub corrections: super::CorrectionsArg,
    /// The vehicle shape (default: found from the data).
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<super::kinematic::ShapeArg>,
    /// Output file, by extension: .csv, .geojson, .mcap (every track), .tum or
    /// .kitti (one track; KITTI's timestamps go to <stem>.times.txt).
    #[arg(long)]
    pub out: PathBuf,
    /// A track to write (repeatable): dead-reckoned, filtered, smoothed, truth.
    /// Default: every estimated track; TUM and KITTI need exactly one.
    #[arg(long)]
    pub track: Vec<String>,
    /// TUM/KITTI: keep only the poses evo's time association pairs with this
    /// track, so two KITTI files line up pose for pose.
    #[arg(long)]
    pub sync_with: Option<String>,
    /// What an .mcap file carries: foxglove (JSON, Foxglove's schemas), ros2
    /// (nav_msgs/msg/Odometry in CDR, `ros2` profile: what ros2 bag, rosbags
    /// and evo read) or both (read by Foxglove and MCAP libraries, not by ROS
    /// tools, which want the ros2 profile).
    #[arg(long, value_enum, default_value_t = McapContent::Foxglove)]
    pub mcap: McapContent,
    /// Largest time difference of associated poses for --sync-with, s (evo's --t_max_diff).
    #[arg(long, default_value_t = evo::DEFAULT_MAX_DIFF_S, value_parser = super::positive)]
    pub max_diff_s: f64,
    /// Filter timing: wheel or each.
    #[arg(long, value_enum, default_value_t = super::TimingArg::Wheel)]
    pub timing: super::TimingArg,
    /// Initial pose for dead reckoning `EAST_M,NORTH_M,YAW_RAD` (default: the truth, else the smoothed GNSS track).
    #[arg(long)]
    pub init_pose: Option<String>,
    /// Fuse every wheel reading: no wheel-health monitor.
    #[arg(long)]
    pub no_wheel_monitor: bool,
    /// Print what was written and the wheel health as JSON.
    #[arg(long)]
    pub json: bool,
}

/// What `run --out x.mcap` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum McapContent {
    /// Foxglove's JSON messages (foxglove.PoseInFrame, foxglove.LocationFix).
    Foxglove,
    /// ROS 2 nav_msgs/msg/Odometry in CDR, `ros2` profile (for ros2 bag, rosbags, evo).
    Ros2,
    /// Both in one file.
    Both,
}

impl RunArgs {
    /// `--init-pose EAST_M,NORTH_M,YAW_RAD`.
    pub fn init_pose(&self) -> anyhow::Result<Option<(f64, f64, f64)>> {
        use anyhow::Context;
        let Some(s) = &self.init_pose else {
            return Ok(None);
        };
        let v: Vec<f64> = s
            .split(',')
            .map(|x| x.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .context("--init-pose EAST_M,NORTH_M,YAW_RAD")?;
        anyhow::ensure!(
            v.len() == 3 && v.iter().all(|x| x.is_finite()),
            "--init-pose needs three finite numbers EAST_M,NORTH_M,YAW_RAD"
        );
        Ok(Some((v[0], v[1], v[2])))
    }

    /// `--track`, `--sync-with`, `--max-diff-s`.
    pub fn selection(&self) -> deadreckon_api::tracks::Selection {
        deadreckon_api::tracks::Selection {
            names: self.track.clone(),
            sync_with: self.sync_with.clone(),
            max_diff_s: self.max_diff_s,
        }
    }
}

impl From<McapContent> for deadreckon_ros::McapOptions {
    fn from(m: McapContent) -> Self {
        match m {
            McapContent::Foxglove => Self::FOXGLOVE,
            McapContent::Ros2 => Self::ROS2,
            McapContent::Both => Self::BOTH,
        }
    }
}
