//! `deadreckon events D | deadreckon stream --params P` against `deadreckon
//! run D --params P` when P stores corrections (issue 29, item 2): the
//! stream applies the stored delays, IMU tilt, gyro scale and driven-axle
//! slip to the events as `run` applies them to the drive.

mod common;
use common::{run, run_ok};

use std::path::Path;

use deadreckon_core::TrackPoint;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::{ScalarSpec, WheelKind};

/// A 600 s drive of family car 5 written to `dir`: wheel speeds, a gyro
/// late by 0.03 s, scaled by +0.8 % and tilted 3° / −2.5° (pitch, roll: the
/// drive has the three-axis gyro and an accelerometer), a CAN speed late by
/// 0.06 s, GNSS late by 0.1 s.
fn delayed_tilted_drive(dir: &Path) {
    let seed = 5;
    let mut sc = CarFamily::draw(seed).drive(seed, 600.0);
    sc.sensors.wheels.kind = WheelKind::Speeds;
    let g = sc.sensors.gyro.as_mut().expect("family gyro");
    g.tilt_deg = Some([3.0, -2.5]);
    g.scale_error = 0.008;
    g.latency_s = 0.03;
    let mut speed = g.clone();
    speed.tilt_deg = None;
    speed.scale_error = 0.0;
    speed.noise_std = 0.1;
    speed.rate_hz = 50.0;
    speed.offset_s = 0.0041;
    speed.latency_s = 0.06;
    sc.sensors.speed = Some(ScalarSpec { ..speed });
    sc.sensors.gnss.as_mut().expect("family gnss").latency_s = 0.1;
    let sim = deadreckon_sim::simulate(&sc, seed).unwrap();
    deadreckon_io::write_drive_whole(dir, &sim.drive, |_| Ok(())).unwrap();
}

/// `run`'s filtered track: (t, east, north, yaw, bound_95_m).
fn run_filtered(drive: &str, params: &str, timing: &str, tmp: &Path) -> Vec<[f64; 5]> {
    let out = tmp.join(format!("run-{timing}.csv"));
    run_ok(&[
        "run",
        drive,
        "--params",
        params,
        "--timing",
        timing,
        "--out",
        out.to_str().unwrap(),
    ]);
    let mut r = csv::Reader::from_path(&out).unwrap();
    let h = r.headers().unwrap().clone();
    let col = |n: &str| h.iter().position(|c| c == n).unwrap();
    let (t, tr, e, no, y, b) = (
        col("t_s"),
        col("track"),
        col("east_m"),
        col("north_m"),
        col("yaw_rad"),
        col("bound_95_m"),
    );
    r.records()
        .map(|x| x.unwrap())
        .filter(|x| &x[tr] == "filtered")
        .map(|x| [t, e, no, y, b].map(|i| x[i].parse().unwrap()))
        .collect()
}

/// The `bound_95_m` of each of `stream`'s pose lines.
fn bounds(stdout: &str) -> Vec<f64> {
    stdout
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            v["bound_95_m"].as_f64().expect("bound_95_m")
        })
        .collect()
}

/// The largest relative difference of `stream`'s bounds and `run`'s
/// `bound_95_m` column, epoch for epoch.
fn largest_bound_gap(stream: &[f64], run: &[[f64; 5]]) -> f64 {
    assert_eq!(stream.len(), run.len(), "epochs");
    stream
        .iter()
        .zip(run)
        .map(|(s, w)| (s - w[4]).abs() / w[4])
        .fold(0.0, f64::max)
}

