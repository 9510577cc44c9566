//! The `[dynamics]` table (`deadreckon_sim::dynamics`): the body turned
//! against the path of M by the rear side slip, the gyro and the wheels
//! following the body, the steering reading the understeer; off by default.

use deadreckon_core::drive::Wheels;
use deadreckon_core::{angle, Params};
use deadreckon_sim::{simulate, DynamicsSpec, Scenario, SimOutput};

/// The evaluation loop (one lap, paper car) with the default dynamics and
/// noise-free gyro and steering.
fn dynamic_drive() -> (Scenario, SimOutput) {
    drive_with(Some(DynamicsSpec::default()))
}

fn drive_with(dynamics: Option<DynamicsSpec>) -> (Scenario, SimOutput) {
    let mut sc = Scenario::builtin("evaluation")
        .unwrap()
        .with_laps(1)
        .with_dynamics(dynamics);
    sc.sensors.gyro.as_mut().unwrap().noise_std = 0.0;
    sc.sensors.steering.as_mut().unwrap().noise_std = 0.0;
    let out = simulate(&sc, 3).unwrap();
    (sc, out)
}

/// Least-squares slope through the origin of `y` on `x`.
fn slope(pairs: &[(f64, f64)]) -> f64 {
    let sxy: f64 = pairs.iter().map(|(x, y)| x * y).sum();
    let sxx: f64 = pairs.iter().map(|(x, _)| x * x).sum();
    sxy / sxx
}

/// From the truth (100 Hz): per interval, the course of M (direction of
/// the displacement), the body yaw at the midpoint, the lateral
/// acceleration v·χ̇ and the speed.
fn course_against_yaw(out: &SimOutput) -> Vec<(f64, f64, f64, f64)> {
    let tr = &out.drive.truth;
    let mut rows = Vec::new();
    for w in tr.windows(3) {
        let (a, b, c) = (&w[0], &w[1], &w[2]);
        let v = b.speed_mps.unwrap();
        if v < 3.0 {
            continue;
        }
        let c1 = (b.north_m - a.north_m).atan2(b.east_m - a.east_m);
        let c2 = (c.north_m - b.north_m).atan2(c.east_m - b.east_m);
        let course = c1 + 0.5 * angle::wrap(c2 - c1);
        let course_rate = angle::wrap(c2 - c1) / (c.t_s - b.t_s);
        rows.push((b.t_s, angle::wrap(course - b.yaw_rad), v * course_rate, v));
    }
    rows
}

#[test]
fn the_body_yaw_is_the_course_less_the_rear_side_slip() {
    let (sc, out) = dynamic_drive();
    let g = DynamicsSpec::default().rear_slip_gradient_rad_per_mps2(&sc.vehicle);
    let rows = course_against_yaw(&out);
    let pairs: Vec<(f64, f64)> = rows.iter().map(|r| (r.2, r.1)).collect();
    let fit = slope(&pairs);
    let max_ay = rows.iter().map(|r| r.2.abs()).fold(0.0, f64::max);
    let max_beta = rows.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
    println!(
        "slope of course − yaw on a_y: {fit:.6} rad per m/s² (gradient {g:.6}); largest a_y \
         {max_ay:.2} m/s², largest β {:.3}°",
        max_beta.to_degrees()
    );
    // Measured: slope −0.004870 against g = 0.004846 (the load transfer
    // adds 0.5 %); a_y up to 2.0 m/s², β up to 0.56°.
    assert!((fit + g).abs() < 0.03 * g, "{fit} vs {g}");
    assert!(max_beta > 0.5f64.to_radians(), "{max_beta}");
    // The residual about the linear model is small: the slip is a function
    // of a_y (plus the load transfer), not noise.
    let rms =
        (rows.iter().map(|r| (r.1 + g * r.2).powi(2)).sum::<f64>() / rows.len() as f64).sqrt();
    assert!(rms < 0.05f64.to_radians(), "rms {rms}");
}

#[test]
fn the_gyro_and_the_rear_wheels_follow_the_body() {
    for dynamics in [None, Some(DynamicsSpec::default())] {
        let (sc, out) = drive_with(dynamics);
        let d = &out.drive;
        let p: Params = out.truth_params;
        // The noise-free gyro, less its bias, integrates to the body yaw.
        let mut yaw = 0.0;
        for w in d.yaw_rate.windows(2) {
            yaw += 0.5 * (w[0].value + w[1].value - 2.0 * p.gyro_bias_rps) * (w[1].t_s - w[0].t_s);
        }
        let first = d.yaw_rate[0].t_s;
        let last = d.yaw_rate.last().unwrap().t_s;
        let at = |t: f64| {
            let i = d
                .truth
                .partition_point(|q| q.t_s < t)
                .min(d.truth.len() - 1);
            d.truth[i].yaw_rad
        };
        let truth_change = angle::wrap(at(last) - at(first));
        println!("integrated gyro {yaw:.5} rad, truth yaw change {truth_change:.5} rad");
        // Measured: within 1e-5 rad over the lap (a closed loop: −2π wrapped).
        assert!(angle::wrap(yaw - truth_change).abs() < 1e-3);
        // The rear wheels' difference is the body yaw rate: their ticks over
        // the lap turn the car by the same angle as the gyro.
        let Wheels::Ticks(ticks) = &d.wheels else {
            panic!("ticks")
        };
        let n = f64::from(d.vehicle.ticks_per_rev);
        let (rl, rr): (i64, i64) = ticks.iter().fold((0, 0), |(l, r), t| (l + t.rl, r + t.rr));
        let turn = (rr as f64 * p.circumference_rr_m - rl as f64 * p.circumference_rl_m)
            / n
            / sc.vehicle.track_rear_m;
        println!("rear wheels turn the car by {turn:.4} rad");
        // Up to one tick's floor on each rear wheel: 2 · C / n / l_R.
        let tick = 2.0 * p.circumference_rr_m / n / sc.vehicle.track_rear_m;
        assert!(angle::wrap(turn - yaw).abs() < tick, "{turn} vs {yaw}");
    }
}

