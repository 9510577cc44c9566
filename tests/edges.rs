//! The edges a user hits: what the command line prints when it fails (each
//! cause once, the file the user named, not a temporary file), values refused
//! with the reason, outputs written whole.

mod common;

use std::process::Command;

use common::bin;

fn vehicle_dir() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    let st = bin()
        .args([
            "simulate",
            "--scenario",
            "evaluation",
            "--seed",
            "3",
            "--duration",
            "30",
            "--out",
        ])
        .arg(tmp.path().join("d"))
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    tmp
}

#[test]
fn a_write_into_a_missing_directory_named_the_os_error_twice_and_the_temp_file() {
    let tmp = vehicle_dir();
    let out = bin()
        .arg("run")
        .arg(tmp.path().join("d"))
        .arg("--out")
        .arg(tmp.path().join("missing/x.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(err.matches("os error 2").count(), 1, "{err}");
    assert!(!err.contains(".x.csv."), "{err}");
    assert!(
        err.contains("missing/x.csv") && err.contains("No such file"),
        "{err}"
    );
}

#[test]
fn a_missing_parameters_file_is_named_once() {
    let tmp = vehicle_dir();
    let out = bin()
        .arg("run")
        .arg(tmp.path().join("d"))
        .args(["--params", "/nonexistent/p.toml", "--out"])
        .arg(tmp.path().join("t.csv"))
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/p.toml"), "{err}");
    assert!(err.matches("os error 2").count() <= 1, "{err}");
}

#[test]
fn geojson_of_a_simulated_drive_failed_for_want_of_an_origin() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path().join("d");
    let sim = |origin: &str, out: &std::path::Path| {
        bin()
            .args([
                "simulate",
                "--scenario",
                "evaluation",
                "--duration",
                "30",
                "--origin",
                origin,
                "--out",
            ])
            .arg(out)
            .output()
            .unwrap()
    };
    // An origin off the globe is refused and nothing is written.
    let st = sim("95,11.6", &d);
    assert!(!st.status.success());
    // The key as vehicle.toml spells it (issue 34: core's errors carry the key).
    assert!(String::from_utf8_lossy(&st.stderr).contains("origin.lat_deg"));
    assert!(!d.exists());
    let st = sim("48.1,11.6", &d);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let g = tmp.path().join("t.geojson");
    let st = bin()
        .arg("run")
        .arg(&d)
        .arg("--out")
        .arg(&g)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let text = std::fs::read_to_string(&g).unwrap();
    assert!(
        text.starts_with("{\"type\":\"FeatureCollection\""),
        "{}",
        &text[..80]
    );
    assert!(text.contains("[11.6,48.1]"), "{}", &text[..200]);
}

#[test]
fn simulate_into_a_directory_of_other_files_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("notes.txt"), "mine").unwrap();
    let st = bin()
        .args([
            "simulate",
            "--scenario",
            "evaluation",
            "--duration",
            "30",
            "--out",
        ])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(!st.status.success());
    assert!(String::from_utf8_lossy(&st.stderr).contains("not replacing"));
    let names: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert_eq!(names.len(), 1);
}

#[test]
fn run_out_onto_an_input_file_overwrote_it() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let before = std::fs::read(d.join("wheel_ticks.csv")).unwrap();
    for out in [d.join("wheel_ticks.csv"), d.join("vehicle.toml")] {
        let st = bin()
            .arg("run")
            .arg(&d)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(!st.status.success());
        assert!(String::from_utf8_lossy(&st.stderr).contains("refusing to write over it"));
    }
    assert_eq!(std::fs::read(d.join("wheel_ticks.csv")).unwrap(), before);
    // A file beside the drive's own, in capitals, is fine.
    let st = bin()
        .arg("run")
        .arg(&d)
        .arg("--out")
        .arg(d.join("TRACK.CSV"))
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(d.join("TRACK.CSV").is_file());
}

