//! The in-memory drive: every sensor stream of one recording, in SI units, in a
//! local east-north frame, on one clock.
//!
//! This mirrors the drive directory format (see `docs/drive-format.md`): readers
//! in `deadreckon-io` and `deadreckon-import` produce a [`Drive`], the simulator
//! produces one, and every estimator consumes one. Streams are sorted by strictly
//! increasing `t_s` (readers validate this; [`Drive::validate`] re-checks it).

use crate::vehicle::Vehicle;
use crate::{DriveFault, Error};

/// Ticks counted by each wheel encoder since the previous row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelTicks {
    /// Time of the end of the counting interval, s.
    pub t_s: f64,
    /// Front-left ticks since the previous row.
    pub fl: i64,
    /// Front-right ticks since the previous row.
    pub fr: i64,
    /// Rear-left ticks since the previous row.
    pub rl: i64,
    /// Rear-right ticks since the previous row.
    pub rr: i64,
}

/// Wheel speeds as reported by the wheel-speed sensors (computed by the ECU with
/// the nominal circumference), m/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelSpeeds {
    /// Timestamp, s.
    pub t_s: f64,
    /// Front-left wheel speed, m/s.
    pub fl_mps: f64,
    /// Front-right wheel speed, m/s.
    pub fr_mps: f64,
    /// Rear-left wheel speed, m/s.
    pub rl_mps: f64,
    /// Rear-right wheel speed, m/s.
    pub rr_mps: f64,
}

/// The wheel stream of a drive: encoder ticks or wheel speeds.
#[derive(Debug, Clone, PartialEq)]
pub enum Wheels {
    /// `wheel_ticks.csv`.
    Ticks(Vec<WheelTicks>),
    /// `wheel_speeds.csv`.
    Speeds(Vec<WheelSpeeds>),
}

impl Wheels {
    /// Number of wheel epochs.
    pub fn len(&self) -> usize {
        match self {
            Wheels::Ticks(v) => v.len(),
            Wheels::Speeds(v) => v.len(),
        }
    }
    /// True when there are no wheel epochs.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Timestamp of wheel epoch `i`.
    pub fn t_s(&self, i: usize) -> f64 {
        match self {
            Wheels::Ticks(v) => v[i].t_s,
            Wheels::Speeds(v) => v[i].t_s,
        }
    }
}

/// One timestamped scalar reading (gyro yaw rate, CAN speed, steering wheel angle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scalar {
    /// Timestamp, s.
    pub t_s: f64,
    /// The reading, in the unit its stream names.
    pub value: f64,
}

/// One GNSS fix in the local east-north frame.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct GnssFix {
    /// Timestamp, s.
    pub t_s: f64,
    /// East of the origin, m.
    pub east_m: f64,
    /// North of the origin, m.
    pub north_m: f64,
    /// Horizontal standard deviation of each coordinate, m.
    pub std_m: f64,
    /// Course over ground, degrees clockwise from north, if the receiver gives it.
    pub course_deg: Option<f64>,
    /// Ground speed, m/s, if the receiver gives it.
    pub speed_mps: Option<f64>,
}

impl GnssFix {
    /// The course as a yaw angle: radians, counter-clockwise from east, in (-π, π].
    pub fn course_yaw_rad(&self) -> Option<f64> {
        self.course_deg.map(course_deg_to_yaw_rad)
    }
}

/// Converts a course (degrees clockwise from north) into a yaw (radians
/// counter-clockwise from east), wrapped to (-π, π].
pub fn course_deg_to_yaw_rad(course_deg: f64) -> f64 {
    crate::angle::wrap(std::f64::consts::FRAC_PI_2 - course_deg.to_radians())
}

/// Converts a yaw (radians counter-clockwise from east) into a course (degrees
/// clockwise from north) in [0, 360).
pub fn yaw_rad_to_course_deg(yaw_rad: f64) -> f64 {
    (90.0 - yaw_rad.to_degrees()).rem_euclid(360.0)
}

/// One reference pose: the position of the rear-axle centre (point M) and the yaw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TruthPose {
    /// Timestamp, s.
    pub t_s: f64,
    /// East of the origin, m.
    pub east_m: f64,
    /// North of the origin, m.
    pub north_m: f64,
    /// Yaw, rad, counter-clockwise from east.
    pub yaw_rad: f64,
    /// Longitudinal speed, m/s, where known.
    pub speed_mps: Option<f64>,
}

