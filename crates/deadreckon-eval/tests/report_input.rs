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

    let input = four_wheel_input(&drive, &c, None, None, &()).unwrap();
    assert_eq!(input.not_computed[..c.skipped.len()], c.skipped[..]);
    let html = tempfile::tempdir().unwrap();
    let path = html.path().join("r.html");
    deadreckon_report::write_report(&path, &input).unwrap();
    let page = std::fs::read_to_string(&path).unwrap();
    assert!(page.contains("Not computed"), "no section");
    assert!(page.contains("truth calibration: "), "no reason given");
}

/// `demo` printed one TedriS-vs-four-wheel table and its report showed other
/// windows and other numbers (e.g. 151.6:231.6 printed, 120–200 s reported).
/// The report's outage curves are now the comparison's own errors.
#[test]
fn the_demo_printed_one_comparison_and_reported_another() {
    use deadreckon_eval::compare::{compare, default_windows};
    use deadreckon_eval::report::tedris_from_model;
    let drive = simulate(&Scenario::builtin("tedris-car").unwrap(), 7)
        .unwrap()
        .drive;
    let windows = default_windows(&drive, 80.0).unwrap();
    assert_eq!(windows.len(), 3);
    let c = compare(&drive, &windows, None, None).unwrap();
    let t = tedris_from_model(&drive, &c.model, &c).unwrap();
    assert_eq!(t.outages.len(), c.rows.len());
    let (t0, _) = drive.time_span().unwrap();
    for ((o, four_wheel, tedris), run) in c.rows.iter().zip(&t.outages) {
        assert_eq!(
            run.name,
            format!("outage {:.0}–{:.0} s", o.start_s - t0, o.end_s - t0)
        );
        for (name, row) in [("TedriS", tedris), ("four-wheel", four_wheel)] {
            let row = row.as_ref().expect("both methods ran");
            let s = run
                .series
                .iter()
                .find(|s| s.method == name)
                .unwrap_or_else(|| panic!("no {name} curve in {}", run.name));
            // The printed final, largest and mean errors are the curve's.
            assert_eq!(
                s.error_m.last().copied(),
                Some(row.final_m()),
                "{name} {}",
                run.name
            );
            let max = s.error_m.iter().copied().fold(f64::NAN, f64::max);
            assert_eq!(max, row.max_m(), "{name} {}", run.name);
            let mean = s.error_m.iter().sum::<f64>() / s.error_m.len() as f64;
            assert!((mean - row.mean_m()).abs() < 1e-12, "{name} {}", run.name);
            // The four-wheel filter's last epoch may fall 0.04 s after the end.
            let len = o.end_s - o.start_s + 0.05;
            assert!(
                s.t_s.iter().all(|&dt| (0.0..=len).contains(&dt)),
                "{name}: {:?} .. {:?}",
                s.t_s.first(),
                s.t_s.last()
            );
        }
    }
}
