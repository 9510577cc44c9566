//! The vehicle's shape, found from the data (issue 29, item 3): one rule
//! every command (`calibrate`, `evaluate`, `run`, `report`, `compare`,
//! `batch`) and Python apply, printed with its reason, and overridden by
//! `--shape`.
//!
//! - A tricycle log (`dataset.txt`), or a drive with one wheel sensor and a
//!   steering stream (what `import tricycle` writes), is a **tricycle**.
//! - A drive without steering whose wheel speeds are one left/right pair
//!   (rear = front in every row: what a ROS odometry twist, body velocity,
//!   becomes), or that has only two wheel sensors, is a **differential
//!   drive**.
//! - Anything else (four wheel speeds or ticks, steering) is a **car**.

use std::path::Path;

use deadreckon_core::drive::Wheels;
use deadreckon_core::kinematics::Shape;
use deadreckon_core::Drive;

/// A shape and why: found from the data, or asked for with `--shape`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found {
    /// The shape.
    pub shape: Shape,
    /// Why, in words ("the log has body velocity and no four wheel speeds").
    pub reason: String,
    /// Whether the user chose it (`--shape`) rather than the data.
    pub asked: bool,
}

impl Found {
    /// The line the commands print: `shape: differential drive (reason)`.
    pub fn line(&self) -> String {
        format!("shape: {} ({})", words(self.shape), self.reason)
    }

    /// The `--json` value (`"shape_found"`): `{"name": "diff_drive", "reason": …, "asked": false}`.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "name": self.shape.name(),
            "reason": self.reason,
            "asked": self.asked,
        })
    }
}

/// A shape in words, as the commands print it.
pub fn words(shape: Shape) -> &'static str {
    match shape {
        Shape::FourWheel => "car",
        Shape::Tricycle => "tricycle",
        Shape::DiffDrive => "differential drive",
    }
}

/// The shape of what `path` holds, found from the path alone: a tricycle
/// log is a tricycle; anything else needs its drive ([`of_drive`]).
pub fn of_path(path: &Path) -> Option<Found> {
    (crate::source::detect(path) == crate::source::SourceKind::TricycleLog).then(|| Found {
        shape: Shape::Tricycle,
        reason: "the file is a tricycle log".into(),
        asked: false,
    })
}

/// The shape of a drive, from the streams it has (the module's rule).
pub fn of_drive(drive: &Drive) -> Found {
    let present = drive.vehicle.wheels_present.iter().filter(|p| **p).count();
    let steering = !drive.steering.is_empty();
    let found = |shape, reason: String| Found {
        shape,
        reason,
        asked: false,
    };
    if present == 1 && steering {
        return found(
            Shape::Tricycle,
            "the drive has one wheel sensor (the steered traction wheel) and a steering stream"
                .into(),
        );
    }
    if !steering {
        if present == 2 {
            return found(
                Shape::DiffDrive,
                "the drive has two wheel sensors and no steering".into(),
            );
        }
        if let Wheels::Speeds(w) = &drive.wheels {
            let paired = !w.is_empty()
                && w.iter()
                    .all(|r| r.rl_mps == r.fl_mps && r.rr_mps == r.fr_mps);
            if paired {
                return found(
                    Shape::DiffDrive,
                    "the log has body velocity (one left/right pair of wheel speeds, rear = front \
                     in every row), no four wheel speeds and no steering"
                        .into(),
                );
            }
        }
    }
    let wheels = match &drive.wheels {
        Wheels::Ticks(_) => "ticks",
        Wheels::Speeds(_) => "speeds",
    };
    found(
        Shape::FourWheel,
        format!(
            "the drive has {present} wheel {wheels}{}",
            if steering {
                " and steering"
            } else {
                " (rear and front apart), no steering"
            }
        ),
    )
}

