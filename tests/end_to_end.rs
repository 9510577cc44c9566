//! End-to-end tests of the `deadreckon` binary in temporary directories: the
//! slow cases (whole simulated drives through every command) live here.

mod common;

use std::path::Path;
use std::process::{Command, Output};

use common::{bin, json, run_ok, COMMA2K19 as COMMA, HUSKY_BAG as HUSKY};

fn run_err(args: &[&str]) -> Output {
    let out = bin().args(args).output().expect("binary runs");
    assert!(
        !out.status.success(),
        "deadreckon {args:?} should have failed"
    );
    out
}

fn simulate(dir: &Path, scenario: &str, seed: u64) {
    common::simulate_into(dir, scenario, &seed.to_string());
}

#[test]
fn simulate_calibrate_evaluate_run() {
    let tmp = tempfile::tempdir().unwrap();
    let cal = tmp.path().join("cal");
    let eval = tmp.path().join("eval");
    simulate(&cal, "calibration", 11);
    simulate(&eval, "evaluation", 12);
    let truth = deadreckon_io::read_truth_params(&cal.join("truth_params.toml"))
        .unwrap()
        .to_array();

    // calibrate --json: the contract keys, close to the truth.
    let params = tmp.path().join("params.toml");
    let v = json(&run_ok(&[
        "calibrate",
        cal.to_str().unwrap(),
        "--method",
        "rts",
        "--json",
        "--out",
        params.to_str().unwrap(),
    ]));
    for (i, k) in deadreckon_core::Params::NAMES.iter().enumerate() {
        let est = v[k].as_f64().unwrap_or_else(|| panic!("missing {k}"));
        let tol = if i == 0 { 0.05 } else { 0.003 };
        assert!(
            ((est - truth[i]) / truth[i]).abs() < tol,
            "{k}: {est} vs {}",
            truth[i]
        );
        assert!(v["std"][k].as_f64().unwrap() > 0.0, "std of {k}");
    }
    assert!(v["iterations"].as_u64().unwrap() >= 1);
    // params.toml: the same keys and a [std] table.
    let p = deadreckon_io::read_params(&params).unwrap();
    assert_eq!(p.params.to_array()[0], v["gyro_bias_rps"].as_f64().unwrap());
    let text = std::fs::read_to_string(&params).unwrap();
    assert!(
        text.contains("[std]") && text.contains("circumference_rr_m"),
        "{text}"
    );

    // evaluate: drift and reset-1m JSON contracts, calibrated beats nominal.
    let d_cal = json(&run_ok(&[
        "evaluate",
        eval.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--metric",
        "drift",
        "--json",
    ]));
    let d_nom = json(&run_ok(&[
        "evaluate",
        eval.to_str().unwrap(),
        "--params",
        "nominal",
        "--metric",
        "drift",
        "--json",
    ]));
    assert_eq!(d_cal["metric"], "drift");
    assert!(d_cal["n"].as_u64().unwrap() >= 40, "{d_cal}");
    let (c, n) = (
        d_cal["mean_pct"].as_f64().unwrap(),
        d_nom["mean_pct"].as_f64().unwrap(),
    );
    assert!(
        c < 0.5 && c < n / 3.0,
        "calibrated drift {c}% vs nominal {n}%"
    );
    assert!(d_cal["std_pct"].as_f64().unwrap() > 0.0);
    // The gate counters of the dead reckoning: every sensor but GNSS.
    let g = &d_cal["gates"];
    assert!(g["gyro"]["accepted"].as_u64().unwrap() > 1000, "{g}");
    assert!(g["wheel_fl"]["accepted"].as_u64().unwrap() > 1000, "{g}");
    assert!(g.get("gnss").is_none(), "dead reckoning gated GNSS: {g}");
    let r = json(&run_ok(&[
        "evaluate",
        eval.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--metric",
        "reset-1m",
        "--json",
    ]));
    assert_eq!(r["metric"], "reset-1m");
    for k in ["mean_m", "median_m", "min_m", "max_m"] {
        assert!(r[k].as_f64().unwrap() > 50.0, "{k}: {r}");
    }

    // Sliding-window outages against the truth.
    let o = json(&run_ok(&[
        "evaluate",
        eval.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--outage",
        "20",
        "--step",
        "30",
        "--json",
    ]));
    assert_eq!(o["reference"], "truth");
    let g = &o["gates"];
    assert!(g["gnss"]["accepted"].as_u64().unwrap() > 100, "{g}");
    assert!(
        g["wheel_rr"]["accepted"].as_u64().unwrap() > g["gnss"]["accepted"].as_u64().unwrap(),
        "{g}"
    );
    assert!(o["windows"].as_u64().unwrap() >= 15, "{o}");
    let fe = &o["final_error_m"];
    assert!(
        fe["mean"].as_f64().unwrap() < 2.0
            && fe["max"].as_f64().unwrap() >= fe["p95"].as_f64().unwrap(),
        "{o}"
    );
    // Every window, with the error the aided run handed over at its start;
    // the summaries are of these.
    let per = o["outages"].as_array().unwrap();
    assert_eq!(per.len() as u64, o["windows"].as_u64().unwrap());
    let field = |k: &str| -> Vec<f64> { per.iter().map(|w| w[k].as_f64().unwrap()).collect() };
    let (starts, finals) = (field("start_error_m"), field("final_error_m"));
    let max = |v: &[f64]| v.iter().copied().fold(f64::NAN, f64::max);
    assert_eq!(max(&starts), o["start_error_m"]["max"].as_f64().unwrap());
    assert_eq!(max(&finals), fe["max"].as_f64().unwrap());
    for w in per {
        let (a, b) = (w["start_s"].as_f64().unwrap(), w["end_s"].as_f64().unwrap());
        assert!((b - a - 20.0).abs() < 1e-9, "{w}");
        assert!(
            w["max_error_m"].as_f64() >= w["final_error_m"].as_f64(),
            "{w}"
        );
        assert!(
            w["max_error_m"].as_f64() >= w["start_error_m"].as_f64(),
            "{w}"
        );
    }

    // run: tracks with covariances.
    let track = tmp.path().join("track.csv");
    run_ok(&[
        "run",
        eval.to_str().unwrap(),
        "--params",
        params.to_str().unwrap(),
        "--out",
        track.to_str().unwrap(),
    ]);
    let text = std::fs::read_to_string(&track).unwrap();
    let header = text.lines().next().unwrap();
    assert!(
        header.starts_with("t_s,track,east_m,north_m,yaw_rad"),
        "{header}"
    );
    for name in ["dead-reckoned", "filtered", "smoothed"] {
        assert!(text.contains(&format!(",{name},")), "track {name} missing");
    }
    // GeoJSON needs a geodetic origin: a clear error and no file left behind.
    let gj = tmp.path().join("track.geojson");
    let e = run_err(&["run", eval.to_str().unwrap(), "--out", gj.to_str().unwrap()]);
    assert!(
        String::from_utf8_lossy(&e.stderr).contains("origin"),
        "{}",
        String::from_utf8_lossy(&e.stderr)
    );
    assert!(!gj.exists());
}

