//! The arguments of `deadreckon ros2`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `ros2`.
#[derive(Args, Debug)]
pub struct Ros2Args {
    /// The vehicle (NavSatFix positions are about its [origin], else about the
    /// first fix), the parameters, the timing.
    #[command(flatten)]
    pub start: super::stream::OnlineStartArgs,
    /// Learn the six parameters while filtering (the 11-state filter); they are
    /// published on /diagnostics.
    #[arg(long)]
    pub learn: bool,
    /// With --learn: publish the learned parameters every this many seconds of stream time.
    #[arg(long, requires = "learn", default_value_t = 1.0, value_parser = super::positive)]
    pub learned_every_s: f64,
    /// The DDS domain (ROS_DOMAIN_ID), 0 to 232.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u16).range(0..=232))]
    pub domain_id: u16,
    /// Stop after this many seconds without a message (default: run until SIGINT/SIGTERM).
    #[arg(long, value_parser = super::positive)]
    pub until_idle: Option<f64>,
    /// Reorder window, seconds of header-stamp time: a message waits until one
    /// this much newer has arrived; an older one after it is late (counted, not applied).
    #[arg(long, default_value_t = deadreckon_ros2::node::DEFAULT_REORDER_WINDOW_S, value_parser = super::non_negative)]
    pub reorder_window: f64,
    /// Resume from this state file if it exists, and write the state to it at the end
    /// (the file of `stream --state`).
    #[arg(long)]
    pub state: Option<PathBuf>,
}
