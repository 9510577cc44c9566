//! `evo` (the Python trajectory-evaluation package, a test-only dependency)
//! reads the TUM and KITTI files `deadreckon run` writes, and its
//! `evo_rpe --delta 100 --delta_unit m` and `evo_ape` numbers equal those of
//! `deadreckon evaluate --metric rpe|ape` on the same tracks.
//!
//! These tests need evo, so they are `#[ignore]`d in the plain test run and
//! run by `.ci/run`, which installs evo 1.38.1 in a virtual environment and
//! runs `cargo test --workspace --profile ci --test evo -- --ignored` with
//! `DEADRECKON_EVO_BIN` set to the environment's `bin` directory. Run them
//! the same way by hand; without the variable they fail, saying so.

mod common;
use common::run_ok;

use std::path::{Path, PathBuf};
use std::process::Command;

use serde_json::Value;

/// Agreement of our numbers with evo's, m: our metric reads the tracks rounded
/// as the files carry them; the quaternions (1e-9) and evo's matrix
/// arithmetic remain.
const TOL_M: f64 = 1e-6;

fn evo_bin() -> PathBuf {
    match std::env::var_os("DEADRECKON_EVO_BIN") {
        Some(dir) => {
            let dir = PathBuf::from(dir);
            assert!(
                dir.join("evo_rpe").is_file(),
                "DEADRECKON_EVO_BIN={} has no evo_rpe",
                dir.display()
            );
            dir
        }
        None => panic!(
            "DEADRECKON_EVO_BIN is not set: these tests run evo. Install it with \
             `python3 -m venv /tmp/evo && /tmp/evo/bin/pip install evo==1.38.1`, then \
             `DEADRECKON_EVO_BIN=/tmp/evo/bin cargo test --profile ci --test evo -- --ignored` \
             (.ci/run does this)"
        ),
    }
}