#[test]
fn a_flipped_gyro_sign_calibrated_to_a_confident_wrong_answer() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let text = std::fs::read_to_string(d.join("yaw_rate.csv")).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for l in lines {
        let (t, v) = l.split_once(',').unwrap();
        out.push_str(&format!("{t},{}\n", -v.parse::<f64>().unwrap()));
    }
    std::fs::write(d.join("yaw_rate.csv"), out).unwrap();
    let st = bin().arg("calibrate").arg(&d).output().unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("other way") && err.contains("gyro_vs_wheel_yaw_rate"),
        "{err}"
    );
    assert!(err.contains("--skip-checks"), "{err}");
    let st = bin()
        .args(["--skip-checks", "calibrate"])
        .arg(&d)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
}

#[test]
fn calibrate_json_into_a_full_device_or_a_closed_pipe_panicked() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    // A full device: an error naming it, no panic.
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    let out = bin()
        .args(["calibrate", "--json"])
        .arg(&d)
        .stdout(full)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(err.contains("No space left on device"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    // A pipe closed before the command writes: it ends quietly.
    let mut child = bin()
        .args(["calibrate", "--json"])
        .arg(&d)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Issue 12: temporary files were left after SIGINT. `simulate` into a new
/// directory is interrupted while its temporary directory exists; the handler
/// removes it and the target is never created.
#[cfg(unix)]
#[test]
fn simulate_interrupted_by_sigint_left_its_temporary_directory() {
    let tmp = tempfile::tempdir().unwrap();
    let target = tmp.path().join("d");
    let mut child = bin()
        .args([
            "simulate",
            "--scenario",
            "calibration",
            "--laps",
            "8",
            "--seed",
            "2",
            "--out",
        ])
        .arg(&target)
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let temporaries = || -> Vec<String> {
        std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".d."))
            .collect()
    };
    // Wait until the write has its temporary directory, then interrupt.
    let start = std::time::Instant::now();
    loop {
        if !temporaries().is_empty() {
            break;
        }
        if let Some(status) = child.try_wait().unwrap() {
            panic!("simulate finished ({status}) before its temporary directory was seen");
        }
        assert!(
            start.elapsed().as_secs() < 300,
            "simulate never started writing"
        );
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(
        temporaries(),
        Vec::<String>::new(),
        "temporary directory left"
    );
    assert!(!target.exists(), "a partial drive was left at the target");
}

/// Issue 12, the report looked at: on the Husky (no truth) the report with a
/// TedriS model drew no dead-reckoned track (its start needed the truth) and
/// no TedriS curve through the outages (measured against the truth only),
/// though the captions named them.
#[test]
fn husky_report_drew_no_dead_reckoned_track_and_no_tedris_outage() {
    let husky = common::HUSKY_BAG;
    let tmp = tempfile::tempdir().unwrap();
    let model = tmp.path().join("model.json");
    let st = bin()
        .args(["tedris", "train", husky, "--out"])
        .arg(&model)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let html = tmp.path().join("h.html");
    let st = bin()
        // The car's report (a differential drive's has no DR (RTS) track).
        .args(["report", husky, "--shape", "car", "--model"])
        .arg(&model)
        .arg("--out")
        .arg(&html)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let html = std::fs::read_to_string(&html).unwrap();
    // Named by where its values and corrections come from (issue 34).
    assert!(
        html.contains("DR (RTS, this drive"),
        "no dead-reckoned track"
    );
    assert!(
        html.contains("final error TedriS"),
        "no TedriS outage curve"
    );
}

#[test]
fn a_drive_with_both_wheel_files_could_not_be_read_from_the_command_line() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    // Nominal parameters: the files read are what is tested. (Calibrated
    // on this short drive's speeds, the fit lands at a 6.7 m circumference,
    // which `calibrate` now rejects.)
    let track = |args: &[&str], out: &str| {
        let st = bin()
            .args(args)
            .arg("run")
            .arg(&d)
            .args(["--params", "nominal", "--out"])
            .arg(tmp.path().join(out))
            .output()
            .unwrap();
        (
            st.status.success(),
            String::from_utf8_lossy(&st.stderr).into_owned(),
        )
    };
    let (ok, err) = track(&[], "ticks_only.csv");
    assert!(ok, "{err}");
    // The same drive's wheels as speeds: ticks over the row interval, times
    // the circumference over ticks per revolution.
    let vehicle = std::fs::read_to_string(d.join("vehicle.toml")).unwrap();
    let value = |key: &str| -> f64 {
        let line = vehicle
            .lines()
            .find(|l| l.trim_start().starts_with(key))
            .unwrap();
        line.split('=').nth(1).unwrap().trim().parse().unwrap()
    };
    let metres_per_tick = value("wheel_circumference_m") / value("ticks_per_rev");
    let ticks = std::fs::read_to_string(d.join("wheel_ticks.csv")).unwrap();
    let mut speeds = String::from("t_s,fl_mps,fr_mps,rl_mps,rr_mps\n");
    let mut previous: Option<f64> = None;
    for l in ticks.lines().skip(1) {
        let f: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        let dt = previous.map_or(0.01, |p| f[0] - p);
        previous = Some(f[0]);
        let v: Vec<String> = f[1..5]
            .iter()
            .map(|n| format!("{:.6}", n * metres_per_tick / dt))
            .collect();
        speeds.push_str(&format!("{},{}\n", f[0], v.join(",")));
    }
    std::fs::write(d.join("wheel_speeds.csv"), speeds).unwrap();

    let (ok, err) = track(&[], "neither.csv");
    assert!(!ok);
    assert!(
        err.contains("both wheel_ticks.csv and wheel_speeds.csv") && err.contains("--wheels"),
        "{err}"
    );
    let (ok, err) = track(&["--wheels", "ticks"], "ticks.csv");
    assert!(ok, "{err}");
    let (ok, err) = track(&["--wheels", "speeds"], "speeds.csv");
    assert!(ok, "{err}");
    let read = |f: &str| std::fs::read_to_string(tmp.path().join(f)).unwrap();
    assert_eq!(read("ticks.csv"), read("ticks_only.csv"));
    assert_ne!(read("speeds.csv"), read("ticks_only.csv"));
}