#[test]
fn malformed_drives_are_reported_with_file_line_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("d");
    simulate(&dir, "evaluation", 3);
    let yaw = dir.join("yaw_rate.csv");
    let original = std::fs::read_to_string(&yaw).unwrap();
    type Corrupt = Box<dyn Fn(&str) -> String>;
    let cases: [(&str, Corrupt); 4] = [
        (
            "bad number",
            Box::new(|s: &str| s.replacen("\n0.", "\nzero.", 1)),
        ),
        (
            "NaN",
            Box::new(|s: &str| {
                let mut l: Vec<String> = s.lines().map(String::from).collect();
                l[5] = format!("{},NaN", l[5].split(',').next().unwrap());
                l.join("\n") + "\n"
            }),
        ),
        (
            "duplicate time",
            Box::new(|s: &str| {
                let mut l: Vec<String> = s.lines().map(String::from).collect();
                l[6] = l[5].clone();
                l.join("\n") + "\n"
            }),
        ),
        (
            "degrees",
            Box::new(|s: &str| {
                let mut l: Vec<String> = s.lines().map(String::from).collect();
                l[5] = format!("{},45.0", l[5].split(',').next().unwrap());
                l.join("\n") + "\n"
            }),
        ),
    ];
    for (what, corrupt) in cases {
        std::fs::write(&yaw, corrupt(&original)).unwrap();
        let e = run_err(&["calibrate", dir.to_str().unwrap(), "--method", "zupt"]);
        let msg = String::from_utf8_lossy(&e.stderr);
        assert!(
            msg.contains("yaw_rate.csv")
                && msg.contains("line")
                && (msg.contains("yaw_rate_rps") || msg.contains("t_s")),
            "{what}: {msg}"
        );
        eprintln!("{what}: {msg}");
        assert!(!msg.contains("panicked"), "{what}: {msg}");
    }
    std::fs::write(&yaw, &original).unwrap();
    // A missing required file.
    std::fs::remove_file(dir.join("wheel_ticks.csv")).unwrap();
    let e = run_err(&["calibrate", dir.to_str().unwrap(), "--method", "zupt"]);
    let msg = String::from_utf8_lossy(&e.stderr);
    assert!(
        msg.contains("wheel_ticks.csv") && msg.contains("wheel_speeds.csv"),
        "{msg}"
    );
    // A missing drive.
    let e = run_err(&["calibrate", tmp.path().join("nope").to_str().unwrap()]);
    assert!(!String::from_utf8_lossy(&e.stderr).contains("panicked"));
}

