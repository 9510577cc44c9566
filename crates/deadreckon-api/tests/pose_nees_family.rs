//! Issue 36: the pose NEES and the outage errors on issue 36's family
//! (`deadreckon_sim::family::good_gyro_car`) through the user's path:
//! `calibrate` with the default request (`--corrections auto`) on one
//! 600 s drive, its params.toml's corrections applied to a second drive
//! (`evaluate --params`), 30 s dead-reckoning windows every 60 s against
//! the truth. Beside auto's choice: the same with white fixes (the
//! receiver's wander left out) and with the wander fitted on the corrected
//! calibration drive always carried. Figures of each rule for applying
//! the wander: docs/gnss-wander.md.
//!
//! ```text
//! NEES_CARS=65-88 cargo test --workspace --profile ci --test pose_nees_family -- --ignored --nocapture
//! ```

use deadreckon_api::calibration::{calibrate, CalibrationRequest};
use deadreckon_api::corrections::stored_corrections;
use deadreckon_core::consistency::{
    errors_through_windows, windows, Consistency, Reported, Verdict,
};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::held_back::Correction;
use deadreckon_core::model_options::ModelOption;
use deadreckon_sim::family::good_gyro_car;
use deadreckon_sim::simulate;
use rayon::prelude::*;

struct Row {
    seed: u64,
    /// The wander's held-back t (NaN: not a candidate), whether applied.
    t: f64,
    /// The hidden fixes' likelihood t (NaN: not a candidate).
    score_t: f64,
    applied: bool,
    /// auto, white, and with `fit_always` the wander always fitted: the
    /// NEES and the mean final error.
    runs: Vec<(Consistency, f64)>,
    fit: Option<deadreckon_core::gnss_error::Wander>,
}

