//! What the command line prints when it fails: each cause once, the file the
//! user named (not a temporary file).

use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_deadreckon"))
}

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