#[test]
fn calibrate_report_tedris_and_stream_wrote_over_their_inputs() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let before: Vec<(std::path::PathBuf, Vec<u8>)> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| {
            let p = e.unwrap().path();
            let b = std::fs::read(&p).unwrap();
            (p, b)
        })
        .collect();
    let p = d.join("p.toml");
    let st = bin()
        .args(["calibrate", "--corrections", "none"])
        .arg(&d)
        .arg("--out")
        .arg(&p)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let params = std::fs::read(&p).unwrap();
    let refused = |args: Vec<std::ffi::OsString>| {
        let st = bin().args(&args).output().unwrap();
        let err = String::from_utf8_lossy(&st.stderr).into_owned();
        assert!(!st.status.success(), "{args:?} was accepted");
        assert!(err.contains("refusing to write over it"), "{args:?}: {err}");
    };
    let os = |v: &[&dyn AsRef<std::ffi::OsStr>]| -> Vec<std::ffi::OsString> {
        v.iter().map(|s| s.as_ref().to_os_string()).collect()
    };
    let vehicle = d.join("vehicle.toml");
    let gnss = d.join("gnss.csv");
    refused(os(&[&"calibrate", &d, &"--out", &vehicle]));
    refused(os(&[&"run", &d, &"--params", &p, &"--out", &p]));
    refused(os(&[&"report", &d, &"--params", &p, &"--out", &p]));
    refused(os(&[&"report", &d, &"--out", &gnss]));
    refused(os(&[&"tedris", &"train", &d, &"--out", &gnss]));
    refused(os(&[
        &"stream",
        &"--vehicle",
        &vehicle,
        &"--params",
        &p,
        &"--learn",
        &"--params-out",
        &p,
    ]));
    refused(os(&[
        &"stream",
        &"--vehicle",
        &vehicle,
        &"--state",
        &vehicle,
    ]));
    for (path, bytes) in before {
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{}", path.display());
    }
    assert_eq!(std::fs::read(&p).unwrap(), params);
}

