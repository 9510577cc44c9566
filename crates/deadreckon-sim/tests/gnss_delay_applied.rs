//! Which GNSS delay the paper's step (`ekf::WheelRows::Instant`, the
//! filter's default) should apply (issue 29): the receiver's (`delay_s`, as
//! `timing::gnss_delay` estimates it), or the delay the filter's own dead
//! reckoning matches (`Delay::applied_s`: the receiver's plus the step's
//! offset; its positions trail by about 0.8 wheel periods while the speed
//! changes, which the delay read as −29, −16 and −9 ms at 25, 50 and 100 Hz
//! before the reference took each row over its interval).
//!
//! Each family member (kinematic, `CarFamily`; true delay 0 for even
//! members, 0.05–0.2 s for odd ones) is calibrated on one 300 s drive with
//! the applied delay, and its 30 s outages (every 10 s) are evaluated on
//! another 300 s drive of the same car with the same delay: no delay, the
//! receiver's estimate `d`, the applied `d + offset` and the truth.
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test gnss_delay_applied -- --ignored --nocapture
//! ```
//! (`APPLIED_SEEDS=a..=b` for other members; 1–8 by default: the
//! development members. 201–208 held out.)

mod common;

use rayon::prelude::*;

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::evaluate;
use deadreckon_core::timing::{self, DelayOptions};
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

/// What each applied delay gave one member at one rate: the estimate and its
/// standard error, s, the step offset, s, and the mean final outage error,
/// m, with no delay, `d`, `d + offset` and the truth.
#[derive(Debug, Clone)]
struct Row {
    seed: u64,
    rate_hz: f64,
    latency_s: f64,
    delay_s: f64,
    std_s: f64,
    z: f64,
    offset_s: f64,
    errors_m: [f64; 4],
}

fn member(seed: u64, rate_hz: f64) -> Row {
    let latency_s = common::gnss_latency_of(seed);
    let mut car = CarFamily::draw(seed);
    car.edge_jitter_m *= car.wheel_rate_hz / rate_hz;
    car.wheel_rate_hz = rate_hz;
    car.gnss_latency_s = latency_s;
    let cal = simulate(&car.drive(300 + seed, 300.0), 300 + seed).unwrap();
    let ev = simulate(&car.drive(400 + seed, 300.0), 400 + seed).unwrap();
    let copts = CalibrationOptions::default();
    let (g, _) = timing::gnss_delay(&cal.drive, &copts, &DelayOptions::default()).unwrap();
    let d = if g.status.is_estimated() {
        g.delay_s
    } else {
        0.0
    };
    let applied = [0.0, d, g.applied_s(), latency_s];
    let errors_m = applied.map(|a| {
        let c = calibrate::calibrate(&timing::shift(&cal.drive, [0.0, 0.0, 0.0, a]), &copts);
        let Ok(c) = c else { return f64::NAN };
        evaluate(
            &timing::shift(&ev.drive, [0.0, 0.0, 0.0, a]),
            &c.estimate.params,
            30.0,
            10.0,
            5.0,
            &FilterOptions::default(),
        )
        .map_or(f64::NAN, |o| o.final_error().mean)
    });
    Row {
        seed,
        rate_hz,
        latency_s,
        delay_s: g.delay_s,
        std_s: g.std_s,
        z: g.delay_s / g.std_s,
        offset_s: g.step_offset_s,
        errors_m,
    }
}

/// The members, at 25 and 100 Hz, on two threads: each applied delay's
/// mean final error over the members with a true delay of 0 and above.
#[test]
#[ignore]
fn which_gnss_delay_the_paper_step_should_apply() {
    let seeds: Vec<u64> = match std::env::var("APPLIED_SEEDS") {
        Ok(s) => {
            let (a, b) = s.split_once("..=").expect("APPLIED_SEEDS=a..=b");
            (a.parse().unwrap()..=b.parse().unwrap()).collect()
        }
        Err(_) => (1..=8).collect(),
    };
    let jobs: Vec<(u64, f64)> = seeds
        .iter()
        .flat_map(|&s| [25.0, 100.0].map(|r| (s, r)))
        .collect();
    // Rows as rayon's pool runs them, sorted below.
    let mut rows: Vec<Row> = jobs.par_iter().map(|&(s, r)| member(s, r)).collect();
    rows.sort_by_key(|r| (r.seed, r.rate_hz as u64));
    eprintln!(
        "member wheels  latency   estimate  std      z    offset   | none    d       d+off   truth (m)"
    );
    for r in &rows {
        eprintln!(
            "{:5} {:4} Hz {:.4} s {:+.4} s {:.4} {:+5.1} {:+.4} | {:.3}  {:.3}  {:.3}  {:.3}",
            r.seed,
            r.rate_hz,
            r.latency_s,
            r.delay_s,
            r.std_s,
            r.z,
            r.offset_s,
            r.errors_m[0],
            r.errors_m[1],
            r.errors_m[2],
            r.errors_m[3]
        );
    }
    for rate in [25.0, 100.0] {
        for (which, zero) in [("delay 0", true), ("delay > 0", false)] {
            let sel: Vec<&Row> = rows
                .iter()
                .filter(|r| r.rate_hz == rate && (r.latency_s == 0.0) == zero)
                .collect();
            let n = sel.len() as f64;
            let mean = |k: usize| sel.iter().map(|r| r.errors_m[k]).sum::<f64>() / n;
            eprintln!(
                "{rate:3} Hz {which:<9} ({} members): none {:.3} m, d {:.3} m, d + offset {:.3} m, truth {:.3} m",
                sel.len(),
                mean(0),
                mean(1),
                mean(2),
                mean(3)
            );
        }
    }
}
