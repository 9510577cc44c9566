//! The four-wheel filter online: the step API against the batch run, state
//! round trips, and `deadreckon events | deadreckon stream` against
//! `deadreckon run` (issue: "the four-wheel estimator online").

mod common;

use std::io::Write;
use std::process::Stdio;

use deadreckon_core::aided::Aided;
use deadreckon_core::drive::Wheels;
use deadreckon_core::ekf::{self, DriveEvents, FilterOptions, Timing};
use deadreckon_core::online::{Online, Start};
use deadreckon_core::{Drive, Params, TrackPoint};
use deadreckon_sim::{simulate, Scenario};

fn drive(seed: u64, duration_s: f64) -> Drive {
    common::sim_drive("evaluation", seed, Some(duration_s))
}

fn online_track(d: &Drive, params: &Params, timing: Timing) -> Vec<TrackPoint> {
    let opts = FilterOptions {
        timing,
        ..Default::default()
    };
    let mut o = Online::new(&d.vehicle, params, &opts, Start::Gnss).unwrap();
    let mut pts = Vec::new();
    for ev in DriveEvents::all(d) {
        o.push(ev, &mut |p| pts.push(p)).unwrap();
    }
    o.finish(&mut |p| pts.push(p)).unwrap();
    pts
}

#[test]
fn online_filter_equals_the_batch_run_in_both_timings() {
    let d = drive(21, 90.0);
    let params = Params::nominal(&d.vehicle);
    for timing in [Timing::WheelEpochs, Timing::EachMeasurement] {
        // The batch run of the aided filter the vehicle calls for (with the
        // default gyro-bias switch: deadreckon_core::aided).
        let opts = FilterOptions {
            timing,
            ..Default::default()
        };
        let mut batch = Vec::new();
        let a = Aided::run(&d, &params, &opts, &mut |e| batch.push(*e)).unwrap();
        let online = online_track(&d, &params, timing);
        assert_eq!(online.len(), batch.len(), "{timing:?}");
        for (p, e) in online.iter().zip(&batch) {
            assert_eq!(p.t_s, e.t_s);
            assert_eq!(p.east_m, e.x[0], "{timing:?} at {}", e.t_s);
            assert_eq!(p.north_m, e.x[1]);
            assert_eq!(p.speed_mps, e.x[3]);
        }
        println!("{timing:?}: {:?}", a.bias_switch());
    }
}

/// Bug (issue 28): with each wheel row over its interval (the vehicle's
/// `wheel_rows_over_interval`, a model option of `--corrections auto`),
/// `stream` ran the epoch of the last row after every input as if the
/// stream had ended, and the next row handed it out again: twice the
/// epochs of `run` (78,961 against 39,779 in `stream_corrections.rs`). The
/// interval stays open until the next row or the stream's end.
#[test]
fn stream_handed_out_each_interval_epoch_twice() {
    let mut d = drive(21, 90.0);
    let params = Params::nominal(&d.vehicle);
    let opts = FilterOptions::default();
    let mut instant = Vec::new();
    Aided::run(&d, &params, &opts, &mut |e| instant.push(*e)).unwrap();
    d.vehicle.noise.wheel_rows_over_interval = true;
    let mut batch = Vec::new();
    Aided::run(&d, &params, &opts, &mut |e| batch.push(*e)).unwrap();
    // The option reached the filter: its epochs differ from the paper's.
    let moved = instant
        .iter()
        .zip(&batch)
        .any(|(a, b)| a.t_s == b.t_s && a.x[0] != b.x[0]);
    assert!(moved);
    let mut o = Online::new(&d.vehicle, &params, &opts, Start::Gnss).unwrap();
    let mut online = Vec::new();
    for ev in DriveEvents::all(&d) {
        o.push(ev, &mut |p| online.push(p)).unwrap();
    }
    o.end(&mut |p| online.push(p)).unwrap();
    assert_eq!(online.len(), batch.len());
    for (p, e) in online.iter().zip(&batch) {
        assert_eq!(p.t_s, e.t_s);
        assert_eq!((p.east_m, p.north_m), (e.x[0], e.x[1]), "at {}", e.t_s);
    }
}