#[test]
fn nan_infinite_zero_and_negative_option_values_were_accepted() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let d = d.to_str().unwrap();
    let out = tmp.path().join("o");
    let out = out.to_str().unwrap();
    // (arguments, the option named in the refusal, what it says)
    let cases: &[(&[&str], &str, &str)] = &[
        (&["evaluate", d, "--outage", "nan"], "--outage", "finite"),
        (
            &["evaluate", d, "--outage", "20", "--step", "0"],
            "--step",
            "above 0",
        ),
        (
            &["evaluate", d, "--segment-m", "0"],
            "--segment-m",
            "above 0",
        ),
        (
            &["evaluate", d, "--threshold-m=-1"],
            "--threshold-m",
            "above 0",
        ),
        (&["evaluate", d, "--warmup", "inf"], "--warmup", "finite"),
        (&["evaluate", d, "--from", "x"], "--from", "not a number"),
        (
            &["evaluate", d, "--metric", "rmse"],
            "--metric",
            "possible values",
        ),
        (
            &["calibrate", d, "--min-speed", "nan"],
            "--min-speed",
            "finite",
        ),
        (
            &["calibrate", d, "--min-speed=-1"],
            "--min-speed",
            "0 or above",
        ),
        (
            &["calibrate", d, "--max-iterations", "0"],
            "--max-iterations",
            "0",
        ),
        (
            &["calibrate", d, "--state", "full"],
            "--state",
            "possible values",
        ),
        (
            &["calibrate", d, "--method", "lsq"],
            "--method",
            "possible values",
        ),
        (
            &["calibrate", d, "--timing", "every"],
            "--timing",
            "possible values",
        ),
        (
            &["batch", d, "--out", out, "--alpha", "2"],
            "--alpha",
            "between 0 and 1",
        ),
        (
            &["report", d, "--out", out, "--outage=-30"],
            "--outage",
            "above 0",
        ),
        (
            &[
                "simulate",
                "--scenario",
                "evaluation",
                "--out",
                out,
                "--duration",
                "0",
            ],
            "--duration",
            "above 0",
        ),
        (
            &[
                "simulate",
                "--scenario",
                "evaluation",
                "--out",
                out,
                "--circumferences",
                "1.9,1.9,nan,1.9",
            ],
            "--circumferences",
            "finite",
        ),
        (
            &["tedris", "train", d, "--out", out, "--epsilon-k=-1"],
            "--epsilon-k",
            "above 0",
        ),
        (
            &[
                "tedris",
                "run",
                d,
                "--model",
                out,
                "--outage",
                "1:2",
                "--threshold-m",
                "inf",
            ],
            "--threshold-m",
            "finite",
        ),
        (
            &["import", "kitti", d, "--out", out],
            "<FORMAT>",
            "possible values",
        ),
    ];
    for (args, option, says) in cases {
        let st = bin().args(*args).output().unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(option) && err.contains(says),
            "{args:?}: {err}"
        );
    }
    // A value that needs a sign is still read as one.
    let st = bin()
        .args(["evaluate", d, "--metric", "ape", "--from=-5", "--json"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    // `--calibrate --method gnss` names the shape that takes it.
    let st = bin()
        .args(["calibrate", d, "--method", "gnss"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(!st.status.success() && err.contains("diff-drive"), "{err}");
    assert!(!std::path::Path::new(out).exists());
}

#[test]
fn plausibility_warnings_reached_stderr_but_not_the_json() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    // A gyro that hardly follows the wheels (another axis?): a warning, not
    // an error.
    let text = std::fs::read_to_string(d.join("yaw_rate.csv")).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    for l in lines {
        let (t, v) = l.split_once(',').unwrap();
        out.push_str(&format!("{t},{}\n", 0.05 * v.parse::<f64>().unwrap()));
    }
    std::fs::write(d.join("yaw_rate.csv"), out).unwrap();
    let json = |global: &[&str]| {
        let st = bin()
            .args(global)
            .args(["evaluate", "--metric", "ape", "--json"])
            .arg(&d)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr).into_owned();
        assert!(st.status.success(), "{err}");
        let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
        (v["checks"].clone(), err)
    };
    let (checks, err) = json(&[]);
    assert!(
        err.contains("warning:") && err.contains("gyro_vs_wheel_yaw_rate"),
        "{err}"
    );
    assert_eq!(checks["skipped"], false);
    let w = checks["warnings"].as_array().unwrap();
    assert_eq!(w.len(), 1, "{checks}");
    assert_eq!(w[0]["check"], "gyro_vs_wheel_yaw_rate");
    assert_eq!(w[0]["severity"], "warning");
    assert!(
        w[0]["message"]
            .as_str()
            .unwrap()
            // 0.049 while every simulated tone ring started at an edge.
            .contains("only 0.048 times"),
        "{checks}"
    );
    let (checks, err) = json(&["--skip-checks"]);
    assert!(!err.contains("warning:"), "{err}");
    assert_eq!(checks, serde_json::json!({"skipped": true, "warnings": []}));
}

#[test]
fn evaluate_used_nominal_for_metrics_but_rts_for_outages() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let eval = |args: &[&str]| -> (serde_json::Value, String) {
        let st = bin().arg("evaluate").arg(&d).args(args).output().unwrap();
        let err = String::from_utf8_lossy(&st.stderr).into_owned();
        assert!(st.status.success(), "{args:?}: {err}");
        let out = String::from_utf8_lossy(&st.stdout).into_owned();
        let v = serde_json::from_str(&out).unwrap_or(serde_json::Value::Null);
        (v, out)
    };
    // One rule, whatever the metric: the RTS calibration on the drive.
    let (ape, _) = eval(&["--metric", "ape", "--json"]);
    let (outage, _) = eval(&["--outage", "10", "--step", "5", "--json"]);
    // The window at pull-away (11.6 s, yaw standard deviation 13.9°) is
    // reported on its own; the heading is known from 13.6 s (at twice the
    // run's median yaw standard deviation, 8.1° on this short drive that is
    // mostly pull-away; 8.3° since the merge of `--corrections auto` and
    // issue 29's rule for "no --params", which of the two not measured;
    // 8.2° since each simulated tone ring starts at its own phase).
    assert_eq!(outage["windows"], 1, "{outage}");
    assert_eq!(outage["unsettled"].as_array().unwrap().len(), 1, "{outage}");
    // With only the pull-away window, nothing is measured, and the error says why.
    let st = bin()
        .arg("evaluate")
        .arg(&d)
        .args(["--outage", "10", "--step", "10"])
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("no 10 s outage window starts with the heading known")
            && err.contains("first falls to 8.2° at 13.6 s"),
        "{err}"
    );
    let label = ape["params"].as_str().unwrap().to_string();
    assert!(label.starts_with("rts ("), "{ape}");
    assert_eq!(outage["params"], label.as_str());
    assert!(ape["corrections"].is_object(), "{ape}");
    // Printed with the rule, after the drive's time span (the 30 s
    // simulated drive's first and last samples; the JSON carries it too).
    let span = ape["time_span_s"].as_array().unwrap();
    let (t0, t1) = (span[0].as_f64().unwrap(), span[1].as_f64().unwrap());
    assert!(
        (0.0..0.05).contains(&t0) && t1 > 29.95 && t1 <= 30.0,
        "{t0} {t1}"
    );
    let (_, text) = eval(&["--metric", "ape"]);
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        format!("drive: drive clock {t0:.3} to {t1:.3} s ({:.1} s)", t1 - t0),
        "{text}"
    );
    // The shape found, with its reason (issue 29).
    assert_eq!(
        lines.next().unwrap(),
        "shape: car (the drive has 4 wheel ticks and steering)",
        "{text}"
    );
    assert!(
        lines.next().unwrap().starts_with(&format!(
            "parameters: {label} (without --params, the parameters are calibrated on the drive itself"
        )),
        "{text}"
    );

    // Given parameters are named as given.
    let (nominal, _) = eval(&["--params", "nominal", "--metric", "ape", "--json"]);
    assert_eq!(nominal["params"], "nominal");
    assert!(
        nominal["stats_m"]["rmse"].as_f64() > ape["stats_m"]["rmse"].as_f64(),
        "{nominal} {ape}"
    );
    // Without a GNSS fix there is nothing to calibrate on: nominal, said so.
    std::fs::remove_file(d.join("gnss.csv")).unwrap();
    let (v, _) = eval(&["--metric", "ape", "--json"]);
    assert_eq!(v["params"], "nominal (no GNSS fix to calibrate on)");
    assert_eq!(v["stats_m"], nominal["stats_m"]);
}