#[test]
fn demo_reproduces_the_papers_ordering() {
    let tmp = tempfile::tempdir().unwrap();
    let v = json(&run_ok(&[
        "demo",
        "--out",
        tmp.path().to_str().unwrap(),
        "--json",
    ]));
    let methods = v["methods"].as_array().unwrap();
    let drift = |name: &str| {
        methods.iter().find(|m| m["method"] == name).unwrap()["drift"]["mean_pct"]
            .as_f64()
            .unwrap()
    };
    let (nom, zupt, rts, truth) = (
        drift("nominal"),
        drift("ZUPT"),
        drift("RTS"),
        drift("truth"),
    );
    assert!(
        rts < zupt && zupt < nom,
        "nominal {nom} ZUPT {zupt} RTS {rts}"
    );
    assert!(rts <= 1.1 * truth, "RTS {rts} truth {truth}");
    assert!(tmp.path().join("params_rts.toml").exists());
    check_in_chromium(&tmp.path().join("report.html"), 24);
    // The TedriS part: both methods through three outages, and its report.
    let outages = v["tedris_comparison"]["outages"].as_array().unwrap();
    assert_eq!(outages.len(), 3);
    for o in outages {
        assert!(
            o["four_wheel"]["mean_error_m"].as_f64().unwrap() < 3.0,
            "{o}"
        );
        assert!(o["tedris"]["mean_error_m"].as_f64().is_some(), "{o}");
    }
    check_in_chromium(&tmp.path().join("tedris-report.html"), 27);
}

/// Renders a report in headless Chromium (`tests/report_chromium.sh`): every
/// figure must have drawn data, no console error, and a screenshot is taken.
/// Without Chromium the check is skipped, except under CI (`CI` set), where
/// `.ci/run` installs it and its absence is a failure.
fn check_in_chromium(html: &Path, min_figures: usize) {
    let have = Command::new("sh")
        .args(["-c", "command -v chromium || command -v chromium-browser"])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !have {
        assert!(
            std::env::var_os("CI").is_none(),
            "CI must have chromium (.ci/run installs it)"
        );
        eprintln!(
            "chromium not installed: skipping the rendering check of {}",
            html.display()
        );
        return;
    }
    let png = html.with_extension("png");
    let out = Command::new("bash")
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/tests/report_chromium.sh"
        ))
        .arg(html)
        .arg(&png)
        .output()
        .expect("bash runs");
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "chromium check failed:\n{text}");
    let figures: usize = text
        .split("figures=")
        .nth(1)
        .and_then(|r| r.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no figure count in:\n{text}"));
    assert!(figures >= min_figures, "only {figures} figures:\n{text}");
    assert!(
        std::fs::metadata(&png)
            .map(|m| m.len() > 50_000)
            .unwrap_or(false),
        "no screenshot"
    );
}