fn poses(stdout: &str) -> Vec<TrackPoint> {
    stdout
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

/// The largest distance between `stream`'s poses and `run`'s track, with
/// the same number of epochs at the same times.
fn largest_gap_m(stream: &[TrackPoint], run: &[[f64; 5]]) -> f64 {
    assert_eq!(stream.len(), run.len(), "epochs");
    let mut worst = 0.0_f64;
    for (p, w) in stream.iter().zip(run) {
        assert!((p.t_s - w[0]).abs() < 1e-9, "{} against {}", p.t_s, w[0]);
        assert!((p.yaw_rad - w[3]).abs() < 1e-9, "yaw at {}", p.t_s);
        worst = worst.max((p.east_m - w[1]).hypot(p.north_m - w[2]));
    }
    worst
}

/// Bug (issue 29): `stream` warned that it could not apply the delays, IMU
/// tilt, gyro scale and slip a params.toml stores, and its track was 0.545 m
/// from `run`'s on an independently generated drive. It now applies them;
/// both timings agree with `run` to 1e-9 m, with every correction
/// (`--corrections all`) and with the default ones.
#[test]
fn stream_disagreed_with_run_on_stored_delays() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    delayed_tilted_drive(&dir);
    let d = dir.to_str().unwrap();
    let vehicle = dir.join("vehicle.toml");
    let events = run_ok(&["events", d]);
    for (which, p) in [
        ("all", "all.toml"),
        ("gnss", "gnss.toml"),
        ("edited", "edited.toml"),
        ("switched", "edited.toml"),
    ] {
        let params = tmp.path().join(p);
        let params = params.to_str().unwrap();
        if which == "edited" {
            // Every correction a params.toml can hold, whether or not this
            // drive determines it: a negative delay (the speed early), a
            // gyro delay beyond the others, and a driven-axle slip with
            // its mean forward force (the drive has wheel speeds and an
            // accelerometer), the rear axle's.
            let text = std::fs::read_to_string(tmp.path().join("all.toml")).unwrap();
            let mut t: toml::Table = toml::from_str(&text).unwrap();
            let d = t["delays"].as_table_mut().unwrap();
            d["gyro"]["delay_s"] = 0.21.into();
            d["speed"]["delay_s"] = (-0.07).into();
            let mut tr = toml::Table::new();
            tr.insert("slip_per_mps2".into(), (-0.006).into());
            tr.insert("mean_force_mps2".into(), 0.25.into());
            t.insert("traction".into(), tr.into());
            // Every addition to the paper's model `auto` can store
            // (issue 28, `deadreckon_core::model_options`).
            let model: toml::Table = toml::from_str(
                "rear_slip_gradient_rad_per_mps2 = 0.005\n\
                 gyro_bias_walk_rps_per_sqrt_s = 3e-6\n\
                 gnss_recovery_after_s = 10.0\n\
                 wheel_rows_over_interval = true\n\
                 [steering]\n\
                 steering_ratio = 16.2\n\
                 steering_offset_rad = 0.01\n\
                 understeer_gradient_rad_per_mps2 = 0.002\n\
                 [gnss_wander]\n\
                 std_m = 0.7\n\
                 tau_s = 60.0\n",
            )
            .unwrap();
            t.insert("model".into(), model.into());
            std::fs::write(params, toml::to_string(&t).unwrap()).unwrap();
            // A gyro bias free to differ on this drive (issue 28,
            // `[noise] gyro_bias_drive_std_rps`, a vehicle setting): it
            // must change `run`'s track, and `stream` must follow it.
            let drive = dir.to_str().unwrap();
            let before = run_filtered(drive, params, "wheel", tmp.path());
            let text = std::fs::read_to_string(&vehicle).unwrap();
            assert!(text.contains("[noise]\n"), "{text}");
            // (Without the switch, which is on by default: the bias a
            // state from the start.)
            let text = text.replace(
                "[noise]\n",
                "[noise]\ngyro_bias_drive_std_rps = 5e-5\ngyro_bias_switch_llr = 0.0\n",
            );
            std::fs::write(&vehicle, text).unwrap();
            let after = run_filtered(drive, params, "wheel", tmp.path());
            let moved = before
                .iter()
                .zip(&after)
                .map(|(a, b)| (a[1] - b[1]).hypot(a[2] - b[2]))
                .fold(0.0, f64::max);
            println!("edited: the per-drive gyro bias moved run's track by up to {moved:.3e} m");
            assert!(moved > 1e-6, "gyro_bias_drive_std_rps did not reach run");
        } else if which == "switched" {
            // The same file with the gyro-bias switch (issue 28,
            // `[noise] gyro_bias_switch_llr`): the constant bias and the
            // bias as a state side by side, switched mid-drive at a fix;
            // `stream` must switch where `run` does. A low threshold so
            // that it fires on this drive.
            let text = std::fs::read_to_string(&vehicle).unwrap();
            assert!(text.contains("gyro_bias_switch_llr = 0.0\n"), "{text}");
            let text = text.replace(
                "gyro_bias_switch_llr = 0.0\n",
                "gyro_bias_switch_llr = 0.5\n",
            );
            std::fs::write(&vehicle, text).unwrap();
            let out = tmp.path().join("switched.csv");
            let j = run_ok(&[
                "run",
                d,
                "--params",
                params,
                "--out",
                out.to_str().unwrap(),
                "--json",
            ]);
            let j: serde_json::Value = serde_json::from_str(&j).unwrap();
            let s = &j["gyro_bias_switch"];
            println!("switched: {s}");
            let fired = s["fired_at_s"].as_f64().expect("the switch fired");
            // After the first epoch: the fixes must first tell.
            let first = run_filtered(d, params, "wheel", tmp.path())[0][0];
            assert!(fired > first + 1.0, "{s}");
            assert!(s["fixes"].as_u64().is_some_and(|n| n > 10), "{s}");
        } else {
            run_ok(&["calibrate", d, "--corrections", which, "--out", params]);
        }
        let stored = std::fs::read_to_string(params).unwrap();
        let extra: toml::Table = toml::from_str(&stored).unwrap();
        let c = deadreckon_api::corrections::stored_corrections(&extra).unwrap();
        // The bound's factor the stream and run both apply: fitted, so the
        // comparison below is of r(k²P + σ²I), not of k = 1.
        let fit = deadreckon_api::bound::bound_from_extra(&extra).unwrap();
        assert_eq!(
            fit.method,
            deadreckon_core::bound::Method::Conformal,
            "{which}"
        );
        println!("{which}: bound factor {:.3}", fit.k);
        // What the file stores (the calibration's estimates of the true
        // 0.03 s, 0.06 s, 0.1 s, tilt and +0.8 %).
        println!("{which}: {c:?}");
        assert!(c.delays_s[3] > 0.05, "{which}: gnss delay {:?}", c.delays_s);
        assert!(c.up.is_some(), "{which}: no tilt");
        assert!(c.gyro_scale_error > 0.004, "{which}: gyro scale");
        if which == "all" {
            assert!(c.delays_s[0] > 0.01 && c.delays_s[1] > 0.03, "{c:?}");
        }
        if which == "edited" {
            assert_eq!(c.traction_slip_per_mps2, -0.006);
            assert_eq!(c.delays_s[1], -0.07);
            assert_eq!(c.model.rear_slip_gradient_rad_per_mps2, Some(0.005));
            assert_eq!(c.model.gyro_bias_walk_rps_per_sqrt_s, Some(3e-6));
            assert_eq!(c.model.steering.map(|s| s.steering_ratio), Some(16.2));
            // The receiver's wander with the walking bias: run and stream
            // both carry both (issues 28, 36).
            assert_eq!(c.model.gnss_wander.map(|w| w.std_m), Some(0.7));
            // Each wheel row over its interval (issue 28): both run it.
            assert_eq!(c.model.wheel_rows_over_interval, Some(true));
        }
        if c.traction_slip_per_mps2 != 0.0 {
            assert!(c.traction_mean_force_mps2.is_some(), "{stored}");
        }
        for timing in ["wheel", "each"] {
            let want = run_filtered(d, params, timing, tmp.path());
            let r = run(
                &[
                    "stream",
                    "--vehicle",
                    vehicle.to_str().unwrap(),
                    "--params",
                    params,
                    "--timing",
                    timing,
                ],
                Some(events.as_bytes()),
            );
            assert!(r.ok, "{}", r.stderr);
            assert!(!r.stderr.contains("warning"), "{}", r.stderr);
            assert!(
                r.stderr.contains("applying the corrections"),
                "{}",
                r.stderr
            );
            if which == "edited" {
                // Held back by the slip's accelerometer window, 0.5 s (above the
                // largest delay, 0.21 s).
                assert!(r.stderr.contains("held back 0.500 s"), "{}", r.stderr);
            }
            // run's CSV has 9 decimals: 7.1e-10 m is its rounding.
            let gap = largest_gap_m(&poses(&r.stdout), &want);
            println!("{which}, --timing {timing}: largest gap {gap:e} m");
            assert!(gap < 1e-9, "{which} {timing}: {gap} m");
            // The same 95 % bound on the same epochs (issue 31), from the
            // factor the file stores: run's CSV has 7 significant digits.
            let b = largest_bound_gap(&bounds(&r.stdout), &want);
            println!("{which}, --timing {timing}: largest bound difference {b:e} (relative)");
            assert!(b < 1e-6, "{which} {timing}: bound {b}");
        }
    }
}

