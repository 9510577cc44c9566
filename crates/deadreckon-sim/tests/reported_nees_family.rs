//! Issue 36: which covariance of a dead-reckoned pose is consistent with
//! its error, on issue 36's family (`deadreckon_sim::family::good_gyro_car`;
//! core's RTS calibration without corrections on one 600 s drive, 30 s
//! windows every 60 s of another, against the truth): the five-state
//! filter's `P`; the error bound's `k²P + F` (docs/bound.md: `k` fitted on
//! the calibration drive, `F` the fixes' declared accuracy, which the
//! simulator's receivers give for their white noise only); `P` plus the
//! wander's variance as fitted (`wander_fit`) or as drawn; the filter
//! carrying the fitted wander (`[noise] gnss_wander_std_m`), and with the
//! wander as drawn; the white filter's errors against the wander filter's
//! covariance. Printed, not asserted (`consistency::Reported`,
//! `errors_through_windows`: one filter run per layout, every covariance
//! from the same errors).
//!
//! Measured on choice cars 65–88 (consistent per car with the χ² bounds of
//! `consistency`; merged: every car's windows averaged, pose NEES per
//! degree of freedom at ¼, ½, ¾ and the end of the windows):
//!
//! | covariance | consistent | merged per dof |
//! |---|---|---|
//! | filter `P` (white fixes) | 0/24 | 74.1 56.4 47.3 42.0 |
//! | the bound's `k²P + F` | 4/24 (8 cars fit `k` = 0: no heading variance, over-confident by ∞) | 3.69 3.24 2.90 2.80 over the 16 with `k` > 0 |
//! | `k²P` + the larger of `F` and `σ_fit²` | 2/24 (the 8 with `k` = 0 by ∞) | 3.13 2.81 2.51 2.43 over the 16 |
//! | `P + σ_fit²` | 6/24 | 2.40 2.07 1.82 1.69 |
//! | `P + F + σ_fit²` | 6/24 | 2.16 1.83 1.57 1.45 |
//! | `P + σ_true²` | 3/24 | 3.81 3.28 2.89 2.67 |
//! | wander filter, fitted (σ, τ) | 12/24 | 1.15 1.10 1.08 1.00 |
//! | wander filter, (σ, τ) as drawn | 5/24 | 2.83 2.53 2.33 2.13 |
//! | white filter's errors, wander filter's `P` | 8/24 | 6.12 5.34 4.80 4.35 |
//! | the same, `+ F` | 7/24 | 4.97 4.41 3.98 3.65 |
//!
//! Only a filter that carries the receiver's wander has a covariance that
//! follows its errors; floors on the white filter's position do not, as
//! its heading follows the wandering fixes too. The fitted wander does
//! better than the drawn one: it also takes up the latency (0–0.15 s) that
//! core's calibration here leaves uncorrected. Per car the χ² bounds of a
//! drive's nine windows assume independent windows, which the wander
//! (τ 20–120 s, windows 60 s apart) makes them not.
//!
//! ```text
//! cargo test --workspace --profile ci --test reported_nees_family -- --ignored --nocapture
//! ```

use deadreckon_core::bound;
use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
use deadreckon_core::consistency::{
    errors_through_windows, windows, Consistency, Reported, Verdict,
};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_sim::family::good_gyro_car as noise_family_car;
use deadreckon_sim::simulate;
use rayon::prelude::*;

struct Row {
    seed: u64,
    text: String,
    variants: Vec<Consistency>,
}

const NAMES: [&str; 10] = [
    "filter P",
    "k²P + F_declared (the bound)",
    "P + σ_fit²",
    "k²P + max(F, σ_fit²)",
    "P + σ_true²",
    "wander filter (fit)",
    "P + F + σ_fit²",
    "white track, wander filter's P",
    "white track, wander P + F",
    "wander filter (true σ, τ)",
];

