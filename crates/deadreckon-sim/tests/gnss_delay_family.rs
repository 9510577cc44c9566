//! The GNSS delay on the car family (issue 28): the estimate against the
//! receiver's true latency at wheel rates of 25, 50 and 100 Hz, with true
//! delays of 0 (even members) and 0.05–0.2 s (odd members).
//!
//! Each member drives its own 600 s route (`CarFamily::drive`), its wheels
//! resampled at each rate with the same tone-ring noise in m/s (the edge
//! jitter scaled by the rate: its speed error is jitter / period). The
//! estimate is `timing::gnss_delay` with the default options: the filter
//! takes the paper's step (`ekf::WheelRows::Instant`), the delay's
//! dead-reckoned reference each wheel row over the interval it describes
//! (`timing::REFERENCE_WHEEL_ROWS`); its error is counted in its own standard
//! errors (`z`). `DELAY_ROWS=interval` runs the same with
//! `WheelRows::Interval` in the filter too.
//!
//! Nothing was tuned for this: `WheelRows::Interval` has no constant. The
//! members 201–220, run once each way:
//!
//! | filter's rows, reference's rows | 25 Hz within 3σ, mean error | 50 Hz | 100 Hz |
//! |---|---|---|---|
//! | instant, interval with each reading in its own interval and Euler's yaw (the default since stop 50) | 20/20, −3.7 ms (RMS z 0.94) | 20/20, −2.9 ms (1.04) | 20/20, −3.6 ms (0.94) |
//! | instant, interval (issue 29 to stop 49: the other readings in the interval after theirs, the trapezoid's yaw) | 20/20, −7.0 ms (RMS z 1.05) | 20/20, −5.5 ms (1.09) | 20/20, −5.9 ms (1.04) |
//! | interval, interval (to stop 49; not run since) | 20/20, −6.5 ms (RMS z 1.22) | 20/20, −5.7 ms (1.10) | 20/20, −5.9 ms (1.03) |
//! | instant, instant (the default before) | 15/20, −26.0 ms (2.49) | 18/20, −15.1 ms (1.77) | 19/20, −10.6 ms (1.48) |
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test gnss_delay_family -- --include-ignored --nocapture
//! ```

mod common;

use rayon::prelude::*;

use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::ekf::{FilterOptions, WheelRows};
use deadreckon_core::timing::{self, DelayOptions};
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

/// The calibration's options: the default (the paper's step,
/// [`WheelRows::Instant`]); `DELAY_ROWS=interval` for each row used over its
/// interval in the filter too.
fn copts() -> CalibrationOptions {
    let wheel_rows = match std::env::var("DELAY_ROWS").as_deref() {
        Ok("interval") => WheelRows::Interval,
        _ => WheelRows::Instant,
    };
    CalibrationOptions {
        filter: FilterOptions {
            wheel_rows,
            ..Default::default()
        },
        ..Default::default()
    }
}

/// The wheel rates every member is resampled at, Hz.
const RATES_HZ: [f64; 3] = [25.0, 50.0, 100.0];

/// Length of each member's drive, s.
const DURATION_S: f64 = 600.0;

/// One member at one wheel rate.
#[derive(Debug, Clone)]
struct Row {
    seed: u64,
    rate_hz: f64,
    /// The receiver's latency, s.
    latency_s: f64,
    /// The estimate and its standard error, s (NaN: the calibration refused
    /// the drive, see `note`).
    delay_s: f64,
    std_s: f64,
    /// Why not estimated, or the calibration's error.
    note: String,
}

impl Row {
    fn z(&self) -> f64 {
        (self.delay_s - self.latency_s) / self.std_s
    }
}

/// Member `seed`'s drive with its wheels at `rate_hz` and the delay estimated.
fn estimate(seed: u64, rate_hz: f64) -> Row {
    let latency_s = common::gnss_latency_of(seed);
    let mut car = CarFamily::draw(seed);
    car.edge_jitter_m *= car.wheel_rate_hz / rate_hz;
    car.wheel_rate_hz = rate_hz;
    car.gnss_latency_s = latency_s;
    let sim = simulate(&car.drive(100 + seed, DURATION_S), 100 + seed).unwrap();
    let mut row = Row {
        seed,
        rate_hz,
        latency_s,
        delay_s: f64::NAN,
        std_s: f64::NAN,
        note: String::new(),
    };
    match timing::gnss_delay(&sim.drive, &copts(), &DelayOptions::default()) {
        Ok((g, _)) => {
            row.delay_s = g.delay_s;
            row.std_s = g.std_s;
            row.note = g.status.reason().unwrap_or("").into();
        }
        Err(e) => row.note = e.to_string(),
    }
    row
}

