//! The comma2k19 RAV4 segment, read end to end.

mod common;

use deadreckon_core::drive::Wheels;
use deadreckon_import::comma2k19::{
    read_comma2k19_with, Comma2k19Options, GyroSource, SpeedSource,
};
use deadreckon_import::npy::read_npy;
use deadreckon_import::read_comma2k19;

fn interp(ts: &[f64], vs: &[f64], t: f64) -> Option<f64> {
    let i = ts.partition_point(|&x| x < t);
    if i == 0 || i >= ts.len() {
        return None;
    }
    let w = (t - ts[i - 1]) / (ts[i] - ts[i - 1]);
    Some(vs[i - 1] * (1.0 - w) + vs[i] * w)
}

#[test]
fn segment_reads_with_plausible_streams() {
    let dir = common::data("comma2k19-rav4");
    let imp = read_comma2k19_with(&dir, &Comma2k19Options::default()).unwrap();
    let d = &imp.drive;
    println!("{}", imp.report);
    let (t0, t1) = d.time_span().unwrap();
    assert!((t1 - t0 - 60.0).abs() < 1.0, "duration {}", t1 - t0);
    let Wheels::Speeds(ws) = &d.wheels else {
        panic!("wheel speeds expected")
    };
    assert_eq!(ws.len(), 4974);
    for w in ws {
        for v in [w.fl_mps, w.fr_mps, w.rl_mps, w.rr_mps] {
            assert!((7.0..21.0).contains(&v), "wheel speed {v}");
        }
    }
    assert_eq!(
        d.speed.len(),
        2487,
        "SPEED 0xB4 runs at half the wheel-speed rate"
    );
    assert!(d.speed.iter().all(|s| (7.0..21.0).contains(&s.value)));
    // The car's speed reads about 2 % above the wheel speeds (speedometer over-read).
    let wt: Vec<f64> = ws.iter().map(|w| w.t_s).collect();
    let wm: Vec<f64> = ws.iter().map(|w| (w.rl_mps + w.rr_mps) / 2.0).collect();
    let ratios: Vec<f64> = d
        .speed
        .iter()
        .filter_map(|s| interp(&wt, &wm, s.t_s).map(|m| s.value / m))
        .collect();
    let mean = ratios.iter().sum::<f64>() / ratios.len() as f64;
    assert!(
        (1.0..1.04).contains(&mean),
        "SPEED / rear wheel speed = {mean}"
    );

    // Raw gyro: the bias (about 0.07 rad/s) is still in it; yaw rate otherwise near 0.
    let yr = d.yaw_rate.iter().map(|s| s.value).sum::<f64>() / d.yaw_rate.len() as f64;
    assert!((-0.09..-0.05).contains(&yr), "mean raw yaw rate {yr}");
    let cal = read_comma2k19_with(
        &dir,
        &Comma2k19Options {
            gyro: GyroSource::Calibrated,
            ..Default::default()
        },
    )
    .unwrap()
    .drive;
    let yc = cal.yaw_rate.iter().map(|s| s.value).sum::<f64>() / cal.yaw_rate.len() as f64;
    assert!(yc.abs() < 0.01, "mean bias-removed yaw rate {yc}");

    // Steering in radians, small on a highway.
    assert!(d.steering.iter().all(|s| s.value.abs() < 0.2));

    // Truth: about 1 km, heading changes by less than a degree.
    let dist: f64 = d
        .truth
        .windows(2)
        .map(|w| (w[1].east_m - w[0].east_m).hypot(w[1].north_m - w[0].north_m))
        .sum();
    assert!((950.0..1070.0).contains(&dist), "truth distance {dist}");
    let yaws: Vec<f64> = d.truth.iter().map(|p| p.yaw_rad).collect();
    let (lo, hi) = yaws
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &y| (a.min(y), b.max(y)));
    assert!(
        (hi - lo).to_degrees() < 2.0,
        "yaw span {} deg",
        (hi - lo).to_degrees()
    );
    assert!(d
        .truth
        .iter()
        .all(|p| p.speed_mps.is_some_and(|v| (7.0..21.0).contains(&v))));
    // Driving north (course about 2 degrees): yaw about 88 degrees.
    assert!(
        (yaws[0].to_degrees() - 88.5).abs() < 2.0,
        "{}",
        yaws[0].to_degrees()
    );
    assert!(d.vehicle.origin.is_some());
    assert_eq!(imp.report.total_gated(), 0);
}