/// With the corrections' reorder buffer, a stream cut between two input
/// timestamps and resumed from `--state` gives the uncut stream's poses:
/// the events held back are kept in the state, not released at the cut.
#[test]
fn a_stream_with_stored_delays_resumes_from_its_state_bit_for_bit() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    delayed_tilted_drive(&dir);
    let d = dir.to_str().unwrap();
    let vehicle = dir.join("vehicle.toml");
    let params = tmp.path().join("p.toml");
    let params = params.to_str().unwrap();
    run_ok(&["calibrate", d, "--corrections", "all", "--out", params]);
    let events = run_ok(&["events", d]);
    let args = [
        "stream",
        "--vehicle",
        vehicle.to_str().unwrap(),
        "--params",
        params,
    ];
    let whole = run(&args, Some(events.as_bytes()));
    assert!(whole.ok, "{}", whole.stderr);
    let lines: Vec<&str> = events.lines().collect();
    let t = |l: &str| {
        serde_json::from_str::<serde_json::Value>(l).unwrap()["t_s"]
            .as_f64()
            .unwrap()
    };
    let mut cut = lines.len() / 2;
    while t(lines[cut]) == t(lines[cut - 1]) {
        cut += 1;
    }
    let state = tmp.path().join("state.json");
    let mut with_state = args.to_vec();
    with_state.extend(["--state", state.to_str().unwrap()]);
    let first = run(
        &with_state,
        Some((lines[..cut].join("\n") + "\n").as_bytes()),
    );
    assert!(first.ok, "{}", first.stderr);
    assert!(
        first.stderr.contains("kept in the state"),
        "{}",
        first.stderr
    );
    // The last part releases what is held back at its end.
    let mut last = with_state.clone();
    last.push("--last-part");
    let second = run(&last, Some((lines[cut..].join("\n") + "\n").as_bytes()));
    assert!(second.ok, "{}", second.stderr);
    assert!(
        !second.stderr.contains("kept in the state"),
        "{}",
        second.stderr
    );
    assert_eq!(first.stdout.clone() + &second.stdout, whole.stdout);
}

