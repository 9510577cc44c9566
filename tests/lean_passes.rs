//! The calibration's passes that keep less than every epoch (issue 30)
//! give what the recorded runs gave, bit for bit.

mod common;

use deadreckon_core::ekf::{self, FilterOptions, Init, SensorSet};
use deadreckon_core::reference::Reference;
use deadreckon_core::{Drive, Params};

fn drive(seed: u64, duration_s: f64) -> Drive {
    common::sim_drive("calibration", seed, Some(duration_s))
}

/// `timing::gnss_delay` smoothed the whole recorded run (every epoch and
/// every smoothed covariance, 2.3 KB per wheel epoch with the dead
/// reckoning's) to use its first state.
#[test]
fn gnss_delay_smoothed_start_equals_the_first_of_smoothing_a_recorded_run() {
    let d = drive(5, 240.0);
    let params = Params::nominal(&d.vehicle);
    let opts = FilterOptions::default();
    let full = ekf::run(&d, &params, &opts, &mut ()).unwrap();
    let want = deadreckon_core::rts::smooth(&full.epochs).unwrap();
    assert!(full.epochs.len() > 10_000, "several segments");
    let f = ekf::car_filter(&d, &params, &opts).unwrap();
    let got = deadreckon_core::checkpoint::smoothed_start(&d, f, &opts)
        .unwrap()
        .unwrap();
    assert_eq!(got.t_s, want[0].t_s);
    assert_eq!(got.x, want[0].x);
    assert_eq!(got.p, want[0].p);
}

/// `timing::gnss_delay` recorded every epoch of its dead reckoning to
/// interpolate it at the fixes' times.
#[test]
fn gnss_delay_states_at_fixes_equal_the_recorded_run_interpolated() {
    let d = drive(6, 240.0);
    let params = Params::nominal(&d.vehicle);
    let aided = ekf::run(&d, &params, &FilterOptions::default(), &mut ()).unwrap();
    let s = &aided.epochs[100];
    let opts = FilterOptions {
        init: Init::Given {
            t_s: s.t_s,
            x: s.x,
            p: s.p,
        },
        sensors: SensorSet::dead_reckoning(),
        ..FilterOptions::default()
    };
    let dr = ekf::run(&d, &params, &opts, &mut ()).unwrap();
    let recorded = Reference::from_states(
        dr.epochs.iter().map(|e| e.t_s).collect(),
        dr.epochs.iter().map(|e| e.x).collect(),
    );
    let got = deadreckon_core::timing::states_at_fixes(&d, &params, &opts).unwrap();
    let inside: Vec<f64> = d
        .gnss
        .iter()
        .map(|g| g.t_s)
        .filter(|&t| recorded.state_at(t).is_some())
        .collect();
    // The fixes before the start are outside.
    assert!(
        inside.len() > 200 && inside.len() < d.gnss.len(),
        "{}",
        inside.len()
    );
    assert_eq!(got.t, inside);
    for g in &d.gnss {
        assert_eq!(
            got.state_at(g.t_s),
            recorded.state_at(g.t_s),
            "at {}",
            g.t_s
        );
    }
}

/// With each wheel row used over the interval it describes
/// (`WheelRows::Interval`), an epoch is handed out one wheel row late; the
/// checkpointed smoother's forward pass keeps no predictions, so a
/// checkpoint taken while an epoch was held would have re-run it without
/// one. Equal, bit for bit, to smoothing the recorded run.
#[test]
fn checkpointed_smoothing_with_interval_wheel_rows_equals_the_recorded_run() {
    let d = drive(29, 240.0);
    let params = Params::nominal(&d.vehicle);
    let opts = FilterOptions {
        wheel_rows: ekf::WheelRows::Interval,
        ..FilterOptions::default()
    };
    let full = ekf::run(&d, &params, &opts, &mut ()).unwrap();
    let want = deadreckon_core::rts::smooth_states(&full.epochs).unwrap();
    assert!(full.epochs.len() > 10_000, "several segments");
    let f = ekf::car_filter(&d, &params, &opts).unwrap();
    let (got, stats) = deadreckon_core::checkpoint::smooth_car_states(&d, f, &opts).unwrap();
    assert_eq!(got.len(), want.len());
    let bad: Vec<usize> = (0..got.len())
        .filter(|&i| {
            got[i].0 != full.epochs[i].t_s || got[i].1 != want[i].1.fixed_rows::<5>(0).into_owned()
        })
        .collect();
    assert!(
        bad.is_empty(),
        "{} of {} epochs differ, the last {:?}",
        bad.len(),
        got.len(),
        bad.last().map(|&i| (
            i,
            got[i].0,
            (got[i].1 - want[i].1.fixed_rows::<5>(0).into_owned()).norm()
        ))
    );
    assert_eq!(stats, full.stats);
    // The same epochs as the paper's scheme, at the same times.
    let instant = ekf::run(&d, &params, &FilterOptions::default(), &mut ()).unwrap();
    assert_eq!(instant.epochs.len(), full.epochs.len());
    assert!(instant
        .epochs
        .iter()
        .zip(&full.epochs)
        .all(|(a, b)| a.t_s == b.t_s));
    assert!(instant
        .epochs
        .iter()
        .zip(&full.epochs)
        .any(|(a, b)| a.x != b.x));
}
