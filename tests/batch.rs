//! `deadreckon batch` through the binary: rows per drive with failures as
//! rows, the history table, outage evaluation columns, refused outputs,
//! closed pipes.

mod common;

use std::path::Path;
use std::process::Stdio;

use common::bin;

fn run(args: &[&str]) -> std::process::Output {
    bin().args(args).output().expect("binary runs")
}

fn simulate(dir: &Path, seed: u64, id: &str, day: u32) {
    let out = run(&[
        "simulate",
        "--scenario",
        "calibration",
        "--seed",
        &seed.to_string(),
        "--duration",
        "200",
        "--vehicle-id",
        id,
        "--recorded-at",
        &format!("2026-04-{day:02}"),
        "--out",
        &dir.to_string_lossy(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn rows(path: &Path) -> Vec<csv::StringRecord> {
    let mut r = csv::Reader::from_path(path).expect("csv");
    r.records().map(|x| x.expect("row")).collect()
}

fn column(path: &Path, name: &str) -> usize {
    let mut r = csv::Reader::from_path(path).expect("csv");
    r.headers()
        .expect("header")
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

#[test]
fn batch_writes_a_row_per_drive_and_the_history() {
    let t = tempfile::tempdir().expect("temp dir");
    let fleet = t.path().join("fleet");
    simulate(&fleet.join("a"), 1, "car-1", 2);
    simulate(&fleet.join("b"), 2, "car-1", 1);
    simulate(&fleet.join("c"), 3, "car-2", 1);
    // A drive whose wheel file has a bad number on line 3.
    let bad = fleet.join("d");
    simulate(&bad, 4, "car-2", 2);
    let ticks = bad.join("wheel_ticks.csv");
    let text = std::fs::read_to_string(&ticks).expect("ticks");
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    lines[2] = lines[2].replacen(',', ",x", 2);
    std::fs::write(&ticks, lines.join("\n")).expect("write");

    let out = t.path().join("results.csv");
    let hist = t.path().join("history.csv");
    let o = run(&[
        "batch",
        &format!("{}/*", fleet.display()),
        "--out",
        &out.to_string_lossy(),
        "--history",
        &hist.to_string_lossy(),
        "--threads",
        "2",
        "--outage",
        "30",
        "--step",
        "60",
    ]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{stderr}");
    assert!(
        stdout.contains("4 drives: 3 calibrated, 1 failed"),
        "{stdout}"
    );
    assert!(
        stdout.contains("vehicle car-1: 2 drives (ordered by recorded_at), 0 failed"),
        "{stdout}"
    );
    assert!(stdout.contains("vehicle car-2: 1 drives"), "{stdout}");
    assert!(
        stderr.contains("failed:") && stderr.contains("wheel_ticks.csv"),
        "{stderr}"
    );

    let r = rows(&out);
    assert_eq!(r.len(), 4);
    let (status, error) = (column(&out, "status"), column(&out, "error"));
    assert_eq!(&r[3][status], "error");
    assert!(
        r[3][error].contains("wheel_ticks.csv") && r[3][error].contains("line 3"),
        "{}",
        &r[3][error]
    );
    assert_eq!(&r[0][column(&out, "vehicle_id")], "car-1");
    assert_eq!(&r[0][column(&out, "status_speed_scale")], "estimated");
    let fl: f64 = r[0][column(&out, "circumference_fl_m")]
        .parse()
        .expect("number");
    assert!((fl - 1.9134).abs() < 0.002, "{fl}");
    let windows: usize = r[0][column(&out, "outage_windows")]
        .parse()
        .expect("windows");
    assert!(windows >= 2, "{windows}");
    // The same numbers as `evaluate --outage` on that drive (without the
    // timing and mounting corrections, which `batch` does not estimate by
    // default).
    let e = run(&[
        "evaluate",
        &fleet.join("a").to_string_lossy(),
        "--outage",
        "30",
        "--step",
        "60",
        "--corrections",
        "none",
        "--json",
    ]);
    assert!(e.status.success());
    let ev: serde_json::Value = serde_json::from_slice(&e.stdout).expect("json");
    for (col, key) in [
        ("outage_final_error_mean_m", "mean"),
        ("outage_final_error_max_m", "max"),
    ] {
        let batch: f64 = r[0][column(&out, col)].parse().expect("number");
        let evaluate = ev["final_error_m"][key].as_f64().expect("number");
        assert_eq!(batch, evaluate, "{col}");
    }
    assert_eq!(windows as u64, ev["windows"].as_u64().expect("windows"));
    assert_eq!(&r[0][column(&out, "outage_reference")], "truth");

    // History: 7 rows per vehicle, nothing changed.
    let h = rows(&hist);
    assert_eq!(h.len(), 14);
    assert!(h.iter().all(|x| &x[8] == "true"), "{h:?}");
}

#[test]
fn outputs_that_are_inputs_and_missing_inputs_are_refused() {
    let t = tempfile::tempdir().expect("temp dir");
    let d = t.path().join("d");
    simulate(&d, 1, "car-1", 1);
    let before = std::fs::read(d.join("vehicle.toml")).expect("read");
    for out in [d.join("vehicle.toml"), d.join("results.csv")] {
        let o = run(&[
            "batch",
            &d.to_string_lossy(),
            "--out",
            &out.to_string_lossy(),
        ]);
        assert!(!o.status.success());
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains("would overwrite"), "{e}");
    }
    assert_eq!(std::fs::read(d.join("vehicle.toml")).expect("read"), before);
    assert!(!d.join("results.csv").exists());
    let o = run(&["batch", "no/such/drive", "--out", "x.csv"]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("no/such/drive") && e.contains("no such file"),
        "{e}"
    );
    let o = run(&[
        "batch",
        &d.to_string_lossy(),
        "--out",
        &t.path().join("r.csv").to_string_lossy(),
        "--tolerance",
        "speed=1",
    ]);
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("unknown parameter `speed`"), "{e}");
}

#[test]
fn a_closed_standard_output_ends_quietly() {
    let t = tempfile::tempdir().expect("temp dir");
    let d = t.path().join("d");
    simulate(&d, 5, "car-1", 1);
    let out = t.path().join("r.csv");
    let mut child = bin()
        .args([
            "batch",
            &d.to_string_lossy(),
            "--out",
            &out.to_string_lossy(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let o = child.wait_with_output().expect("wait");
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert_eq!(rows(&out).len(), 1);
}

/// Regression (issue 13): `batch` calibrated every drive without the
/// timing and mounting corrections `calibrate` estimates, and had no column
/// for them. With `--corrections gnss` each row has the delays (the GNSS
/// one applied, equal to `calibrate --json --corrections gnss`'s on that drive); by default
/// none are estimated and the columns are empty.
#[test]
fn batch_had_no_corrections_and_no_columns_for_them() {
    let t = tempfile::tempdir().expect("temp dir");
    let drive = t.path().join("fleet").join("a");
    simulate(&drive, 1, "car-1", 2);
    let d = drive.to_string_lossy();
    let out = t.path().join("results.csv");
    let o = run(&[
        "batch",
        &d,
        "--out",
        &out.to_string_lossy(),
        "--corrections",
        "gnss",
        "--quiet",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let r = rows(&out);
    assert_eq!(&r[0][column(&out, "status_delay_gnss")], "applied");
    assert_eq!(&r[0][column(&out, "status_imu_tilt")], "none");
    let delay: f64 = r[0][column(&out, "delay_gnss_s")].parse().expect("number");
    let c = run(&["calibrate", &d, "--json", "--corrections", "gnss"]);
    assert!(c.status.success());
    let cal: serde_json::Value = serde_json::from_slice(&c.stdout).expect("json");
    assert_eq!(
        Some(delay),
        cal["corrections"]["delays"]["gnss"]["delay_s"].as_f64(),
        "{}",
        cal["corrections"]
    );
    // The same calibration as calibrate's, corrections included.
    let fl: f64 = r[0][column(&out, "circumference_fl_m")]
        .parse()
        .expect("number");
    assert_eq!(Some(fl), cal["circumference_fl_m"].as_f64());

    let plain = t.path().join("plain.csv");
    let o = run(&["batch", &d, "--out", &plain.to_string_lossy(), "--quiet"]);
    assert!(o.status.success());
    let r = rows(&plain);
    assert_eq!(&r[0][column(&plain, "delay_gnss_s")], "");
    assert_eq!(&r[0][column(&plain, "status_delay_gnss")], "");
}

/// One car calibration (issue 30): `batch`'s row and `calibrate --json`
/// on the same drive with the same options are the same numbers (both call
/// `deadreckon_api::calibration::calibrate`), and the status columns are
/// the JSON's `not_estimated` rule. Before, `batch` ran its own sequence
/// with its own rule for "estimated" (`std > 0 && samples > 0`).
#[test]
fn batch_row_and_calibrate_json_are_one_calibration() {
    let t = tempfile::tempdir().expect("temp dir");
    let d = t.path().join("d");
    simulate(&d, 5, "car-1", 1);
    let dir = d.to_string_lossy();
    for method in ["rts", "zupt"] {
        let out = t.path().join(format!("{method}.csv"));
        same_numbers(&dir, &out, method);
    }
}

fn same_numbers(dir: &str, out: &Path, method: &str) {
    let r = run(&[
        "batch",
        dir,
        "--out",
        &out.to_string_lossy(),
        "--method",
        method,
        "--quiet",
    ]);
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    // batch's default corrections are none; calibrate's are auto.
    let c = run(&[
        "calibrate",
        dir,
        "--json",
        "--corrections",
        "none",
        "--method",
        method,
    ]);
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let json: serde_json::Value = serde_json::from_slice(&c.stdout).expect("json");
    let row = &rows(out)[0];
    let cell = |name: &str| row[column(out, name)].to_string();
    assert_eq!(cell("iterations"), json["iterations"].to_string());
    assert_eq!(cell("converged"), json["converged"].to_string());
    let not_estimated = json["not_estimated"].as_object().expect("object");
    for (i, name) in deadreckon_core::Params::NAMES.iter().enumerate() {
        let v: f64 = cell(name).parse().expect("number");
        let s: f64 = cell(&format!("std_{name}")).parse().expect("number");
        assert_eq!(v, json[name].as_f64().unwrap(), "{name}");
        assert_eq!(s, json["std"][name].as_f64().unwrap(), "std {name}");
        assert_eq!(
            cell(&format!("samples_{name}")),
            json["samples"][i].to_string()
        );
        let status = if not_estimated.contains_key(*name) {
            "not-estimated"
        } else {
            "estimated"
        };
        assert_eq!(cell(&format!("status_{name}")), status, "{name}");
    }
    // ZUPT estimates the bias only; RTS all six on this drive.
    let expected = if method == "zupt" { 5 } else { 0 };
    assert_eq!(not_estimated.len(), expected, "{method}: {not_estimated:?}");
}
