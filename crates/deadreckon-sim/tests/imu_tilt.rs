//! The IMU tilt while driving, on a simulated highway drive that never stops
//! (so the tilt comes from the driving branch of
//! [`deadreckon_core::imu::estimate_tilt`]), with a phone's raw gyro: a bias
//! of 0.05 rad/s on its z axis (the comma2k19 phone's is 0.068 rad/s).

use deadreckon_core::imu::{estimate_tilt, TiltSource};
use deadreckon_sim::sensors::tilt_rotation;
use deadreckon_sim::{simulate, Scenario};

const PITCH_DEG: f64 = -3.5;
const ROLL_DEG: f64 = 1.5;
const GYRO_BIAS_RPS: f64 = 0.05;

fn highway() -> Scenario {
    let text = format!(
        r#"
name = "tilted-phone-highway"
vehicle = "paper-car"

[errors]
gyro_bias_rps = {GYRO_BIAS_RPS}
speed_scale = 1.0
circumference_fl_m = 1.913
circumference_fr_m = 1.913
circumference_rl_m = 1.913
circumference_rr_m = 1.913

[route]
start_yaw_deg = 90.0
segments = [
  {{ kind = "straight", length_m = 600 }},
  {{ kind = "turn", angle_deg = 15, radius_m = 600 }},
  {{ kind = "straight", length_m = 500 }},
  {{ kind = "turn", angle_deg = -25, radius_m = 500 }},
  {{ kind = "straight", length_m = 600 }},
]

[speed]
default_limit_kmh = 72
start_stop_s = 0
end_stop_s = 0

[sensors.wheels]
kind = "speeds"
rate_hz = 83
offset_s = 0.004

[sensors.gyro]
rate_hz = 100
offset_s = 0.001
noise_std = 0.003
tilt_deg = [{PITCH_DEG}, {ROLL_DEG}]

[sensors.gnss]
rate_hz = 10
offset_s = 0.05
std_m = 0.5
velocity_std_mps = 0.05
"#
    );
    Scenario::from_toml_str(&text).unwrap()
}

#[test]
fn the_roll_was_taken_from_a_centripetal_acceleration_with_the_gyro_bias_in_it() {
    let out = simulate(&highway(), 7).unwrap();
    let t = estimate_tilt(&out.drive).expect("three-axis IMU");
    eprintln!("{t:?}");
    assert!(t.is_estimated(), "{t:?}");
    assert_eq!(t.source, TiltSource::Driving);
    let m = tilt_rotation(PITCH_DEG.to_radians(), ROLL_DEG.to_radians());
    let up = [m[0][2], m[1][2], m[2][2]];
    let (pitch, roll) = (up[0].asin(), up[1].asin());
    eprintln!(
        "pitch {:+.3}° ± {:.3}° (truth {:+.3}°), roll {:+.3}° ± {:.3}° (truth {:+.3}°)",
        t.pitch_rad.to_degrees(),
        t.pitch_std_rad.to_degrees(),
        pitch.to_degrees(),
        t.roll_rad.to_degrees(),
        t.roll_std_rad.to_degrees(),
        roll.to_degrees()
    );
    // Before: `speed × gyro z` with the bias in it was taken for the
    // centripetal acceleration, up to 20 m/s × 0.05 rad/s = 1 m/s² across,
    // and the roll read −3.30° ± 0.19° instead of +1.50° (measured with the
    // bias taken out of the centripetal term again).
    assert!(
        (t.roll_rad - roll).abs() <= 3.0 * t.roll_std_rad,
        "roll {:.3}° ± {:.3}°, truth {:.3}°",
        t.roll_rad.to_degrees(),
        t.roll_std_rad.to_degrees(),
        roll.to_degrees()
    );
    assert!((t.pitch_rad - pitch).abs() <= 3.0 * t.pitch_std_rad);
    let tilt = up[2].acos();
    assert!((t.tilt_rad - tilt).abs() <= 3.0 * t.std_rad);
    // Physical precision, not a wide error bar: the simulated accelerometer
    // has no bias, so what is left is the blocks' scatter and the bias's error.
    assert!(t.roll_std_rad.to_degrees() < 0.1, "{t:?}");
    // The bias the centripetal term used, from the GNSS course; the gyro's z
    // axis is tilted, so it reads the bias alone (the simulator adds it there).
    let b = t.gyro_bias.expect("driving: bias from the course");
    assert!(
        (b.bias_rps - GYRO_BIAS_RPS).abs() <= 3.0 * b.std_rps,
        "{b:?}"
    );
}

#[test]
fn a_tilt_while_driving_without_a_gnss_course_is_not_estimated() {
    let mut sc = highway();
    sc.sensors.gnss.as_mut().unwrap().velocity_std_mps = None;
    let out = simulate(&sc, 7).unwrap();
    let t = estimate_tilt(&out.drive).expect("three-axis IMU");
    assert!(!t.is_estimated(), "{t:?}");
    let reason = t.status.reason().unwrap();
    assert!(reason.contains("gyro's bias"), "{reason}");
}
