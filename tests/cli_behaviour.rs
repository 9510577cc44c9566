//! Command-line behaviour of issue 34: `simulate --duration` repeats laps,
//! `--quiet` prints nothing but errors and the data asked for, `import`
//! does not replace a drive unasked, a track without uncertainty leaves its
//! `std_*` columns empty.

mod common;

use common::{run, run_err, run_ok, simulated};

/// The last time the truth moves faster than 1 m/s, and the last time.
fn last_moving_and_end(dir: &str) -> (f64, f64) {
    let text = std::fs::read_to_string(format!("{dir}/truth.csv")).unwrap();
    let mut header = text.lines().next().unwrap().split(',');
    let speed = header.position(|c| c == "speed_mps").unwrap();
    let (mut moving, mut end) = (0.0, 0.0);
    for line in text.lines().skip(1) {
        let f: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
        end = f[0];
        if f[speed].abs() > 1.0 {
            moving = f[0];
        }
    }
    (moving, end)
}

#[test]
fn simulate_duration_3600_repeats_laps_instead_of_parking_after_935_s() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path().join("d");
    let d = d.to_str().unwrap();
    let out = run_ok(&[
        "simulate",
        "--scenario",
        "calibration",
        "--duration",
        "3600",
        "--out",
        d,
    ]);
    // One lap is 8.14 km in 935 s; measured: 32.40 km in 3600 s, 33 stops.
    assert!(out.contains("32.40 km in 3600 s"), "{out}");
    let (moving, end) = last_moving_and_end(d);
    assert_eq!(end, 3600.0);
    assert!(moving > 3590.0, "the car parked at {moving} s");

    // With --laps, --duration still keeps the laps asked for and stands
    // still after them.
    let d2 = tmp.path().join("d2");
    let d2 = d2.to_str().unwrap();
    run_ok(&[
        "simulate",
        "--scenario",
        "calibration",
        "--laps",
        "1",
        "--duration",
        "1200",
        "--out",
        d2,
    ]);
    let (moving, end) = last_moving_and_end(d2);
    assert_eq!(end, 1200.0);
    assert!(moving < 940.0, "{moving}");
}

#[test]
fn quiet_prints_nothing_but_errors_and_the_data_asked_for() {
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).to_str().unwrap().to_string();
    let (d, params) = (p("d"), p("p.toml"));
    let silent = |args: &[&str]| {
        let mut all = vec!["--quiet"];
        all.extend_from_slice(args);
        let r = run(&all, None);
        assert!(r.ok, "{args:?}: {}", r.stderr);
        assert!(
            r.stdout.is_empty() && r.stderr.is_empty(),
            "{args:?} printed:\n{}{}",
            r.stdout,
            r.stderr
        );
    };
    silent(&[
        "simulate",
        "--scenario",
        "calibration",
        "--duration",
        "200",
        "--out",
        &d,
    ]);
    silent(&["calibrate", &d, "--out", &params]);
    silent(&["evaluate", &d, "--params", &params, "--outage", "30"]);
    silent(&["run", &d, "--params", &params, "--out", &p("t.csv")]);
    silent(&["batch", &d, "--out", &p("b.csv")]);
    // A drive with a warning (an outlier fix): still silent.
    let gnss = std::fs::read_to_string(format!("{d}/gnss.csv")).unwrap();
    let bad: Vec<String> = gnss
        .lines()
        .enumerate()
        .map(|(i, l)| {
            let mut f: Vec<String> = l.split(',').map(str::to_string).collect();
            if i == 200 {
                f[1] = (f[1].parse::<f64>().unwrap() + 1000.0).to_string();
            }
            f.join(",")
        })
        .collect();
    std::fs::write(format!("{d}/gnss.csv"), bad.join("\n") + "\n").unwrap();
    silent(&["calibrate", &d]);
    // The data asked for is printed.
    let json = run_ok(&["--quiet", "calibrate", &d, "--json"]);
    assert!(json.trim_start().starts_with('{'), "{json}");
    // Errors are printed.
    let e = run_err(&["--quiet", "calibrate", &p("nodir")]);
    assert!(e.starts_with("error: "), "{e}");
}

