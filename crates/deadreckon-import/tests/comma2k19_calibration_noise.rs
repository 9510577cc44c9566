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
    for (label, opts) in [
        ("table I's 1e-5", table_one),
        ("the vehicle's 5e-5", CalibrationOptions::default()),
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
        }
        bias.push((e[0].params.gyro_bias_rps, e[1].params.gyro_bias_rps, z));
    }
    // Measured: at 1e-5 the halves' gyro biases −0.067709 ± 0.000116 and
    // −0.067903 ± 0.000099 rad/s, apart by +1.28 joint σ; the speed scale
    // −1.16, the circumferences +0.22, +0.45, −0.20, +0.09. At 5e-5 within
    // 3e-6 rad/s of these (+1.26σ). (The command's default corrections,
    // estimated per half, put them 5.2σ apart with either noise.) The pose
    // NEES of the other half's two windows is over-confident by ×10.3 and
    // ×7.9 with either (the dead-reckoning filter is the same): printed, not
    // asserted; the calibrated error bound is the remedy (docs/bound.md).
    let (now, before) = (&bias[0], &bias[1]);
    assert!(now.2.iter().all(|z| z.abs() < 1.5), "{:?}", now.2);
    assert!((now.0 - before.0).abs() < 1e-5 && (now.1 - before.1).abs() < 1e-5);
}
