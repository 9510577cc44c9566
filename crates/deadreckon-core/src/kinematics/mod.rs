//! Vehicle models as one concept with several shapes, and their kinematic
//! calibration against a reference.
//!
//! A [`Shape`] names the kinematics of a vehicle:
//!
//! - [`Shape::FourWheel`]: the four-wheel Ackermann car of the paper, filtered
//!   by [`crate::filter`] and calibrated by [`crate::calibrate`] (unchanged),
//!   with its steering ratio and steering-wheel offset calibrated against a
//!   reference by [`steering`];
//! - [`Shape::Tricycle`]: one steered, driven front wheel with a steering
//!   encoder and a traction encoder ([`tricycle`]);
//! - [`Shape::DiffDrive`]: left/right wheels, or the odometry twist they give.
//!
//! The shapes other than the car are dead-reckoned by integrating their
//! kinematics directly (no filter: a tricycle has no gyro, and the
//! integration `x += ds·cos φ·cos ψ`, `ψ += ds·sin φ / L` has no division
//! that could blow up at any steering angle, ±90° included) and calibrated by
//! nonlinear least squares over relative motions in short windows
//! ([`calibrate`]) through the [`KinematicModel`] trait, which a shape
//! implements with an analytic Jacobian. Outages are evaluated by
//! [`evaluate`]: each window starts from the reference pose and is scored at
//! the point the reference measures. A differential drive, calibrated and
//! scored against GNSS fixes rather than a reference pose, has its own
//! calibration and outages ([`diff_drive`]), the outages started from a
//! GNSS-aided filter ([`diff_drive::filter`]).
//!
//! Frames: poses are `(x, y, ψ)` in the reference's frame (m, m, rad
//! counter-clockwise). The *base* is the shape's kinematic centre (the rear
//! axle centre of a tricycle, the axle centre of a differential drive); the
//! *measured point* is where the reference (tracker, truth, GNSS antenna)
//! sits, at the mounting pose [`Pose2`] `m` in the base frame:
//! `measured = base ∘ m`.

pub mod calibrate;
pub mod diff_drive;
pub mod evaluate;
pub mod steering;
pub mod tricycle;

use serde::{Deserialize, Serialize};

pub use calibrate::{calibrate, KinematicCalibration, KinematicOptions, ParamEstimate};
pub use evaluate::{evaluate, KinematicOutages};

/// The kinematic shapes a vehicle can have.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Shape {
    /// Four wheels, front-steered (Ackermann): the car of the paper.
    FourWheel,
    /// One steered, driven front wheel and a passive rear axle.
    Tricycle,
    /// Left and right driven wheels (or the twist their odometry gives).
    DiffDrive,
}

impl Shape {
    /// The name used in files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Shape::FourWheel => "four_wheel",
            Shape::Tricycle => "tricycle",
            Shape::DiffDrive => "diff_drive",
        }
    }

    /// The default speed threshold of the calibration, m/s: samples slower
    /// than this carry too little motion for speed-dependent parameters. A
    /// car is calibrated above 2 m/s (wheel-tick quantisation and
    /// standstill dominate below); robots of the 0.5–1 m/s class above
    /// 0.05 m/s (the tricycle log never exceeds 0.6 m/s, the Husky 1 m/s).
    pub fn default_min_speed_mps(self) -> f64 {
        match self {
            // The car calibration's own default (one place).
            Shape::FourWheel => crate::calibrate::CalibrationOptions::default().min_speed_mps,
            Shape::Tricycle | Shape::DiffDrive => 0.05,
        }
    }
}

/// A planar pose: position (m) and heading (rad, counter-clockwise).
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Pose2 {
    /// x, m.
    pub x_m: f64,
    /// y, m.
    pub y_m: f64,
    /// Heading, rad.
    pub yaw_rad: f64,
}