#[test]
fn gnss_agrees_with_truth_plus_lever_arm() {
    let dir = common::data("comma2k19-rav4");
    // The known u-blox latency given by hand (the default is 0: the tool
    // estimates it, see the timing tests below).
    let d = read_comma2k19_with(
        &dir,
        &Comma2k19Options {
            gnss_latency_s: 0.1,
            ..Default::default()
        },
    )
    .unwrap()
    .drive;
    let t: Vec<f64> = d.truth.iter().map(|p| p.t_s).collect();
    let e: Vec<f64> = d
        .truth
        .iter()
        .map(|p| p.east_m + d.vehicle.gnss_lever_arm_m * p.yaw_rad.cos())
        .collect();
    let n: Vec<f64> = d
        .truth
        .iter()
        .map(|p| p.north_m + d.vehicle.gnss_lever_arm_m * p.yaw_rad.sin())
        .collect();
    let mut sq = 0.0;
    let mut count = 0;
    let mut worst: f64 = 0.0;
    for g in &d.gnss {
        let (Some(te), Some(tn)) = (interp(&t, &e, g.t_s), interp(&t, &n, g.t_s)) else {
            continue;
        };
        let err = (g.east_m - te).hypot(g.north_m - tn);
        sq += err * err;
        count += 1;
        worst = worst.max(err);
    }
    let rms = (sq / count as f64).sqrt();
    println!("gnss vs truth: {count} fixes, rms {rms:.3} m, max {worst:.3} m");
    assert!(count > 550);
    assert!(rms < 1.0 && worst < 2.0, "rms {rms} max {worst}");
    // The first fix is the origin (its latency-shifted time is before the first truth pose).
    assert!(d.gnss[0].east_m.abs() < 1e-6 && d.gnss[0].north_m.abs() < 1e-6);
    // GNSS course: about 2 degrees (north, slightly east).
    assert!(d
        .gnss
        .iter()
        .all(|g| g.course_deg.is_some_and(|c| !(5.0..=355.0).contains(&c))));
}

#[test]
fn processed_speed_is_the_mean_of_the_wheel_speeds() {
    // Pins the reason the default speed source is the SPEED message.
    let dir = common::data("comma2k19-rav4");
    let o = Comma2k19Options {
        speed: SpeedSource::Processed,
        ..Default::default()
    };
    let d = read_comma2k19_with(&dir, &o).unwrap().drive;
    let Wheels::Speeds(ws) = &d.wheels else {
        panic!()
    };
    assert_eq!(d.speed.len(), ws.len());
    for (s, w) in d.speed.iter().zip(ws) {
        assert_eq!(s.t_s, w.t_s);
        assert!((s.value - (w.fl_mps + w.fr_mps + w.rl_mps + w.rr_mps) / 4.0).abs() < 1e-9);
    }
}

#[test]
fn fortran_ordered_imu_arrays_are_read_in_row_order() {
    // IMU values are stored in Fortran order; gyro = gyro_uncalibrated - gyro_bias row by row.
    let imu = common::data("comma2k19-rav4/processed_log/IMU");
    let rows = |name: &str| {
        let p = imu.join(name).join("value");
        read_npy(&p).unwrap().f64_rows::<3>(&p).unwrap()
    };
    let (g, u, b) = (rows("gyro"), rows("gyro_uncalibrated"), rows("gyro_bias"));
    assert_eq!(g.len(), 6256);
    for ((g, u), b) in g.iter().zip(&u).zip(&b) {
        for k in 0..3 {
            assert!((g[k] - (u[k] - b[k])).abs() < 1e-6, "{g:?} {u:?} {b:?}");
        }
    }
}

