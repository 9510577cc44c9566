//! Whether a correction was estimated, or why not: [`Status`], shared by
//! the delays ([`crate::timing`]), the IMU's tilt ([`crate::imu`]), the
//! driven axle's slip ([`crate::traction`]) and the gyro's scale
//! ([`crate::gyro_scale`]). A leaf: it imports none of them.

/// How the reason of every correction measured but not applied starts
/// (`--corrections gnss`'s other delays, `auto`'s rejected corrections).
pub const MEASURED: &str = "measured, not applied";

/// Estimated, or not with the reason.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    /// Estimated and applied.
    Estimated,
    /// Not estimated (and not applied): why.
    NotEstimated(String),
}

impl Status {
    /// True when estimated.
    pub fn is_estimated(&self) -> bool {
        matches!(self, Status::Estimated)
    }
    /// True when it was measured and deliberately not applied (the reason
    /// starts with [`MEASURED`]): its value and standard error are kept.
    pub fn is_measured_not_applied(&self) -> bool {
        matches!(self, Status::NotEstimated(r) if r.starts_with(MEASURED))
    }
    /// The reason it was not estimated, if not.
    pub fn reason(&self) -> Option<&str> {
        match self {
            Status::Estimated => None,
            Status::NotEstimated(r) => Some(r),
        }
    }
}
