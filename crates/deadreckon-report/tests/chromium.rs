//! Opens a full synthetic report in headless Chromium through
//! `tests/report_chromium.sh` (at the workspace root): every figure must draw data
//! and the page must log no error. Needs Debian's `chromium`, so it is ignored by
//! default: `cargo test -p deadreckon-report --test chromium -- --ignored`.

use std::path::Path;
use std::process::Command;

#[test]
#[ignore = "needs Debian's chromium (apt-get install -y chromium); run with --ignored"]
fn the_sample_report_draws_every_figure_in_headless_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let html = dir.path().join("report.html");
    let png = dir.path().join("report.png");
    deadreckon_report::write_report(&html, &deadreckon_report::sample::sample_input(600.0))
        .unwrap();
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/report_chromium.sh");
    let out = Command::new("bash")
        .arg(&script)
        .arg(&html)
        .arg(&png)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{script:?} failed:\n{stdout}\n{stderr}"
    );
    // 22 since the outage bound figure (issue 31), 24 since the error
    // against time and distance (issue 34).
    assert!(stdout.contains("selfcheck: ok=true figures=24"), "{stdout}");
    assert!(
        png.metadata().unwrap().len() > 10_000,
        "screenshot too small"
    );
}
