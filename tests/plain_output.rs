//! Output meant for people (issue 34): the text every command prints, on the
//! simulator and on the three real logs, carries no Rust debug formatting
//! (`Some(`, `{ `, `Converged {`, CamelCase enum names) and no `NaN`. A value
//! that was not computed is said in words.

mod common;

use common::{run, Ran};

const COMMA: &str = "../shared/data/comma2k19-rav4";
const HUSKY: &str = "../shared/data/husky-gps-bag/husky_gps.bag";
const TRICYCLE: &str = "../shared/data/tricycle-tracker/dataset.txt";

/// Words with capitals inside that are names, not enum variants.
const NAMES: &[&str] = &["TedriS", "GeoJSON", "MiB", "DataFrame", "McAP"];

/// What in `line` looks like debug formatting, if anything.
fn debug_pattern(line: &str) -> Option<String> {
    for p in ["Some(", "None", "{ ", "Converged {", "NaN", "Ok(", "Err("] {
        if line.contains(p) {
            return Some(format!("`{p}`"));
        }
    }
    // A CamelCase word: a capital, lower-case letters, another capital
    // (`GnssCourse`, `BodyYaw`).
    for word in line.split(|c: char| !c.is_ascii_alphanumeric()) {
        let b = word.as_bytes();
        let camel = b.len() > 3
            && b[0].is_ascii_uppercase()
            && b[1].is_ascii_lowercase()
            && b[2..].iter().any(u8::is_ascii_uppercase)
            && b.iter().all(u8::is_ascii_alphabetic);
        if camel && !NAMES.contains(&word) {
            return Some(format!("the CamelCase word `{word}`"));
        }
    }
    None
}

/// Checks the text of one command; returns the offences found.
fn offences(what: &str, text: &str) -> Vec<String> {
    text.lines()
        .enumerate()
        .filter_map(|(i, line)| {
            debug_pattern(line).map(|p| format!("{what}, line {}: {p} in {line:?}", i + 1))
        })
        .collect()
}

/// Runs one command, asserting that it succeeded, and collects the
/// offences of its standard error and (unless it is JSON lines or a track)
/// its standard output.
fn check(found: &mut Vec<String>, args: &[&str], stdin: Option<&[u8]>, scan_stdout: bool) -> Ran {
    let r = run(args, stdin);
    let what = format!("deadreckon {}", args.join(" "));
    assert!(r.ok, "{what} failed:\n{}", r.stderr);
    if scan_stdout {
        found.extend(offences(&format!("{what} (stdout)"), &r.stdout));
    }
    found.extend(offences(&format!("{what} (stderr)"), &r.stderr));
    r
}

#[test]
fn the_pattern_finder_finds_what_it_should() {
    assert!(debug_pattern("converged (Converged { ftol: true, xtol: false })").is_some());
    assert!(debug_pattern("RMS at the window ends 1.686 m / NaN rad").is_some());
    assert!(debug_pattern("reference heading: GnssCourse").is_some());
    assert!(debug_pattern("IMU vertical Some([0.1, 0.2, 0.9])").is_some());
    assert!(debug_pattern("TedriS checks: 3 courses, GNSS 5 used, RAV4, χ²").is_none());
}

#[test]
fn no_command_prints_debug_formatting_or_nan() {
    let tmp = tempfile::tempdir().unwrap();
    let p = |name: &str| tmp.path().join(name).to_str().unwrap().to_string();
    let (cal, ev, params, model) = (p("cal"), p("ev"), p("p.toml"), p("m.json"));
    let mut found = Vec::new();
    let f = &mut found;
    // The simulator: five minutes of each scenario.
    check(
        f,
        &[
            "simulate",
            "--scenario",
            "calibration",
            "--duration",
            "300",
            "--out",
            &cal,
        ],
        None,
        true,
    );
    check(
        f,
        &[
            "simulate",
            "--scenario",
            "evaluation",
            "--duration",
            "300",
            "--seed",
            "2",
            "--out",
            &ev,
        ],
        None,
        true,
    );
    check(f, &["calibrate", &cal, "--out", &params], None, true);
    check(
        f,
        &["evaluate", &ev, "--params", &params, "--outage", "30"],
        None,
        true,
    );
    check(f, &["evaluate", &ev, "--params", &params], None, true);
    check(
        f,
        &["run", &ev, "--params", &params, "--out", &p("track.csv")],
        None,
        true,
    );
    let events = check(f, &["events", &ev], None, false).stdout;
    let vehicle = format!("{ev}/vehicle.toml");
    check(
        f,
        &["stream", "--vehicle", &vehicle, "--params", &params],
        Some(events.as_bytes()),
        false,
    );
    check(f, &["tedris", "train", &cal, "--out", &model], None, true);
    check(
        f,
        &[
            "tedris", "run", &ev, "--model", &model, "--outage", "100:130",
        ],
        None,
        true,
    );
    check(f, &["batch", &cal, &ev, "--out", &p("b.csv")], None, true);
    // comma2k19: import, calibrate (every correction), evaluate, stream.
    let rav4 = p("rav4");
    let rav4_params = p("rav4.toml");
    check(
        f,
        &["import", "comma2k19", COMMA, "--out", &rav4],
        None,
        true,
    );
    check(f, &["calibrate", &rav4, "--out", &rav4_params], None, true);
    check(
        f,
        &[
            "evaluate",
            &rav4,
            "--params",
            &rav4_params,
            "--outage",
            "10",
        ],
        None,
        true,
    );
    let events = check(f, &["events", &rav4], None, false).stdout;
    let vehicle = format!("{rav4}/vehicle.toml");
    check(
        f,
        &["stream", "--vehicle", &vehicle, "--params", &rav4_params],
        Some(events.as_bytes()),
        false,
    );
    // The Husky bag as a differential drive.
    let husky = p("husky.toml");
    check(
        f,
        &["calibrate", HUSKY, "--shape", "diff-drive", "--out", &husky],
        None,
        true,
    );
    check(
        f,
        &[
            "evaluate",
            HUSKY,
            "--shape",
            "diff-drive",
            "--params",
            &husky,
            "--outage",
            "30",
        ],
        None,
        true,
    );
    // The tricycle.
    let tri = p("tri.toml");
    check(f, &["calibrate", TRICYCLE, "--out", &tri], None, true);
    check(
        f,
        &["evaluate", TRICYCLE, "--params", &tri, "--outage", "30"],
        None,
        true,
    );
    check(
        f,
        &["import", "tricycle", TRICYCLE, "--out", &p("tri")],
        None,
        true,
    );
    assert!(
        found.is_empty(),
        "debug formatting in the output:\n{}",
        found.join("\n")
    );
}