#[test]
fn import_into_an_existing_drive_directory_is_refused_without_force() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("tri");
    let out = out.to_str().unwrap();
    let log = "../shared/data/tricycle-tracker/dataset.txt";
    run_ok(&["import", "tricycle", log, "--out", out]);
    let before = std::fs::read_to_string(format!("{out}/vehicle.toml")).unwrap();
    std::fs::write(format!("{out}/notes.txt"), "mine").unwrap();
    let e = run_err(&["import", "tricycle", log, "--out", out]);
    assert!(
        e.contains("exists and is not empty") && e.contains("--force"),
        "{e}"
    );
    assert_eq!(
        std::fs::read_to_string(format!("{out}/notes.txt")).unwrap(),
        "mine"
    );
    run_ok(&["import", "tricycle", log, "--out", out, "--force"]);
    assert_eq!(
        std::fs::read_to_string(format!("{out}/vehicle.toml")).unwrap(),
        before
    );
    // An empty directory is a new one.
    let empty = tmp.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    run_ok(&["import", "tricycle", log, "--out", empty.to_str().unwrap()]);
}

#[test]
fn tedris_track_csv_wrote_std_zero_where_it_has_no_uncertainty() {
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).to_str().unwrap().to_string();
    let d = p("d");
    run_ok(&["simulate", "--scenario", "tedris-car", "--out", &d]);
    run_ok(&["tedris", "train", &d, "--out", &p("m.json")]);
    run_ok(&[
        "tedris",
        "run",
        &d,
        "--model",
        &p("m.json"),
        "--outage",
        "150:200",
        "--out",
        &p("t.csv"),
    ]);
    let text = std::fs::read_to_string(p("t.csv")).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert!(rows.len() > 1000);
    for row in rows {
        assert!(row.ends_with(",,,,"), "{row}");
    }
    // The filter's tracks keep theirs.
    run_ok(&["run", &d, "--out", &p("r.csv")]);
    let text = std::fs::read_to_string(p("r.csv")).unwrap();
    let row = text.lines().nth(1).unwrap();
    let std_east: f64 = row.split(',').nth(7).unwrap().parse().unwrap();
    assert!(std_east > 0.0, "{row}");
}

#[test]
fn report_had_no_step_so_an_evaluate_figure_could_not_be_reproduced_in_a_report() {
    let tmp = tempfile::tempdir().unwrap();
    let p = |n: &str| tmp.path().join(n).to_str().unwrap().to_string();
    let d = simulated(tmp.path(), "d", "300");
    let windows = |extra: &[&str]| -> u64 {
        let mut args = vec!["evaluate", d.as_str(), "--outage", "30", "--json"];
        args.extend_from_slice(extra);
        let v: serde_json::Value = serde_json::from_str(&run_ok(&args)).unwrap();
        v["windows"].as_u64().unwrap_or_else(|| panic!("{v}"))
    };
    let (every_10, every_15) = (windows(&["--step", "10"]), windows(&[]));
    assert!(every_10 > every_15, "{every_10} {every_15}");
    let html = |extra: &[&str]| -> String {
        let out = p("r.html");
        let mut args = vec![
            "report",
            d.as_str(),
            "--outage",
            "30",
            "--out",
            out.as_str(),
        ];
        args.extend_from_slice(extra);
        run_ok(&args);
        std::fs::read_to_string(&out).unwrap()
    };
    // The outage histogram's legend counts the windows of each method,
    // named by where its parameters came from (issue 34: "RTS, this drive",
    // with "+ corrections estimated here" when any were applied).
    let rts = |html: &str, n: u64| {
        html.contains("RTS, this drive") && html.contains(&format!("(n = {n})"))
    };
    assert!(rts(&html(&["--step", "10"]), every_10));
    assert!(rts(&html(&[]), every_15));
    let e = run_err(&["report", &d, "--step", "10", "--out", &p("x.html")]);
    assert!(e.contains("--outage"), "{e}");
}
