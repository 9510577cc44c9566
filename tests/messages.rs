//! Messages that misled (issue 34), each replaced and pinned by a test named
//! after what it now says.

mod common;

use common::{run, run_err, run_ok, simulated};

const HUSKY: &str = "../shared/data/husky-gps-bag/husky_gps.bag";

/// A seeded simulated drive of `args` in `dir/name`; its path.
fn scenario(dir: &std::path::Path, name: &str, args: &[&str]) -> String {
    let out = dir.join(name).to_str().unwrap().to_string();
    let mut all = vec!["simulate", "--out", &out];
    all.extend_from_slice(args);
    run_ok(&all);
    out
}

#[test]
fn calibrate_of_a_missing_directory_says_the_directory_does_not_exist() {
    let tmp = tempfile::tempdir().unwrap();
    let missing = tmp.path().join("nodir");
    let e = run_err(&["calibrate", missing.to_str().unwrap()]);
    assert!(e.contains("nodir: no such directory"), "{e}");
    // It used to name vehicle.toml as the missing file.
    assert!(!e.contains("vehicle.toml: missing required file"), "{e}");
}

#[test]
fn a_drive_without_yaw_rate_csv_says_it_has_no_gyro_not_no_samples_above_the_threshold() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "200");
    std::fs::remove_file(format!("{d}/yaw_rate.csv")).unwrap();
    let out = run_ok(&["calibrate", &d]);
    let line = out
        .lines()
        .find(|l| l.starts_with("gyro_bias_rps: NOT ESTIMATED"))
        .unwrap_or_else(|| panic!("no gyro bias line:\n{out}"));
    assert!(line.contains("no yaw_rate.csv"), "{line}");
    assert!(
        !line.contains("samples above the speed threshold"),
        "{line}"
    );
}

#[test]
fn diff_drive_parameters_given_to_a_car_are_named_as_such_not_a_missing_gyro_bias_key() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "60");
    let p = tmp.path().join("husky.toml");
    std::fs::write(
        &p,
        "shape = \"diff_drive\"\nmethod = \"gnss\"\nyaw_source = \"gyro\"\n",
    )
    .unwrap();
    let e = run_err(&["evaluate", &d, "--params", p.to_str().unwrap()]);
    assert!(e.contains("a diff-drive parameter file"), "{e}");
    assert!(e.contains("--shape diff-drive"), "{e}");
    assert!(!e.contains("missing key `gyro_bias_rps`"), "{e}");
}

#[test]
fn car_parameters_with_shape_diff_drive_name_the_gnss_method_not_truth() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "120");
    let p = tmp.path().join("car.toml");
    run_ok(&["calibrate", &d, "--out", p.to_str().unwrap()]);
    let e = run_err(&[
        "evaluate",
        HUSKY,
        "--shape",
        "diff-drive",
        "--params",
        p.to_str().unwrap(),
        "--outage",
        "30",
    ]);
    assert!(e.contains("--shape diff-drive --method gnss"), "{e}");
    assert!(!e.contains("--method truth"), "{e}");
}

#[test]
fn batch_help_does_not_offer_method_gnss_that_batch_refuses() {
    let help = run_ok(&["batch", "--help"]);
    let method = help
        .split("--method <METHOD>")
        .nth(1)
        .and_then(|s| s.split("--max-iterations").next())
        .unwrap_or_else(|| panic!("no --method in:\n{help}"));
    assert!(!method.contains("gnss"), "{method}");
    for m in ["rts", "zupt", "truth"] {
        assert!(
            method.contains(&format!("- {m}:")),
            "{m} missing:\n{method}"
        );
    }
    let e = run_err(&["batch", "x", "--method", "gnss", "--out", "x.csv"]);
    assert!(e.contains("invalid value 'gnss'"), "{e}");
}

#[test]
fn import_help_gives_the_gnss_latency_default_the_import_uses() {
    let help = run_ok(&["import", "--help"]);
    let after = help
        .split("--gnss-latency-s <GNSS_LATENCY_S>")
        .nth(1)
        .unwrap_or_else(|| panic!("no --gnss-latency-s in:\n{help}"));
    let default: f64 = after
        .split("(default ")
        .nth(1)
        .and_then(|s| s.split([':', ')']).next())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or_else(|| panic!("no default in:\n{after}"));
    let used = deadreckon_import::comma2k19::Comma2k19Options::default().gnss_latency_s;
    assert_eq!(
        default, used,
        "help says {default} s, the import uses {used} s"
    );
}

#[test]
fn a_delay_measured_but_not_applied_is_not_called_not_estimated() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    let out = run_ok(&["calibrate", &d, "--corrections", "gnss"]);
    let speed = out
        .lines()
        .find(|l| l.starts_with("speed "))
        .unwrap_or_else(|| panic!("no speed delay row:\n{out}"));
    assert!(speed.contains("measured, not applied"), "{speed}");
    assert!(!speed.contains("not estimated"), "{speed}");
    // The measured value is in the columns, not in the words.
    let value: f64 = speed.split_whitespace().nth(1).unwrap().parse().unwrap();
    assert!(value.abs() < 0.05, "{speed}");
}

#[test]
fn the_wheel_monitors_max_t_short_and_long_is_explained() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "120");
    let out = run_ok(&["calibrate", &d]);
    assert!(out.contains("max |T|"), "{out}");
    let legend = out
        .lines()
        .find(|l| l.contains("(|T|:"))
        .unwrap_or_else(|| panic!("no |T| legend:\n{out}"));
    for w in [
        "normalised residual",
        "short: over 0.5 s",
        "long: over 50 m",
        "dropped above 4.5",
    ] {
        assert!(legend.contains(w), "{w} missing: {legend}");
    }
}

#[test]
fn compare_does_not_say_tedris_trained_twice() {
    let tmp = tempfile::tempdir().unwrap();
    // TedriS needs the turns of its own scenario to train.
    let d = scenario(tmp.path(), "d", &["--scenario", "tedris-car"]);
    let out = run_ok(&["compare", &d, "--outage", "150:200"]);
    assert!(!out.contains("TedriS: TedriS"), "{out}");
    assert!(
        out.contains("TedriS: trained on the drive, outages hidden"),
        "{out}"
    );
}

#[test]
fn stream_names_the_streams_of_the_stored_delays() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    let p = tmp.path().join("p.toml");
    // `gnss`, so that a delay is stored (`auto`, the default, applies none
    // on this drive without delays).
    run_ok(&[
        "calibrate",
        &d,
        "--corrections",
        "gnss",
        "--out",
        p.to_str().unwrap(),
    ]);
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
        .find(|l| l.contains("applying the corrections"))
        .unwrap_or_else(|| panic!("no note of the corrections:\n{}", r.stderr));
    assert!(warning.contains("gnss delay"), "{warning}");
    assert!(
        !warning.contains('[') && !warning.contains("Some("),
        "{warning}"
    );
}
