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
/// (`WheelRows::Interval`), an epoch is handed out one wheel row late (until
/// stop 50 it was held, predicted, while the next row was awaited, and the
/// checkpointed smoother's forward pass, which keeps no predictions, could
/// have re-run it without one; now it is predicted when the row arrives).
/// Equal, bit for bit, to smoothing the recorded run, with the paper's
/// scheme's epoch times.
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

/// The checkpoints of the smoother held a copy of the wheel monitor's
/// windows each (about 63 KB on the bench's hour, 11.7 MB of the default
/// `calibrate`'s 69.1 MB heap peak); they now replay the verdicts its
/// forward pass recorded. On a drive whose monitor takes wheels out and
/// back (spin bursts on the left rear wheel, the front right 3 % smaller
/// from 120 s), the re-runs take the same wheels out at the same epochs:
/// equal, bit for bit, to smoothing the recorded run.
#[test]
fn checkpoints_without_the_wheel_monitors_windows_replay_its_verdicts() {
    let faults = deadreckon_sim::WheelFaultsSpec {
        spin: Some(deadreckon_sim::SpinSpec {
            wheel: 2,
            slip: 0.3,
            duration_s: 1.0,
            mean_gap_s: 20.0,
            min_accel_mps2: 0.3,
        }),
        shrink: Some(deadreckon_sim::ShrinkSpec {
            wheel: 1,
            from_s: 120.0,
            factor: 0.97,
        }),
    };
    let sc = deadreckon_sim::Scenario::builtin("calibration")
        .unwrap()
        .with_duration_s(240.0)
        .with_wheel_faults(faults);
    let d = deadreckon_sim::simulate(&sc, 7).unwrap().drive;
    let params = Params::nominal(&d.vehicle);
    let prior = deadreckon_core::calibrate::CalibrationOptions::default().prior_std;
    let opts = FilterOptions::default();
    let full = ekf::run_augmented(&d, &params, &prior, &opts).unwrap();
    let health = full.wheel_health.clone().expect("the monitor ran");
    let out: usize = health.wheels.iter().map(|w| w.intervals.len()).sum();
    assert!(out >= 2, "wheels taken out and back: {:?}", health.lines());
    let want = deadreckon_core::rts::smooth_states(&full.epochs).unwrap();
    let f = ekf::augmented_filter(&d, &params, &prior, &opts).unwrap();
    let (got, stats) = deadreckon_core::checkpoint::smooth_car_states(&d, f, &opts).unwrap();
    assert_eq!(got.len(), want.len());
    assert!(got.len() > 10_000, "{} epochs: several segments", got.len());
    let bad = got
        .iter()
        .zip(&want)
        .filter(|(g, w)| g.0 != w.0 || g.1 != w.1.fixed_rows::<5>(0).into_owned())
        .count();
    assert_eq!(bad, 0, "{bad} of {} smoothed epochs differ", got.len());
    assert_eq!(stats, full.stats);
}

/// The smoothed track of `run` as it was made before issue 30's fourth
/// round: the aided filter of layout `L` (its feeder with the standstill,
/// `deadreckon_core::standstill`) recorded every epoch (with the gyro-bias switch, both hypotheses did: 1.6 KB per wheel
/// epoch) and the smoother went back over them.
fn recorded_smoothed<L, const N: usize>(
    d: &Drive,
    vehicle: &deadreckon_core::Vehicle,
    params: &Params,
    prior: Option<&Params>,
    wander: Option<deadreckon_core::rts::WanderStates>,
) -> Vec<deadreckon_core::TrackPoint>
where
    L: deadreckon_core::filter::Layout<N>,
{
    let opts = FilterOptions::default();
    let car = ekf::car_filter(d, params, &opts).unwrap();
    let f = deadreckon_core::filter::Filter::<L, N>::new(
        vehicle,
        params,
        prior,
        car.time_s(),
        *car.state(),
        *car.covariance(),
    )
    .unwrap()
    .with_covariance_form(opts.covariance_form);
    // Every epoch recorded, the feeder with the aided filter's standstill.
    let (feeder, events) = ekf::feed(d, &opts, car.time_s());
    let (mut feeder, mut f, mut epochs) = (feeder.with_standstill(), f, Vec::new());
    feeder.keep_predictions(true);
    let mut record = |f: &mut deadreckon_core::filter::Filter<L, N>, e: ekf::EpochOut<'_, N>| {
        epochs.push(ekf::Epoch::after(f, e.prediction.unwrap()))
    };
    for ev in events {
        feeder.push(&mut f, ev, &mut record).unwrap();
    }
    feeder.finish(&mut f, &mut record).unwrap();
    deadreckon_core::rts::smooth_carrying(&epochs, wander)
        .unwrap()
        .iter()
        .map(|s| {
            deadreckon_core::TrackPoint::from_state(
                s.t_s,
                &s.x.fixed_rows::<5>(0).into_owned(),
                &s.p.fixed_view::<5, 5>(0, 0).into_owned(),
            )
        })
        .collect()
}

