//! The hostile inputs of issue 34 that used to pass silently: every file's
//! times in milliseconds at once, a GNSS jump of 1 km mid-drive, a
//! circumference in millimetres in params.toml. Each is refused, or warned
//! about, with the reason.

mod common;

use common::{run, run_err, run_ok, simulated};

/// Rewrites every data row of the CSV `file` with `f(row index, fields)`.
fn rewrite(file: &str, f: impl Fn(usize, &mut Vec<String>)) {
    let text = std::fs::read_to_string(file).unwrap();
    let mut lines = text.lines();
    let mut out = vec![lines.next().unwrap().to_string()];
    for (i, line) in lines.enumerate() {
        let mut fields: Vec<String> = line.split(',').map(str::to_string).collect();
        f(i, &mut fields);
        out.push(fields.join(","));
    }
    std::fs::write(file, out.join("\n") + "\n").unwrap();
}

fn scaled(field: &str, k: f64) -> String {
    (field.parse::<f64>().unwrap() * k).to_string()
}

#[test]
fn every_files_times_in_milliseconds_are_refused_as_milliseconds() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    for f in std::fs::read_dir(&d).unwrap() {
        let p = f.unwrap().path();
        if p.extension().is_some_and(|e| e == "csv") {
            rewrite(p.to_str().unwrap(), |_, r| r[0] = scaled(&r[0], 1000.0));
        }
    }
    let e = run_err(&["calibrate", &d]);
    // Measured: the receiver's speed_mps is 987 times the speed between the fixes.
    assert!(e.contains("(time_unit)"), "{e}");
    assert!(e.contains("every file's times in milliseconds?"), "{e}");
    assert!(e.contains("timestamps run 1000 times too fast"), "{e}");

    // Without a speed read in m/s (no speed.csv, no speed_mps), the wheel
    // rows' interval still says it, as a warning.
    std::fs::remove_file(format!("{d}/speed.csv")).unwrap();
    rewrite(&format!("{d}/gnss.csv"), |_, r| r[5].clear());
    // `events` reads the drive through the same checks, without calibrating
    // the 83-hour drive.
    let r = run(&["events", &d], None);
    assert!(
        r.stderr
            .contains("the wheel rows come every 20.000 s (median)")
            && r.stderr.contains("milliseconds"),
        "{}",
        r.stderr
    );
}

#[test]
fn a_gnss_jump_of_a_kilometre_that_stays_is_refused_with_its_time() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    // Every fix from the 299th (149.1 s) on, 1 km east.
    rewrite(&format!("{d}/gnss.csv"), |i, r| {
        if i >= 298 {
            r[1] = (r[1].parse::<f64>().unwrap() + 1000.0).to_string();
        }
    });
    let e = run_err(&["calibrate", &d]);
    assert!(e.contains("(gnss_jump)"), "{e}");
    assert!(
        e.contains("jumps 1000 m between the fixes at 148.637 and 149.137 s"),
        "{e}"
    );
}

#[test]
fn a_gnss_outlier_a_kilometre_off_is_warned_about_and_gated() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    rewrite(&format!("{d}/gnss.csv"), |i, r| {
        if i == 298 {
            r[1] = (r[1].parse::<f64>().unwrap() + 1000.0).to_string();
        }
    });
    let r = run(&["calibrate", &d], None);
    assert!(r.ok, "{}", r.stderr);
    assert!(
        r.stderr.contains("1 GNSS outlier stretch") && r.stderr.contains("the largest 1000 m"),
        "{}",
        r.stderr
    );
    // The gate rejected it (measured: 2 of 599 fixes rejected, against 1 on
    // the clean drive).
    let filter = r
        .stdout
        .lines()
        .find(|l| l.starts_with("filter:"))
        .unwrap_or_else(|| panic!("{}", r.stdout));
    let rejected: u32 = filter
        .split(" rejected by the gate")
        .next()
        .and_then(|s| s.rsplit(' ').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("{filter}"));
    assert!(rejected >= 1, "{filter}");
}

/// A circumference in millimetres was taken (issue 29): refused, naming the
/// file, the key and both values.
#[test]
fn a_circumference_in_millimetres_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let d = simulated(tmp.path(), "d", "300");
    let p = tmp.path().join("p.toml");
    let p = p.to_str().unwrap();
    run_ok(&["calibrate", &d, "--out", p]);
    let text = std::fs::read_to_string(p).unwrap();
    let mm: String = text
        .lines()
        .map(|l| match l.strip_prefix("circumference_rl_m = ") {
            Some(v) => format!(
                "circumference_rl_m = {}\n",
                v.parse::<f64>().unwrap() * 1000.0
            ),
            None => format!("{l}\n"),
        })
        .collect();
    assert_ne!(mm, text);
    std::fs::write(p, mm).unwrap();
    for args in [
        vec!["evaluate", &d, "--params", p],
        vec!["run", &d, "--params", p, "--out", "-"],
    ] {
        let e = run_err(&args);
        assert!(
            e.contains(p) && e.contains("circumference_rl_m = 19"),
            "{e}"
        );
        assert!(
            e.contains("nominal wheel_circumference_m = 1.92 m (millimetres?)"),
            "{e}"
        );
    }
    let events = run_ok(&["events", &d]);
    let vehicle = format!("{d}/vehicle.toml");
    let r = run(
        &["stream", "--vehicle", &vehicle, "--params", p],
        Some(events.as_bytes()),
    );
    assert!(!r.ok && r.stderr.contains("(millimetres?)"), "{}", r.stderr);
}