#[test]
fn missing_segment_names_the_file() {
    let e = read_comma2k19(std::path::Path::new("/nonexistent-segment"), None).unwrap_err();
    assert!(
        e.to_string()
            .contains("/nonexistent-segment/processed_log/CAN/wheel_speed/t"),
        "{e}"
    );
}

/// Means of `(t, v)` samples in 1-second bins.
fn bins(samples: impl Iterator<Item = (f64, f64)>) -> std::collections::BTreeMap<i64, f64> {
    let mut acc: std::collections::BTreeMap<i64, (f64, usize)> = Default::default();
    for (t, v) in samples {
        let e = acc.entry(t.floor() as i64).or_default();
        e.0 += v;
        e.1 += 1;
    }
    acc.into_iter()
        .map(|(k, (s, n))| (k, s / n as f64))
        .collect()
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let (mx, my) = (
        x.iter().sum::<f64>() / x.len() as f64,
        y.iter().sum::<f64>() / y.len() as f64,
    );
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let syy: f64 = y.iter().map(|b| (b - my).powi(2)).sum();
    sxy / (sxx * syy).sqrt()
}

#[test]
fn gyro_and_steering_signs_agree_with_the_truth_yaw_rate() {
    // Counter-clockwise yaw rate and left-positive steering: both follow the
    // reference's yaw rate (1 s means; the segment turns by less than a degree,
    // so this checks signs, not scales).
    let d = read_comma2k19(&common::data("comma2k19-rav4"), None).unwrap();
    let truth_rate = bins(d.truth.windows(2).map(|w| {
        let dy = deadreckon_core::angle::wrap(w[1].yaw_rad - w[0].yaw_rad);
        (w[0].t_s, dy / (w[1].t_s - w[0].t_s))
    }));
    let gyro = bins(d.yaw_rate.iter().map(|s| (s.t_s, s.value)));
    let steer = bins(d.steering.iter().map(|s| (s.t_s, s.value)));
    let keys: Vec<i64> = truth_rate
        .keys()
        .copied()
        .filter(|k| gyro.contains_key(k) && steer.contains_key(k))
        .collect();
    let keys = &keys[1..keys.len() - 1]; // drop partial bins
    let tr: Vec<f64> = keys.iter().map(|k| truth_rate[k]).collect();
    let g: Vec<f64> = keys.iter().map(|k| gyro[k]).collect();
    let s: Vec<f64> = keys.iter().map(|k| steer[k]).collect();
    let (cg, cs) = (correlation(&g, &tr), correlation(&s, &tr));
    println!("correlation with the truth yaw rate: gyro {cg:.3}, steering {cs:.3}");
    assert!(cg > 0.9, "gyro {cg}");
    assert!(cs > 0.7, "steering {cs}");
}

/// The GNSS delay against the reference trajectory: the regression step
/// repeated until it settles.
fn gnss_delay_against_truth(d: &deadreckon_core::Drive, window_s: f64) -> (f64, f64) {
    use deadreckon_core::reference::Reference;
    use deadreckon_core::timing;
    let reference = Reference::from_truth(&d.truth).unwrap();
    let mut delay = 0.0;
    let mut std = f64::NAN;
    for _ in 0..10 {
        let s = timing::shift(d, [0.0, 0.0, 0.0, delay]);
        let (step, sd, _) =
            timing::regress_gnss(&s.gnss, &reference, d.vehicle.gnss_lever_arm_m, window_s)
                .unwrap();
        delay += step;
        std = sd;
        if step.abs() < 1e-5 {
            break;
        }
    }
    (delay, std)
}

