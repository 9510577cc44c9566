//! Issue 36 on the comma2k19 segment: the RTS calibration of each half (split
//! at 46438.6 s, as `tests/end_to_end.rs`'s held-out halves) with its
//! passes at table I's yaw noise (`calibrate::SMOOTHING_PROCESS_YAW_RAD`,
//! the default since issue 36) and at the vehicle's 5e-5 (the default
//! before; the figures below were measured then, with the lag-1 standard
//! errors); the two halves' estimates against each other in
//! their joint standard error (the truth of the parameters is unknown); and
//! the pose NEES of the other half's 20 s dead-reckoning windows (every
//! 5 s) against the reference trajectory (`truth.csv` of the import), with
//! the dead-reckoning filter at the vehicle's noise. The core calibration
//! without the corrections `calibrate` estimates (those are the same for
//! both noises).
//!
//! ```text
//! cargo test --profile ci -p deadreckon-import --test comma2k19_calibration_noise -- --nocapture
//! ```

mod common;

use deadreckon_core::calibrate::{calibrate, CalibrationOptions, SMOOTHING_PROCESS_YAW_RAD};
use deadreckon_core::consistency::{nees_through_windows, windows};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::{Drive, ParamsWithStd};
use deadreckon_import::read_comma2k19;

const SPLIT_S: f64 = 46438.6;

fn halves(d: &Drive) -> [Drive; 2] {
    [
        d.time_range(None, Some(SPLIT_S)),
        d.time_range(Some(SPLIT_S), None),
    ]
}

/// `(a − b) / √(σa² + σb²)` per parameter.
fn apart(a: &ParamsWithStd, b: &ParamsWithStd) -> [f64; 6] {
    let (pa, sa, pb, sb) = (
        a.params.to_array(),
        a.std.to_array(),
        b.params.to_array(),
        b.std.to_array(),
    );
    std::array::from_fn(|i| (pa[i] - pb[i]) / sa[i].hypot(sb[i]))
}

#[test]
fn comma2k19_halves_with_either_yaw_noise_in_the_calibration() {
    let d = read_comma2k19(&common::data("comma2k19-rav4"), None).unwrap();
    let hs = halves(&d);
    let table_one = CalibrationOptions {
        smoothing_process_yaw_rad: Some(SMOOTHING_PROCESS_YAW_RAD),
        ..CalibrationOptions::default()
    };
    let mut bias = Vec::new();
    // The end-of-window pose NEES: white fixes, and the wander carried.
    let mut ends = Vec::new();
    for (label, opts) in [
        ("table I's 1e-5", table_one),
        (
            "the vehicle's 5e-5",
            CalibrationOptions {
                smoothing_process_yaw_rad: None,
                ..CalibrationOptions::default()
            },
        ),
    ] {
        let e = hs
            .iter()
            .map(|h| calibrate(h, &opts).unwrap().estimate)
            .collect::<Vec<_>>();
        let z = apart(&e[0], &e[1]);
        println!(
            "passes at {label}: gyro bias {:.6} ± {:.6} / {:.6} ± {:.6} rad/s; halves apart in joint σ: {}",
            e[0].params.gyro_bias_rps,
            e[0].std.gyro_bias_rps,
            e[1].params.gyro_bias_rps,
            e[1].std.gyro_bias_rps,
            z.map(|v| format!("{v:+.2}")).join(" ")
        );
        for (i, cal) in e.iter().enumerate() {
            let other = &hs[1 - i];
            let w = windows(other, 20.0, 5.0, 2.0);
            let c =
                nees_through_windows(other, &cal.params, &w, &FilterOptions::default()).unwrap();
            let pts: Vec<String> = c
                .pose
                .points
                .iter()
                .map(|p| {
                    format!(
                        "{:.2}@{:.2} [{:.2},{:.2}]",
                        p.nees, p.fraction, p.lower, p.upper
                    )
                })
                .collect();
            println!(
                "  calibrated on half {}, {} windows of the other: pose NEES {} -> {}",
                i + 1,
                w.len(),
                pts.join(" "),
                c.pose.verdict()
            );
            // Issue 36's second stop: the receiver's wander fitted on the
            // calibrating half (`wander_fit`), carried by the other's filter.
            let fitted =
                deadreckon_core::wander_fit::fit(&hs[i], &cal.params, &FilterOptions::default())
                    .unwrap()
                    .best;
            let mut carried = other.clone();
            if let Some(wd) = fitted {
                carried.vehicle.noise.gnss_wander_std_m = wd.std_m;
                carried.vehicle.noise.gnss_wander_tau_s = wd.tau_s;
            }
            let cw =
                nees_through_windows(&carried, &cal.params, &w, &FilterOptions::default()).unwrap();
            println!(
                "    with the receiver's wander fitted on half {} ({}): pose NEES {} -> {}",
                i + 1,
                fitted.map_or("white".into(), |wd| format!(
                    "{:.2} m, {:.0} s",
                    wd.std_m, wd.tau_s
                )),
                cw.pose
                    .points
                    .iter()
                    .map(|p| format!("{:.2}@{:.2}", p.nees, p.fraction))
                    .collect::<Vec<_>>()
                    .join(" "),
                cw.pose.verdict()
            );
            let end = |c: &deadreckon_core::consistency::Consistency| {
                c.pose.points.last().map_or(f64::NAN, |p| p.nees)
            };
            ends.push((end(&c), end(&cw)));
        }
        bias.push((e[0].params.gyro_bias_rps, e[1].params.gyro_bias_rps, z));
    }
    // Measured: at 1e-5 the halves' gyro biases −0.067709 ± 0.000116 and
    // −0.067903 ± 0.000131 rad/s (the batch means' standard errors), apart
    // by +1.11 joint σ; the speed scale −0.56, the circumferences +0.11,
    // +0.19, −0.11, +0.04. At 5e-5 within 3e-6 rad/s of these (+1.10σ).
    // (Until issue 36's second stop both rows ran the default, which had
    // become 1e-5.) The pose NEES of the other half's two windows is
    // over-confident by ×10.3 and ×7.9 with either (the dead-reckoning
    // filter is the same); with the receiver's wander fitted on the
    // calibrating half carried (0.50 m 60 s, 0.25 m 30 s) ×2.5 and ×4.0,
    // the end-of-window NEES 22.1 -> 5.6 and 22.6 -> 11.6: still
    // over-confident, printed; the calibrated error bound is the remedy
    // (docs/bound.md).
    for (white, wander) in &ends {
        assert!(wander < &(0.6 * white), "{wander} against {white}");
    }
    let (now, before) = (&bias[0], &bias[1]);
    assert!(now.2.iter().all(|z| z.abs() < 1.5), "{:?}", now.2);
    assert!((now.0 - before.0).abs() < 1e-5 && (now.1 - before.1).abs() < 1e-5);
}
