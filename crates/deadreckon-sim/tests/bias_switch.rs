//! The gyro-bias switch (issue 28, `deadreckon_core::aided::switch`): on a
//! drive whose gyro bias is not the calibration's, the drive's own fixes
//! switch the aided filter to the bias as a state and the outages end
//! closer; on a drive whose bias is the calibration's it stays with the
//! constant, bit for bit.
//!
//! Dynamic car 2's 300 s drive without effects (seeded), evaluated with its
//! true parameters except the gyro bias: the calibration drive's is
//! `JUMP_RPS` off the bias this drive's gyro has (the bias of a gyro
//! differs between drives: turn-on repeatability, temperature).

use deadreckon_core::drive::Drive;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::{evaluate, OutageEvaluation};
use deadreckon_core::vehicle::Params;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;

/// How far the calibrated bias is from this drive's, rad/s (≈ 21 °/h: a
/// 30 s outage at 20 m/s ends about 0.9 m off with it, ½·v·b·t²).
const JUMP_RPS: f64 = 1e-4;

/// The drive and its true parameters.
fn drive(seed: u64) -> (Drive, Params) {
    let car = DynamicCar::draw(seed);
    let sim = simulate(&car.drive(500 + seed, 300.0, &Effects::none()), 500 + seed).unwrap();
    (sim.drive, sim.truth_params)
}

/// 30 s outages every 10 s with the calibrated bias `jump` off; with the
/// switch (the bias free to differ by 5e-5 rad/s, threshold 2) or with the
/// constant bias alone.
fn outages(d: &Drive, truth: &Params, jump: f64, switch: bool) -> OutageEvaluation {
    let mut d = d.clone();
    let (std, llr) = if switch { (5e-5, 2.0) } else { (0.0, 0.0) };
    d.vehicle.noise.gyro_bias_drive_std_rps = std;
    d.vehicle.noise.gyro_bias_switch_llr = llr;
    let params = Params {
        gyro_bias_rps: truth.gyro_bias_rps - jump,
        ..*truth
    };
    evaluate(&d, &params, 30.0, 10.0, 5.0, &FilterOptions::default()).unwrap()
}