/// Every member at every rate, on two threads, sorted by member and rate.
fn estimate_all(seeds: &[u64]) -> Vec<Row> {
    let jobs: Vec<(u64, f64)> = seeds
        .iter()
        .flat_map(|&s| RATES_HZ.map(|r| (s, r)))
        .collect();
    // Rows as rayon's pool runs them, sorted below.
    let mut rows: Vec<Row> = jobs.par_iter().map(|&(s, r)| estimate(s, r)).collect();
    rows.sort_by_key(|r| (r.seed, r.rate_hz as u64));
    rows
}

/// What one rate's rows show.
#[derive(Debug, Clone, Copy)]
struct Summary {
    /// Rows with a standard error (the calibration did not refuse the drive).
    with_std: usize,
    /// Of those, within 3 standard errors of the latency.
    within_3_sigma: usize,
    /// Mean error, s, and mean standard error, s.
    mean_error_s: f64,
    mean_std_s: f64,
    /// Root mean square of the errors in standard errors.
    rms_z: f64,
}

fn summary(rows: &[&Row]) -> Summary {
    let ok: Vec<&&Row> = rows.iter().filter(|r| r.std_s.is_finite()).collect();
    let n = ok.len() as f64;
    Summary {
        with_std: ok.len(),
        within_3_sigma: ok.iter().filter(|r| r.z().abs() <= 3.0).count(),
        mean_error_s: ok.iter().map(|r| r.delay_s - r.latency_s).sum::<f64>() / n,
        mean_std_s: ok.iter().map(|r| r.std_s).sum::<f64>() / n,
        rms_z: (ok.iter().map(|r| r.z().powi(2)).sum::<f64>() / n).sqrt(),
    }
}

/// Prints the rows and each rate's summary (all members, and those with a
/// true delay of 0 and above 0); returns the summaries per rate.
fn table(rows: &[Row]) -> Vec<(f64, Summary)> {
    eprintln!("member  wheels   latency    estimate   std err       z  note");
    for r in rows {
        eprintln!(
            "{:6} {:4} Hz  {:.4} s  {:+.4} s  {:.4} s  {:+6.2}  {}",
            r.seed,
            r.rate_hz,
            r.latency_s,
            r.delay_s,
            r.std_s,
            r.z(),
            r.note.chars().take(70).collect::<String>()
        );
    }
    let mut out = Vec::new();
    for rate in RATES_HZ {
        for (which, keep) in [
            ("all", &(|_: &Row| true) as &dyn Fn(&Row) -> bool),
            ("delay 0", &|r: &Row| r.latency_s == 0.0),
            ("delay > 0", &|r: &Row| r.latency_s > 0.0),
        ] {
            let sel: Vec<&Row> = rows
                .iter()
                .filter(|r| r.rate_hz == rate && keep(r))
                .collect();
            let s = summary(&sel);
            eprintln!(
                "{rate:3} Hz {which:<9}: {} of {} with a standard error, {} within 3σ; mean error {:+.4} s, mean std {:.4} s, rms z {:.2}",
                s.with_std,
                sel.len(),
                s.within_3_sigma,
                s.mean_error_s,
                s.mean_std_s,
                s.rms_z
            );
            if which == "all" {
                out.push((rate, s));
            }
        }
    }
    out
}