#[test]
fn the_steering_reads_the_understeer() {
    let (sc, out) = dynamic_drive();
    let d = &out.drive;
    let k_us = DynamicsSpec::default().understeer_gradient_rad_per_mps2(&sc.vehicle);
    let rows = course_against_yaw(&out);
    let r_s = sc.vehicle.steering_ratio;
    let l = sc.vehicle.wheelbase_m;
    // Road-wheel angle read against the kinematic one atan(L·χ̇/v).
    let mut pairs = Vec::new();
    for (t, _, ay, v) in &rows {
        // The nearest reading (the steering runs 8.9 ms after the truth).
        let i = d.steering.partition_point(|s| s.t_s < *t).max(1);
        let Some(s) = d.steering[i - 1..]
            .iter()
            .take(2)
            .min_by(|a, b| (a.t_s - t).abs().total_cmp(&(b.t_s - t).abs()))
        else {
            continue;
        };
        if (s.t_s - t).abs() > 0.006 {
            continue;
        }
        let kinematic = (l * ay / (v * v)).atan();
        pairs.push((*ay, s.value / r_s - kinematic));
    }
    let fit = slope(&pairs);
    println!(
        "understeer: {fit:.6} rad per m/s² (K_us {k_us:.6}) over {} rows",
        pairs.len()
    );
    // Measured 0.003217 against K_us 0.003063: the load transfer softens
    // the front axle more than the rear (roll-stiffness share 0.6), +5 %.
    assert!(
        k_us > 0.0 && (fit - k_us).abs() < 0.1 * k_us,
        "{fit} vs {k_us}"
    );
}

#[test]
fn without_dynamics_the_scenario_and_its_file_are_unchanged() {
    let base = Scenario::builtin("evaluation").unwrap();
    assert!(base.dynamics.is_none());
    assert!(!base.to_toml_string().unwrap().contains("dynamics"));
    let with = base.clone().with_dynamics(Some(DynamicsSpec::default()));
    let text = with.to_toml_string().unwrap();
    assert!(text.contains("[dynamics]"), "{text}");
    assert_eq!(Scenario::from_toml_str(&text).unwrap(), with);
    // An empty table takes every default; a misspelt key is refused.
    let empty = base.to_toml_string().unwrap() + "\n[dynamics]\n";
    assert_eq!(
        Scenario::from_toml_str(&empty).unwrap().dynamics,
        Some(DynamicsSpec::default())
    );
    let typo = base.to_toml_string().unwrap() + "\n[dynamics]\nmass = 1200\n";
    assert!(Scenario::from_toml_str(&typo).is_err());
    let bad = with.clone().with_dynamics(Some(DynamicsSpec {
        front_load_share: 1.2,
        ..DynamicsSpec::default()
    }));
    let e = bad.validate().unwrap_err().to_string();
    assert!(e.contains("dynamics.front_load_share"), "{e}");
    // The kinematic drive is the same as before the table existed: the
    // body points along the path.
    let out = simulate(&base.with_laps(1), 3).unwrap();
    let rows = course_against_yaw(&out);
    let worst = rows.iter().map(|r| r.1.abs()).fold(0.0, f64::max);
    assert!(worst < 1e-3, "{worst}");
}

/// Straights with speed changes (the traction test's), noise-free wheel
/// speeds at 100 Hz and a level IMU, with `dynamics` (TOML keys).
fn straights(dynamics: &str) -> SimOutput {
    let text = format!(
        r#"
name = "speed-changes"
vehicle = "paper-car"

[route]
segments = [
  {{ kind = "straight", length_m = 400, speed_limit_kmh = 50 }},
  {{ kind = "straight", length_m = 1200, speed_limit_kmh = 100 }},
  {{ kind = "straight", length_m = 300, speed_limit_kmh = 40 }},
  {{ kind = "straight", length_m = 700, speed_limit_kmh = 80 }},
]

[speed]
max_accel_mps2 = 2.0
max_decel_mps2 = 2.5
start_stop_s = 0
end_stop_s = 0

[sensors]
truth_rate_hz = 100

[sensors.wheels]
kind = "speeds"
rate_hz = 100
noise_std_mps = 0.0
resolution_mps = 0.0

[sensors.gyro]
rate_hz = 100
noise_std = 0.0
tilt_deg = [0.0, 0.0]

[dynamics]
side_slip = false
{dynamics}
"#
    );
    simulate(&Scenario::from_toml_str(&text).unwrap(), 5).unwrap()
}