fn row(seed: u64) -> Row {
    let (s, _) = noise_family_car(seed, 100 + seed);
    let truth_wander = s.sensors.gnss.as_ref().unwrap().markov_std_m;
    let latency = s.sensors.gnss.as_ref().unwrap().latency_s;
    let cal = simulate(&s, 100 + seed).unwrap();
    let c = calibrate(&cal.drive, &CalibrationOptions::default()).unwrap();
    let params = &c.estimate.params;
    let fo = FilterOptions::default();
    let k = bound::fit_on_drive(&cal.drive, params, &fo).k;
    let fit = deadreckon_core::wander_fit::fit(&cal.drive, params, &fo)
        .unwrap()
        .best;
    let sfit = fit.map_or(0.0, |w| w.std_m);
    let (s2, _) = noise_family_car(seed, 200 + seed);
    let ev = simulate(&s2, 200 + seed).unwrap();
    let declared = ev
        .drive
        .gnss
        .iter()
        .map(bound::receiver_std_m)
        .fold(0.0, f64::max);
    let w = windows(&ev.drive, 30.0, 60.0, 60.0);
    let e = errors_through_windows(&ev.drive, params, &w, &fo).unwrap();
    let f = declared * declared;
    let r = |k: f64, floor_m2: f64| e.consistency(&Reported { k, floor_m2 }).unwrap();
    let mut carried = ev.drive.clone();
    if let Some(wd) = fit {
        carried.vehicle.noise.gnss_wander_std_m = wd.std_m;
        carried.vehicle.noise.gnss_wander_tau_s = wd.tau_s;
    }
    let we = errors_through_windows(&carried, params, &w, &fo).unwrap();
    let wf = we.consistency(&Reported::FILTER).unwrap();
    let mut oracle = ev.drive.clone();
    oracle.vehicle.noise.gnss_wander_std_m = truth_wander.max(0.01);
    oracle.vehicle.noise.gnss_wander_tau_s = s2.sensors.gnss.as_ref().unwrap().markov_tau_s;
    let of = errors_through_windows(&oracle, params, &w, &fo)
        .unwrap()
        .consistency(&Reported::FILTER)
        .unwrap();
    let mut mixed = e.clone();
    for (a, b) in mixed.windows.iter_mut().zip(&we.windows) {
        for (pa, pb) in a.iter_mut().zip(b) {
            assert_eq!(pa.point, pb.point);
            pa.pose_cov = pb.pose_cov;
            pa.motion_cov = pb.motion_cov;
        }
    }
    let variants = vec![
        r(1.0, 0.0),
        r(k, f),
        r(1.0, sfit * sfit),
        r(k, f.max(sfit * sfit)),
        r(1.0, truth_wander * truth_wander),
        wf,
        r(1.0, f + sfit * sfit),
        mixed.consistency(&Reported::FILTER).unwrap(),
        mixed
            .consistency(&Reported {
                k: 1.0,
                floor_m2: f,
            })
            .unwrap(),
        of,
    ];
    let text = format!(
        "{seed:3} wander {truth_wander:.2} m {:.0} s fit {sfit:.2} {:.0} s latency {latency:.3} s declared {declared:.2} k {k:.2} | {}",
        s.sensors.gnss.as_ref().unwrap().markov_tau_s,
        fit.map_or(0.0, |w| w.tau_s),
        variants
            .iter()
            .map(|v| v.pose.verdict().to_string())
            .collect::<Vec<_>>()
            .join(" | ")
    );
    Row {
        seed,
        text,
        variants,
    }
}

#[test]
#[ignore = "experiment"]
fn reported_pose_nees_on_the_family() {
    let cars: Vec<u64> = std::env::var("NEES_CARS").map_or((65..=88).collect(), |v| {
        let (a, b) = v.split_once('-').unwrap();
        (a.parse().unwrap()..=b.parse().unwrap()).collect()
    });
    let mut rows: Vec<Row> = cars.into_par_iter().map(row).collect();
    rows.sort_by_key(|r| r.seed);
    for r in &rows {
        println!("{}", r.text);
    }
    for (i, name) in NAMES.iter().enumerate() {
        // A covariance without heading variance (the bound's with k = 0)
        // is over-confident by ∞: counted as not consistent, and left out
        // of the merged figure, which it would make ∞.
        let judged: Vec<&Row> = rows
            .iter()
            .filter(|r| r.variants[i].pose.points.iter().all(|p| p.nees.is_finite()))
            .collect();
        let ok = judged
            .iter()
            .filter(|r| r.variants[i].pose.verdict() == Verdict::Consistent)
            .count();
        let merged = judged[1..]
            .iter()
            .fold(judged[0].variants[i].clone(), |m, r| {
                m.merged(&r.variants[i]).unwrap()
            });
        let pts = merged
            .pose
            .points
            .iter()
            .map(|p| format!("{:.2}", p.nees / 3.0))
            .collect::<Vec<_>>()
            .join(" ");
        println!(
            "{name}: consistent {ok}/{} with a finite NEES of {}; merged over those per dof {pts} ({})",
            judged.len(),
            rows.len(),
            merged.pose.verdict()
        );
    }
}
