//! Golden files: the numbers of one seeded 60 s simulated drive
//! (`tests/golden/scenario.toml`, seed 11: the campus car around a block and a
//! roundabout) pinned to 1e-8 (as adskalman-rs pins its filter), so that moving
//! code cannot change a result unnoticed. The files in `tests/golden/`:
//!
//! - `filtered.csv`, `smoothed.csv`: the 5-state EKF's `x̂_{k|k}` and the RTS
//!   smoother's `x̂_{k|N}` at every epoch, with the covariance diagonal;
//! - `params.toml`: the RTS calibration of the drive, written as
//!   `deadreckon calibrate --out` writes it (estimates, passes, not-estimated
//!   parameters, standard errors);
//! - `calibrate.json`: `calibrate --json` with the default corrections (the
//!   receiver's 0.1 s latency estimated and applied, the other delays and
//!   the gyro scale measured), the speed scale of the drive's CAN speed
//!   (1.5 % high) estimated;
//! - `dead_reckoned.csv`: the four-wheel dead-reckoned track (`run`'s first
//!   track) with the calibrated parameters;
//! - `tedris_model.json`: a TedriS model trained on the drive (default car
//!   configuration with a 20 s initialisation, as a 60 s drive needs);
//! - `tedris_track.csv`: TedriS's track through a 20 s GNSS outage with that
//!   model, and `tedris_outage.json` its errors.
//!
//! A value matches when `|got − golden| ≤ 1e-8 · |golden| + 1e-14`; on a mismatch
//! the test prints, per file, the first differing rows or fields and the largest
//! absolute difference. Regenerate (after a change that is meant to change the
//! numbers, and say why in the commit) with
//!
//! ```text
//! DEADRECKON_BLESS=1 cargo test --profile ci --test golden
//! ```
//!
//! With `CI` set, a bless fails and writes nothing.
//!
//! Every path here is sequential (no parallel reductions), so the numbers are
//! the same from run to run (`golden_outputs_are_deterministic`, bit for bit).

mod common;

use std::fmt::Write as _;
use std::path::PathBuf;

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::{self, FilterOptions};
use deadreckon_core::{rts, track, Drive, Track};
use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::{run_outages_with, train, Outage, RunOptions, TedrisConfig};

/// Relative tolerance.
const TOL: f64 = 1e-8;
/// Absolute floor, for values that are rounding noise around zero (a
/// covariance's cross terms of 1e-20): 1e-14 in any unit here is far below
/// anything the outputs mean. It was 1e-8 below 1 (issue 33: loose for the
/// 11–18 % of values under 1e-5).
const FLOOR: f64 = 1e-14;
const SEED: u64 = 11;
const DURATION_S: f64 = 60.0;

fn golden_dir() -> PathBuf {
    common::repo_path("tests/golden")
}

fn drive() -> Drive {
    let sc = Scenario::load(&golden_dir().join("scenario.toml")).unwrap();
    assert_eq!(sc.duration_s, Some(DURATION_S));
    simulate(&sc, SEED).unwrap().drive
}

/// A number as Rust prints it: the shortest text that reads back to the same f64.
fn num(v: f64) -> String {
    format!("{v:e}")
}

fn states_csv<const N: usize>(
    rows: impl Iterator<Item = (f64, nalgebra::SVector<f64, N>, nalgebra::SMatrix<f64, N, N>)>,
) -> String {
    let mut s = String::from("t_s,x,y,yaw,v,yaw_rate,p_x,p_y,p_yaw,p_v,p_yaw_rate\n");
    for (t, x, p) in rows {
        let mut cells = vec![num(t)];
        cells.extend(x.iter().map(|v| num(*v)));
        cells.extend((0..N).map(|i| num(p[(i, i)])));
        s += &cells.join(",");
        s.push('\n');
    }
    s
}

fn track_csv(t: &Track) -> String {
    let mut s = String::from("t_s,east_m,north_m,yaw_rad,speed_mps,yaw_rate_rps");
    for i in 0..9 {
        let _ = write!(s, ",cov_pose_{i}");
    }
    s.push('\n');
    for p in &t.points {
        let mut cells = vec![
            num(p.t_s),
            num(p.east_m),
            num(p.north_m),
            num(p.yaw_rad),
            num(p.speed_mps),
            num(p.yaw_rate_rps),
        ];
        cells.extend(p.cov_pose.iter().map(|v| num(*v)));
        s += &cells.join(",");
        s.push('\n');
    }
    s
}