#[test]
fn gnss_delay_is_estimated_without_being_told() {
    use deadreckon_core::calibrate::CalibrationOptions;
    use deadreckon_core::timing::{self, DelayOptions};
    let dir = common::data("comma2k19-rav4");
    let d = read_comma2k19(&dir, None).unwrap();
    for w in [f64::INFINITY, 20.0, 10.0] {
        let (t, ts) = gnss_delay_against_truth(&d, w);
        println!("window {w} s: delay against the reference {t:.4} ± {ts:.4} s");
        let o = DelayOptions {
            gnss_window_s: w,
            ..Default::default()
        };
        let (est, _) = timing::gnss_delay(&d, &CalibrationOptions::default(), &o).unwrap();
        println!("window {w} s: delay from the drive alone {est:?}");
    }
    // As `calibrate` estimates it: after the other streams' delays, which
    // move them to the receiver's clock (`timing::on_true_time`). Alone
    // (`timing::gnss_delay`, printed above) the reference keeps the phone's
    // gyro where it is stamped: 0.108 ± 0.007 s until stop 50, 0.120 ±
    // 0.007 s since its readings update the wheel interval they are stamped
    // in (the gyro reads −0.036 s against the wheels).
    let (delays, params) =
        timing::estimate_with_params(&d, &CalibrationOptions::default(), &DelayOptions::default())
            .unwrap();
    let est = delays.gnss;
    assert!(est.status.is_estimated() && params.is_some(), "{est:?}");
    // The "done": within 0.02 s of the u-blox's known 0.1 s
    // (measured 0.098 ± 0.006 s against the wheel clock; the reference
    // trajectory's own clock gives about 0.06 s, printed above).
    assert!((est.delay_s - 0.1).abs() < 0.02, "{est:?}");
}

/// The reference's vertical in the device's axes, averaged over the segment:
/// `(pitch, roll)`, rad, nose up and left side up. `global_pose` rotates the
/// device's `[forward, right, down]` axes into ECEF; the local up is the
/// ellipsoid's normal at each position.
fn reference_vertical() -> (f64, f64) {
    let gp = common::data("comma2k19-rav4").join("global_pose");
    let q = {
        let p = gp.join("frame_orientations");
        read_npy(&p).unwrap().f64_rows::<4>(&p).unwrap()
    };
    let pos = {
        let p = gp.join("frame_positions");
        read_npy(&p).unwrap().f64_rows::<3>(&p).unwrap()
    };
    let mut sum = [0.0; 3];
    for (q, p) in q.iter().zip(&pos) {
        let (lat, lon, _) = map_3d::ecef2geodetic(p[0], p[1], p[2], map_3d::Ellipsoid::WGS84);
        let up = [lat.cos() * lon.cos(), lat.cos() * lon.sin(), lat.sin()];
        let n = q.iter().map(|c| c * c).sum::<f64>().sqrt();
        let [w, x, y, z] = q.map(|c| c / n);
        // Columns of the rotation: the device's axes in ECEF.
        let axes = [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y + z * w),
                2.0 * (x * z - y * w),
            ],
            [
                2.0 * (x * y - z * w),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z + x * w),
            ],
            [
                2.0 * (x * z + y * w),
                2.0 * (y * z - x * w),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ];
        for (s, a) in sum.iter_mut().zip(axes) {
            *s += a.iter().zip(up).map(|(a, u)| a * u).sum::<f64>();
        }
    }
    let n = sum.iter().map(|c| c * c).sum::<f64>().sqrt();
    // [forward, right, down] → forward and left components of the unit up.
    ((sum[0] / n).asin(), (-sum[1] / n).asin())
}

