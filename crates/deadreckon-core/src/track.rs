//! An estimated trajectory: what `deadreckon run` writes and every exporter reads.

use crate::vehicle::Origin;

/// One estimated pose with its uncertainty.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
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
    /// Covariance of (east, north, yaw): [[ee, en, ey], [ne, nn, ny], [ye, yn, yy]], row-major
    /// (NaN where unknown: the kinematic dead reckoning of a tricycle carries none).
    pub cov_pose: [f64; 9],
}

/// The square root of a variance, clamped at zero; unknown (NaN) stays unknown.
fn std_of(var: f64) -> f64 {
    if var.is_nan() {
        var
    } else {
        var.max(0.0).sqrt()
    }
}

impl TrackPoint {
    /// Standard deviation of the east coordinate, m.
    pub fn std_east_m(&self) -> f64 {
        std_of(self.cov_pose[0])
    }
    /// Standard deviation of the north coordinate, m.
    pub fn std_north_m(&self) -> f64 {
        std_of(self.cov_pose[4])
    }
    /// Standard deviation of the yaw, rad.
    pub fn std_yaw_rad(&self) -> f64 {
        std_of(self.cov_pose[8])
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

impl TrackPoint {
    /// A track point from a state and its covariance (yaw wrapped for output).
    pub fn from_state(t_s: f64, x: &crate::model::State, p: &crate::model::Mat) -> Self {
        use crate::model::{V, X, Y, YAW, YAW_RATE};
        let idx = [X, Y, YAW];
        let mut cov_pose = [0.0; 9];
        for (a, &i) in idx.iter().enumerate() {
            for (b, &j) in idx.iter().enumerate() {
                cov_pose[3 * a + b] = p[(i, j)];
            }
        }
        TrackPoint {
            t_s,
            east_m: x[X],
            north_m: x[Y],
            yaw_rad: crate::angle::wrap(x[YAW]),
            speed_mps: x[V],
            yaw_rate_rps: x[YAW_RATE],
            cov_pose,
        }
    }
}

impl Track {
    /// The filtered states of a filter run.
    pub fn from_epochs(name: &str, epochs: &[crate::ekf::Epoch], origin: Option<Origin>) -> Track {
        Track {
            name: name.into(),
            points: epochs
                .iter()
                .map(|e| TrackPoint::from_state(e.t_s, &e.x, &e.p))
                .collect(),
            origin,
        }
    }

    /// The smoothed states of an RTS pass.
    pub fn from_smoothed(
        name: &str,
        smoothed: &[crate::rts::Smoothed],
        origin: Option<Origin>,
    ) -> Track {
        Track {
            name: name.into(),
            points: smoothed
                .iter()
                .map(|s| TrackPoint::from_state(s.t_s, &s.x, &s.p))
                .collect(),
            origin,
        }
    }
}
