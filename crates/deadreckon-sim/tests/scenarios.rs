//! The built-in scenarios have the shape the papers describe.

mod common;

use common::{calibration, distance, evaluation, stops, yaw};
use deadreckon_core::drive::Wheels;
use deadreckon_sim::{simulate, Scenario};

#[test]
fn calibration_is_an_8_km_urban_drive() {
    let out = calibration();
    let truth = &out.drive.truth;
    let dist = distance(truth);
    assert!((dist - 8000.0).abs() < 800.0, "distance {dist} m");
    assert!(
        (dist - out.stats.distance_m).abs() < 0.05,
        "{dist} vs {}",
        out.stats.distance_m
    );
    let duration = truth.last().unwrap().t_s - truth[0].t_s;
    let mean_kmh = dist / duration * 3.6;
    assert!(
        (25.0..=35.0).contains(&mean_kmh),
        "mean speed {mean_kmh} km/h"
    );
    let max_kmh = truth
        .iter()
        .map(|p| p.speed_mps.unwrap())
        .fold(0.0, f64::max)
        * 3.6;
    assert!(max_kmh < 70.0, "max speed {max_kmh} km/h");
    let long_stops = stops(truth).into_iter().filter(|s| s.1 >= 2.0).count();
    assert!(long_stops >= 3, "{long_stops} stops of at least 2 s");
}

#[test]
fn calibration_turns_both_ways_and_has_a_roundabout() {
    let out = calibration();
    let truth = &out.drive.truth;
    let yaw = yaw(truth);
    let rates: Vec<f64> = yaw.windows(2).map(|w| (w[1] - w[0]) / 0.01).collect();
    assert!(rates.iter().any(|&r| r > 0.2) && rates.iter().any(|&r| r < -0.2));
    // A roundabout: more than 270° of heading change in one direction within 150 m.
    let s: Vec<f64> = std::iter::once(0.0)
        .chain(truth.windows(2).scan(0.0, |acc, w| {
            *acc += 0.5 * (w[0].speed_mps.unwrap() + w[1].speed_mps.unwrap()) * 0.01;
            Some(*acc)
        }))
        .collect();
    let mut best: f64 = 0.0;
    let mut j = 0;
    for i in 0..yaw.len() {
        while s[i] - s[j] > 150.0 {
            j += 1;
        }
        // Largest one-direction change ending at i within the window.
        let window = &yaw[j..=i];
        let min = window.iter().cloned().fold(f64::INFINITY, f64::min);
        let max = window.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        best = best.max((yaw[i] - min).max(max - yaw[i]));
    }
    assert!(
        best.to_degrees() > 270.0,
        "largest turn within 150 m: {}°",
        best.to_degrees()
    );
}

#[test]
fn evaluation_is_three_laps_of_1_7_km() {
    let out = evaluation();
    let dist = distance(&out.drive.truth);
    assert!((dist - 5100.0).abs() < 510.0, "distance {dist} m");
    // Three laps of a closed loop: back at the start, three full turns.
    let first = &out.drive.truth[0];
    let last = out.drive.truth.last().unwrap();
    assert!((last.east_m - first.east_m).hypot(last.north_m - first.north_m) < 1e-3);
    assert!((out.stats.heading_change_rad.abs() - 3.0 * std::f64::consts::TAU).abs() < 1e-6);
}

#[test]
fn tedris_car_has_wheel_speeds_and_course() {
    let out = simulate(&Scenario::builtin("tedris-car").unwrap(), 5).unwrap();
    out.drive.validate().unwrap();
    let minutes = out.stats.duration_s / 60.0;
    assert!((8.0..=15.0).contains(&minutes), "{minutes} min");
    let Wheels::Speeds(ws) = &out.drive.wheels else {
        panic!("tedris-car must have wheel speeds")
    };
    let dt = ws[1].t_s - ws[0].t_s;
    assert!((dt - 0.04).abs() < 1e-9, "25 Hz");
    let gnss = &out.drive.gnss;
    assert!((gnss[1].t_s - gnss[0].t_s - 0.25).abs() < 1e-9, "4 Hz");
    assert!(gnss.iter().filter(|g| g.course_deg.is_some()).count() > gnss.len() / 2);
    // The ECU's speeds use the nominal circumference: the integrated rear
    // speeds are the true distances scaled by nominal / true circumference.
    let p = out.truth_params;
    let nominal = out.drive.vehicle.wheel_circumference_m;
    let rl: f64 = ws.iter().map(|w| w.rl_mps * dt).sum();
    let rr: f64 = ws.iter().map(|w| w.rr_mps * dt).sum();
    let [_, _, d_rl, d_rr] = out.stats.wheel_distance_m;
    assert!((rl / (d_rl * nominal / p.circumference_rl_m) - 1.0).abs() < 1e-3);
    assert!((rr / (d_rr * nominal / p.circumference_rr_m) - 1.0).abs() < 1e-3);
    // The rear wheels differ by 0.2 %.
    assert!((p.circumference_rl_m / p.circumference_rr_m - 1.002).abs() < 1e-4);
    let speeds: Vec<f64> = out
        .drive
        .truth
        .iter()
        .map(|t| t.speed_mps.unwrap())
        .collect();
    let max = speeds.iter().cloned().fold(0.0, f64::max);
    assert!(max > 10.0 && max <= 12.0, "max speed {max}");
}

#[test]
fn tedris_robot_is_a_slow_differential_drive() {
    let out = simulate(&Scenario::builtin("tedris-robot").unwrap(), 5).unwrap();
    out.drive.validate().unwrap();
    let minutes = out.stats.duration_s / 60.0;
    assert!((5.0..=10.0).contains(&minutes), "{minutes} min");
    assert!((out.stats.max_speed_mps - 0.3).abs() < 1e-9);
    assert!((0.4..=0.6).contains(&out.stats.max_abs_yaw_rate_rps));
    let Wheels::Ticks(ticks) = &out.drive.wheels else {
        panic!("the robot has encoder ticks")
    };
    assert!((ticks[1].t_s - ticks[0].t_s - 0.1).abs() < 1e-9, "10 Hz");
    // Gyro and encoders share the robot board's clock.
    assert_eq!(ticks[3].t_s, out.drive.yaw_rate[3].t_s);
    // The curves sharpen: the yaw rate of the second half exceeds the first.
    let yaw = yaw(&out.drive.truth);
    let n = yaw.len();
    let rate = |a: usize, b: usize| -> f64 {
        yaw[a..b]
            .windows(2)
            .map(|w| ((w[1] - w[0]) / 0.01).abs())
            .fold(0.0, f64::max)
    };
    assert!(rate(n / 2, n - 1) > 2.0 * rate(0, n / 5));
}

#[test]
fn every_builtin_validates_and_covers_its_duration() {
    for name in Scenario::names() {
        let scenario = Scenario::builtin(name).unwrap().with_duration_s(60.0);
        let out = simulate(&scenario, 2).unwrap();
        out.drive.validate().unwrap();
        let last = out.drive.truth.last().unwrap().t_s;
        assert!((last - 60.0).abs() < 1e-9, "{name}: truth ends at {last}");
    }
}
