//! The Husky bag (`husky-gps-bag/husky_gps.bag`, 395 s, about 1 m/s, SBAS
//! fixes) as a differential drive: the five kinematic parameters calibrated
//! against the fixes, and 30 s outages every 10 s scored against the hidden
//! fix at each outage's end. Each outage starts from the GNSS-aided filter
//! (the default; the fixes' wander carried into the outage) or, the
//! baseline, from 60 s of dead reckoning aligned to the fixes. Runs the real
//! binary.
//!
//! Measured at this commit (mean final error, gyro yaw rate; the filter's
//! fix-error model identified on the first half's innovations). `calibrate`
//! keeps a parameter nominal unless the drive's held-back GNSS says the
//! calibrated value is better (`diff_drive::held_back`, issue 29 item 4);
//! `--every-param` fits every determined parameter as before. The fit's
//! 90 s window was first chosen on this bag's in-sample outage errors and
//! since checked on simulated robots; the held-back rule (threshold, folds)
//! was chosen on simulated robots, the folds after alternating ones let the
//! first half's gyro bias through (see the module docs).
//!
//! | parameters | filter | alignment |
//! |---|---|---|
//! | `--every-param` on the whole drive (in-sample) | 2.848 m | 3.154 m |
//! | default (held-back) on the whole drive: every parameter nominal | 3.307 m | |
//! | `--every-param` on the first half, second half evaluated | 3.832 m | 4.015 m |
//! | `--every-param` on the second half, first half evaluated | 4.408 m | 5.656 m |
//! | default on the first half (antenna x taken), second half evaluated | 2.629 m | |
//! | default on the second half (every parameter nominal), first half evaluated | 4.196 m | |
//! | nominal, whole drive / second half / first half | 3.307 / 2.586 / 4.196 m | 3.290 m (whole) |
//!
//! The bounds pin these numbers within about 5% (0.15 m; 0.25 m on the
//! 11-window halves of `--every-param`, 0.05 m where the default is
//! compared with nominal) so that a degradation shows.

mod common;
use common::run_ok;

use std::process::Command;

const HUSKY: &str = "../shared/data/husky-gps-bag/husky_gps.bag";
/// The middle of the bag on its clock (odometry from 1432235498.028 s for
/// 395.3 s).
const MIDDLE: &str = "1432235695.7";

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

fn calibrate(out: &std::path::Path, extra: &[&str]) -> serde_json::Value {
    let mut args = vec![
        "calibrate",
        HUSKY,
        "--shape",
        "diff-drive",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    serde_json::from_str(&run_ok(&args)).unwrap()
}

fn near(what: &str, got: f64, measured: f64, margin: f64) {
    assert!(
        (got - measured).abs() < margin,
        "{what}: {got:.3} m, measured {measured:.3} m ± {margin}"
    );
}

#[test]
fn husky_diff_drive_calibrated_against_gnss_through_30_s_outages() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("husky.toml");
    let c = calibrate(&p, &["--every-param"]);
    eprintln!("husky diff-drive calibration: {c}");
    assert_eq!(c["shape"], "diff_drive");
    assert_eq!(c["yaw_source"], "gyro");
    assert_eq!(c["converged"], true, "{c}");
    let speed = c["params"]["speed_scale"]["value"].as_f64().unwrap();
    assert!((speed - 0.969).abs() < 0.02, "{c}");
    let p = p.to_str().unwrap();

    let (filter, vf) = outage_mean(p, &[]);
    let (aligned, va) = outage_mean(p, &["--start", "align"]);
    let (gyro, vg) = outage_mean("nominal", &["--yaw", "gyro", "--start", "align"]);
    let (gyro_filter, _) = outage_mean("nominal", &["--yaw", "gyro"]);
    let (odo, _) = outage_mean("nominal", &["--yaw", "odometry", "--start", "align"]);
    eprintln!(
        "calibrated: filter {filter:.3} m, aligned {aligned:.3} m; nominal gyro: filter \
         {gyro_filter:.3} m, aligned {gyro:.3} m; nominal odometry aligned {odo:.3} m\n{vf}"
    );
    assert_eq!(vf["start"], "filter");
    assert_eq!(va["start"], "align");
    for v in [&va, &vg] {
        assert_eq!(vf["windows"], v["windows"]);
    }
    assert!(vf["windows"].as_u64().unwrap() >= 30, "{vf}");
    // The numbers measured at this commit (in-sample: every parameter
    // fitted on the drive it is judged on).
    near("calibrated, filter start", filter, 2.848, 0.15);
    near("calibrated, aligned start", aligned, 3.154, 0.15);
    near("nominal gyro, filter start", gyro_filter, 3.307, 0.15);
    near("nominal gyro, aligned start", gyro, 3.290, 0.15);
    near("nominal odometry, aligned start", odo, 3.865, 0.2);
    // The filter's fix counts: one jump of the SBAS fixes (at 55 s) taken
    // after 2 s of rejections.
    assert_eq!(vf["fix_jumps"], 1, "{vf}");
    assert!(vf["fixes_rejected"].as_u64().unwrap() <= 10, "{vf}");
    // Issue 31: the file stores the factor fitted with the calibration on
    // the bag's own hidden fixes (k 1.428, 31 windows): 31 of 31 within,
    // median bound / median final error 2.37 (in-sample; with the filter's
    // covariance alone, k = 1, it was 26 of 31 and 1.66). The alignment
    // start has no covariance and says so.
    assert_eq!(vf["bound"]["method"], "conformal", "{vf}");
    assert_eq!(vf["bound_95_coverage"].as_f64(), Some(1.0), "{vf}");
    near(
        "sharpness, stored factor",
        vf["bound_95_sharpness"].as_f64().unwrap(),
        2.37,
        0.15,
    );
    assert!(
        va["bound"].is_null() && va["bound_95_note"].is_string(),
        "{va}"
    );

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
            p,
            "--outage",
            "30",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--yaw gyro"));
}