/// A params.toml written before `traction.mean_force_mps2` stores a slip
/// that a stream cannot apply as `run` does (at each drive's own mean
/// forward force): `stream` says so instead of applying it silently
/// otherwise.
#[test]
fn stream_says_it_cannot_apply_a_slip_stored_without_its_mean_force() {
    let tmp = tempfile::tempdir().unwrap();
    let d = common::simulated(tmp.path(), "d", "120");
    let p = tmp.path().join("p.toml");
    run_ok(&[
        "calibrate",
        &d,
        "--corrections",
        "none",
        "--out",
        p.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&p).unwrap() + "\n[traction]\nslip_per_mps2 = 0.003\n";
    std::fs::write(&p, text).unwrap();
    let events = run_ok(&["events", &d]);
    let r = run(
        &[
            "stream",
            "--vehicle",
            &format!("{d}/vehicle.toml"),
            "--params",
            p.to_str().unwrap(),
        ],
        Some(events.as_bytes()),
    );
    assert!(r.ok, "{}", r.stderr);
    let warning = r
        .stderr
        .lines()
        .find(|l| l.starts_with("warning"))
        .unwrap_or_else(|| panic!("no warning:\n{}", r.stderr));
    assert!(warning.contains("mean_force_mps2"), "{warning}");
}

/// The library under the commands, without the CSV's rounding: the online
/// filter with stored corrections (every kind, the slip included) fed a
/// drive's input events equals the batch filter on the corrected drive bit
/// for bit, and the slip changes the track (so the comparison would see it
/// applied wrongly or not at all).
#[test]
fn online_corrections_equal_the_batch_filter_on_the_corrected_drive_bit_for_bit() {
    use deadreckon_core::aided::Aided;
    use deadreckon_core::ekf::{FilterOptions, Timing};
    use deadreckon_core::live_corrections::input_events;
    use deadreckon_core::online::{Online, Start};
    use deadreckon_core::timing::KnownCorrections;

    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    delayed_tilted_drive(&dir);
    let drive = deadreckon_io::read_drive(&dir).unwrap();
    let params = deadreckon_core::Params::nominal(&drive.vehicle);
    let known = KnownCorrections {
        delays_s: [0.03, 0.06, 0.0, 0.1],
        up: Some(deadreckon_core::imu::estimate_tilt(&drive).unwrap().up),
        gyro_scale_error: 0.008,
        traction_slip_per_mps2: 0.004,
        traction_mean_force_mps2: Some(0.3),
        ..Default::default()
    };
    let events = input_events(&drive);
    let mut finals = Vec::new();
    for known in [
        known,
        KnownCorrections {
            traction_slip_per_mps2: 0.0,
            ..known
        },
    ] {
        for timing in [Timing::WheelEpochs, Timing::EachMeasurement] {
            let opts = FilterOptions {
                timing,
                ..Default::default()
            };
            // The batch run of the aided filter the vehicle calls for (the
            // default gyro-bias switch included: deadreckon_core::aided).
            let mut batch = Vec::new();
            Aided::run(&known.apply(&drive), &params, &opts, &mut |e| {
                batch.push(*e)
            })
            .unwrap();
            let mut online = Online::new(&drive.vehicle, &params, &opts, Start::Gnss)
                .unwrap()
                .with_corrections(&known)
                .unwrap();
            let mut pts = Vec::new();
            for ev in &events {
                online.push(*ev, &mut |p| pts.push(p)).unwrap();
            }
            online.end(&mut |p| pts.push(p)).unwrap();
            assert_eq!(pts.len(), batch.len(), "{timing:?}");
            for (p, e) in pts.iter().zip(&batch) {
                assert_eq!(p.t_s, e.t_s);
                assert_eq!(
                    (p.east_m, p.north_m),
                    (e.x[0], e.x[1]),
                    "{timing:?} at {}",
                    e.t_s
                );
            }
            let last = pts.last().unwrap();
            finals.push((last.east_m, last.north_m));
        }
    }
    // With and without the slip (wheel timing): the GNSS-aided tracks end
    // 0.0081 m apart (measured on this drive).
    let moved = (finals[0].0 - finals[2].0).hypot(finals[0].1 - finals[2].1);
    println!("the slip moves the final point {moved:.3} m");
    assert!(moved > 0.004, "{moved} m");
}

/// Parameters learned on corrected events belong to the corrected streams:
/// `--params-out` writes the corrections beside them, read back as they
/// were given, so that the next stream started from the file applies them.
#[test]
fn learned_parameters_keep_the_corrections_they_were_learned_under() {
    use deadreckon_core::timing::KnownCorrections;
    let tmp = tempfile::tempdir().unwrap();
    let known = KnownCorrections {
        delays_s: [0.021, -0.013, 0.0, 0.0775],
        up: Some([
            0.052,
            -0.0435,
            (1.0f64 - 0.052 * 0.052 - 0.0435 * 0.0435).sqrt(),
        ]),
        gyro_scale_error: 0.0079,
        traction_slip_per_mps2: -0.004,
        traction_mean_force_mps2: Some(0.31),
        model: deadreckon_core::model_options::ModelOptions {
            gyro_bias_walk_rps_per_sqrt_s: Some(3e-6),
            ..Default::default()
        },
    };
    let p = deadreckon_core::Params {
        gyro_bias_rps: 0.0014,
        speed_scale: 1.008,
        circumference_fl_m: 1.934,
        circumference_fr_m: 1.933,
        circumference_rl_m: 1.934,
        circumference_rr_m: 1.929,
    };
    let learned = deadreckon_core::online::Learned {
        params: p,
        std: deadreckon_api::stream::default_prior(),
        valid: false,
        calibrated_pct: 40.0,
    };
    let path = tmp.path().join("learned.toml");
    deadreckon_api::stream::save_learned(&path, &learned, &known).unwrap();
    let back = deadreckon_api::corrections::stored_in_file(&path).unwrap();
    assert_eq!(back, known);
    let read = deadreckon_io::read_params(&path).unwrap();
    assert_eq!(read.params, p);
}
