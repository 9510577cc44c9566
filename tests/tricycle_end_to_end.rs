//! End-to-end tests of the tricycle on its real log (`tricycle-tracker/`,
//! 113 s, 37 m of path, forward and reverse, steering near ±1.1 rad): the
//! kinematic calibration against the tracker, sliding 30 s outages from the
//! tracker pose, halves, and the bugs the log showed. Runs the real binary in
//! temporary directories.
//!
//! Bounds are the measured values plus a stated margin (about 10%), so a
//! twofold degradation fails. Measured at this commit: in-sample mean final
//! error 0.271 m (84 windows; nominal parameters 9.10 m); first half →
//! second 0.200 m, second → first 0.586 m.

mod common;

use std::path::Path;

use common::{json, run_err, run_ok, TRICYCLE_LOG as LOG};

fn calibrate(out: &Path, range: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "calibrate",
        LOG,
        "--method",
        "truth",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(range);
    json(&run_ok(&args))
}

fn evaluate(params: &str, range: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "evaluate", LOG, "--params", params, "--outage", "30", "--step", "1", "--json",
    ];
    args.extend_from_slice(range);
    json(&run_ok(&args))
}

fn mean(v: &serde_json::Value) -> f64 {
    v["final_error_m"]["mean"].as_f64().unwrap()
}

/// The log's first and last timestamps (drive clock).
fn span() -> (f64, f64) {
    let d =
        deadreckon_import::tricycle::read_tricycle_kinematic(Path::new(LOG), &Default::default())
            .unwrap();
    (d.samples[0].t_s, d.samples.last().unwrap().t_s)
}

#[test]
fn tricycle_calibrate_truth_then_30_s_outages_in_sample() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("p.toml");
    let c = calibrate(&p, &[]);
    assert_eq!(c["shape"], "tricycle");
    assert_eq!(c["converged"], true, "{c}");
    // Every parameter is determined by this drive (it turns both ways at up
    // to 1.1 rad, forward and reverse), with a standard error.
    for (name, v) in c["params"].as_object().unwrap() {
        assert_eq!(v["estimated"], true, "{name}: {v}");
        assert!(v["std"].as_f64().unwrap() > 0.0, "{name}: {v}");
    }
    let val = |k: &str| c["params"][k]["value"].as_f64().unwrap();
    // The findings: Ktraction right within 1%, the steering scale
    // about 5.6× the header's 0.1, the tracked point about 1.8 m ahead.
    assert!((val("ktraction_m") / 0.0106141 - 1.0).abs() < 0.02, "{c}");
    assert!((val("ksteer") - 0.56).abs() < 0.03, "{c}");
    assert!((val("mount_x_m") - 1.81).abs() < 0.1, "{c}");
    assert!(
        val("axle_length_m") > 1.3 && val("axle_length_m") < 1.8,
        "{c}"
    );
    let names = c["correlation"]["names"].as_array().unwrap();
    assert_eq!(names.len(), 7);
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("shape = \"tricycle\""), "{text}");

    let nominal = evaluate("nominal", &[]);
    let cal = evaluate(p.to_str().unwrap(), &[]);
    eprintln!("tricycle 30 s outages: nominal {nominal}\ncalibrated {cal}");
    assert_eq!(cal["windows"].as_u64().unwrap(), 84, "{cal}");
    for k in ["mean", "median", "p95", "max"] {
        assert!(cal["final_error_m"][k].is_number(), "{cal}");
    }
    // Issue target 0.35 m; measured 0.271 m.
    assert!(mean(&cal) < 0.30, "{cal}");
    // Nominal (the header's guesses): 9.10 m.
    assert!(mean(&nominal) > 8.0, "{nominal}");
}

#[test]
fn tricycle_calibrated_on_one_half_evaluated_on_the_other() {
    let tmp = tempfile::tempdir().unwrap();
    let (t0, t1) = span();
    let mid = format!("{}", 0.5 * (t0 + t1));
    let (first, second) = (
        tmp.path().join("first.toml"),
        tmp.path().join("second.toml"),
    );
    calibrate(&first, &["--until", &mid]);
    calibrate(&second, &["--from", &mid]);
    let e12 = evaluate(first.to_str().unwrap(), &["--from", &mid]);
    let e21 = evaluate(second.to_str().unwrap(), &["--until", &mid]);
    eprintln!("first -> second {e12}\nsecond -> first {e21}");
    // Issue target 0.7 m each; measured 0.200 m and 0.586 m.
    assert!(mean(&e12) < 0.25, "{e12}");
    assert!(mean(&e21) < 0.65, "{e21}");
}

/// Regression: `calibrate --method truth` at the car's default speed
/// threshold (2 m/s) used 0 samples on this 0.6 m/s robot and wrote the
/// nominal values with `converged: true`.
#[test]
fn calibrate_truth_with_zero_samples_reports_not_estimated_not_converged() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("p.toml");
    let c = calibrate(&p, &["--min-speed", "2"]);
    assert_eq!(c["converged"], false, "{c}");
    assert_eq!(c["windows_used"], 0, "{c}");
    for (name, v) in c["params"].as_object().unwrap() {
        assert_eq!(v["estimated"], false, "{name}: {v}");
        assert!(v["std"].is_null(), "{name}: {v}");
        let why = v["reason"].as_str().unwrap();
        assert!(
            why.contains("0 of") && why.contains("2 m/s"),
            "{name}: {why}"
        );
    }
    let text = std::fs::read_to_string(&p).unwrap();
    assert!(text.contains("converged = false"), "{text}");
    assert_eq!(text.matches("estimated = false").count(), 7, "{text}");
    // The default threshold fits the robot.
    let c = calibrate(&p, &[]);
    assert!(c["windows_used"].as_u64().unwrap() > 40, "{c}");
}