/// comma2k19 held out (issue 33): calibrated on one half of the segment
/// (split at 46438.6 s), evaluated on the other with 20 s outages every
/// 2 s, both ways, as the README's commands do. The in-sample figures above
/// calibrate on the windows they judge; these do not. Bounds near the
/// measured figures (printed).
#[test]
fn comma2k19_held_out_halves() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("rav4");
    let d = drive.to_str().unwrap();
    run_ok(&["import", "comma2k19", COMMA, "--out", d]);
    let mut got = Vec::new();
    let mut bound = Vec::new();
    for (cal, eval) in [("--until", "--from"), ("--from", "--until")] {
        let params = tmp
            .path()
            .join(format!("half{}.toml", cal.trim_start_matches('-')));
        let p = params.to_str().unwrap();
        run_ok(&["calibrate", d, cal, "46438.6", "--out", p]);
        let o = json(&run_ok(&[
            "evaluate", d, eval, "46438.6", "--params", p, "--outage", "20", "--step", "2",
            "--warmup", "2", "--json",
        ]));
        let (mean, median) = (
            o["final_error_m"]["mean"].as_f64().unwrap(),
            o["final_error_m"]["median"].as_f64().unwrap(),
        );
        eprintln!(
            "comma2k19 calibrated {cal} 46438.6, evaluated {eval}: {} windows, final mean {mean:.3} m, median {median:.3} m, {} unsettled",
            o["windows"],
            o["unsettled"].as_array().map_or(0, |u| u.len())
        );
        got.push((mean, median));
        // Issue 31: the 95 % bound with the factor the half's calibration
        // stored (fitted on its own hidden fixes).
        let within = o["outages"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|w| w["within_bound_95"] == true)
            .count();
        let sharp = o["bound_95_sharpness"].as_f64().unwrap();
        eprintln!(
            "  bound: k {} ({}), {within} windows within, sharpness {sharp:.2}",
            o["bound"]["k"], o["bound"]["method"]
        );
        assert_eq!(o["bound"]["method"], "conformal", "{o}");
        bound.push((within, o["outages"].as_array().unwrap().len(), sharp));
    }
    // Measured (docs/bound.md's construction, r(k² P + F)): first half ->
    // second 4 of 4 windows within (k 0: the u-blox's declared 1 m
    // explains every fit window's error, so the bound is that floor,
    // 2.448 m; sharpness 2.92), second -> first 3 of 3 (k 0, 4.69): 7 of 7,
    // the issue's at least 80 % (the first construction, k · r(P + F):
    // 4 of 4 and 2 of 3).
    assert_eq!((bound[0].0, bound[0].1), (4, 4), "{bound:?}");
    assert_eq!((bound[1].0, bound[1].1), (3, 3), "{bound:?}");
    assert!(
        (bound[0].2 - 2.92).abs() < 0.2 && (bound[1].2 - 4.69).abs() < 0.3,
        "{bound:?}"
    );
    // Measured: first half -> second 0.811 / 0.837 m (mean / median, 4
    // windows), second -> first 0.623 / 0.537 m (3 windows, the pull-away
    // reported apart), at stop 34 after the receiver's GNSS delay and the
    // wander option (both unchanged by them). They were 0.773 / 0.807 and
    // 0.593 / 0.511 m when first pinned (stop 30) and drifted by 4-5 %
    // inside the old 10 % band over stops 31-33, cause not found (not the
    // GNSS delay's settled steps). Within 5 % now.
    let within = |x: f64, m: f64| (x - m).abs() < 0.05 * m;
    assert!(
        within(got[0].0, 0.811) && within(got[0].1, 0.837),
        "{got:?}"
    );
    assert!(
        within(got[1].0, 0.623) && within(got[1].1, 0.537),
        "{got:?}"
    );
}