#[test]
fn an_origin_at_95_degrees_wrote_geojson_at_85_north() {
    let tmp = vehicle_dir();
    let d = tmp.path().join("d");
    let vehicle = std::fs::read_to_string(d.join("vehicle.toml")).unwrap();
    std::fs::write(
        d.join("vehicle.toml"),
        format!("{vehicle}\n[origin]\nlat_deg = 95.0\nlon_deg = 8.0\n"),
    )
    .unwrap();
    let out = tmp.path().join("t.geojson");
    let st = bin()
        .arg("run")
        .arg(&d)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(!st.status.success());
    assert!(
        // Issue 34: the key as the file spells it (was "origin latitude").
        err.contains("vehicle.toml")
            && err.contains("origin.lat_deg must be a number within ±90, got 95"),
        "{err}"
    );
    assert!(!out.exists());
    // The same for a height that is not metres above the ellipsoid.
    std::fs::write(
        d.join("vehicle.toml"),
        format!("{vehicle}\n[origin]\nlat_deg = 45.0\nlon_deg = 8.0\nheight_m = 250000.0\n"),
    )
    .unwrap();
    let st = bin()
        .arg("run")
        .arg(&d)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        !st.status.success()
            && err.contains("origin.height_m must be metres above the WGS84 ellipsoid"),
        "{err}"
    );
}

