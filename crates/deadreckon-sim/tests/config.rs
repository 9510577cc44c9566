//! User scenarios from TOML, builder overrides, and bad input reported as errors.

use deadreckon_core::{Params, Vehicle};
use deadreckon_sim::{simulate, Scenario, Segment, SimError};

const SMALL: &str = r#"
name = "small"
laps = 2

[vehicle]
wheelbase_m = 2.7
track_front_m = 1.55
track_rear_m = 1.55
gnss_lever_arm_m = 0.5
ticks_per_rev = 96
wheel_circumference_m = 2.0
steering_ratio = 14.0

[errors]
gyro_bias_rps = 0.001
speed_scale = 1.02
circumference_fl_m = 2.001
circumference_fr_m = 2.002
circumference_rl_m = 1.999
circumference_rr_m = 1.998

[route]
closed = true
segments = [
  { kind = "straight", length_m = 100 },
  { kind = "turn", angle_deg = 90, radius_m = 20 },
  { kind = "straight", length_m = 60 },
  { kind = "turn", angle_deg = 90, radius_m = 20 },
  { kind = "straight", length_m = 100 },
  { kind = "stop", duration_s = 3 },
  { kind = "turn", angle_deg = 90, radius_m = 20 },
  { kind = "straight", length_m = 60 },
  { kind = "turn", angle_deg = 90, radius_m = 20 },
]

[sensors.wheels]
kind = "ticks"
rate_hz = 50
"#;

#[test]
fn a_user_scenario_runs() {
    let s = Scenario::from_toml_str(SMALL).unwrap();
    let out = simulate(&s, 1).unwrap();
    out.drive.validate().unwrap();
    assert_eq!(out.drive.vehicle.ticks_per_rev, 96);
    assert_eq!(out.truth_params.speed_scale, 1.02);
    assert!(out.drive.gnss.is_empty() && out.drive.yaw_rate.is_empty());
    assert_eq!(out.stats.stops.len(), 4, "{:?}", out.stats.stops);
}

#[test]
fn overrides_apply() {
    let errors = Params {
        gyro_bias_rps: 0.01,
        ..Params::nominal(&Vehicle::paper_car())
    };
    let s = Scenario::builtin("evaluation")
        .unwrap()
        .with_laps(1)
        .with_errors(errors)
        .with_gnss_std_m(2.0);
    let out = simulate(&s, 3).unwrap();
    assert_eq!(out.truth_params, errors);
    assert!(out.drive.gnss.iter().all(|g| g.std_m == 2.0));
    let robot = Scenario::vehicle_preset("turtlebot2").unwrap();
    let s = Scenario::builtin("tedris-robot")
        .unwrap()
        .with_vehicle(robot.clone());
    assert_eq!(s.vehicle, robot);
}

fn expect_invalid(s: Scenario, key: &str) {
    match simulate(&s, 1) {
        Err(SimError::Invalid { key: k, .. }) => {
            assert!(k.contains(key), "{k} does not name {key}")
        }
        Err(SimError::Core(_)) if key == "core" => {}
        other => panic!("expected an error on {key}, got {other:?}"),
    }
}

#[test]
fn bad_values_are_errors_not_panics() {
    let base = Scenario::from_toml_str(SMALL).unwrap();
    expect_invalid(base.clone().with_laps(0), "laps");
    expect_invalid(base.clone().with_duration_s(f64::NAN), "duration_s");
    let mut s = base.clone();
    s.route.segments[1] = Segment::Turn {
        angle_deg: 90.0,
        radius_m: -3.0,
        speed_limit_kmh: None,
        transition_m: None,
    };
    expect_invalid(s, "segments[1].radius_m");
    let mut s = base.clone();
    s.route.segments.pop();
    expect_invalid(s, "route.closed");
    let mut s = base.clone();
    s.route.segments.clear();
    expect_invalid(s, "route.segments");
    let mut s = base.clone();
    s.sensors.wheels.rate_hz = 0.0;
    expect_invalid(s, "sensors.wheels.rate_hz");
    let mut s = base.clone();
    s.sensors.wheels.offset_s = -1.0;
    expect_invalid(s, "sensors.wheels.offset_s");
    let mut s = base.clone();
    s.speed.max_accel_mps2 = 0.0;
    expect_invalid(s, "speed.max_accel_mps2");
    let mut s = base.clone();
    s.integration_rate_hz = 10.0;
    expect_invalid(s, "integration_rate_hz");
    let mut s = base.clone().with_gnss_std_m(0.0);
    s.name = "zero gnss".into();
    expect_invalid(s, "sensors.gnss.std_m");
    let mut s = base.clone();
    s.route.segments[0] = Segment::Straight {
        length_m: 1e300,
        speed_limit_kmh: None,
    };
    expect_invalid(s, "segments[0].length_m");
    let mut s = base.clone();
    s.speed.default_limit_kmh = 1e-3;
    expect_invalid(s, "duration_s");
    expect_invalid(base.clone().with_laps(u32::MAX), "laps");
    let mut s = base.clone();
    s.vehicle.wheelbase_m = -1.0;
    expect_invalid(s, "core");
    let errors = Params {
        circumference_fl_m: 0.0,
        ..base.true_params()
    };
    expect_invalid(base.clone().with_errors(errors), "core");
}

#[test]
fn bad_toml_is_a_parse_error() {
    for text in [
        "",
        "name = 3",
        "name = \"x\"\nvehicle = \"paper-car\"\n[route]\nsegments = [{ kind = \"spiral\" }]",
    ] {
        assert!(
            matches!(Scenario::from_toml_str(text), Err(SimError::Parse { .. })),
            "{text}"
        );
    }
    let e = Scenario::load(std::path::Path::new("/nonexistent/scenario.toml")).unwrap_err();
    assert!(matches!(e, SimError::Io { .. }));
}