impl Pose2 {
    /// A pose from its components.
    pub fn new(x_m: f64, y_m: f64, yaw_rad: f64) -> Pose2 {
        Pose2 { x_m, y_m, yaw_rad }
    }

    /// `self ∘ m`: the pose of a frame mounted at `m` in `self`'s frame.
    pub fn compose(&self, m: &Pose2) -> Pose2 {
        let (s, c) = self.yaw_rad.sin_cos();
        Pose2 {
            x_m: self.x_m + c * m.x_m - s * m.y_m,
            y_m: self.y_m + s * m.x_m + c * m.y_m,
            yaw_rad: self.yaw_rad + m.yaw_rad,
        }
    }

    /// The base pose whose frame mounted at `m` is `self`: `self ∘ m⁻¹`.
    pub fn unmount(&self, m: &Pose2) -> Pose2 {
        let yaw = self.yaw_rad - m.yaw_rad;
        let (s, c) = yaw.sin_cos();
        Pose2 {
            x_m: self.x_m - (c * m.x_m - s * m.y_m),
            y_m: self.y_m - (s * m.x_m + c * m.y_m),
            yaw_rad: yaw,
        }
    }
}

/// The Jacobian of a pose with respect to a model's parameters: three rows
/// (x, y, ψ), one column per parameter.
pub type PoseJacobian = nalgebra::OMatrix<f64, nalgebra::U3, nalgebra::Dyn>;

/// A vehicle shape's kinematics over a recorded drive, as the calibration and
/// the outage evaluation see it: parameters in a vector (SI units), samples
/// indexed in time order, and dead reckoning between two samples with its
/// analytic Jacobian.
pub trait KinematicModel {
    /// Parameter names with their units (`ktraction_m`, `axle_length_m`, …).
    fn names(&self) -> &'static [&'static str];
    /// The nominal parameters (the vehicle's description): where the fit
    /// starts, and what a parameter that is not estimated keeps.
    fn nominal(&self) -> Vec<f64>;
    /// The physical bounds `(low, high)` of each parameter: a fit at or
    /// beyond one is rejected.
    fn bounds(&self) -> Vec<(f64, f64)>;
    /// The standard error above which a parameter counts as not determined
    /// by the drive, given the fitted values (same units as the parameter).
    fn determination_tolerance(&self, params: &[f64]) -> Vec<f64>;
    /// Number of samples.
    fn len(&self) -> usize;
    /// Whether there are no samples.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Time of sample `i`, s.
    fn time(&self, i: usize) -> f64;
    /// The reference pose of the measured point at sample `i`, if any.
    fn reference(&self, i: usize) -> Option<Pose2>;
    /// Distance the driven wheel(s) travelled from sample `a` to `b` with the
    /// nominal scale, m (unsigned: reversing counts as motion).
    fn path_m(&self, a: usize, b: usize) -> f64;
    /// Dead reckons from the measured pose `start` at sample `a` to sample
    /// `b` (`b ≥ a`) with `params`, returning the measured point's pose at
    /// `b` and, if asked, its Jacobian with respect to the parameters.
    fn predict(
        &self,
        params: &[f64],
        start: &Pose2,
        a: usize,
        b: usize,
        jacobian: bool,
    ) -> (Pose2, Option<PoseJacobian>);
    /// Why the samples `windows` (index ranges) cannot determine parameter
    /// `k`, before any fit (no turning, no steering change, …), or `None`.
    fn unexcited(&self, windows: &[(usize, usize)], k: usize) -> Option<String>;
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unmount_inverts_compose() {
        let b = Pose2::new(1.0, -2.0, 0.7);
        let m = Pose2::new(1.8, 0.1, -0.05);
        let s = b.compose(&m);
        let back = s.unmount(&m);
        assert!((back.x_m - b.x_m).abs() < 1e-12);
        assert!((back.y_m - b.y_m).abs() < 1e-12);
        assert!((back.yaw_rad - b.yaw_rad).abs() < 1e-12);
    }
}