/// A calibration whose smoothing filter lost the fixes (family car 30 with
/// white fixes: its circumferences 12 % off, "converged") is refused with the
/// reason and writes no params file; it used to be written. The filter lost
/// them by learning the circumferences while its heading was unknown, which
/// `[noise] scale_hold_yaw_std_rad` (2°) now prevents: the drive calibrates,
/// and with the hold off (`inf`) it is refused as before. With the default
/// corrections the delay estimate's own calibration is the one refused.
/// The chords' figures are the refusal's with the smoothing passes at
/// table I's yaw noise (issue 36's default, `calibrate::SMOOTHING_PROCESS_YAW_RAD`):
/// −9.81 % for both since issue 29's GNSS delay (−7.57 % for `gnss`
/// before; −8.56 % and −6.67 % at the vehicle's 5e-5 then). With
/// the hold on (the default) the drive calibrates at either yaw noise: the
/// refusal issue 36's first stop saw at 1e-5 was this second half only.
#[test]
fn a_calibration_that_lost_the_fixes_was_written_as_converged() {
    let tmp = tempfile::tempdir().unwrap();
    let mut car = deadreckon_sim::family::CarFamily::draw(30);
    car.gnss_markov = (0.0, 60.0);
    let mut sim = deadreckon_sim::simulate(&car.drive(130, 600.0), 130).unwrap();
    let dir = tmp.path().join("car30");
    deadreckon_io::write_drive(&dir, &sim.drive).unwrap();
    let params = tmp.path().join("params.toml");
    let calibrate = |corrections: &str| {
        bin()
            .arg("calibrate")
            .arg(&dir)
            .args(["--corrections", corrections, "--out"])
            .arg(&params)
            .output()
            .unwrap()
    };
    for corrections in ["none", "gnss"] {
        let out = calibrate(corrections);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{corrections}: {err}");
        std::fs::remove_file(&params).unwrap();
    }
    sim.drive.vehicle.noise.scale_hold_yaw_std_rad = f64::INFINITY;
    std::fs::remove_dir_all(&dir).unwrap();
    deadreckon_io::write_drive(&dir, &sim.drive).unwrap();
    assert!(std::fs::read_to_string(dir.join("vehicle.toml"))
        .unwrap()
        .contains("scale_hold_yaw_std_rad = inf"));
    // With `gnss` the refusal comes from the GNSS delay's first
    // calibration, on the drive before its delays (the same −9.81 % as
    // `none`), since that delay is measured with the scalar streams on
    // true time (issue 29, `timing::on_true_time`); before, the delay
    // stage passed and the final calibration was refused at −7.57 %.
    for (corrections, chords) in [("none", "-9.81%"), ("gnss", "-9.81%")] {
        let out = calibrate(corrections);
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{err}");
        assert!(
            err.contains("estimate rejected")
                && err.contains(&format!("disagrees with the GNSS chords by {chords}"))
                && err.contains("rejected by its gate"),
            "{corrections}: {err}"
        );
        assert!(!params.exists());
    }
}
