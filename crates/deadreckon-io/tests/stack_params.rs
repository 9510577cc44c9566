//! Calibrated parameters for Autoware and Eagleye, parsed back with a YAML
//! parser: upstream names, ROS 2 doubles, units and signs.

use std::path::Path;

use deadreckon_core::vehicle::Noise;
use deadreckon_core::{Params, ParamsWithStd, Vehicle};
use deadreckon_io::stack_params::{self, names, StackExport};

fn estimate() -> ParamsWithStd {
    ParamsWithStd {
        params: Params {
            gyro_bias_rps: -0.002979,
            speed_scale: 0.987,
            circumference_fl_m: 1.9136,
            circumference_fr_m: 1.9131,
            circumference_rl_m: 1.91679,
            circumference_rr_m: 1.91659,
        },
        std: Params {
            gyro_bias_rps: 9e-6,
            speed_scale: 3e-5,
            circumference_fl_m: 7e-4,
            circumference_fr_m: 7e-4,
            circumference_rl_m: 7e-4,
            circumference_rr_m: 7e-4,
        },
    }
}

fn yaml(path: &Path) -> serde_yaml::Value {
    serde_yaml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn ros_params(path: &Path) -> serde_yaml::Mapping {
    yaml(path)["/**"]["ros__parameters"]
        .as_mapping()
        .unwrap()
        .clone()
}

fn f(m: &serde_yaml::Mapping, key: &str) -> f64 {
    // A float, not an integer: ROS 2 declares these parameters as doubles.
    match &m[key] {
        serde_yaml::Value::Number(n) if n.is_f64() => n.as_f64().unwrap(),
        other => panic!("{key}: {other:?} is not a double"),
    }
}

#[test]
fn autoware_files_parse_with_upstream_names_units_and_signs() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("autoware");
    let noise = Vehicle::paper_car().noise;
    let est = estimate();
    let x = StackExport {
        estimate: &est,
        samples: [3000, 2500, 2400, 2400, 2400, 2400],
        noise: &noise,
        provenance: "Calibrated on test drive\nwith two lines.".into(),
    };
    let written = stack_params::write_autoware(&out, &x).unwrap();
    assert_eq!(
        written,
        [
            out.join(names::IMU_CORRECTOR),
            out.join(names::VEHICLE_VELOCITY_CONVERTER)
        ]
    );
    let imu = ros_params(&written[0]);
    let keys: Vec<&str> = imu.keys().map(|k| k.as_str().unwrap()).collect();
    assert_eq!(
        keys,
        [
            "angular_velocity_offset_x",
            "angular_velocity_offset_y",
            "angular_velocity_offset_z",
            "angular_velocity_stddev_xx",
            "angular_velocity_stddev_yy",
            "angular_velocity_stddev_zz",
            "acceleration_stddev",
        ]
    );
    // Autoware subtracts the offset: offset = b_gyro.
    assert_eq!(f(&imu, "angular_velocity_offset_z"), -0.002979);
    assert_eq!(f(&imu, "angular_velocity_offset_x"), 0.0);
    assert_eq!(f(&imu, "angular_velocity_stddev_zz"), noise.gyro_rps);
    assert_eq!(f(&imu, "angular_velocity_stddev_xx"), 0.03);
    assert_eq!(f(&imu, "acceleration_stddev"), 10000.0);
    let text = std::fs::read_to_string(&written[0]).unwrap();
    assert!(text.contains("# with two lines."), "{text}");

    let vvc = ros_params(&written[1]);
    // It multiplies the reported speed: factor = 1 / a_v.
    let factor = f(&vvc, "speed_scale_factor");
    assert!((factor - 1.0 / 0.987).abs() < 1e-9, "{factor}");
    assert_eq!(f(&vvc, "velocity_stddev_xx"), noise.speed_mps);
    assert_eq!(f(&vvc, "angular_velocity_stddev_zz"), 0.1);
    assert_eq!(vvc["frame_id"].as_str(), Some("base_link"));
}

#[test]
fn eagleye_files_parse_and_carry_the_scale_factor_and_negated_offset() {
    let dir = tempfile::tempdir().unwrap();
    let noise = Noise::default();
    let est = estimate();
    let mut x = StackExport {
        estimate: &est,
        samples: [3000, 2500, 2400, 2400, 2400, 2400],
        noise: &noise,
        provenance: "test".into(),
    };
    let written = stack_params::write_eagleye(dir.path(), &x).unwrap();
    assert_eq!(
        written,
        [
            dir.path().join(names::EAGLEYE_CONFIG),
            dir.path().join(names::EAGLEYE_VELOCITY_SCALE_FACTOR)
        ]
    );
    let cfg = ros_params(&written[0]);
    let vsf = cfg["velocity_scale_factor"].as_mapping().unwrap();
    assert_eq!(vsf["save_velocity_scale_factor"].as_bool(), Some(true));
    assert_eq!(
        vsf["velocity_scale_factor_save_str"].as_str(),
        Some("/config/velocity_scale_factor.txt")
    );
    let heading = cfg["heading"].as_mapping().unwrap();
    assert_eq!(heading["skip_static_initialization"].as_bool(), Some(true));
    // Eagleye adds the offset: offset = −b_gyro.
    assert_eq!(f(heading, "yaw_rate_offset_stop_in_skip_mode"), 0.002979);
    // The saved scale factor in Eagleye's own four-line layout.
    let txt = std::fs::read_to_string(&written[1]).unwrap();
    let lines: Vec<&str> = txt.lines().collect();
    assert_eq!(lines[0], "estimated_number");
    assert_eq!(lines[1].parse::<usize>().unwrap(), 2500);
    assert_eq!(lines[2], "velocity_scale_factor");
    assert!((lines[3].parse::<f64>().unwrap() - 1.0 / 0.987).abs() < 1e-9);

    // A ZUPT calibration estimates only the gyro bias: no scale factor file,
    // saving left off, the offset still seeded.
    let other = tempfile::tempdir().unwrap();
    x.samples = [3000, 0, 0, 0, 0, 0];
    let written = stack_params::write_eagleye(other.path(), &x).unwrap();
    assert_eq!(written, [other.path().join(names::EAGLEYE_CONFIG)]);
    let cfg = ros_params(&written[0]);
    assert_eq!(
        cfg["velocity_scale_factor"]["save_velocity_scale_factor"].as_bool(),
        Some(false)
    );
    assert_eq!(
        cfg["heading"]["skip_static_initialization"].as_bool(),
        Some(true)
    );
    // And Autoware then keeps the ideal speed factor, saying so.
    let written = stack_params::write_autoware(other.path(), &x).unwrap();
    assert_eq!(f(&ros_params(&written[1]), "speed_scale_factor"), 1.0);
    assert!(std::fs::read_to_string(&written[1])
        .unwrap()
        .contains("not estimated"));
}

#[test]
fn a_speed_scale_without_inverse_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let noise = Noise::default();
    let mut est = estimate();
    est.params.speed_scale = 0.0;
    let x = StackExport {
        estimate: &est,
        samples: [3000, 2500, 0, 0, 0, 0],
        noise: &noise,
        provenance: "test".into(),
    };
    let e = stack_params::write_autoware(dir.path(), &x)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains(names::VEHICLE_VELOCITY_CONVERTER) && e.contains("a_v = 0"),
        "{e}"
    );
}
