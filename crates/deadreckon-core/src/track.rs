//! An estimated trajectory: what `deadreckon run` writes and every exporter reads.

use crate::vehicle::Origin;

/// One estimated pose with its uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrackPoint {
    /// Timestamp, s.
    pub t_s: f64,
    /// East of the origin, m (rear-axle centre).
    pub east_m: f64,
    /// North of the origin, m.
    pub north_m: f64,
    /// Yaw, rad, counter-clockwise from east, wrapped to (-π, π].
    pub yaw_rad: f64,
    /// Longitudinal speed, m/s.
    pub speed_mps: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_rps: f64,
    /// Covariance of (east, north, yaw): [[ee, en, ey], [ne, nn, ny], [ye, yn, yy]], row-major.
    pub cov_pose: [f64; 9],
}

impl TrackPoint {
    /// Standard deviation of the east coordinate, m.
    pub fn std_east_m(&self) -> f64 {
        self.cov_pose[0].max(0.0).sqrt()
    }
    /// Standard deviation of the north coordinate, m.
    pub fn std_north_m(&self) -> f64 {
        self.cov_pose[4].max(0.0).sqrt()
    }
    /// Standard deviation of the yaw, rad.
    pub fn std_yaw_rad(&self) -> f64 {
        self.cov_pose[8].max(0.0).sqrt()
    }
}

/// A named trajectory (e.g. "filtered", "smoothed", "dead-reckoned").
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// What produced it.
    pub name: String,
    /// The poses, by increasing time.
    pub points: Vec<TrackPoint>,
    /// The geodetic origin of the local frame, where known (for map exports).
    pub origin: Option<Origin>,
}