#[test]
fn a_gyro_bias_jump_switches_to_the_bias_state_and_the_outages_end_closer() {
    let (d, truth) = drive(2);
    let constant = outages(&d, &truth, JUMP_RPS, false);
    let switched = outages(&d, &truth, JUMP_RPS, true);
    assert!(constant.bias_switch.is_none());
    let s = switched.bias_switch.expect("the switch runs");
    let (c, w) = (constant.final_error().mean, switched.final_error().mean);
    println!(
        "jump {JUMP_RPS:e} rad/s: {s:?}; mean final error constant {c:.3} m, switched {w:.3} m"
    );
    let fired = s.fired_at_s.expect("the switch fired");
    assert!(s.llr >= 2.0 && s.fixes > 0, "{s:?}");
    // Windows that start before the switch dead-reckon from the constant
    // hypothesis, bit for bit; those after, from the bias state, closer.
    let (mut before, mut after_c, mut after_w) = (0, Vec::new(), Vec::new());
    for (a, b) in constant.windows.iter().zip(&switched.windows) {
        assert_eq!(a.start_s, b.start_s);
        if a.start_s < fired {
            assert_eq!(a, b);
            before += 1;
        } else {
            after_c.push(a.final_m());
            after_w.push(b.final_m());
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ac, aw) = (mean(&after_c), mean(&after_w));
    println!(
        "fired at {fired:.1} s: {before} windows before; {} after, mean final error constant {ac:.3} m, switched {aw:.3} m",
        after_c.len()
    );
    assert!(
        after_c.len() >= 5,
        "{} windows after the switch",
        after_c.len()
    );
    assert!(
        aw < 0.7 * ac,
        "after the switch {aw:.3} m against {ac:.3} m"
    );
}

#[test]
fn without_a_jump_the_switch_stays_with_the_constant_bias() {
    let (d, truth) = drive(2);
    let constant = outages(&d, &truth, 0.0, false);
    let switched = outages(&d, &truth, 0.0, true);
    let s = switched.bias_switch.expect("the switch runs");
    println!("no jump: {s:?}");
    assert_eq!(s.fired_at_s, None, "{s:?}");
    assert!(s.fixes > 100, "{s:?}");
    // The constant hypothesis is handed out throughout: the same windows,
    // bit for bit.
    assert_eq!(constant.windows, switched.windows);
}

/// A list of numbers from the environment, or `default`.
fn env_list<T: std::str::FromStr + Clone>(name: &str, default: &[T]) -> Vec<T> {
    std::env::var(name)
        .map(|s| s.split(',').filter_map(|x| x.trim().parse().ok()).collect())
        .unwrap_or_else(|_| default.to_vec())
}

/// One car's mean final errors: constant, always a state, and each
/// switch's with when it fired.
type Member = (f64, f64, Vec<(f64, Option<f64>)>);

/// One dynamic car with `effects`: calibrated (core, default options) on
/// one 300 s drive, 30 s outages every 10 s on another with the same
/// effects: the mean final error with the constant bias, with the bias
/// always a state (drive std `std`), and with the switch at each of
/// `thresholds`, and when each switch fired.
fn family_member(seed: u64, effects: &str, std: f64, thresholds: &[f64]) -> Result<Member, String> {
    use deadreckon_core::calibrate::{calibrate, CalibrationOptions};
    let car = DynamicCar::draw(seed);
    let fx = match effects {
        "none" => Effects::none(),
        "all" => Effects::all(),
        n => match n.strip_prefix("all_but_") {
            Some(but) => Effects::all_but(but),
            None => Effects::only(n),
        }
        .ok_or(format!("no effect {n}"))?,
    };
    let cal =
        simulate(&car.drive(1000 + seed, 300.0, &fx), 1000 + seed).map_err(|e| e.to_string())?;
    let ev =
        simulate(&car.drive(2000 + seed, 300.0, &fx), 2000 + seed).map_err(|e| e.to_string())?;
    let c = calibrate(&cal.drive, &CalibrationOptions::default()).map_err(|e| e.to_string())?;
    let run = |drive_std: f64, llr: f64| -> Result<OutageEvaluation, String> {
        let mut d = ev.drive.clone();
        d.vehicle.noise.gyro_bias_drive_std_rps = drive_std;
        d.vehicle.noise.gyro_bias_switch_llr = llr;
        evaluate(
            &d,
            &c.estimate.params,
            30.0,
            10.0,
            5.0,
            &FilterOptions::default(),
        )
        .map_err(|e| e.to_string())
    };
    let constant = run(0.0, 0.0)?.final_error().mean;
    let always = run(std, 0.0)?.final_error().mean;
    let mut switched = Vec::new();
    for &t in thresholds {
        let e = run(std, t)?;
        switched.push((
            e.final_error().mean,
            e.bias_switch.and_then(|s| s.fired_at_s),
        ));
    }
    Ok((constant, always, switched))
}

/// The switch on the dynamic family (issue 28): per effect, the mean over
/// cars of the mean 30 s outage error with the constant bias, the bias
/// always a state, and the switch at each threshold. `SWITCH_EFFECTS`
/// takes `none`, `all`, an effect's name or `all_but_NAME` (every effect
/// but that one).
///
/// ```text
/// RAYON_NUM_THREADS=2 SWITCH_CARS=1,…,25 SWITCH_EFFECTS=none,gyro_drift,all \
///     SWITCH_STD=5e-5 SWITCH_LLR=1,2,3,5 cargo test --profile ci \
///     -p deadreckon-sim --test bias_switch -- --ignored --nocapture
/// ```
#[test]
#[ignore]
fn bias_switch_on_the_family() {
    use rayon::prelude::*;
    let cars: Vec<u64> = env_list("SWITCH_CARS", &[1, 2, 3, 4, 5, 6]);
    let effects: Vec<String> = env_list(
        "SWITCH_EFFECTS",
        &["none".to_string(), "gyro_drift".to_string()],
    );
    let std = env_list("SWITCH_STD", &[5e-5])[0];
    let thresholds: Vec<f64> = env_list("SWITCH_LLR", &[2.0]);
    let jobs: Vec<(u64, String)> = effects
        .iter()
        .flat_map(|e| cars.iter().map(move |&c| (c, e.clone())))
        .collect();
    let rows: Vec<_> = jobs
        .par_iter()
        .map(|(c, e)| family_member(*c, e, std, &thresholds))
        .collect();
    let mut ran = 0;
    for e in &effects {
        let mut n = 0usize;
        let (mut sc, mut sa) = (0.0, 0.0);
        let mut ss = vec![0.0; thresholds.len()];
        let mut fired = vec![0usize; thresholds.len()];
        let mut better = vec![0usize; thresholds.len()];
        let mut worse = vec![0usize; thresholds.len()];
        for ((car, _), r) in jobs.iter().zip(&rows).filter(|(j, _)| &j.1 == e) {
            match r {
                Ok((c, a, s)) => {
                    let cells: Vec<String> = s
                        .iter()
                        .zip(&thresholds)
                        .map(|((m, f), t)| {
                            format!(
                                "switch@{t} {m:.3}{}",
                                f.map_or(String::new(), |f| format!(" (at {f:.0} s)"))
                            )
                        })
                        .collect();
                    println!(
                        "{e:>10} car {car:>3}: constant {c:.3} always {a:.3} {}",
                        cells.join(" ")
                    );
                    n += 1;
                    sc += c;
                    sa += a;
                    for (k, (m, f)) in s.iter().enumerate() {
                        ss[k] += m;
                        fired[k] += usize::from(f.is_some());
                        better[k] += usize::from(*m < c - 1e-9);
                        worse[k] += usize::from(*m > c + 1e-9);
                    }
                }
                Err(why) => println!("{e:>10} car {car:>3}: {why}"),
            }
        }
        if n == 0 {
            continue;
        }
        ran += n;
        let nf = n as f64;
        println!(
            "{e}: over {n} cars, constant {:.3} m, always {:.3} m",
            sc / nf,
            sa / nf
        );
        for (k, t) in thresholds.iter().enumerate() {
            println!(
                "{e}:   switch@{t}: {:.3} m, fired on {}, better than constant on {}, worse on {}",
                ss[k] / nf,
                fired[k],
                better[k],
                worse[k]
            );
        }
    }
    assert!(ran > 0, "no car ran");
}