/// Every golden file's name and content, computed from the drive.
fn outputs() -> Vec<(&'static str, String)> {
    let drive = drive();
    let mut out = Vec::new();

    // Calibration, written as `calibrate --out params.toml` writes it.
    let opts = CalibrationOptions::default();
    let c = calibrate::calibrate(&drive, &opts).unwrap();
    let tables = deadreckon_api::params_file::ParamsTables {
        method: Some("rts".into()),
        iterations: Some(c.iterations),
        converged: Some(c.converged),
        not_estimated: deadreckon_api::json::not_estimated(
            &c,
            opts.min_speed_mps,
            deadreckon_api::json::Absent::of(&drive),
        )
        .into_iter()
        .map(|(k, why)| (k.to_string(), why))
        .collect(),
        ..Default::default()
    };
    let dir = tempfile::tempdir().unwrap();
    let params_path = dir.path().join("params.toml");
    deadreckon_api::params_file::ParamsFile::new(c.estimate, tables, "params.toml")
        .unwrap()
        .write(&params_path)
        .unwrap();
    out.push((
        "params.toml",
        std::fs::read_to_string(&params_path).unwrap(),
    ));
    let params = c.estimate.params;

    // The command's calibration (`calibrate --json` with the default
    // corrections): the corrections estimated and applied, then the RTS
    // calibration, its steering and what it could not estimate.
    let car = deadreckon_api::calibration::calibrate(
        &drive,
        &deadreckon_api::calibration::CalibrationRequest::default(),
        "the golden drive",
    )
    .unwrap();
    out.push((
        "calibrate.json",
        serde_json::to_string_pretty(&car.json()).unwrap() + "\n",
    ));

    // Filter and smoother with the calibrated parameters.
    let f = ekf::run(
        &drive,
        &params,
        &FilterOptions {
            record_epochs: true,
            ..Default::default()
        },
        &mut (),
    )
    .unwrap();
    let s = rts::smooth(&f.epochs).unwrap();
    out.push((
        "filtered.csv",
        states_csv(f.epochs.iter().map(|e| (e.t_s, e.x, e.p))),
    ));
    out.push((
        "smoothed.csv",
        states_csv(s.iter().map(|e| (e.t_s, e.x, e.p))),
    ));
    let tracks = track::drive_tracks(&drive, &params, &FilterOptions::default(), None).unwrap();
    let dr = track::find(&tracks, track::names::DEAD_RECKONED).unwrap();
    out.push(("dead_reckoned.csv", track_csv(dr)));

    // TedriS: trained on the drive, run through one outage.
    // The joint calibration asks for 120 s of reference heading by default;
    // 30 s here so that a 60 s drive pins it (issue 33).
    let cfg = TedrisConfig {
        init_s: 20.0,
        min_calibration_span_s: 30.0,
        ..TedrisConfig::default()
    };
    let (model, _) = train(&drive, cfg, None).unwrap();
    out.push((
        "tedris_model.json",
        serde_json::to_string_pretty(&model).unwrap() + "\n",
    ));
    let outage = Outage {
        start_s: 35.0,
        end_s: 55.0,
    };
    let r = run_outages_with(&drive, &model, &[outage], &RunOptions::default()).unwrap();
    out.push(("tedris_track.csv", track_csv(&r.track)));
    let errs = serde_json::json!({ "reference": r.reference, "outages": r.outages });
    out.push((
        "tedris_outage.json",
        serde_json::to_string_pretty(&errs).unwrap() + "\n",
    ));
    out
}

/// The numeric leaves of a document, by path (`a.b[3]`), or its text leaves.
#[derive(Debug, PartialEq)]
enum Leaf {
    Num(f64),
    Text(String),
}