/// Held-out members 201–220 at 25, 50 and 100 Hz: within 3σ on at least
/// 90 % of them at each rate, the mean error a small part of the standard
/// error, the errors in standard errors near 1 in RMS. 100 s on two cores:
/// not in CI (`the_wheel_step_lag_was_read_as_a_gnss_delay` is).
#[test]
#[ignore]
fn the_gnss_delay_is_unbiased_with_honest_errors_on_held_out_family_members() {
    let seeds: Vec<u64> = (201..=220).collect();
    let rows = estimate_all(&seeds);
    for (rate, s) in table(&rows) {
        // A drive the calibration refuses is not a delay estimate; none of
        // these members' is.
        assert_eq!(s.with_std, seeds.len(), "{rate} Hz: {s:?}");
        assert!(
            s.within_3_sigma as f64 >= 0.9 * s.with_std as f64,
            "{rate} Hz: {s:?}"
        );
        // Measured (default options): mean errors −3.7, −2.9 and −3.6 ms at
        // 25, 50 and 100 Hz (0.25, 0.19 and 0.23 of the mean standard
        // errors, 14.9–15.4 ms; the mean of 20 members scatters by about
        // 3.4 ms); before stop 50 −7.0, −5.5 and −5.9 ms. With
        // `DELAY_ROWS=interval` (before stop 50): −6.5, −5.7 and −5.9 ms.
        assert!(
            s.mean_error_s.abs() <= 0.5 * s.mean_std_s,
            "{rate} Hz: {s:?}"
        );
        // Measured RMS of z: 0.94, 1.04 and 0.94 (before stop 50 1.05, 1.09
        // and 1.04; `DELAY_ROWS=interval` 1.22, 1.10 and 1.03); all 20
        // within 3σ at each rate.
        assert!(s.rms_z > 0.8 && s.rms_z < 1.3, "{rate} Hz: {s:?}");
    }
}

/// The larger held-out run, members 201–260: the table and the same
/// checks (not run at this change).
#[test]
#[ignore]
fn the_gnss_delay_on_sixty_held_out_family_members() {
    let seeds: Vec<u64> = (201..=260).collect();
    let rows = estimate_all(&seeds);
    for (rate, s) in table(&rows) {
        assert!(
            s.within_3_sigma as f64 >= 0.9 * s.with_std as f64,
            "{rate} Hz: {s:?}"
        );
        assert!(
            s.mean_error_s.abs() <= 0.5 * s.mean_std_s,
            "{rate} Hz: {s:?}"
        );
    }
}

/// Members 1–40, for comparison with the held-out ones.
#[test]
#[ignore]
fn the_gnss_delay_on_the_development_members() {
    let seeds: Vec<u64> = (1..=40).collect();
    table(&estimate_all(&seeds));
}

/// Regression: the GNSS delay's dead-reckoned reference took the filter's
/// own step, and with the paper's step (`WheelRows::Instant`, the default)
/// each wheel step carried the previous row's speed (the mean over the
/// period that ended), so the reference trailed by about one wheel period
/// while the speed changed and the delay read −0.7 to −0.9 wheel periods
/// with a true delay of 0 (issues 28 and 29); `--corrections auto` then
/// applied it on its significance. Car 1, its 300 s drive with nearly
/// noise-free fixes (0.03 m, white) at 25, 50 and 100 Hz, default options:
/// before, −29.4 ± 6.5, −15.5 ± 3.1 and −8.6 ± 1.2 ms; now the reference
/// takes each row over its own interval (`timing::REFERENCE_WHEEL_ROWS`)
/// whatever the filter's step, and the delay is within 3 ms of 0 at every
/// rate with either step.
#[test]
fn the_wheel_step_lag_was_read_as_a_gnss_delay() {
    let run = |rows: WheelRows, rates_hz: &[f64]| {
        let copts = CalibrationOptions {
            filter: FilterOptions {
                wheel_rows: rows,
                ..Default::default()
            },
            ..Default::default()
        };
        let mut estimates = Vec::new();
        for &rate_hz in rates_hz {
            let mut car = CarFamily::draw(1);
            car.gnss_markov.0 = 0.0;
            car.gnss_std_m = 0.03;
            car.edge_jitter_m *= car.wheel_rate_hz / rate_hz;
            car.wheel_rate_hz = rate_hz;
            car.gnss_latency_s = 0.0;
            let sim = simulate(&car.drive(101, 300.0), 101).unwrap();
            let (g, _) = timing::gnss_delay(&sim.drive, &copts, &DelayOptions::default()).unwrap();
            eprintln!(
                "{rows:?} {rate_hz} Hz: {:+.4} ± {:.4} s",
                g.delay_s, g.std_s
            );
            assert!(g.status.is_estimated(), "{g:?}");
            assert!(g.delay_s.abs() < 0.003, "{rows:?} {rate_hz} Hz: {g:?}");
            assert!(
                g.delay_s.abs() <= 3.0 * g.std_s,
                "{rows:?} {rate_hz} Hz: {g:?}"
            );
            estimates.push(g.delay_s);
        }
        estimates
    };
    // The default (the paper's step): before, −29.4, −15.5 and −8.6 ms,
    // 20.8 ms from 25 to 100 Hz.
    assert_eq!(FilterOptions::default().wheel_rows, WheelRows::Instant);
    let d = run(WheelRows::Instant, &[25.0, 50.0, 100.0]);
    let spread = d.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - d.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert!(spread < 0.001, "{d:?}");
    // Each row over its interval in the filter too, at the rate where the
    // lag was largest.
    run(WheelRows::Interval, &[25.0]);
}