#[test]
fn a_stopped_and_resumed_stream_equals_an_uninterrupted_one_bit_for_bit() {
    let d = drive(22, 60.0);
    let params = Params::nominal(&d.vehicle);
    let events: Vec<_> = DriveEvents::all(&d).collect();
    // Split between two timestamps, after the filter has started.
    let mut cut = events.len() / 2;
    while events[cut].t_s == events[cut - 1].t_s {
        cut += 1;
    }
    let opts = FilterOptions::default();
    let mut whole = Vec::new();
    let mut o = Online::new(&d.vehicle, &params, &opts, Start::Gnss).unwrap();
    for ev in &events {
        o.push(*ev, &mut |p| whole.push(p)).unwrap();
    }
    o.finish(&mut |p| whole.push(p)).unwrap();

    let mut parts = Vec::new();
    let mut a = Online::new(&d.vehicle, &params, &opts, Start::Gnss).unwrap();
    for ev in &events[..cut] {
        a.push(*ev, &mut |p| parts.push(p)).unwrap();
    }
    a.finish(&mut |p| parts.push(p)).unwrap();
    assert!(a.is_started());
    let json = serde_json::to_string(&a).unwrap();
    let mut b: Online = serde_json::from_str(&json).unwrap();
    assert_eq!(b, a, "the state loads back bit-identical");
    assert_eq!(serde_json::to_string(&b).unwrap(), json);
    for ev in &events[cut..] {
        b.push(*ev, &mut |p| parts.push(p)).unwrap();
    }
    b.finish(&mut |p| parts.push(p)).unwrap();
    assert_eq!(parts, whole);
}

/// Bug: the wheel-speed branch of the filter ignored `wheels_present`, so an
/// absent wheel's column (a tricycle writes its one encoder as FL) was fused.
#[test]
fn regression_wheel_speeds_of_absent_wheels_were_fused() {
    let mut sc = Scenario::builtin("evaluation")
        .unwrap()
        .with_duration_s(60.0);
    sc.sensors.wheels.kind = deadreckon_sim::WheelKind::Speeds;
    let mut d = simulate(&sc, 23).unwrap().drive;
    d.vehicle.wheels_present = [false, false, true, true];
    let params = Params::nominal(&d.vehicle);
    let opts = FilterOptions::default();
    let clean = ekf::run(&d, &params, &opts, &mut ()).unwrap();
    let Wheels::Speeds(rows) = &mut d.wheels else {
        panic!("wheel speeds expected")
    };
    for r in rows.iter_mut() {
        r.fl_mps = 55.0;
        r.fr_mps = -3.0;
    }
    let garbage = ekf::run(&d, &params, &opts, &mut ()).unwrap();
    assert_eq!(clean.epochs.len(), garbage.epochs.len());
    for (a, b) in clean.epochs.iter().zip(&garbage.epochs) {
        assert_eq!(
            a.x, b.x,
            "the absent front wheels changed the state at {}",
            a.t_s
        );
    }
    assert_eq!(garbage.stats.gates.accepted(ekf::SensorKind::Wheel(0)), 0);
    assert!(garbage.stats.gates.accepted(ekf::SensorKind::Wheel(2)) > 1000);
}

