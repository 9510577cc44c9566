//! Issue 30, item 1: one car calibration. What `calibrate --out` writes
//! (`CarCalibration::write`) reads back through the one reader
//! (`ParamsFile::read`) as the same parameters, standard errors, vehicle,
//! stored corrections and bound, every table equal to what was written;
//! and the `--json` object is the type's `Serialize`.

use deadreckon_api::calibrate::Export;
use deadreckon_api::calibration::{calibrate, CalibrationRequest, ParamStatus};
use deadreckon_api::params_file::ParamsFile;
use deadreckon_core::timing::Which;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

#[test]
fn what_calibrate_writes_reads_back_through_the_one_reader() {
    let family = CarFamily::draw(301);
    let sim = simulate(&family.drive(1301, 300.0), 1301).expect("simulated");
    let car = calibrate(
        &sim.drive,
        &CalibrationRequest::with_corrections(Which::All),
        "the drive",
    )
    .expect("calibrated");
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("params.toml");
    car.write(&path, Export::Params, &sim.drive.vehicle.noise, "the drive")
        .expect("written");
    let back = ParamsFile::read(&path.to_string_lossy()).expect("read back");
    // Written and read through the same type: what was written reads back
    // equal, tables and all.
    let written = car
        .params_file(&path.to_string_lossy())
        .expect("a valid file");
    assert_eq!(back, written);
    assert_eq!(back.estimate, car.calibration.estimate);
    assert_eq!(back.vehicle(), Some(&car.vehicle));
    assert_eq!(back.bound, car.bound);
    // The corrections applied are those stored: applying the stored ones
    // to the raw drive gives the drive the calibration ran on.
    let stored = deadreckon_api::corrections::stored_corrections(&car.params_extra()).unwrap();
    assert_eq!(back.corrections, stored);
    assert!(!back.corrections.is_empty(), "{:?}", car.corrections);
    assert_eq!(back.tables.method.as_deref(), Some("rts"));
    assert_eq!(back.tables.iterations, Some(car.calibration.iterations));
    assert!(back.tables.delays.is_some());
    // The --json object is the type's serde projection.
    assert_eq!(serde_json::to_value(&car).unwrap(), car.json());
    // Status: the one rule, and the JSON's not_estimated agrees.
    let json = car.json();
    for (name, s) in deadreckon_core::Params::NAMES.iter().zip(car.status()) {
        let listed = json["not_estimated"].get(*name).is_some();
        assert_eq!(listed, s == ParamStatus::NotEstimated, "{name}");
    }
}