#[test]
fn phone_tilt_is_estimated_from_gravity() {
    let dir = common::data("comma2k19-rav4");
    let d = read_comma2k19(&dir, None).unwrap();
    assert_eq!(d.imu.gyro.len(), d.yaw_rate.len());
    assert!(d.imu.accel.len() > 6000);
    let t = deadreckon_core::imu::estimate_tilt(&d).unwrap();
    let (pitch, roll) = reference_vertical();
    println!(
        "{t:?}\ntilt {:.2}° ± {:.2}°, pitch {:+.2}° ± {:.2}° (reference {:+.2}°), roll {:+.2}° ± {:.2}° (reference {:+.2}°)",
        t.tilt_rad.to_degrees(),
        t.std_rad.to_degrees(),
        t.pitch_rad.to_degrees(),
        t.pitch_std_rad.to_degrees(),
        pitch.to_degrees(),
        t.roll_rad.to_degrees(),
        t.roll_std_rad.to_degrees(),
        roll.to_degrees()
    );
    assert!(t.is_estimated());
    // Measured: pitch −3.66° ± 0.77°, roll +0.81° ± 0.73° (tilt 3.75° ± 0.77°)
    // against the reference's −3.22° and +1.24° (tilt 3.46°). The standard
    // errors are mostly the accelerometer's own error (|f| is 0.12 m/s² short
    // of gravity), which gravity alone cannot tell from a tilt: against the
    // reference specific force the accelerometer reads (−0.075, +0.076,
    // +0.142) m/s² off in [forward, right, down].
    for (what, est, std, reference) in [
        ("pitch", t.pitch_rad, t.pitch_std_rad, pitch),
        ("roll", t.roll_rad, t.roll_std_rad, roll),
    ] {
        assert!(
            (est - reference).abs() <= 2.0 * std,
            "{what} {:+.2}° ± {:.2}°, reference {:+.2}°",
            est.to_degrees(),
            std.to_degrees(),
            reference.to_degrees()
        );
    }
    // Not the 8.31° (roll +7.47°) read with the gyro's 0.068 rad/s bias in
    // the centripetal acceleration, and not a bar wide enough to cover it.
    assert!((3.0..4.5).contains(&t.tilt_rad.to_degrees()), "{t:?}");
    assert!(t.std_rad.to_degrees() < 1.0, "{t:?}");
    let b = t.gyro_bias.expect("no standstill: bias from the course");
    assert!((b.bias_rps + 0.068).abs() < 0.002, "{b:?}");
}

#[test]
fn the_truth_speed_was_taken_along_the_tilted_camera_axis() {
    // The drive is two-dimensional: the truth speed is the horizontal one.
    // Along the device's forward axis (3–4° below the horizontal, and the
    // road climbing and falling a few degrees) it was 0.166 % short of the
    // horizontal path of the truth positions (1.7 m over the 1.01 km); now
    // 0.005 %.
    let d = read_comma2k19(&common::data("comma2k19-rav4"), None).unwrap();
    let by_speed: f64 = d
        .truth
        .windows(2)
        .map(|w| 0.5 * (w[0].speed_mps.unwrap() + w[1].speed_mps.unwrap()) * (w[1].t_s - w[0].t_s))
        .sum();
    let by_position: f64 = d
        .truth
        .windows(2)
        .map(|w| (w[1].east_m - w[0].east_m).hypot(w[1].north_m - w[0].north_m))
        .sum();
    let rel = by_speed / by_position - 1.0;
    println!(
        "truth path {by_position:.2} m, integrated speed {by_speed:.2} m ({:+.3} %)",
        100.0 * rel
    );
    assert!(rel.abs() < 5e-4, "{:+.3} %", 100.0 * rel);
}