/// Runs an evo tool with `--save_results`, and returns the saved statistics
/// and error array (read by the environment's Python from the result zip).
fn evo(tool: &str, args: &[&str], work: &Path) -> (Value, Vec<f64>) {
    let bin = evo_bin();
    let zip = work.join(format!(
        "{tool}-{}.zip",
        args.join("_").replace(['/', '.'], "-")
    ));
    // evo keeps its settings in $HOME/.evo: a private home keeps runs apart.
    let home = work.join("home");
    std::fs::create_dir_all(&home).unwrap();
    let out = Command::new(bin.join(tool))
        .args(args)
        .args(["--save_results", zip.to_str().unwrap(), "--no_warnings"])
        .current_dir(work)
        .env("HOME", &home)
        .env("MPLBACKEND", "Agg")
        .output()
        .expect("evo runs");
    assert!(
        out.status.success(),
        "{tool} {args:?} failed:\n{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let script = "import io, json, sys, zipfile\nimport numpy as np\n\
        z = zipfile.ZipFile(sys.argv[1])\n\
        e = np.load(io.BytesIO(z.read('error_array.npy')))\n\
        print(json.dumps({'stats': json.loads(z.read('stats.json')), 'errors': e.tolist()}))\n";
    let out = Command::new(bin.join("python"))
        .args(["-c", script, zip.to_str().unwrap()])
        .output()
        .expect("python runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let errors = v["errors"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    (v["stats"].clone(), errors)
}

/// Our metric, from `evaluate --json`.
fn ours(drive: &Path, extra: &[&str]) -> (Value, Vec<f64>) {
    // The parameters `run` wrote the files with.
    let mut args = vec![
        "evaluate",
        drive.to_str().unwrap(),
        "--params",
        "nominal",
        "--json",
    ];
    args.extend_from_slice(extra);
    let v: Value = serde_json::from_str(&run_ok(&args)).unwrap();
    let errors = v["errors_m"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    (v["stats_m"].clone(), errors)
}

fn assert_same(what: &str, ours: &(Value, Vec<f64>), evo: &(Value, Vec<f64>)) {
    assert_within(what, ours, evo, TOL_M)
}

fn assert_within(
    what: &str,
    (ours_s, ours_e): &(Value, Vec<f64>),
    (evo_s, evo_e): &(Value, Vec<f64>),
    tol_m: f64,
) {
    assert_eq!(ours_e.len(), evo_e.len(), "{what}: number of errors");
    for (k, (a, b)) in ours_e.iter().zip(evo_e).enumerate() {
        assert!((a - b).abs() < tol_m, "{what}: error {k}: ours {a} evo {b}");
    }
    for key in ["rmse", "mean", "median", "std", "min", "max"] {
        let (a, b) = (ours_s[key].as_f64().unwrap(), evo_s[key].as_f64().unwrap());
        assert!((a - b).abs() < tol_m, "{what}: {key}: ours {a} evo {b}");
    }
}

fn write(drive: &Path, out: &Path, track: &str, sync_with: Option<&str>) {
    // Nominal, as `ours` evaluates (run without --params calibrates on the
    // drive, issue 29).
    let mut args = vec![
        "run",
        drive.to_str().unwrap(),
        "--params",
        "nominal",
        "--out",
        out.to_str().unwrap(),
        "--track",
        track,
    ];
    if let Some(w) = sync_with {
        args.extend(["--sync-with", w]);
    }
    run_ok(&args);
}

fn lines(path: &Path) -> usize {
    std::fs::read_to_string(path).unwrap().lines().count()
}

/// The whole comparison on one drive; returns (our RPE rmse, evo's).
fn compare(drive: &Path, work: &Path, label: &str) -> (f64, f64) {
    let f = |n: &str| work.join(n);
    write(drive, &f("dr.tum"), "dead-reckoned", None);
    write(drive, &f("truth.tum"), "truth", None);
    write(drive, &f("filtered.tum"), "filtered", None);

    // RPE per 100 m, pairs from the estimate's path (evo's default).
    let rpe_ours = ours(drive, &["--metric", "rpe"]);
    let rpe_evo = evo(
        "evo_rpe",
        &[
            "tum",
            "truth.tum",
            "dr.tum",
            "--delta",
            "100",
            "--delta_unit",
            "m",
        ],
        work,
    );
    eprintln!(
        "{label}: RPE per 100 m of dead-reckoned vs truth: ours rmse {} over {} pairs, evo {} over {}",
        rpe_ours.0["rmse"],
        rpe_ours.1.len(),
        rpe_evo.0["rmse"],
        rpe_evo.1.len()
    );
    assert!(rpe_ours.1.len() >= 5, "{label}: too few pairs to compare");
    assert_same(&format!("{label} rpe tum"), &rpe_ours, &rpe_evo);

    // Pairs from the reference's path, on the filtered track.
    let ours_ref = ours(
        drive,
        &[
            "--metric",
            "rpe",
            "--track",
            "filtered",
            "--pairs-from",
            "reference",
        ],
    );
    let evo_ref = evo(
        "evo_rpe",
        &[
            "tum",
            "truth.tum",
            "filtered.tum",
            "--delta",
            "100",
            "--delta_unit",
            "m",
            "--pairs_from_reference",
        ],
        work,
    );
    assert_same(
        &format!("{label} rpe filtered, pairs from the reference"),
        &ours_ref,
        &evo_ref,
    );

    // APE, no alignment.
    let ape_ours = ours(drive, &["--metric", "ape"]);
    let ape_evo = evo("evo_ape", &["tum", "truth.tum", "dr.tum"], work);
    assert_same(&format!("{label} ape tum"), &ape_ours, &ape_evo);

    // KITTI: each file synced with the other has as many poses, so evo,
    // which pairs KITTI poses by line, finds the same errors as with TUM.
    write(drive, &f("dr.kitti"), "dead-reckoned", Some("truth"));
    write(drive, &f("truth.kitti"), "truth", Some("dead-reckoned"));
    assert_eq!(lines(&f("dr.kitti")), lines(&f("truth.kitti")));
    assert_eq!(lines(&f("dr.kitti")), rpe_ours_matched(drive));
    assert_eq!(lines(&f("dr.times.txt")), lines(&f("dr.kitti")));
    let rpe_kitti = evo(
        "evo_rpe",
        &[
            "kitti",
            "truth.kitti",
            "dr.kitti",
            "--delta",
            "100",
            "--delta_unit",
            "m",
        ],
        work,
    );
    assert_same(&format!("{label} rpe kitti"), &rpe_ours, &rpe_kitti);
    let ape_kitti = evo("evo_ape", &["kitti", "truth.kitti", "dr.kitti"], work);
    assert_same(&format!("{label} ape kitti"), &ape_ours, &ape_kitti);

    // ROS 2 nav_msgs/Odometry in MCAP, read by evo through rosbags: positions
    // in full precision there (ours are rounded to the micrometre as in the
    // text files, hence the looser bound).
    run_ok(&[
        "run",
        drive.to_str().unwrap(),
        "--params",
        "nominal",
        "--out",
        f("tracks.mcap").to_str().unwrap(),
        "--track",
        "dead-reckoned",
        "--track",
        "truth",
        "--mcap",
        "ros2",
    ]);
    let ape_mcap = evo(
        "evo_ape",
        &[
            "mcap",
            "tracks.mcap",
            "/deadreckon/truth/odom",
            "/deadreckon/dead_reckoned/odom",
        ],
        work,
    );
    assert_within(&format!("{label} ape mcap"), &ape_ours, &ape_mcap, 2e-6);
    (
        rpe_ours.0["rmse"].as_f64().unwrap(),
        rpe_evo.0["rmse"].as_f64().unwrap(),
    )
}

fn rpe_ours_matched(drive: &Path) -> usize {
    let v: Value = serde_json::from_str(&run_ok(&[
        "evaluate",
        drive.to_str().unwrap(),
        "--params",
        "nominal",
        "--metric",
        "ape",
        "--json",
    ]))
    .unwrap();
    v["matched"].as_u64().unwrap() as usize
}

#[test]
#[ignore = "needs evo: run by .ci/run (DEADRECKON_EVO_BIN)"]
fn evo_agrees_on_a_simulated_drive() {
    evo_bin();
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("eval");
    run_ok(&[
        "simulate",
        "--scenario",
        "evaluation",
        "--seed",
        "12",
        "--out",
        drive.to_str().unwrap(),
    ]);
    let (a, b) = compare(&drive, tmp.path(), "simulated evaluation drive, seed 12");
    // Nominal parameters on the simulated car (0.7% off circumferences, a
    // gyro bias) drift 2.31 m per 100 m (rmse) on this drive.
    assert!((a - b).abs() < TOL_M && a > 1.0 && a < 5.0, "{a} {b}");
}

#[test]
#[ignore = "needs evo: run by .ci/run (DEADRECKON_EVO_BIN)"]
fn evo_agrees_on_the_comma2k19_segment() {
    evo_bin();
    let comma = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data/comma2k19-rav4");
    let tmp = tempfile::tempdir().unwrap();
    let drive = tmp.path().join("rav4");
    run_ok(&[
        "import",
        "comma2k19",
        comma,
        "--out",
        drive.to_str().unwrap(),
    ]);
    let (a, b) = compare(&drive, tmp.path(), "comma2k19 segment");
    assert!((a - b).abs() < TOL_M);
}
