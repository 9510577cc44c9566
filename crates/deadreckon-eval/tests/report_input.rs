//! The report's input built from a drive: what cannot be computed is listed
//! with its reason, not dropped.

use deadreckon_eval::report::{calibrations, four_wheel_input, Source};
use deadreckon_sim::{simulate, Scenario};

#[test]
fn a_failed_calibration_silently_vanished_from_the_report() {
    let mut drive = simulate(&Scenario::builtin("evaluation").unwrap(), 3)
        .unwrap()
        .drive
        .time_range(None, Some(60.0));
    // No reference: the truth calibration cannot be made.
    drive.truth.clear();
    let c = calibrations(&drive, &());
    let sources: Vec<Source> = c.sets.iter().map(|s| s.source).collect();
    assert!(sources.contains(&Source::Nominal) && sources.contains(&Source::Rts));
    assert!(!sources.contains(&Source::Truth), "{sources:?}");
    let truth = c
        .skipped
        .iter()
        .find(|s| s.what == "truth calibration")
        .expect("the truth calibration listed as skipped");
    assert!(truth.reason.contains("truth"), "{}", truth.reason);
    // Every calibration is either a set or a skipped entry with a reason.
    assert_eq!(c.sets.len() - 1 + c.skipped.len(), 3);
    assert!(c.skipped.iter().all(|s| !s.reason.is_empty()));

    let input = four_wheel_input(&drive, &c, None, &()).unwrap();
    assert_eq!(input.not_computed[..c.skipped.len()], c.skipped[..]);
    let html = tempfile::tempdir().unwrap();
    let path = html.path().join("r.html");
    deadreckon_report::write_report(&path, &input).unwrap();
    let page = std::fs::read_to_string(&path).unwrap();
    assert!(page.contains("Not computed"), "no section");
    assert!(page.contains("truth calibration: "), "no reason given");
}