#[test]
fn a_slipping_wheel_is_gated_and_counted() {
    let mut d = drive(24, 60.0);
    let params = Params::nominal(&d.vehicle);
    let Wheels::Ticks(rows) = &mut d.wheels else {
        panic!("wheel ticks expected")
    };
    // The rear-left wheel spins: 40 extra ticks per row for 20 rows.
    let n = rows.len();
    for r in rows[n / 2..n / 2 + 20].iter_mut() {
        r.rl += 40;
    }
    // The χ² gate alone: without the wheel-health monitor, which would take
    // the wheel out of the fusion after its first rows (checked below).
    let gate_only = FilterOptions {
        wheel_monitor: None,
        ..Default::default()
    };
    let out = ekf::run(&d, &params, &gate_only, &mut ()).unwrap();
    let rl = out.stats.gates.rejected(ekf::SensorKind::Wheel(2));
    assert!((18..=20).contains(&rl), "{rl} rejected");
    assert_eq!(out.stats.gates.rejected(ekf::SensorKind::Wheel(0)), 0);
    // With the monitor (the default) the spin is one slip stretch of the
    // rear-left wheel, and no other wheel is touched.
    let out = ekf::run(&d, &params, &FilterOptions::default(), &mut ()).unwrap();
    let h = out.wheel_health.unwrap();
    let t0 = rows_t(&d, n / 2);
    let rl = &h.wheels[2].intervals;
    assert_eq!(rl.len(), 1, "{rl:?}");
    assert_eq!(
        rl[0].reason,
        deadreckon_core::wheel_health::DropReason::Slip
    );
    assert!(
        rl[0].start_s >= t0 && rl[0].start_s < t0 + 0.1,
        "{rl:?} from {t0}"
    );
    for w in [0, 1, 3] {
        assert!(h.wheels[w].intervals.is_empty(), "wheel {w}");
    }
}

fn rows_t(d: &deadreckon_core::Drive, k: usize) -> f64 {
    d.wheels.t_s(k)
}

use common::bin;

