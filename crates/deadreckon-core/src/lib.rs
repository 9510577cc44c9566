//! # deadreckon-core
//!
//! The mathematics of deadreckon, with no I/O: the in-memory [`drive::Drive`]
//! (every sensor stream of a recording, SI units, local east-north frame), the
//! four-wheel car model of Welte, Xu and Bonnifait (ICRA 2019), its extended
//! Kalman filter and Rauch–Tung–Striebel smoother, the least-squares calibration
//! of gyro bias, speed scale and wheel circumferences, dead reckoning, and the
//! papers' evaluation metrics. Other vehicle shapes (a tricycle with a
//! steered driven wheel, a differential drive) and their kinematic
//! calibration against a reference live in [`kinematics`]. Slipping and bad
//! wheels are found and dropped from the fusion by [`wheel_health`]; the
//! filter's consistency against the truth is [`consistency`] (NEES), and what a
//! calibration drive lacked is [`observability`].
//!
//! ## Conventions
//!
//! - Positions are metres east (`east_m`) and north (`north_m`) of a local origin.
//! - Yaw is radians counter-clockwise from east; yaw rate is counter-clockwise
//!   positive. GNSS course (`course_deg`) is the navigation convention, degrees
//!   clockwise from north: convert with [`drive::course_deg_to_yaw_rad`].
//! - The position estimated is that of the rear-axle centre (point M of the paper).
//! - Every sample carries its own timestamp `t_s` (s); `dt` is derived.
#![deny(missing_docs)]

pub mod aided;
pub mod angle;
pub mod bound;
pub mod bound_diff;
pub mod bound_pose;
pub mod calibrate;
pub mod checkpoint;
pub mod chords;
pub mod compared;
pub mod consistency;
mod cursor;
pub mod drive;
pub mod ekf;
mod error;
pub mod event;
pub mod evo;
pub mod filter;
pub mod geo;
pub mod gnss_error;
pub mod gnss_jumps;
pub mod gyro_drift;
pub mod gyro_hold;
pub mod gyro_scale;
pub mod gyro_switch_defaults;
pub mod held_back;
pub mod imu;
pub mod init;
pub mod kalman;
pub mod kinematics;
pub mod lend;
pub mod live_corrections;
pub mod metrics;
pub mod model;
pub mod model_options;
pub mod observability;
pub mod observation;
pub mod online;
pub mod outage;
pub mod plausibility;
pub mod reference;
pub mod rts;
mod series;
pub mod side_slip;
pub mod standstill;
mod status;
pub mod tick_interval;
pub mod timing;
pub mod track;
pub mod traction;
pub mod vehicle;
pub mod wander_fit;
pub mod wheel_health;

pub use drive::Drive;
pub use track::{Track, TrackPoint};
pub use vehicle::{Params, ParamsWithStd, Vehicle};

pub use error::{
    DriveFault, Error, Input, Invalid, Limit, Need, Rule, ScaleRejection, Task, Value,
};
