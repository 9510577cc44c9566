//! The Husky bag (`husky-gps-bag/husky_gps.bag`, 395 s, about 1 m/s, SBAS
//! fixes) as a differential drive: the five kinematic parameters calibrated
//! against the fixes, and 30 s outages every 10 s, each started from 60 s of
//! dead reckoning aligned to the fixes and scored against the hidden fix at
//! its end. Runs the real binary.
//!
//! Measured at this commit (mean final error): nominal parameters with the
//! gyro 3.29 m, with the odometry yaw rate 3.87 m; calibrated on the whole
//! drive (gyro, 90 s windows) 3.15 m. The target (3.05 m) is not
//! reached, and across halves the calibration does worse than the nominal
//! parameters (first half → second 4.01 m against 2.56 m nominal; second →
//! first 5.66 m against 5.15 m): the fit follows the SBAS fixes' slow wander
//! (an antenna 0.6–1 m behind the axle). The bounds pin these numbers with
//! a margin of about 10% so that a degradation shows.

mod common;
use common::run_ok;

use std::process::Command;

const HUSKY: &str = "../shared/data/husky-gps-bag/husky_gps.bag";

fn outage_mean(params: &str, extra: &[&str]) -> (f64, serde_json::Value) {
    let mut args = vec![
        "evaluate",
        HUSKY,
        "--shape",
        "diff-drive",
        "--params",
        params,
        "--outage",
        "30",
        "--step",
        "10",
        "--json",
    ];
    args.extend_from_slice(extra);
    let v: serde_json::Value = serde_json::from_str(&run_ok(&args)).unwrap();
    (v["final_error_m"]["mean"].as_f64().unwrap(), v)
}

#[test]
fn husky_diff_drive_calibrated_against_gnss_through_30_s_outages() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("husky.toml");
    let c: serde_json::Value = serde_json::from_str(&run_ok(&[
        "calibrate",
        HUSKY,
        "--shape",
        "diff-drive",
        "--json",
        "--out",
        p.to_str().unwrap(),
    ]))
    .unwrap();
    eprintln!("husky diff-drive calibration: {c}");
    assert_eq!(c["shape"], "diff_drive");
    assert_eq!(c["yaw_source"], "gyro");
    assert_eq!(c["converged"], true, "{c}");
    let speed = c["params"]["speed_scale"]["value"].as_f64().unwrap();
    assert!((speed - 0.969).abs() < 0.02, "{c}");

    let (gyro, v) = outage_mean("nominal", &["--yaw", "gyro"]);
    let (odo, _) = outage_mean("nominal", &["--yaw", "odometry"]);
    let (cal, vc) = outage_mean(p.to_str().unwrap(), &[]);
    eprintln!("nominal gyro {gyro:.3} m, nominal odometry {odo:.3} m, calibrated {cal:.3} m\n{vc}");
    assert_eq!(v["windows"], vc["windows"]);
    assert!(v["windows"].as_u64().unwrap() >= 30, "{v}");
    assert!((gyro - 3.29).abs() < 0.3, "{gyro}");
    assert!((odo - 3.87).abs() < 0.4, "{odo}");
    assert!(cal < 3.5, "{cal}");
    // The params file carries its yaw source: evaluating it with the other is an error.
    let out = Command::new(env!("CARGO_BIN_EXE_deadreckon"))
        .args([
            "evaluate",
            HUSKY,
            "--shape",
            "diff-drive",
            "--yaw",
            "odometry",
            "--params",
            p.to_str().unwrap(),
            "--outage",
            "30",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--yaw gyro"));
}