#[test]
fn comma2k19_import_calibrate_evaluate_report() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("rav4");
    run_ok(&[
        "import",
        "comma2k19",
        COMMA,
        "--out",
        drive.to_str().unwrap(),
    ]);
    let c = json(&run_ok(&["calibrate", drive.to_str().unwrap(), "--json"]));
    eprintln!("comma2k19 calibration: {c}");
    // TedriS cannot train on this 60 s of nearly straight road, and says
    // which requirement failed and by how much (it used to point at the
    // sample count whatever failed): first the 60 s of reference it needs,
    // then, with 30 s asked for, the turning.
    let model = tmp.path().join("model.json");
    let train_err = |extra: &[&str]| {
        let mut args = vec![
            "tedris",
            "train",
            drive.to_str().unwrap(),
            "--out",
            model.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        String::from_utf8_lossy(&run_err(&args).stderr).into_owned()
    };
    let msg = train_err(&[]);
    assert!(
        msg.contains("55.4 s of wheel samples") && msg.contains("init_s needs 60"),
        "{msg}"
    );
    let cfg = tmp.path().join("tedris.json");
    std::fs::write(&cfg, r#"{"init_s": 30}"#).unwrap();
    let msg = train_err(&["--config", cfg.to_str().unwrap()]);
    assert!(
        msg.contains("cross-correlation peak of ω and γ is 0.032")
            && msg.contains("min_ccf_peak needs 0.3"),
        "{msg}"
    );
    assert!(!model.exists());
    let mut finals = Vec::new();
    for len in ["20", "40"] {
        let o = json(&run_ok(&[
            "evaluate",
            drive.to_str().unwrap(),
            "--outage",
            len,
            "--step",
            "5",
            "--json",
        ]));
        eprintln!("comma2k19 {len} s outages: {o}");
        assert_eq!(o["reference"], "truth");
        assert!(o["windows"].as_u64().unwrap() >= 3, "{o}");
        finals.push(o["final_error_m"]["mean"].as_f64().unwrap());
        // The GNSS delay the importer no longer corrects, estimated (issue
        // 13: within 0.02 s of u-blox's 0.1 s; measured 0.086 ± 0.007 s with
        // the front wheels' slip corrected), the phone's tilt reported
        // (measured 3.75° ± 0.77°) and the driven axle found.
        let c = &o["corrections"];
        let d = c["delays"]["gnss"]["delay_s"].as_f64().unwrap();
        assert!((d - 0.1).abs() < 0.02, "{c}");
        assert_eq!(c["imu"]["estimated"], true, "{c}");
        assert_eq!(c["traction"]["axle"], "front", "{c}");
        if len == "20" {
            // Issue 13's target (median final error 0.5 m) is under what
            // the GNSS-aided start hands over: the u-blox fixes sit 0.39 m
            // west of the reference for the whole segment (which heads
            // north throughout), and the windows start a median 0.432 m
            // off. Measured: start 0.434 m, final 0.613 m (medians; 0.621
            // before the augmented pass held the scale and circumferences
            // while the heading was unknown, 0.559 m before the steering
            // waited for the gyro (issue 28), which took the held-out
            // halves from 0.908 / 0.744 m to 0.807 / 0.691 m: this figure
            // is in-sample, and a gyro bias 2.4e-5 rad/s off moves it by
            // 0.1 m).
            let (s, f) = (&o["start_error_m"]["median"], &o["final_error_m"]["median"]);
            let (s, f) = (s.as_f64().unwrap(), f.as_f64().unwrap());
            assert!((0.40..0.47).contains(&s), "start {s}");
            assert!((0.57..0.65).contains(&f), "final {f}");
            // Every window starts with the heading known (yaw standard
            // deviation 0.14-0.48 deg measured).
            assert_eq!(o["unsettled"].as_array().unwrap().len(), 0, "{o}");
            // Issue 31, the 95 % bound fitted on the drive itself (in-sample,
            // 20 windows of 18.2 s against its own fixes) is checked in
            // comma2k19_whole_drive_bound_covers_80_percent_of_outages.
        }
    }
    // Bounds on the measured figures (see the closing note of the readers issue).
    assert!(
        finals[0] < 1.5 && finals[1] < 2.5,
        "final errors {finals:?}"
    );
    // (Issue 13 dropped "40 s outages drift further than 20 s": on this
    // 60 s segment they are 3 windows against 7; with the corrections the
    // means are 0.59 m (20 s) and 0.80 m (40 s), without them 1.51 m and
    // 1.41 m.)
    let html = tmp.path().join("rav4.html");
    run_ok(&[
        "report",
        drive.to_str().unwrap(),
        "--outage",
        "20",
        "--out",
        html.to_str().unwrap(),
    ]);
    check_in_chromium(&html, 15);
}

/// Issue 31's comma2k19 figure: with the default options (calibrated and
/// the bound fitted on the drive itself), 20 s outages every 5 s, at least
/// 80 % of the windows end within `bound_95_m`. The first construction
/// (`k · r(P + F)`, the factor shrinking the receiver's floor: k 0.148)
/// gave 2 of 7.
#[test]
fn comma2k19_whole_drive_bound_covers_80_percent_of_outages() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("rav4");
    let d = drive.to_str().unwrap();
    run_ok(&["import", "comma2k19", COMMA, "--out", d]);
    let o = json(&run_ok(&[
        "evaluate", d, "--outage", "20", "--step", "5", "--json",
    ]));
    let k = o["bound"]["k"].as_f64().unwrap();
    let cover = o["bound_95_coverage"].as_f64().unwrap();
    let sharp = o["bound_95_sharpness"].as_f64().unwrap();
    eprintln!("comma2k19 whole drive: k {k}, coverage {cover}, sharpness {sharp}");
    // Measured: k 0 (fitted on 20 windows of 18.2 s: the u-blox's declared
    // 1 m explains every hidden fix's error), so every bound is the floor
    // r(F) = 2.448 m; 7 of 7 windows within, median bound / median final
    // error 3.99 (final errors 0.22-0.89 m).
    assert_eq!(o["bound"]["method"], "conformal", "{o}");
    assert!(k < 0.05, "k {k}");
    assert!(cover >= 0.8, "coverage {cover}");
    assert_eq!(o["outages"].as_array().unwrap().len(), 7, "{o}");
    assert!((sharp - 3.99).abs() < 0.3, "sharpness {sharp}");
}