/// One three-axis reading in the vehicle's axes: x forward, y left, z up
/// (the axes a perfectly mounted sensor would have).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    /// Timestamp, s.
    pub t_s: f64,
    /// Forward component.
    pub x: f64,
    /// Left component.
    pub y: f64,
    /// Up component.
    pub z: f64,
}

impl Axes {
    /// The components as an array `[x, y, z]`.
    pub fn xyz(&self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

/// Optional three-axis inertial streams (`gyro.csv` with three axes,
/// `accel.csv`): what [`crate::imu`] needs to find the sensor's tilt. Empty
/// when the drive has a one-axis yaw-rate gyro only.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Imu {
    /// Angular rate, rad/s, about the sensor's x, y, z axes (bias included).
    /// When present, the drive's `yaw_rate` is its z axis.
    pub gyro: Vec<Axes>,
    /// Specific force, m/s² (at rest and level: z = +9.81).
    pub accel: Vec<Axes>,
}

/// A whole recording.
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// Geometry, nominal parameters and noise of the vehicle.
    pub vehicle: Vehicle,
    /// Wheel encoders or wheel speeds (required).
    pub wheels: Wheels,
    /// Raw gyro yaw rate, rad/s, counter-clockwise positive, bias not removed.
    pub yaw_rate: Vec<Scalar>,
    /// CAN vehicle speed, m/s.
    pub speed: Vec<Scalar>,
    /// Steering wheel angle, rad, left positive.
    pub steering: Vec<Scalar>,
    /// GNSS fixes.
    pub gnss: Vec<GnssFix>,
    /// Reference trajectory.
    pub truth: Vec<TruthPose>,
    /// Three-axis gyro and accelerometer, when the drive has them.
    pub imu: Imu,
}

/// Whether `t` falls in one of `windows`, each `[start, end)` on the drive
/// clock: the one rule by which GNSS is hidden, whether fixes are removed
/// ([`Drive::without_gnss_in`]) or skipped by a filter
/// (`FilterOptions::gnss_outages`) or by TedriS.
pub fn in_windows(t: f64, windows: &[(f64, f64)]) -> bool {
    windows.iter().any(|&(a, b)| t >= a && t < b)
}

impl Drive {
    /// A copy of the drive without its truth (every other stream copied):
    /// for passes that never read it, e.g. the held-back choice's
    /// calibrations ([`crate::held_back`]), so a drive read with its truth
    /// does not copy it too (`evaluate --outage`'s peak on the bench's hour:
    /// docs/performance.md, "Fifth round").
    pub fn clone_without_truth(&self) -> Drive {
        Drive {
            vehicle: self.vehicle.clone(),
            wheels: self.wheels.clone(),
            yaw_rate: self.yaw_rate.clone(),
            speed: self.speed.clone(),
            steering: self.steering.clone(),
            gnss: self.gnss.clone(),
            truth: Vec::new(),
            imu: self.imu.clone(),
        }
    }

    /// The drive without the GNSS fixes inside `windows` ([`in_windows`]);
    /// every other stream kept.
    pub fn without_gnss_in(&self, windows: &[(f64, f64)]) -> Drive {
        let mut d = self.clone();
        d.gnss.retain(|g| !in_windows(g.t_s, windows));
        d
    }

    /// The part of the drive with `from_s ≤ t < until_s` (drive clock;
    /// `None`: open), every stream cut alike (wheel ticks are per-epoch
    /// increments, so the cut is exact).
    pub fn time_range(&self, from_s: Option<f64>, until_s: Option<f64>) -> Drive {
        let lo = from_s.unwrap_or(f64::NEG_INFINITY);
        let hi = until_s.unwrap_or(f64::INFINITY);
        let keep = |t: f64| t >= lo && t < hi;
        let mut d = self.clone();
        match &mut d.wheels {
            Wheels::Ticks(v) => v.retain(|w| keep(w.t_s)),
            Wheels::Speeds(v) => v.retain(|w| keep(w.t_s)),
        }
        d.yaw_rate.retain(|s| keep(s.t_s));
        d.speed.retain(|s| keep(s.t_s));
        d.steering.retain(|s| keep(s.t_s));
        d.gnss.retain(|g| keep(g.t_s));
        d.truth.retain(|p| keep(p.t_s));
        d.imu.gyro.retain(|s| keep(s.t_s));
        d.imu.accel.retain(|s| keep(s.t_s));
        d
    }