/// Issue 31: with the default options (no --params: calibrated on the bag
/// and the bound's factor fitted on its own windows against the hidden
/// fixes, in-sample), the final error of every 30 s outage is within the
/// 95 % bound. Measured: k 1.362, 31 of 31 windows within, sharpness 2.668
/// (the parameters the held-back choice keeps, all nominal; with every
/// parameter fitted it was k 1.428 and 2.37). The issue asks at least 80 %.
#[test]
fn husky_bound_covers_30_s_outages_with_the_default_options() {
    let v: serde_json::Value = serde_json::from_str(&run_ok(&[
        "evaluate", HUSKY, "--outage", "30", "--step", "10", "--json",
    ]))
    .unwrap();
    eprintln!(
        "husky bound: {} coverage {} sharpness {}",
        v["bound"], v["bound_95_coverage"], v["bound_95_sharpness"]
    );
    assert_eq!(v["shape"], "diff_drive", "{v}");
    assert_eq!(v["bound"]["method"], "conformal", "{v}");
    let outages = v["outages"].as_array().unwrap();
    assert_eq!(outages.len(), 31);
    let within = outages
        .iter()
        .filter(|w| w["within_bound_95"] == true)
        .count();
    assert!(within >= 30, "{within} of 31 within the bound");
    assert!(v["bound_95_coverage"].as_f64().unwrap() >= 0.8);
    near("k", v["bound"]["k"].as_f64().unwrap(), 1.428, 0.1);
    near(
        "sharpness",
        v["bound_95_sharpness"].as_f64().unwrap(),
        2.668,
        0.15,
    );
}

#[test]
fn husky_diff_drive_every_param_calibrated_on_one_half_and_evaluated_on_the_other() {
    let tmp = tempfile::tempdir().unwrap();
    let (first, second) = (
        tmp.path().join("first.toml"),
        tmp.path().join("second.toml"),
    );
    calibrate(&first, &["--until", MIDDLE, "--every-param"]);
    calibrate(&second, &["--from", MIDDLE, "--every-param"]);
    let (first, second) = (first.to_str().unwrap(), second.to_str().unwrap());
    let (f12, v) = outage_mean(first, &["--from", MIDDLE]);
    let (a12, _) = outage_mean(first, &["--from", MIDDLE, "--start", "align"]);
    let (f21, v21) = outage_mean(second, &["--until", MIDDLE]);
    let (a21, _) = outage_mean(second, &["--until", MIDDLE, "--start", "align"]);
    eprintln!(
        "first -> second: filter {f12:.3} m, aligned {a12:.3} m; second -> first: filter \
         {f21:.3} m, aligned {a21:.3} m"
    );
    assert_eq!(v["windows"], 11, "{v}");
    near("first half -> second, filter start", f12, 3.832, 0.25);
    near("first half -> second, aligned start", a12, 4.015, 0.25);
    near("second half -> first, filter start", f21, 4.408, 0.25);
    near("second half -> first, aligned start", a21, 5.656, 0.25);
    // Issue 31, held out: each half's file stores the factor fitted on its
    // own hidden fixes. Measured: first -> second k 1.38, 11 of 11 within,
    // sharpness 1.88; second -> first k 1.08, 7 of 11, 1.11: 18 of 22
    // (82 %), the at least 80 %.
    let within = |v: &serde_json::Value| {
        v["outages"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|w| w["within_bound_95"] == true)
            .count()
    };
    let (w12, w21) = (within(&v), within(&v21));
    eprintln!(
        "bound: first -> second {w12} of 11 (k {}), second -> first {w21} of 11 (k {})",
        v["bound"]["k"], v21["bound"]["k"]
    );
    assert_eq!((w12, w21), (11, 7));
    near(
        "k, first half",
        v["bound"]["k"].as_f64().unwrap(),
        1.38,
        0.1,
    );
    near(
        "k, second half",
        v21["bound"]["k"].as_f64().unwrap(),
        1.08,
        0.1,
    );
    near(
        "sharpness, first -> second",
        v["bound_95_sharpness"].as_f64().unwrap(),
        1.88,
        0.15,
    );
    near(
        "sharpness, second -> first",
        v21["bound_95_sharpness"].as_f64().unwrap(),
        1.11,
        0.15,
    );
}

