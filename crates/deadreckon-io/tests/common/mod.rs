//! A small drive built in code, shared by the integration tests.
#![allow(dead_code)]

use std::path::Path;

use deadreckon_core::drive::{GnssFix, Scalar, TruthPose, WheelSpeeds, WheelTicks, Wheels};
use deadreckon_core::{Drive, Vehicle};

/// A drive of 10 wheel epochs at 50 Hz from t = 100 s, with every stream,
/// values chosen so that their decimal forms are long (full-precision test).
pub fn small_drive() -> Drive {
    let mut vehicle = Vehicle::paper_car();
    vehicle.noise.gyro_rps = 0.1 / 3.0;
    let t = |i: usize| 100.0 + i as f64 * 0.02;
    let mut drive = Drive::empty(vehicle);
    drive.wheels = Wheels::Ticks(
        (0..10)
            .map(|i| WheelTicks {
                t_s: t(i),
                fl: i as i64,
                fr: i as i64 + 1,
                rl: -(i as i64),
                rr: 3,
            })
            .collect(),
    );
    drive.yaw_rate = (0..10)
        .map(|i| Scalar {
            t_s: t(i) + 0.001,
            value: 0.1 / 3.0 + i as f64 * 1e-7,
        })
        .collect();
    drive.speed = (0..5)
        .map(|i| Scalar {
            t_s: t(2 * i),
            value: 10.0 / 3.0,
        })
        .collect();
    drive.steering = (0..5)
        .map(|i| Scalar {
            t_s: t(2 * i) + 1e-9,
            value: -0.7 + i as f64 * 0.123456789,
        })
        .collect();
    drive.gnss = (0..3)
        .map(|i| GnssFix {
            t_s: t(3 * i),
            east_m: 12.5 + i as f64 / 7.0,
            north_m: -3.25 * i as f64,
            std_m: 0.05,
            course_deg: if i == 1 { None } else { Some(359.9) },
            speed_mps: Some(1.0 / 3.0),
        })
        .collect();
    drive.truth = (0..10)
        .map(|i| TruthPose {
            t_s: t(i),
            east_m: 1e-3 * i as f64,
            north_m: 2.0 / 3.0,
            yaw_rad: -3.0 + 0.6 * i as f64,
            speed_mps: None,
        })
        .collect();
    drive
}

/// The same drive with wheel speeds instead of ticks.
pub fn small_drive_speeds() -> Drive {
    let mut d = small_drive();
    d.wheels = Wheels::Speeds(
        (0..10)
            .map(|i| WheelSpeeds {
                t_s: 100.0 + i as f64 * 0.02,
                fl_mps: 5.0 / 3.0,
                fr_mps: -0.1,
                rl_mps: 1e-12,
                rr_mps: 99.99,
            })
            .collect(),
    );
    d
}

/// Writes `text` to `dir/name`.
pub fn put(dir: &Path, name: &str, text: &str) {
    std::fs::write(dir.join(name), text).expect("test file written");
}