fn final_error(e: &deadreckon_core::consistency::WindowErrors) -> f64 {
    let v: Vec<f64> = e
        .windows
        .iter()
        .filter_map(|w| w.iter().find(|p| p.point == 3))
        .map(|p| p.pose[0].hypot(p.pose[1]))
        .collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// Car `seed`'s figures; `fit_always` also fits the wander on the
/// corrected calibration drive and carries it (16 more filter runs).
fn row(seed: u64, fit_always: bool) -> Result<Row, String> {
    let (s, _) = good_gyro_car(seed, 100 + seed);
    let cal = simulate(&s, 100 + seed).map_err(|e| e.to_string())?;
    let c =
        calibrate(&cal.drive, &CalibrationRequest::default(), "cal").map_err(|e| e.to_string())?;
    let stored = stored_corrections(&c.params_extra())?;
    let params = c.calibration.estimate.params;
    let fo = FilterOptions::default();
    let judged = c.corrections.held_back.as_ref().and_then(|h| {
        h.decision(Correction::Model(ModelOption::GnssWander))
            .cloned()
    });
    let (s2, _) = good_gyro_car(seed, 200 + seed);
    let ev = simulate(&s2, 200 + seed).map_err(|e| e.to_string())?;
    let w = windows(&ev.drive, 30.0, 60.0, 60.0);
    let auto = stored.apply(&ev.drive);
    let mut white = auto.clone();
    white.vehicle.noise.gnss_wander_std_m = 0.0;
    let run = |d: &deadreckon_core::Drive| -> Result<(Consistency, f64), String> {
        let e = errors_through_windows(d, &params, &w, &fo).map_err(|e| e.to_string())?;
        Ok((
            e.consistency(&Reported::FILTER)
                .map_err(|e| e.to_string())?,
            final_error(&e),
        ))
    };
    let mut runs = vec![run(&auto)?, run(&white)?];
    let mut fit = None;
    if fit_always {
        fit = deadreckon_core::model_options::wander_candidate(
            &stored.apply(&cal.drive),
            &params,
            &fo,
        );
        let mut always = white.clone();
        if let Some(wd) = fit {
            always.vehicle.noise.gnss_wander_std_m = wd.std_m;
            always.vehicle.noise.gnss_wander_tau_s = wd.tau_s;
        }
        runs.push(run(&always)?);
    }
    Ok(Row {
        seed,
        t: judged.as_ref().map_or(f64::NAN, |j| j.t),
        score_t: judged.as_ref().map_or(f64::NAN, |j| j.score_t),
        applied: judged.as_ref().is_some_and(|j| j.applied),
        runs,
        fit,
    })
}

#[test]
#[ignore = "slow: a default calibration per car"]
fn pose_nees_through_the_user_path() {
    let cars: Vec<u64> = std::env::var("NEES_CARS").map_or((65..=88).collect(), |v| {
        let (a, b) = v.split_once('-').expect("NEES_CARS=a-b");
        (a.parse().unwrap()..=b.parse().unwrap()).collect()
    });
    let mut rows: Vec<Row> = cars
        .into_par_iter()
        .map(|s| row(s, true).unwrap_or_else(|e| panic!("car {s}: {e}")))
        .collect();
    rows.sort_by_key(|r| r.seed);
    for r in &rows {
        println!(
            "{:3} wander t {:+.2} likelihood t {:+.2} {} fit {} | auto {} {:.2} m | white {} {:.2} m | always {} {:.2} m",
            r.seed,
            r.t,
            r.score_t,
            if r.applied { "applied" } else { "not applied" },
            r.fit.map_or("white".into(), |w| format!("{:.2} m {:.0} s", w.std_m, w.tau_s)),
            r.runs[0].0.pose.verdict(),
            r.runs[0].1,
            r.runs[1].0.pose.verdict(),
            r.runs[1].1,
            r.runs[2].0.pose.verdict(),
            r.runs[2].1,
        );
    }
    // What a threshold t0 would have carried: the wander where t ≤ −t0.
    for t0 in [1.0, 0.5, 0.0] {
        let pick = |r: &Row| if r.t <= -t0 { 2 } else { 1 };
        summary(&format!("wander where t ≤ −{t0}"), &rows, &pick);
    }
    summary("as auto chose", &rows, &|_| 0);
    summary("white", &rows, &|_| 1);
    summary("always fitted", &rows, &|_| 2);
}

fn summary(name: &str, rows: &[Row], pick: &dyn Fn(&Row) -> usize) {
    let n = rows.len();
    let ok = rows
        .iter()
        .filter(|r| r.runs[pick(r)].0.pose.verdict() == Verdict::Consistent)
        .count();
    let merged = rows[1..]
        .iter()
        .fold(rows[0].runs[pick(&rows[0])].0.clone(), |m, r| {
            m.merged(&r.runs[pick(r)].0).unwrap()
        });
    let err = rows.iter().map(|r| r.runs[pick(r)].1).sum::<f64>() / n as f64;
    println!(
        "{name}: pose NEES consistent {ok}/{n}; merged per dof {} ({}); mean final error {err:.3} m",
        merged
            .pose
            .points
            .iter()
            .map(|p| format!("{:.2}", p.nees / 3.0))
            .collect::<Vec<_>>()
            .join(" "),
        merged.pose.verdict()
    );
}

/// Car `seed`'s row without the always-fitted run, printed.
fn car(seed: u64) -> Row {
    let r = row(seed, false).unwrap();
    println!(
        "car {seed}: t {:+.2} likelihood t {:+.2} applied {}; auto {} {:.3} m, white {} {:.3} m",
        r.t,
        r.score_t,
        r.applied,
        r.runs[0].0.pose.verdict(),
        r.runs[0].1,
        r.runs[1].0.pose.verdict(),
        r.runs[1].1
    );
    r
}

/// A verdict's factor (1 when consistent).
fn factor_of(v: Verdict) -> f64 {
    match v {
        Verdict::Consistent => 1.0,
        Verdict::OverConfident(k) | Verdict::UnderConfident(k) => k,
    }
}

/// Issue 36: the receiver's wander was applied only at a held-back t of
/// −1 or below (`held_back::MIN_T`), so receivers whose fixes wander, where
/// the wander lowered the held-back error at t between −1 and 0, kept the
/// white-fix filter: on choice car 81 (t −0.94) 30 s outages ended 1.26 m
/// off on average with the pose covariance over-confident by ×24.1, and
/// 0.72 m (under-confident by ×3.2) with the wander. Now it is applied
/// below t = 0 (`held_back::WANDER_MIN_T`).
#[test]
fn a_wander_that_lowered_the_held_back_error_was_left_out() {
    let r = car(81);
    assert!(r.t > -1.0 && r.t < 0.0, "t {}", r.t);
    assert!(r.applied);
    // Measured: 0.72 m against 1.26 m; ×3.2 under against ×24.1 over.
    assert!(
        r.runs[0].1 < 0.8 && r.runs[1].1 > 1.15,
        "{} {}",
        r.runs[0].1,
        r.runs[1].1
    );
    assert!(factor_of(r.runs[0].0.pose.verdict()) < 4.0);
    assert!(factor_of(r.runs[1].0.pose.verdict()) > 15.0);
}

/// Issue 36: the receiver's wander was judged on the held-back error alone,
/// which does not see the covariance it changes. On choice car 70 it
/// lowered the error at no t below 0 (t +0.16) and was left out, though
/// the hidden fixes were more likely with it (likelihood t +1.12): the
/// evaluation drive's pose covariance was over-confident by ×45.6 and its
/// 30 s outages ended 0.92 m off, against ×1.7 and 0.69 m with the wander.
/// Now a wander that makes the hidden fixes more likely is applied unless
/// it raises the error by a standard error (`held_back::wander_wins`).
#[test]
fn a_wander_that_made_the_hidden_fixes_likelier_was_left_out() {
    let r = car(70);
    assert!(r.t > 0.0 && r.t < 1.0, "t {}", r.t);
    assert!(r.score_t > 0.0, "likelihood t {}", r.score_t);
    assert!(r.applied);
    // Measured: 0.69 m against 0.92 m; ×1.7 against ×45.6 over.
    assert!(
        r.runs[0].1 < 0.75 && r.runs[1].1 > 0.85,
        "{} {}",
        r.runs[0].1,
        r.runs[1].1
    );
    assert!(factor_of(r.runs[0].0.pose.verdict()) < 2.5);
    assert!(factor_of(r.runs[1].0.pose.verdict()) > 30.0);
}