/// The Husky bag is read directly by every command (no conversion step), and
/// dead-reckons through 30 s outages against the hidden GNSS fixes, here
/// through the car pipeline (`--shape car`: its shape found from the data is
/// a differential drive, tests/shape_and_params.rs).
#[test]
fn husky_bag_read_directly_through_30_s_outages() {
    let tmp = tempfile::tempdir().unwrap();
    let params = tmp.path().join("husky.toml");
    let c = json(&run_ok(&[
        "calibrate",
        HUSKY,
        "--shape",
        "car",
        "--min-speed",
        "0.5",
        "--json",
        "--out",
        params.to_str().unwrap(),
    ]));
    // The SBAS fixes wander: most are used, the gate rejects some, and the filter
    // recovers instead of locking itself out.
    let used = c["gnss"]["used"].as_u64().unwrap();
    let rejected = c["gnss"]["rejected"].as_u64().unwrap();
    assert!(used > 8 * rejected, "{c}");
    let o = json(&run_ok(&[
        "evaluate",
        HUSKY,
        "--shape",
        "car",
        "--params",
        params.to_str().unwrap(),
        "--outage",
        "30",
        "--step",
        "10",
        "--json",
    ]));
    eprintln!("husky 30 s outages: {o}");
    assert_eq!(o["reference"], "gnss");
    assert!(o["windows"].as_u64().unwrap() >= 30, "{o}");
    let fe = &o["final_error_m"];
    assert!(
        fe["mean"].as_f64().unwrap() < 6.0 && fe["max"].as_f64().unwrap() < 20.0,
        "{o}"
    );
    // And written out for Foxglove.
    let mcap = tmp.path().join("husky.mcap");
    run_ok(&[
        "run",
        HUSKY,
        "--shape",
        "car",
        "--params",
        params.to_str().unwrap(),
        "--out",
        mcap.to_str().unwrap(),
    ]);
    let bytes = std::fs::read(&mcap).unwrap();
    assert!(bytes.starts_with(b"\x89MCAP0\r\n"), "not an MCAP file");
}