#[test]
fn the_gnss_delay_was_measured_against_slipping_front_wheels() {
    use deadreckon_core::calibrate::CalibrationOptions;
    use deadreckon_core::timing::{self, DelayOptions};
    use deadreckon_core::traction::{self, Axle};
    let d = read_comma2k19(&common::data("comma2k19-rav4"), None).unwrap();
    let delay = |d: &deadreckon_core::Drive| {
        let (g, _) =
            timing::gnss_delay(d, &CalibrationOptions::default(), &DelayOptions::default())
                .unwrap();
        assert!(g.status.is_estimated(), "{g:?}");
        g
    };
    // The RAV4's front wheels are driven: they read high while pulling (0.32 %
    // per m/s² of forward specific force against the reference, the rear
    // −0.03 %), so the four wheels' speed looked early and the GNSS late.
    let mut rear = d.clone();
    rear.vehicle.wheels_present = [false, false, true, true];
    let (all, rear) = (delay(&d), delay(&rear));
    let t = traction::estimate(&d).unwrap();
    let corrected = delay(&traction::apply(&d, t.slip_per_mps2));
    println!(
        "{t:?}\nGNSS delay against all four wheels {:.4} ± {:.4} s, the rear {:.4} ± {:.4} s, all corrected {:.4} ± {:.4} s",
        all.delay_s, all.std_s, rear.delay_s, rear.std_s, corrected.delay_s, corrected.std_s
    );
    assert!(t.is_estimated() && t.axle == Axle::Front, "{t:?}");
    // Against the reference: each axle's speed over the reference's
    // horizontal speed, per one-second block, regressed on the block's
    // forward specific force (measured: front +0.316 %, rear −0.033 % per
    // m/s²);
    // the estimate from the wheels and the accelerometer alone is 0.325 % ±
    // 0.024 %.
    let (front, rear_slip) = reference_slips(&d);
    println!("against the reference: front {front:+.5}, rear {rear_slip:+.5} per m/s²");
    assert!(front > 0.0025 && rear_slip.abs() < 0.001);
    assert!(
        (t.slip_per_mps2 - (front - rear_slip)).abs() <= 3.0 * t.std,
        "{t:?}"
    );
    // Measured 0.108 s (all), 0.084 s (rear), 0.087 s (all, corrected).
    assert!(all.delay_s - rear.delay_s > 0.02);
    assert!((corrected.delay_s - rear.delay_s).abs() < 0.01);
    assert!((corrected.delay_s - 0.1).abs() < 0.02);
}

/// The slope of (axle speed / reference horizontal speed − 1) on the forward
/// specific force over one-second blocks, for the front and the rear axle.
fn reference_slips(d: &deadreckon_core::Drive) -> (f64, f64) {
    let Wheels::Speeds(ws) = &d.wheels else {
        panic!("wheel speeds expected")
    };
    let mean = |xs: &mut dyn Iterator<Item = f64>| {
        let (s, n) = xs.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        (n > 0).then(|| s / n as f64)
    };
    let (t0, t1) = (d.truth[0].t_s, d.truth[d.truth.len() - 1].t_s);
    let mut rows = Vec::new();
    let mut t = t0 + 1.0;
    while t + 1.0 < t1 {
        let within = |x: f64| x >= t && x < t + 1.0;
        let v = mean(
            &mut d
                .truth
                .iter()
                .filter(|p| within(p.t_s))
                .map(|p| p.speed_mps.unwrap()),
        );
        let f = mean(
            &mut ws
                .iter()
                .filter(|w| within(w.t_s))
                .map(|w| 0.5 * (w.fl_mps + w.fr_mps)),
        );
        let r = mean(
            &mut ws
                .iter()
                .filter(|w| within(w.t_s))
                .map(|w| 0.5 * (w.rl_mps + w.rr_mps)),
        );
        let a = mean(&mut d.imu.accel.iter().filter(|s| within(s.t_s)).map(|s| s.x));
        if let (Some(v), Some(f), Some(r), Some(a)) = (v, f, r, a) {
            rows.push((a, f / v - 1.0, r / v - 1.0));
        }
        t += 1.0;
    }
    let slope = |y: fn(&(f64, f64, f64)) -> f64| {
        let n = rows.len() as f64;
        let mx = rows.iter().map(|r| r.0).sum::<f64>() / n;
        let my = rows.iter().map(y).sum::<f64>() / n;
        let sxy: f64 = rows.iter().map(|r| (r.0 - mx) * (y(r) - my)).sum();
        let sxx: f64 = rows.iter().map(|r| (r.0 - mx).powi(2)).sum();
        sxy / sxx
    };
    (slope(|r| r.1), slope(|r| r.2))
}
