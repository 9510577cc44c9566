//! What a calibration drive contained and lacked (issue 13): the inventory of
//! `deadreckon_core::observability` on simulated drives with a known route.

use deadreckon_core::observability::{manoeuvres, MIN_STOP_S};
use deadreckon_sim::{simulate, Scenario};

#[test]
fn the_built_in_calibration_drive_lacks_nothing_and_its_stops_are_counted() {
    let sim = simulate(&Scenario::builtin("calibration").unwrap(), 1).unwrap();
    let m = manoeuvres(&sim.drive, 2.0);
    // Measured on seed 1: 935 s, 807 s above 2 m/s, 130 s left, 121 s right,
    // 556 s straight, 10 stops.
    assert!(m.lacking().is_empty(), "{:?}", m.lacking());
    let true_stops = sim
        .stats
        .stops
        .iter()
        .filter(|s| s.1 >= MIN_STOP_S + 0.5)
        .count();
    assert_eq!(m.stops, true_stops, "{m:?} vs {:?}", sim.stats.stops);
    assert!(m.left_turn_s > 100.0 && m.right_turn_s > 100.0, "{m:?}");
    assert!((m.duration_s - sim.stats.duration_s).abs() < 1.0, "{m:?}");
}

#[test]
fn its_first_minute_lacks_turns_straights_and_time_at_speed() {
    let sim = simulate(&Scenario::builtin("calibration").unwrap(), 1).unwrap();
    let short = sim.drive.time_range(None, Some(60.0));
    let m = manoeuvres(&short, 2.0);
    let lacks = m.lacking();
    let said = |w: &str| lacks.iter().any(|l| l.what.contains(w));
    assert!(said("above the speed threshold"), "{lacks:?}");
    // Measured: 32 s above 2 m/s, 4 s of turns each way, 24 s straight.
    for w in ["left turns", "right turns", "straight driving"] {
        assert!(said(w), "{w}: {lacks:?}");
    }
    // Every lack names the parameters it weakens.
    assert!(lacks.iter().all(|l| !l.weakens.is_empty()));
}