/// `tedris train --variant paper` trains the paper's method alone (its
/// regression, no per-metre form) and says so in the model; the default is
/// the extended variant, which reports the course convention it found.
#[test]
fn tedris_train_variant_paper_and_extended() {
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("car");
    run_ok(&[
        "simulate",
        "--scenario",
        "tedris-car",
        "--out",
        drive.to_str().unwrap(),
    ]);
    let paper = tmp.path().join("paper.json");
    let p = json(&run_ok(&[
        "tedris",
        "train",
        drive.to_str().unwrap(),
        "--variant",
        "paper",
        "--out",
        paper.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(p["chosen"], "paper", "{p}");
    assert_eq!(p["per_metre_straight"], false, "{p}");
    let saved = json(&std::fs::read_to_string(&paper).unwrap());
    assert_eq!(saved["config"]["variant"], "paper");
    let ext = tmp.path().join("extended.json");
    let e = json(&run_ok(&[
        "tedris",
        "train",
        drive.to_str().unwrap(),
        "--out",
        ext.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(e["per_metre_straight"], true, "{e}");
    // No heading per sample in that form: not reported as if estimated.
    assert!(e["dcf_rad"].is_null(), "{e}");
    assert!(p["dcf_rad"].as_f64().is_some(), "{p}");
    // The paper's method estimates neither a heading per metre nor a turn gain.
    assert!(
        p["dcf_distance_rad_per_m"].is_null() && p["turn_gain"].is_null(),
        "{p}"
    );
    // Standard errors: none from eq. (6) nor for what is not estimated
    // (null, never 0); the joint calibration's distance term has one.
    for k in ["dcf_std_rad", "dcf_distance_std_rad_per_m", "turn_gain_std"] {
        assert!(p[k].is_null(), "{k}: {p}");
    }
    assert!(e["dcf_std_rad"].is_null(), "{e}");
    let per_m_std = e["dcf_distance_std_rad_per_m"].as_f64().unwrap();
    assert!(per_m_std > 0.0, "{e}");
    eprintln!(
        "tedris-car: heading per metre {} ± {per_m_std:.2e} rad/m, turn gain {} ± {}",
        e["dcf_distance_rad_per_m"], e["turn_gain"], e["turn_gain_std"]
    );
    // The simulated receiver's course is the antenna's velocity.
    assert_eq!(
        e["course_convention"]["convention"], "antenna_velocity",
        "{e}"
    );
    // The rear tyres are 0.2 % apart (right smaller) on a 1.57 m track: the
    // heading per metre is −0.002/1.57 = −1.27e-3 rad/m.
    let per_m = e["dcf_distance_rad_per_m"].as_f64().unwrap();
    assert!((per_m + 1.27e-3).abs() < 5e-5, "{per_m}");
    // A kind the user fixes is kept: ARX, which the per-metre form cannot
    // use, gets the per-sample form instead of being swapped for another kind.
    let arx = tmp.path().join("arx.json");
    let a = json(&run_ok(&[
        "tedris",
        "train",
        drive.to_str().unwrap(),
        "--model",
        "arx",
        "--out",
        arx.to_str().unwrap(),
        "--json",
    ]));
    assert_eq!(a["chosen"], "arx", "{a}");
    assert_eq!(a["per_metre_straight"], false, "{a}");
    // compare --json: both methods through an outage, with the four-wheel
    // gate counters and TedriS's course checks (the outage starts a new
    // heading segment).
    let c = json(&run_ok(&[
        "compare",
        drive.to_str().unwrap(),
        "--outage",
        "200:280",
        "--json",
    ]));
    assert!(
        c["four_wheel_gates"]["gnss"]["accepted"].as_u64().unwrap() > 100,
        "{c}"
    );
    assert!(
        c["tedris_checks"]["heading_segments"].as_u64().unwrap() >= 2,
        "{c}"
    );
    let o = &c["outages"][0];
    assert!(o["tedris"]["mean_error_m"].as_f64().unwrap() < 5.0, "{c}");
    assert!(
        o["four_wheel"]["mean_error_m"].as_f64().unwrap() < 5.0,
        "{c}"
    );
}

/// Regression: `calibrate --method truth` wrote the nominal values with
/// `converged: true` when no sample was above the speed threshold. Now the
/// parameters without samples are listed as not estimated, with why, and the
/// steering ratio and offset are calibrated beside the six (or not, and why).
#[test]
fn car_truth_calibration_with_zero_samples_is_not_converged() {
    let tmp = tempfile::tempdir().unwrap();
    let cal = tmp.path().join("cal");
    simulate(&cal, "calibration", 11);
    let out = tmp.path().join("p.toml");
    let v = json(&run_ok(&[
        "calibrate",
        cal.to_str().unwrap(),
        "--method",
        "truth",
        "--min-speed",
        "100",
        "--json",
        "--out",
        out.to_str().unwrap(),
    ]));
    assert_eq!(v["converged"], false, "{v}");
    let not = v["not_estimated"].as_object().unwrap();
    assert_eq!(not.len(), 5, "{v}");
    assert!(
        not["speed_scale"].as_str().unwrap().contains("0 samples"),
        "{v}"
    );
    assert_eq!(v["steering"]["ratio"]["estimated"], false, "{v}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("converged = false") && text.contains("[not_estimated]"),
        "{text}"
    );
    // At the default threshold everything is estimated, steering included.
    let v = json(&run_ok(&[
        "calibrate",
        cal.to_str().unwrap(),
        "--method",
        "truth",
        "--json",
    ]));
    assert_eq!(v["converged"], true, "{v}");
    assert!(v["not_estimated"].as_object().unwrap().is_empty(), "{v}");
    let ratio = v["steering"]["ratio"]["value"].as_f64().unwrap();
    // The simulator's true ratio is the nominal 15.9 here.
    assert!((ratio / 15.9 - 1.0).abs() < 0.005, "{v}");
}

/// Regressions (issue 13): `tedris train` and `tedris run` could not apply
/// the corrections a params.toml stores (a GNSS delay here), and `tedris
/// run --json` put TedriS's checks under `"checks"`, where every `--json`
/// object's plausibility checks then replaced them.
#[test]
fn tedris_ignored_the_stored_corrections_and_its_json_lost_its_checks() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("drive");
    let seed = 7;
    let mut sc = deadreckon_sim::family::CarFamily::draw(seed).drive_forward(seed, 500.0);
    sc.sensors.gnss.as_mut().expect("family gnss").latency_s = 0.2;
    let sim = deadreckon_sim::simulate(&sc, seed).unwrap();
    deadreckon_io::write_drive_whole(&dir, &sim.drive, |_| Ok(())).unwrap();
    let d = dir.to_str().unwrap();
    let p = tmp.path().join("params.toml");
    let ps = p.to_str().unwrap();
    run_ok(&["calibrate", d, "--out", ps]);
    let stored: toml::Table = std::fs::read_to_string(&p).unwrap().parse().unwrap();
    let delay = stored["delays"]["gnss"]["delay_s"].as_float().unwrap();
    assert!(delay > 0.1, "{stored}");
    let model = tmp.path().join("model.json");
    let m = model.to_str().unwrap();
    let t = json(&run_ok(&[
        "tedris", "train", d, "--params", ps, "--out", m, "--json",
    ]));
    // Stream::ALL order: gyro, speed, steering, gnss.
    assert_eq!(t["corrections"]["delays_s"][3].as_f64(), Some(delay), "{t}");
    let saved = json(&std::fs::read_to_string(&model).unwrap());
    assert_eq!(saved["corrections"], t["corrections"]);
    // tedris run applies the model's corrections without --params, a
    // params.toml's with it.
    let end = sim.drive.gnss.last().unwrap().t_s;
    let window = format!("{:.0}:{:.0}", end - 200.0, end - 120.0);
    let r = json(&run_ok(&[
        "tedris", "run", d, "--model", m, "--outage", &window, "--json",
    ]));
    assert_eq!(r["corrections"], "the model's (trained with them)", "{r}");
    assert!(
        r["tedris_checks"]["heading_segments"].as_u64().unwrap() >= 2,
        "{r}"
    );
    assert_eq!(r["checks"]["skipped"], false, "{r}");
    // The values the machine holds at the end of the run, with their
    // standard errors (null when not estimated).
    let cal = &r["calibrated"];
    assert!(cal["turn_gain"].as_f64().is_some(), "{r}");
    for k in ["dcf_std_rad", "dcf_distance_std_rad_per_m", "turn_gain_std"] {
        assert!(
            cal[k].is_null() || cal[k].as_f64().is_some_and(|s| s > 0.0),
            "{k}: {r}"
        );
    }
    let r = json(&run_ok(&[
        "tedris", "run", d, "--model", m, "--outage", &window, "--params", ps, "--json",
    ]));
    assert_eq!(r["corrections"], format!("stored in {ps}"), "{r}");
    let text = run_ok(&["tedris", "run", d, "--model", m, "--outage", &window]);
    assert!(text.contains("corrections applied: the model's"), "{text}");
    assert!(text.contains("at the end of the run: "), "{text}");
}