/// The one function the commands call: the shape asked for (`--shape`),
/// else a tricycle log's, else the drive's ([`of_drive`]); `drive` is read
/// by the caller (`None` only for a tricycle log, read through its own
/// kinematics).
pub fn detect(path: &Path, drive: Option<&Drive>, asked: Option<Shape>) -> Found {
    if let Some(shape) = asked {
        return Found {
            shape,
            reason: "--shape".into(),
            asked: true,
        };
    }
    if let Some(f) = of_path(path) {
        return f;
    }
    match drive {
        Some(d) => of_drive(d),
        None => Found {
            shape: Shape::FourWheel,
            reason: "the default (no drive read)".into(),
            asked: false,
        },
    }
}

/// Reads what `path` holds and finds its shape ([`detect`]), reading it
/// once: a tricycle log not asked to be a car is left to its own
/// kinematics (no drive); a drive found to be a tricycle is read again
/// with its truth (its reference) when `options` left it out.
pub fn load(
    loader: &crate::load::Loader,
    path: &Path,
    options: &deadreckon_io::ReadOptions,
    asked: Option<Shape>,
) -> Result<(Option<Drive>, Found), crate::Error> {
    if of_path(path).is_some() && !matches!(asked, Some(Shape::FourWheel)) {
        return Ok((None, detect(path, None, asked)));
    }
    let drive = loader.drive_with(path, options)?;
    let found = detect(path, Some(&drive), asked);
    if found.shape == Shape::Tricycle && options.skip_truth {
        let mut with_truth = options.clone();
        with_truth.skip_truth = false;
        return Ok((Some(loader.drive_with(path, &with_truth)?), found));
    }
    Ok((Some(drive), found))
}

#[cfg(test)]
mod tests {
    use super::*;
    use deadreckon_core::drive::{Scalar, WheelSpeeds, WheelTicks};
    use deadreckon_core::Vehicle;

    fn speeds(rear_equal: bool) -> Drive {
        let mut d = Drive::empty(Vehicle::paper_car());
        d.wheels = Wheels::Speeds(
            (0..10)
                .map(|i| {
                    let v = 1.0 + 0.1 * i as f64;
                    WheelSpeeds {
                        t_s: i as f64,
                        fl_mps: v,
                        fr_mps: v + 0.1,
                        rl_mps: if rear_equal { v } else { v + 0.01 },
                        rr_mps: v + 0.1,
                    }
                })
                .collect(),
        );
        d
    }

    #[test]
    fn body_velocity_without_steering_is_a_differential_drive() {
        let f = of_drive(&speeds(true));
        assert_eq!(f.shape, Shape::DiffDrive);
        assert!(f
            .line()
            .starts_with("shape: differential drive (the log has body velocity"));
        // Four wheel speeds of their own: a car, even without steering.
        assert_eq!(of_drive(&speeds(false)).shape, Shape::FourWheel);
        // Steering makes it a car whatever the wheels.
        let mut d = speeds(true);
        d.steering.push(Scalar {
            t_s: 0.0,
            value: 0.0,
        });
        assert_eq!(of_drive(&d).shape, Shape::FourWheel);
    }

    #[test]
    fn one_steered_wheel_is_a_tricycle_and_two_wheels_a_differential_drive() {
        let mut d = Drive::empty(Vehicle::paper_car());
        d.wheels = Wheels::Ticks(vec![WheelTicks {
            t_s: 0.0,
            fl: 1,
            fr: 1,
            rl: 0,
            rr: 0,
        }]);
        d.vehicle.wheels_present = [true, false, false, false];
        assert_eq!(of_drive(&d).shape, Shape::FourWheel);
        d.steering.push(Scalar {
            t_s: 0.0,
            value: 0.1,
        });
        assert_eq!(of_drive(&d).shape, Shape::Tricycle);
        d.steering.clear();
        d.vehicle.wheels_present = [false, false, true, true];
        assert_eq!(of_drive(&d).shape, Shape::DiffDrive);
    }

    #[test]
    fn shape_asked_for_overrides_the_data() {
        let f = detect(Path::new("x"), Some(&speeds(true)), Some(Shape::FourWheel));
        assert_eq!(f.shape, Shape::FourWheel);
        assert!(f.asked);
        assert_eq!(f.line(), "shape: car (--shape)");
    }
}
