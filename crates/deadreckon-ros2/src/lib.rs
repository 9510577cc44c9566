//! # deadreckon-ros2
//!
//! deadreckon as a live ROS 2 node (`deadreckon ros2`), over the pure-Rust
//! `ros2-client` 0.12.1 (RustDDS 0.15): no ROS installation needed, and it
//! speaks to any ROS 2 middleware on the network (tested against Eclipse
//! Cyclone DDS).
//!
//! - **In**: the topics of a bag [`Mapping`](deadreckon_ros::Mapping)
//!   (`odometry_wheels`, `imu_yaw_rate`, `navsatfix_gnss`, `twist_speed`),
//!   each message converted by the bag reader's own conversion
//!   ([`deadreckon_ros::Converter`]: the same wheel speeds, yaw rate and
//!   east/north about the vehicle's origin as `deadreckon events` gives for
//!   the recorded message). Messages go to the filter in header-stamp
//!   order through a [`Reorder`] window; a message older than one already
//!   given to the filter is late: counted, never applied.
//! - **Filter**: the `Online` filter of `deadreckon stream`, fed the same
//!   events, so the node's epochs and values are `stream`'s.
//! - **Out**: one `nav_msgs/msg/Odometry` per epoch on `/deadreckon/odom`
//!   (frame `odom`, child `base_link`, pose east/north/up about the origin
//!   with the filter's covariance, twist in the body frame:
//!   [`deadreckon_ros::ros2_out::odometry_in`]); with learning, the learned
//!   parameters as [`diagnostics`] on `/diagnostics`.
//! - **QoS**: reliable, keep last [`dds::HISTORY_DEPTH`] each way; the
//!   subscriptions volatile, the publishers transient local ([`dds::publisher_qos`]).
//! - **Latency**: from each message's receipt to the publication of the first
//!   Odometry after it ([`Latency`]), median and 99th percentile in the
//!   [`Summary`].
//!
//! The node stops when the stop flag is set (the command line sets it on
//! SIGINT/SIGTERM) or after a time without input, empties the reorder
//! window, finishes the filter and waits [`node::LINGER`] so that reliable
//! subscribers receive the last samples. Saving and resuming the filter's
//! state is the caller's (the command line uses `stream --state`'s files).
#![deny(missing_docs)]

pub mod dds;
pub mod diagnostics;
mod latency;
pub mod node;
pub mod pipeline;
mod reorder;

pub use latency::{Latency, LatencySummary};
pub use node::{run, NodeOptions, Stop, Summary};
pub use pipeline::{Pipeline, Sink};
pub use reorder::Reorder;

/// What went wrong in the node.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A DDS operation failed.
    #[error("{doing}: {detail}")]
    Dds {
        /// What was being done.
        doing: String,
        /// ros2-client's error.
        detail: String,
    },
    /// Polling the subscriptions failed.
    #[error("{0}")]
    Io(&'static str, #[source] std::io::Error),
    /// The filter refused an event or could not finish.
    #[error("the filter")]
    Filter(#[from] deadreckon_core::Error),
}