/// Issue 29 item 4: the Husky calibrated on one half lost to the nominal
/// values on the other (3.832 against 2.586 m, 4.408 against 4.196 m).
/// With the held-back choice (the default) the second half keeps every
/// parameter nominal (4.196 m, equal to nominal) and the first half takes
/// only the antenna's x (-0.765 m, paired t -1.0 over 5 windows): 2.629 m
/// against nominal's 2.586 m, 1.7 % above it (not yet "at least as good").
#[test]
fn calibrated_husky_loses_to_nominal_on_the_other_half() {
    let tmp = tempfile::tempdir().unwrap();
    let (first, second) = (
        tmp.path().join("first.toml"),
        tmp.path().join("second.toml"),
    );
    let c1 = calibrate(&first, &["--until", MIDDLE]);
    let c2 = calibrate(&second, &["--from", MIDDLE]);
    let (first, second) = (first.to_str().unwrap(), second.to_str().unwrap());
    let (f12, _) = outage_mean(first, &["--from", MIDDLE]);
    let (n2, _) = outage_mean("nominal", &["--from", MIDDLE]);
    let (f21, _) = outage_mean(second, &["--until", MIDDLE]);
    let (n1, _) = outage_mean("nominal", &["--until", MIDDLE]);
    eprintln!(
        "first -> second {f12:.3} m (nominal {n2:.3}); second -> first {f21:.3} m (nominal {n1:.3})"
    );
    // Each judgement is in the JSON and the file, both figures per parameter.
    for c in [&c1, &c2] {
        let h = &c["held_back"];
        assert_eq!(h["windows"], 5, "{h}");
        assert_eq!(h["judged"].as_array().unwrap().len(), 5, "{h}");
    }
    let applied = |c: &serde_json::Value| -> Vec<String> {
        c["held_back"]["judged"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|j| j["applied"] == true)
            .map(|j| j["name"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(applied(&c1), ["antenna_x_m"], "{c1}");
    assert!(applied(&c2).is_empty(), "{c2}");
    let reason = c2["params"]["yaw_scale"]["reason"].as_str().unwrap();
    assert!(
        reason.contains("held-back GNSS prefers the nominal value"),
        "{reason}"
    );
    let file = std::fs::read_to_string(second).unwrap();
    assert!(
        file.contains("[held_back]") && file.contains("with_m"),
        "{file}"
    );
    // The second half's parameters are the nominal ones: the same figure.
    assert!((f21 - n1).abs() < 1e-9, "{f21} vs {n1}");
    near("nominal, second half", n2, 2.586, 0.05);
    near("nominal, first half", n1, 4.196, 0.05);
    near("first half -> second", f12, 2.629, 0.05);
    assert!(f12 < n2 + 0.06, "{f12} vs nominal {n2}");
}

/// The default calibration of the whole drive keeps every parameter
/// nominal (no candidate lowers the held-back error: paired t from -0.5 to
/// +2.0 over 11 windows), so its outages are nominal's, 3.307 m: above the
/// 2.9 m the in-sample fit of every parameter reached (2.848 m).
#[test]
fn husky_whole_drive_default_calibration_keeps_nominal() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("husky.toml");
    let c = calibrate(&p, &[]);
    assert_eq!(c["held_back"]["windows"], 11, "{c}");
    assert!(c["held_back"].get("chosen_m").is_none(), "{c}");
    for (name, v) in c["params"].as_object().unwrap() {
        assert_eq!(v["estimated"], false, "{name}: {v}");
    }
    let (mean, _) = outage_mean(p.to_str().unwrap(), &[]);
    let (nominal, _) = outage_mean("nominal", &[]);
    assert!((mean - nominal).abs() < 1e-9, "{mean} vs {nominal}");
    near("default calibration, whole drive", mean, 3.307, 0.05);
}