fn csv_filtered(path: &std::path::Path) -> Vec<(f64, f64, f64, f64)> {
    let mut r = csv::Reader::from_path(path).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let (t, tr, e, no, y) = (
        col("t_s"),
        col("track"),
        col("east_m"),
        col("north_m"),
        col("yaw_rad"),
    );
    r.records()
        .map(|x| x.unwrap())
        .filter(|x| &x[tr] == "filtered")
        .map(|x| {
            (
                x[t].parse().unwrap(),
                x[e].parse().unwrap(),
                x[no].parse().unwrap(),
                x[y].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn events_piped_into_stream_reproduce_the_filtered_track_of_run() {
    stream_reproduces_run(None);
}

/// With a walking gyro bias (`[noise] gyro_bias_walk_rps_per_sqrt_s`,
/// `deadreckon_core::gyro_drift`) `run` and `stream` both carry the bias as
/// a state, and agree; the track is not the constant bias's.
#[test]
fn stream_equals_run_with_a_walking_gyro_bias() {
    let (constant, truth) = stream_reproduces_run(None);
    let (walking, _) = stream_reproduces_run(Some(2e-5));
    assert_eq!(constant.len(), walking.len());
    // `run` without --params takes the nominal gyro bias, 0, against the
    // drive's −0.00298 rad/s: the walking bias learns it from the fixes and
    // the filtered track comes closer to the truth. Measured: RMS 1.380 m
    // (constant) and 1.084 m (walking).
    let (c, w) = (
        rms_against(&constant, &truth),
        rms_against(&walking, &truth),
    );
    println!("filtered track RMS against the truth: constant {c:.3} m, walking {w:.3} m");
    assert!(w < 0.85 * c, "walking {w} m against constant {c} m");
}

/// RMS horizontal distance of `track` to the truth (interpolated linearly).
fn rms_against(track: &[(f64, f64, f64, f64)], truth: &[(f64, f64, f64)]) -> f64 {
    let mut k = 0;
    let mut sum = 0.0;
    for p in track {
        while k + 2 < truth.len() && truth[k + 1].0 <= p.0 {
            k += 1;
        }
        let (a, b) = (truth[k], truth[k + 1]);
        assert!(a.0 <= p.0 && p.0 <= b.0, "no truth around {}", p.0);
        let u = (p.0 - a.0) / (b.0 - a.0);
        let (e, n) = (a.1 + u * (b.1 - a.1), a.2 + u * (b.2 - a.2));
        sum += (p.1 - e).powi(2) + (p.2 - n).powi(2);
    }
    (sum / track.len() as f64).sqrt()
}

/// Simulates a 90 s drive, runs `run` and `events | stream` on it (with
/// `walk` as the vehicle's gyro bias walk when given), checks that they
/// agree to 1e-9 and returns run's filtered track and the truth.
#[allow(clippy::type_complexity)]
fn stream_reproduces_run(walk: Option<f64>) -> (Vec<(f64, f64, f64, f64)>, Vec<(f64, f64, f64)>) {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let st = bin()
        .args([
            "simulate",
            "--scenario",
            "evaluation",
            "--seed",
            "25",
            "--duration",
            "90",
        ])
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    if let Some(w) = walk {
        let path = dir.join("vehicle.toml");
        let text = std::fs::read_to_string(&path).unwrap();
        let key = format!("gyro_bias_walk_rps_per_sqrt_s = {w}");
        let text = if text.contains("[noise]") {
            text.replacen("[noise]", &format!("[noise]\n{key}"), 1)
        } else {
            format!("{text}\n[noise]\n{key}\n")
        };
        std::fs::write(&path, text).unwrap();
    }
    let track = tmp.path().join("t.csv");
    let st = bin()
        .arg("run")
        .arg(&dir)
        // The nominal parameters, as `stream` without --params (`run`
        // without them calibrates on the drive, issue 29).
        .args(["--params", "nominal"])
        .arg("--out")
        .arg(&track)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let events = bin().arg("events").arg(&dir).output().unwrap();
    assert!(events.status.success());
    let mut child = bin()
        .arg("stream")
        .arg("--vehicle")
        .arg(dir.join("vehicle.toml"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Feed standard input from a thread: the child writes while it reads.
    let mut stdin = child.stdin.take().unwrap();
    let input = events.stdout.clone();
    let feeder = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    feeder.join().unwrap().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines: Vec<TrackPoint> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let want = csv_filtered(&track);
    assert_eq!(lines.len(), want.len());
    for (p, w) in lines.iter().zip(&want) {
        assert!((p.t_s - w.0).abs() < 1e-9);
        assert!((p.east_m - w.1).abs() < 1e-9, "{} vs {}", p.east_m, w.1);
        assert!((p.north_m - w.2).abs() < 1e-9);
        assert!((p.yaw_rad - w.3).abs() < 1e-9);
    }
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("epochs"), "{err}");
    let truth = csv::Reader::from_path(dir.join("truth.csv"))
        .unwrap()
        .records()
        .map(|r| {
            let r = r.unwrap();
            (
                r[0].parse().unwrap(),
                r[1].parse().unwrap(),
                r[2].parse().unwrap(),
            )
        })
        .collect();
    (want, truth)
}

#[test]
fn stream_names_the_bad_line_and_skips_it_when_asked() {
    let tmp = tempfile::tempdir().unwrap();
    let vehicle = tmp.path().join("vehicle.toml");
    deadreckon_io::write_vehicle(&vehicle, &deadreckon_core::Vehicle::paper_car()).unwrap();
    let input = "{\"t_s\": 0.0, \"sensor\": \"yaw_rate\", \"yaw_rate_rps\": 0.0}\n{\"t_s\": 0.1, \"sensor\": \"yaw_rate\", \"yaw_rate_rps\": \"x\"}\n";
    let run = |mode: &str| {
        let mut c = bin()
            .arg("stream")
            .arg("--vehicle")
            .arg(&vehicle)
            .args(["--on-bad-line", mode])
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        c.stdin.take().unwrap().write_all(input.as_bytes()).unwrap();
        c.wait_with_output().unwrap()
    };
    let refused = run("refuse");
    assert!(!refused.status.success());
    let err = String::from_utf8_lossy(&refused.stderr);
    assert!(err.contains("stdin: line 2, column"), "{err}");
    let skipped = run("skip");
    let err = String::from_utf8_lossy(&skipped.stderr);
    assert!(err.contains("skipped: stdin: line 2"), "{err}");
    // No GNSS ever arrived: the filter never started, which is an error, not a panic.
    assert!(err.contains("needs at least one fix"), "{err}");
}

#[test]
fn events_into_a_closed_pipe_exits_quietly() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let st = bin()
        .args([
            "simulate",
            "--scenario",
            "evaluation",
            "--seed",
            "26",
            "--duration",
            "30",
        ])
        .arg("--out")
        .arg(&dir)
        .output()
        .unwrap();
    assert!(st.status.success());
    let mut c = bin()
        .arg("events")
        .arg(&dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    drop(c.stdout.take());
    let out = c.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A filter given its start state is started before any event, and its
/// first pose is that state carried to the first wheel epoch: the test
/// asserted only `is_started()` (issue 33).
#[test]
fn init_given_starts_at_once() {
    let d = drive(27, 30.0);
    let params = Params::nominal(&d.vehicle);
    let x0 = ekf::truth_state(&d, 1.0).unwrap();
    let p0 = deadreckon_core::model::Mat::identity() * 0.01;
    let mut o = Online::new(
        &d.vehicle,
        &params,
        &FilterOptions::default(),
        Start::Given(1.0, x0, p0),
    )
    .unwrap();
    assert!(o.is_started());
    let mut poses: Vec<TrackPoint> = Vec::new();
    for ev in DriveEvents::all(&d) {
        o.push(ev, &mut |p| poses.push(p)).unwrap();
    }
    o.finish(&mut |p| poses.push(p)).unwrap();
    // No pose before the given start, and the first one is the truth it
    // started from, carried to the second wheel row after it (the first
    // opens the wheel interval): at most two 20 ms intervals at under
    // 20 m/s, 0.8 m. Measured: 1.0237 s.
    let first = poses.first().expect("poses");
    assert!(first.t_s > 1.0 && first.t_s <= 1.0 + 0.041, "{}", first.t_s);
    let moved = (first.east_m - x0[0]).hypot(first.north_m - x0[1]);
    assert!(moved < 0.8, "{moved}");
    assert!(
        (first.yaw_rad - x0[2]).abs() < 0.01,
        "{} vs {}",
        first.yaw_rad,
        x0[2]
    );
    // Its covariance grew from the given one by one step, not from an
    // initialisation's metres.
    assert!(
        first.cov_pose[0] > 0.01 && first.cov_pose[0] < 0.02,
        "{:?}",
        first.cov_pose
    );
    // And it runs to the end of the drive.
    assert!(poses.last().unwrap().t_s > 29.0);
}

#[test]
fn checkpointed_smoothing_equals_smoothing_a_recorded_run_exactly() {
    let d = drive(28, 240.0);
    let params = Params::nominal(&d.vehicle);
    let prior = deadreckon_core::calibrate::CalibrationOptions::default().prior_std;
    let opts = FilterOptions::default();
    let full = ekf::run_augmented(&d, &params, &prior, &opts).unwrap();
    let want = deadreckon_core::rts::smooth_states(&full.epochs).unwrap();
    let f = ekf::augmented_filter(&d, &params, &prior, &opts).unwrap();
    let (got, stats) = deadreckon_core::checkpoint::smooth_car_states(&d, f, &opts).unwrap();
    assert_eq!(got.len(), want.len());
    assert!(got.len() > 10_000, "{} epochs: several segments", got.len());
    for (g, w) in got.iter().zip(&want) {
        assert_eq!(g.0, w.0);
        assert_eq!(g.1, w.1.fixed_rows::<5>(0).into_owned(), "at {}", g.0);
    }
    assert_eq!(stats, full.stats);
}

fn stream_with(args: &[&str], input: &[u8]) -> std::process::Output {
    let mut child = bin()
        .arg("stream")
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let input = input.to_vec();
    let feeder = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    feeder.join().unwrap().unwrap();
    out
}

#[test]
fn stream_learns_the_parameters_and_the_next_drive_starts_from_them() {
    let tmp = tempfile::tempdir().unwrap();
    let sc = Scenario::builtin("calibration").unwrap().with_laps(2);
    let mut learned = Vec::new();
    let mut prev: Option<std::path::PathBuf> = None;
    for (k, seed) in [31u64, 32].into_iter().enumerate() {
        let sim = simulate(&sc, seed).unwrap();
        let vehicle = tmp.path().join("vehicle.toml");
        deadreckon_io::write_vehicle(&vehicle, &sim.drive.vehicle).unwrap();
        let mut input = String::new();
        for ev in DriveEvents::all(&sim.drive) {
            input.push_str(&deadreckon_io::events::to_line(&ev));
            input.push('\n');
        }
        let out_path = tmp.path().join(format!("learned{k}.toml"));
        let params_arg = prev
            .as_ref()
            .map(|p| p.to_str().unwrap().to_string())
            .unwrap_or_else(|| "nominal".into());
        let out = stream_with(
            &[
                "--vehicle",
                vehicle.to_str().unwrap(),
                "--params",
                &params_arg,
                "--learn",
                "--params-out",
                out_path.to_str().unwrap(),
            ],
            input.as_bytes(),
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{err}");
        assert!(err.contains("100% calibrated, valid"), "{err}");
        let (p, extra) = deadreckon_io::read_params_with_extra(&out_path).unwrap();
        assert_eq!(extra["valid"].as_bool(), Some(true));
        let truth = sim.truth_params.to_array();
        let est = p.params.to_array();
        let bounds = [0.05, 0.003, 0.001, 0.001, 0.001, 0.001];
        for i in 0..6 {
            let rel = ((est[i] - truth[i]) / truth[i]).abs();
            assert!(
                rel < bounds[i],
                "drive {k}: {} off by {rel}",
                Params::NAMES[i]
            );
        }
        learned.push(p);
        prev = Some(out_path);
    }
    // The second drive started from the first's estimates and their std: it
    // ends at least as sure of every circumference.
    let (a, b) = (learned[0].std.to_array(), learned[1].std.to_array());
    for i in 2..6 {
        assert!(b[i] <= a[i], "{}: {} then {}", Params::NAMES[i], a[i], b[i]);
    }
}

#[test]
fn the_rts_calibration_does_not_read_truth_csv() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    let sim = simulate(
        &Scenario::builtin("evaluation")
            .unwrap()
            .with_duration_s(60.0),
        29,
    )
    .unwrap();
    deadreckon_io::write_drive(&dir, &sim.drive).unwrap();
    let opts = deadreckon_io::ReadOptions::default().without_truth();
    let d = deadreckon_io::read_drive_with(&dir, &opts).unwrap();
    assert!(d.truth.is_empty());
    assert_eq!(d.gnss, deadreckon_io::read_drive(&dir).unwrap().gnss);
    // A truth.csv that does not parse stops only the commands that read it.
    std::fs::write(dir.join("truth.csv"), "not,a,truth\n1,2\n").unwrap();
    let rts = bin()
        .arg("calibrate")
        .arg(&dir)
        .args(["--method", "rts", "--json"])
        .output()
        .unwrap();
    assert!(
        rts.status.success(),
        "{}",
        String::from_utf8_lossy(&rts.stderr)
    );
    let truth = bin()
        .arg("calibrate")
        .arg(&dir)
        .args(["--method", "truth"])
        .output()
        .unwrap();
    assert!(!truth.status.success());
    assert!(String::from_utf8_lossy(&truth.stderr).contains("truth.csv"));
}