/// `run` kept every epoch of the aided run, of both hypotheses with the
/// gyro-bias switch (1.6 KB per wheel epoch, `run` on the bench's hour
/// peaked at 346 MB), to smooth the one the drive ended with. It now runs
/// that hypothesis again from the start and smooths it segment by segment
/// (`Aided::smoothed_each`): the same track, bit for bit, whichever the
/// layout.
#[test]
fn run_kept_every_aided_epoch_of_both_hypotheses_for_its_smoothed_track() {
    use deadreckon_core::filter::Layout;
    use deadreckon_core::gnss_error::{CarWanderLayout, Wander, N_WANDER};
    use deadreckon_core::gyro_drift::{prior_std, CarBiasLayout, N_BIAS};
    use deadreckon_core::track::{self, names};

    let smoothed_of = |d: &Drive, params: &Params| {
        let (tracks, switch) =
            track::drive_tracks_and_switch(d, params, &FilterOptions::default(), None).unwrap();
        let t = track::find(&tracks, names::SMOOTHED)
            .unwrap()
            .points
            .clone();
        assert!(t.len() > 10_000, "several segments: {}", t.len());
        (t, switch.expect("the switch runs by default"))
    };
    let mut d = drive(7, 240.0);
    let truth = Params::nominal(&d.vehicle);

    // The calibrated bias 3e-4 rad/s off this drive's: the switch fires and
    // the drive ends with the bias as a state.
    let off = Params {
        gyro_bias_rps: truth.gyro_bias_rps - 3e-4,
        ..truth
    };
    let (got, switch) = smoothed_of(&d, &off);
    assert!(switch.fired_at_s.is_some(), "{switch:?}");
    let want = recorded_smoothed::<CarBiasLayout, N_BIAS>(
        &d,
        &d.vehicle,
        &off,
        Some(&prior_std(&d.vehicle.noise)),
        None,
    );
    assert!(got == want, "the switched track differs");

    // The receiver's wander carried, the switch out of reach: the drive
    // ends with the constant bias, smoothed with the wander's φ.
    d.vehicle.noise.gnss_wander_std_m = 0.8;
    d.vehicle.noise.gnss_wander_tau_s = 60.0;
    d.vehicle.noise.gyro_bias_switch_llr = 1e9;
    let (got, switch) = smoothed_of(&d, &truth);
    assert!(switch.fired_at_s.is_none(), "{switch:?}");
    let mut constant = d.vehicle.clone();
    constant.noise.gyro_bias_drive_std_rps = 0.0;
    constant.noise.gyro_bias_walk_rps_per_sqrt_s = 0.0;
    let want = recorded_smoothed::<CarWanderLayout, N_WANDER>(
        &d,
        &constant,
        &truth,
        None,
        Some(deadreckon_core::rts::WanderStates {
            index: <CarWanderLayout as Layout<N_WANDER>>::wander_index().unwrap(),
            wander: Wander {
                std_m: 0.8,
                tau_s: 60.0,
            },
        }),
    );
    assert!(got == want, "the wander's track differs");
}