/// A window of the drive without turns cannot determine the steering: it is
/// reported as not estimated with the reason, in the table too.
#[test]
fn calibrate_on_a_straight_stretch_says_which_parameters_it_cannot_determine() {
    let (t0, _) = span();
    let table = run_ok(&[
        "calibrate",
        LOG,
        "--method",
        "truth",
        "--until",
        &format!("{}", t0 + 6.0),
    ]);
    assert!(table.contains("NOT ESTIMATED"), "{table}");
}

/// Regression: `run --params nominal` on the tricycle log fed the car
/// filter, whose wheel and steering observations made speed and yaw rate
/// oscillate step to step at steering angles near 1.1 rad: speeds from −587
/// to 2045 m/s, a 294 m track for 37 m of path. The tricycle is now
/// dead-reckoned through its own kinematics.
#[test]
fn run_on_the_tricycle_log_does_not_diverge_at_large_steering_angles() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("track.csv");
    run_ok(&[
        "run",
        LOG,
        "--params",
        "nominal",
        "--out",
        out.to_str().unwrap(),
    ]);
    let mut r = csv::Reader::from_path(&out).unwrap();
    let (mut len, mut vmax, mut prev) = (0.0f64, 0.0f64, None::<(f64, f64)>);
    for rec in r.records() {
        let rec = rec.unwrap();
        if &rec[1] != "dead-reckoned" {
            continue;
        }
        let (e, n): (f64, f64) = (rec[2].parse().unwrap(), rec[3].parse().unwrap());
        let v: f64 = rec[5].parse().unwrap();
        vmax = vmax.max(v.abs());
        if let Some((pe, pn)) = prev {
            len += (e - pe).hypot(n - pn);
        }
        prev = Some((e, n));
    }
    // The robot never exceeds 0.42 m/s over a second; step to step the
    // encoder's jittery timestamps give up to 1.86 m/s of wheel speed, which
    // bounds the base's (|cos φ| ≤ 1). It drives 37 m of path; the tracked
    // point, 1.5 m ahead of the base at nominal, sweeps somewhat more.
    assert!(vmax < 1.9, "dead-reckoned speed up to {vmax} m/s");
    assert!(len > 30.0 && len < 60.0, "track length {len} m");
}

#[test]
fn bad_tricycle_arguments_are_clear_errors() {
    let e = run_err(&["calibrate", LOG, "--method", "rts"]);
    assert!(e.contains("--method truth"), "{e}");
    let e = run_err(&["evaluate", LOG, "--params", "nominal"]);
    assert!(e.contains("--outage"), "{e}");
    let e = run_err(&[
        "evaluate", LOG, "--outage", "30", "--from", "5", "--until", "1",
    ]);
    assert!(e.contains("before"), "{e}");
    let e = run_err(&["evaluate", LOG, "--outage", "30", "--from", "1e12"]);
    assert!(e.contains("0 samples"), "{e}");
    let tmp = tempfile::tempdir().unwrap();
    let car = tmp.path().join("car.toml");
    std::fs::write(&car, "b_gyro = 0.0\n").unwrap();
    let e = run_err(&[
        "evaluate",
        LOG,
        "--outage",
        "30",
        "--params",
        car.to_str().unwrap(),
    ]);
    assert!(e.contains("not a tricycle parameter file"), "{e}");
}

/// Regression: the car filter on the tricycle log imported as a drive
/// directory, with the calibrated steering scale (wheel angles up to about
/// 1.1 rad), diverged: eq. (7)'s pseudo-measurement `v_prior·tan δ` feeds the
/// prior speed back with a loop gain of about tan²δ, so speed and yaw rate
/// alternated in sign and grew (a 12.2 km track for 37 m of path). Above 45°
/// of wheel angle the filter now takes the steering as the constraint
/// `l·ψ̇·cos δ − v·sin δ = 0`: 105.7 m. What remains is not the steering:
/// rows where the traction counter did not advance (0 ticks, then twice as
/// many) still make single-step speed spikes (±350 m/s; the same with the
/// header's parameters, whose wheel angles stay below 0.25 rad).
#[test]
fn car_filter_on_the_imported_tricycle_log_does_not_diverge_at_large_steering_angles() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("tri");
    run_ok(&["import", "tricycle", LOG, "--out", dir.to_str().unwrap()]);
    let vt = dir.join("vehicle.toml");
    let text = std::fs::read_to_string(&vt).unwrap();
    let text: String = text
        .lines()
        .map(|l| {
            if l.starts_with("steering_ratio =") {
                "steering_ratio = 1.783".to_string()
            } else if l.starts_with("wheelbase_m =") {
                "wheelbase_m = 1.53".to_string()
            } else if l.starts_with("wheel_circumference_m =") {
                "wheel_circumference_m = 0.010726".to_string()
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&vt, text).unwrap();
    let out = tmp.path().join("track.csv");
    run_ok(&[
        "run",
        dir.to_str().unwrap(),
        "--params",
        "nominal",
        "--out",
        out.to_str().unwrap(),
    ]);
    let mut r = csv::Reader::from_path(&out).unwrap();
    let (mut len, mut prev) = (0.0f64, None::<(f64, f64)>);
    for rec in r.records() {
        let rec = rec.unwrap();
        if &rec[1] != "dead-reckoned" {
            continue;
        }
        let (e, n): (f64, f64) = (rec[2].parse().unwrap(), rec[3].parse().unwrap());
        if let Some((pe, pn)) = prev {
            len += (e - pe).hypot(n - pn);
        }
        prev = Some((e, n));
    }
    assert!(len < 150.0, "track length {len} m (37 m of path)");
}