    /// An empty drive for `vehicle` with wheel ticks, to be filled by a reader or simulator.
    pub fn empty(vehicle: Vehicle) -> Self {
        Drive {
            vehicle,
            wheels: Wheels::Ticks(Vec::new()),
            yaw_rate: Vec::new(),
            speed: Vec::new(),
            steering: Vec::new(),
            gnss: Vec::new(),
            truth: Vec::new(),
            imu: Imu::default(),
        }
    }

    /// First and last wheel timestamps.
    pub fn time_span(&self) -> Option<(f64, f64)> {
        if self.wheels.is_empty() {
            None
        } else {
            Some((self.wheels.t_s(0), self.wheels.t_s(self.wheels.len() - 1)))
        }
    }

    /// Checks the invariants every estimator relies on: finite values and strictly
    /// increasing timestamps in every stream, at least two wheel epochs, a valid vehicle.
    pub fn validate(&self) -> Result<(), Error> {
        self.vehicle.validate()?;
        if self.wheels.len() < 2 {
            return Err(Error::drive(
                "wheels",
                DriveFault::TooFewSamples {
                    min: 2,
                    have: self.wheels.len(),
                },
            ));
        }
        fn check(name: &'static str, ts: impl Iterator<Item = f64>) -> Result<(), Error> {
            let mut prev = f64::NEG_INFINITY;
            for (i, t) in ts.enumerate() {
                if !t.is_finite() {
                    return Err(Error::drive(
                        name,
                        DriveFault::NonFiniteTime {
                            index: Some(i),
                            t_s: t,
                        },
                    ));
                }
                if t <= prev {
                    return Err(Error::drive(
                        name,
                        DriveFault::NotIncreasing {
                            index: i,
                            t_s: t,
                            previous_t_s: prev,
                        },
                    ));
                }
                prev = t;
            }
            Ok(())
        }
        match &self.wheels {
            Wheels::Ticks(v) => check("wheel_ticks", v.iter().map(|s| s.t_s))?,
            Wheels::Speeds(v) => {
                check("wheel_speeds", v.iter().map(|s| s.t_s))?;
                if v.iter().any(|s| {
                    !(s.fl_mps.is_finite()
                        && s.fr_mps.is_finite()
                        && s.rl_mps.is_finite()
                        && s.rr_mps.is_finite())
                }) {
                    return Err(Error::drive(
                        "wheel_speeds",
                        DriveFault::NonFinite { what: "speed" },
                    ));
                }
            }
        }
        for (name, s) in [
            ("yaw_rate", &self.yaw_rate),
            ("speed", &self.speed),
            ("steering", &self.steering),
        ] {
            check(name, s.iter().map(|s| s.t_s))?;
            if s.iter().any(|s| !s.value.is_finite()) {
                return Err(Error::drive(name, DriveFault::NonFinite { what: "value" }));
            }
        }
        check("gnss", self.gnss.iter().map(|s| s.t_s))?;
        if self
            .gnss
            .iter()
            .any(|g| !(g.east_m.is_finite() && g.north_m.is_finite()))
        {
            return Err(Error::drive(
                "gnss",
                DriveFault::NonFinite { what: "position" },
            ));
        }
        if self
            .gnss
            .iter()
            .any(|g| !(g.std_m.is_finite() && g.std_m > 0.0))
        {
            return Err(Error::drive(
                "gnss",
                DriveFault::NotPositive { what: "std_m" },
            ));
        }
        check("truth", self.truth.iter().map(|s| s.t_s))?;
        for (name, s) in [
            ("gyro (3 axes)", &self.imu.gyro),
            ("accel", &self.imu.accel),
        ] {
            check(name, s.iter().map(|s| s.t_s))?;
            if s.iter().any(|s| s.xyz().iter().any(|v| !v.is_finite())) {
                return Err(Error::drive(name, DriveFault::NonFinite { what: "value" }));
            }
        }
        Ok(())
    }
}
