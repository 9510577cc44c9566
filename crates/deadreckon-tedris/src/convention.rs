//! What a GNSS course is the direction of ([`CourseConvention`]) and the
//! evidence a drive gave for it ([`ConventionFit`]): found by the machine
//! ([`crate::machine::course_convention`]) and stored with a model
//! ([`crate::model::TedrisModel`]), so a leaf both import.

use serde::{Deserialize, Serialize};

/// What a GNSS course is the direction of.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CourseConvention {
    /// The antenna's velocity: the rear-axle heading plus atan(l·ψ̇/v).
    AntennaVelocity,
    /// The body's yaw (receivers fusing an IMU or two antennas).
    BodyYaw,
}

impl std::fmt::Display for CourseConvention {
    /// Words for people: what the receiver's course is the direction of.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            CourseConvention::AntennaVelocity => "the antenna's velocity",
            CourseConvention::BodyYaw => "the body's yaw",
        })
    }
}

impl CourseConvention {
    /// True for [`CourseConvention::AntennaVelocity`].
    pub fn is_antenna(self) -> bool {
        self == CourseConvention::AntennaVelocity
    }
}

/// The convention found on a drive, with its evidence.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ConventionFit {
    /// The convention chosen.
    pub convention: CourseConvention,
    /// Residual sum of squares of the heading fit taking the course as the
    /// body's yaw over that taking it as the antenna's (each at its best lag).
    pub rss_ratio: f64,
}