/// Regression: with each wheel row over its interval
/// (`timing::REFERENCE_WHEEL_ROWS`), the GNSS delay's dead-reckoned
/// reference still applied the gyro's and the CAN speed's readings at the
/// wheel epoch after them, so they set the rates of the *next* interval:
/// on 48-tooth tick counts, which weigh little against a 0.1 m/s CAN speed,
/// the speed trailed by half a wheel period and a few ms more, and the
/// receiver's delay read it (issues 28 and 29: `calibrate` on the
/// evaluation scenario, seed 2, applied −26.4 ± 5.6 ms with none true).
/// The built-in evaluation scenario (48-tooth ticks, 100 Hz CAN speed and
/// gyro, no delays) with nearly noise-free fixes (0.05 m), its ticks at 25,
/// 50 and 100 Hz, the delays estimated as `calibrate` does
/// (`timing::estimate_with_params`): before, −21.7 ± 1.5, −16.8 ± 1.0 and
/// −10.1 ± 0.8 ms (11.6 ms from 25 to 100 Hz); now every reading updates
/// the state of the interval it is stamped in, and the delay read
/// −5.7 ± 0.7, −5.7 ± 0.7 and −1.7 ± 0.8 ms. Most of what was left was the
/// simulator's: its counters started standing at an edge, so the counted
/// distance trailed the true one by half a tooth on average (2 cm), which
/// turns read as time (with 4800 teeth the same drives read −0.4, −0.4 and
/// −0.5 ms). Each ring now stands at its own phase, as a parked wheel
/// stops anywhere between two edges, and the delay reads −1.97 ± 0.71,
/// −1.67 ± 0.76 and −1.99 ± 0.72 ms (4800 teeth: −0.42, −0.41, −0.46 ms);
/// the bounds, 4 ms and a 2 ms spread, would have caught the edge's
/// −5.7 ms and its 4.0 ms spread too.
#[test]
fn the_can_speed_set_the_next_intervals_speed_and_read_as_a_gnss_delay() {
    use deadreckon_sim::scenario::Scenario;
    let estimates: Vec<f64> = RATES_HZ
        .par_iter()
        .map(|&rate_hz| {
            let mut s = Scenario::builtin("evaluation").unwrap();
            s.sensors.wheels.rate_hz = rate_hz;
            s.sensors.gnss.as_mut().unwrap().std_m = 0.05;
            let sim = simulate(&s, 2).unwrap();
            let (d, _) = timing::estimate_with_params(
                &sim.drive,
                &CalibrationOptions::default(),
                &DelayOptions::default(),
            )
            .unwrap();
            let g = d.gnss;
            eprintln!(
                "{rate_hz} Hz ticks: {:+.2} ± {:.2} ms",
                1e3 * g.delay_s,
                1e3 * g.std_s
            );
            assert!(g.status.is_estimated(), "{rate_hz} Hz: {g:?}");
            assert!(g.delay_s.abs() < 0.004, "{rate_hz} Hz: {g:?}");
            assert!(g.std_s < 0.001, "{rate_hz} Hz: {g:?}");
            g.delay_s
        })
        .collect();
    let spread = estimates.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b))
        - estimates.iter().fold(f64::INFINITY, |a, &b| a.min(b));
    assert!(spread < 0.002, "{estimates:?}");
}