fn json_leaves(v: &serde_json::Value, path: &str, out: &mut Vec<(String, Leaf)>) {
    use serde_json::Value;
    match v {
        Value::Object(m) => m
            .iter()
            .for_each(|(k, v)| json_leaves(v, &format!("{path}.{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, v)| json_leaves(v, &format!("{path}[{i}]"), out)),
        Value::Number(n) => out.push((path.into(), Leaf::Num(n.as_f64().unwrap()))),
        other => out.push((path.into(), Leaf::Text(other.to_string()))),
    }
}

fn toml_leaves(v: &toml::Value, path: &str, out: &mut Vec<(String, Leaf)>) {
    use toml::Value;
    match v {
        Value::Table(m) => m
            .iter()
            .for_each(|(k, v)| toml_leaves(v, &format!("{path}.{k}"), out)),
        Value::Array(a) => a
            .iter()
            .enumerate()
            .for_each(|(i, v)| toml_leaves(v, &format!("{path}[{i}]"), out)),
        Value::Float(f) => out.push((path.into(), Leaf::Num(*f))),
        Value::Integer(i) => out.push((path.into(), Leaf::Num(*i as f64))),
        other => out.push((path.into(), Leaf::Text(other.to_string()))),
    }
}

fn csv_leaves(text: &str) -> Vec<(String, Leaf)> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap_or("").split(',').collect();
    let mut out = Vec::new();
    for (r, line) in lines.enumerate() {
        for (c, cell) in line.split(',').enumerate() {
            let name = header.get(c).copied().unwrap_or("?");
            let leaf = cell
                .parse::<f64>()
                .map_or_else(|_| Leaf::Text(cell.into()), Leaf::Num);
            out.push((format!("row {} {name}", r + 1), leaf));
        }
    }
    out
}

fn leaves(name: &str, text: &str) -> Vec<(String, Leaf)> {
    let mut out = Vec::new();
    if name.ends_with(".json") {
        json_leaves(&serde_json::from_str(text).unwrap(), "", &mut out);
    } else if name.ends_with(".toml") {
        toml_leaves(
            &toml::Value::Table(toml::from_str(text).unwrap()),
            "",
            &mut out,
        );
    } else {
        out = csv_leaves(text);
    }
    out
}

fn close(got: f64, want: f64) -> bool {
    (got.is_nan() && want.is_nan()) || (got - want).abs() <= TOL * want.abs() + FLOOR
}

/// The differences of one file as readable lines (empty when it matches).
fn diff(name: &str, got: &str, want: &str) -> Vec<String> {
    let (g, w) = (leaves(name, got), leaves(name, want));
    let mut lines = Vec::new();
    if g.len() != w.len() {
        lines.push(format!(
            "{name}: {} values, golden has {}",
            g.len(),
            w.len()
        ));
    }
    let mut max_abs = 0.0_f64;
    let mut n_diff = 0;
    for ((gp, gv), (wp, wv)) in g.iter().zip(&w) {
        let same = gp == wp
            && match (gv, wv) {
                (Leaf::Num(a), Leaf::Num(b)) => {
                    if a.is_finite() && b.is_finite() {
                        max_abs = max_abs.max((a - b).abs());
                    }
                    close(*a, *b)
                }
                (a, b) => a == b,
            };
        if !same {
            n_diff += 1;
            if n_diff <= 8 {
                lines.push(format!("{name}: {gp}: {gv:?}, golden {wp}: {wv:?}"));
            }
        }
    }
    if n_diff > 0 || !lines.is_empty() {
        lines.push(format!(
            "{name}: {n_diff} values differ beyond {TOL:e} (relative), largest absolute difference {max_abs:e}"
        ));
    }
    lines
}

#[test]
fn golden_files_match() {
    let dir = golden_dir();
    let outs = outputs();
    if std::env::var_os("DEADRECKON_BLESS").is_some() {
        // Under CI a bless would pass whatever changed: refused, and nothing
        // is written (issue 33).
        assert!(
            std::env::var_os("CI").is_none(),
            "DEADRECKON_BLESS is refused when CI is set: golden files are regenerated \
             by hand, with the reason in the commit"
        );
        std::fs::create_dir_all(&dir).unwrap();
        for (name, text) in &outs {
            std::fs::write(dir.join(name), text).unwrap();
        }
        eprintln!("golden files written to {}", dir.display());
        return;
    }
    let mut report = Vec::new();
    for (name, text) in &outs {
        let path = dir.join(name);
        match std::fs::read_to_string(&path) {
            Ok(want) => report.extend(diff(name, text, &want)),
            Err(e) => report.push(format!("{}: {e}", path.display())),
        }
    }
    assert!(
        report.is_empty(),
        "outputs differ from the golden files (regenerate with DEADRECKON_BLESS=1 cargo test --profile ci --test golden if the change is meant):\n{}",
        report.join("\n")
    );
}

#[test]
fn golden_outputs_are_deterministic() {
    // Bit for bit from run to run: the golden comparison's tolerance is for
    // other platforms, not for this one.
    assert_eq!(outputs(), outputs());
}

#[test]
fn golden_diff_names_the_differing_value() {
    // The comparison itself: a change beyond the tolerance is reported with its
    // row, column and size, one within it is not.
    let want = "t_s,x\n0e0,1e2\n1e0,2e2\n";
    let got = "t_s,x\n0e0,1.0000000000005e2\n1e0,2.000001e2\n";
    let d = diff("f.csv", got, want);
    assert_eq!(d.len(), 2, "{d:?}");
    assert!(d[0].contains("row 2 x"), "{d:?}");
    assert!(d[1].contains("1 values differ"), "{d:?}");
    assert!(diff("f.csv", want, want).is_empty());
    let d = diff("f.csv", "t_s,x\n0e0,1e2\n", want);
    assert!(d[0].contains("2 values, golden has 4"), "{d:?}");
}