/// Per wheel row: (time, truth speed and acceleration at that time, the
/// wheel speeds FL, FR, RL, RR).
fn rows(out: &SimOutput) -> Vec<(f64, f64, f64, [f64; 4])> {
    let Wheels::Speeds(ws) = &out.drive.wheels else {
        panic!("speeds")
    };
    let tr = &out.drive.truth;
    let mut v = Vec::new();
    for w in ws.iter().skip(1) {
        // The reading is the mean over the last 10 ms: the truth at its middle.
        let t = w.t_s - 0.005;
        let i = tr.partition_point(|p| p.t_s < t);
        if i < 2 || i + 1 >= tr.len() {
            continue;
        }
        let (a, b) = (&tr[i - 1], &tr[i]);
        let l = (t - a.t_s) / (b.t_s - a.t_s);
        let (va, vb) = (a.speed_mps.unwrap(), b.speed_mps.unwrap());
        let speed = va + l * (vb - va);
        let accel = (tr[i + 1].speed_mps.unwrap() - tr[i - 2].speed_mps.unwrap())
            / (tr[i + 1].t_s - tr[i - 2].t_s);
        v.push((
            w.t_s,
            speed,
            accel,
            [w.fl_mps, w.fr_mps, w.rl_mps, w.rr_mps],
        ));
    }
    v
}

#[test]
fn the_driven_axle_slips_with_the_traction_force() {
    let c_x = 150_000.0;
    let out = straights(&format!("longitudinal_stiffness_n = {c_x}"));
    let spec = DynamicsSpec::default();
    let (m, g) = (spec.mass_kg, 9.806_65);
    let mut xy = Vec::new();
    for (_, v, a, w) in rows(&out) {
        let force = m * a + spec.rolling_resistance * m * g + spec.drag_n_per_mps2 * v * v;
        if v > 5.0 && force > 0.0 {
            // Front-wheel drive: the front wheels turn 1 + F/C_x times, the
            // rear ones roll.
            xy.push((
                force / c_x,
                0.5 * (w[0] + w[1]) / (0.5 * (w[2] + w[3])) - 1.0,
            ));
        }
    }
    let fit = slope(&xy);
    let largest = xy.iter().map(|p| p.1).fold(0.0, f64::max);
    println!("front/rear − 1 against F/C_x: slope {fit:.4}, largest slip {largest:.4}");
    // Measured: slope 1.0000 (the truth's speed difference quotient), slip
    // up to 2 %.
    assert!((fit - 1.0).abs() < 0.02, "{fit}");
    assert!(largest > 0.015, "{largest}");
    // Without the key, the axles agree.
    let flat = straights("");
    for (_, v, _, w) in rows(&flat) {
        if v > 5.0 {
            assert!((w[0] / w[2] - 1.0).abs() < 1e-9);
        }
    }
}

#[test]
fn rolling_radii_grow_with_speed_and_slopes_add_distance() {
    let k = 2e-6;
    let out = straights(&format!("radius_growth_per_mps2 = {k}"));
    let mut worst: f64 = 0.0;
    for (_, v, _, w) in rows(&out) {
        if v > 5.0 {
            worst = worst.max((w[2] / v * (1.0 + k * v * v) - 1.0).abs());
        }
    }
    println!("rear-left speed against v/(1 + k·v²): worst relative error {worst:.2e}");
    // Measured 5.6e-7 (the truth's speed interpolated to the reading's middle).
    assert!(worst < 1e-5, "{worst}");
    // A grade of 2π·5/500 = 6.3 % at most: the wheels roll the length of the
    // slope, 1 + (2πA/λ)²/4 on average, and the accelerometer reads g·sin θ.
    let out = straights("grade_amplitude_m = 5.0\ngrade_wavelength_m = 500.0");
    let ratio = out.stats.wheel_distance_m[2] / out.stats.distance_m;
    let expected = 1.0 + (std::f64::consts::TAU * 5.0 / 500.0).powi(2) / 4.0;
    println!("rear-left distance over the path's: {ratio:.6} (expected about {expected:.6})");
    assert!((ratio - expected).abs() < 2e-4, "{ratio}");
    let largest = out
        .drive
        .imu
        .accel
        .iter()
        .map(|f| f.x.abs())
        .fold(0.0, f64::max);
    // g·0.0628 = 0.62 m/s² from the slope, plus up to 2.5 from the speed changes.
    assert!(largest > 0.6, "{largest}");
    let flat = straights("");
    let level = flat.stats.wheel_distance_m[2] / flat.stats.distance_m;
    assert!((level - 1.0).abs() < 1e-9, "{level}");
}
