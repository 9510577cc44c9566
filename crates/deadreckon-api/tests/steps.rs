//! The commands' steps in `deadreckon-api`, called as the command line and
//! Python call them, on a short seeded simulated drive.

use deadreckon_api::evaluate::{self, Metric};
use deadreckon_api::load::{self, Loader};
use deadreckon_api::{kinematic, stream, tracks};
use deadreckon_core::ekf::{FilterOptions, Timing};
use deadreckon_io::TrackFormat;

/// A 120 s drive of the calibration scenario, seed 7, written and read back.
fn drive(dir: &std::path::Path) -> deadreckon_core::Drive {
    let sc = load::scenario("calibration")
        .unwrap()
        .with_duration_s(120.0);
    load::write_simulated(sc, "calibration", 7, dir).unwrap();
    Loader::default().drive(dir).unwrap()
}

#[test]
fn the_range_rule_names_the_options_as_the_caller_spells_them() {
    assert!(load::check_range(Some(1.0), Some(2.0)).is_ok());
    assert!(load::check_range(None, Some(-2.0)).is_ok());
    assert_eq!(
        load::check_range(Some(5.0), Some(1.0))
            .unwrap_err()
            .to_string(),
        "--from 5 must be before --until 1"
    );
    assert_eq!(
        load::check_range_named(Some(1.0), Some(1.0), ["from_s", "until_s"])
            .unwrap_err()
            .to_string(),
        "from_s 1 must be before until_s 1"
    );
    assert_eq!(
        load::check_range(Some(f64::NAN), None)
            .unwrap_err()
            .to_string(),
        "--from / --until must be finite, got NaN"
    );
}

#[test]
fn the_loader_keeps_the_checks_verdict_and_the_span_of_the_last_drive() {
    let dir = tempfile::tempdir().unwrap();
    let d = drive(&dir.path().join("d"));
    let (t0, t1) = d.time_span().unwrap();
    let l = Loader::default();
    assert!(l.checks().time_span_s.is_none());
    l.drive(&dir.path().join("d")).unwrap();
    assert_eq!(l.checks().time_span_s, Some((t0, t1)));
    assert!(!l.checks().skipped);
    let cut = load::cut(d, Some(t0 + 30.0), Some(t0 + 60.0)).unwrap();
    let (c0, c1) = cut.time_span().unwrap();
    assert!(c0 >= t0 + 30.0 && c1 < t0 + 60.0, "{c0} {c1}");
}

#[test]
fn a_stream_prior_keeps_the_default_where_the_file_fixes_a_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let d = drive(&dir.path().join("d"));
    let start = stream::start_params("nominal", &d.vehicle).unwrap();
    let p = start.params;
    assert_eq!(p, deadreckon_core::Params::nominal(&d.vehicle));
    assert_eq!(start.prior, stream::default_prior());
    assert!(start.stored.is_empty());
    assert_eq!(start.bound, deadreckon_core::bound::BoundFit::FILTER);
    // A file whose gyro bias std is 0 and speed-scale std is 1e-4.
    let mut std = deadreckon_core::Params::from_array([0.0; 6]);
    std.speed_scale = 1e-4;
    let f = dir.path().join("p.toml");
    deadreckon_io::write_params(&f, &deadreckon_core::ParamsWithStd { params: p, std }, None)
        .unwrap();
    let prior = stream::start_params(f.to_str().unwrap(), &d.vehicle)
        .unwrap()
        .prior;
    assert_eq!(prior.speed_scale, 1e-4);
    assert_eq!(prior.gyro_bias_rps, stream::default_prior().gyro_bias_rps);
}

#[test]
fn one_track_formats_refuse_several_tracks_and_name_those_there_are() {
    let dir = tempfile::tempdir().unwrap();
    let d = drive(&dir.path().join("d"));
    let params = deadreckon_core::Params::nominal(&d.vehicle);
    let all = tracks::drive_tracks(&d, &params, &FilterOptions::default(), None).unwrap();
    let names: Vec<&str> = all.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["dead-reckoned", "filtered", "smoothed", "truth"]);
    let out = dir.path().join("t.tum");
    let e = tracks::select(all.clone(), &Default::default(), &out, TrackFormat::Tum).unwrap_err();
    assert!(
        e.to_string().ends_with("holds one track: choose it with --track NAME (dead-reckoned, filtered, smoothed, truth)"),
        "{e}"
    );
    let s = tracks::Selection {
        names: vec!["truth".into(), "filtered".into()],
        ..Default::default()
    };
    let chosen =
        tracks::select(all.clone(), &s, &dir.path().join("t.csv"), TrackFormat::Csv).unwrap();
    assert_eq!(chosen[0].name, "truth");
    assert_eq!(chosen[1].name, "filtered");
}

#[test]
fn evaluate_reports_the_parameters_it_measured_with() {
    let dir = tempfile::tempdir().unwrap();
    let d = drive(&dir.path().join("d"));
    let (p, d) = evaluate::given_parameters("nominal", d).unwrap();
    let ev = evaluate::measure(
        &d,
        p,
        Timing::WheelEpochs,
        Metric::Drift { segment_m: 100.0 },
    )
    .unwrap();
    let v = ev.json();
    assert_eq!(v["params"], "nominal");
    let lines = ev.lines();
    assert!(lines[0].starts_with("drift per 100 m over "), "{lines:?}");
    assert!(
        lines[1].starts_with("rejected by the χ² gates: "),
        "{lines:?}"
    );
}

#[test]
fn a_car_drive_is_not_a_tricycle_and_a_kinematic_method_must_fit_the_shape() {
    let dir = tempfile::tempdir().unwrap();
    let d = drive(&dir.path().join("d"));
    assert!(!kinematic::is_tricycle_log(&dir.path().join("d")));
    // The simulated car has no odometry twist: not a differential drive.
    let o = kinematic::CalibrateOptions {
        method: Some("rts"),
        ..Default::default()
    };
    let e = kinematic::calibrate_diff(
        &d,
        dir.path(),
        deadreckon_core::kinematics::diff_drive::YawSource::Gyro,
        &o,
    )
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "a differential drive is calibrated against its GNSS fixes with --method gnss (got `rts`)"
    );
}
