//! The drive metadata keys of `vehicle.toml`: `vehicle_id` and `recorded_at`.

use deadreckon_core::Vehicle;
use deadreckon_io::{read_vehicle, write_vehicle};

#[test]
fn vehicle_id_and_recorded_at_round_trip_and_are_optional() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("vehicle.toml");
    let mut v = Vehicle::paper_car();
    write_vehicle(&path, &v).expect("written");
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(!text.contains("vehicle_id") && !text.contains("recorded_at"));
    assert_eq!(read_vehicle(&path).expect("read").vehicle_id, None);
    v.vehicle_id = Some("fleet car \"7\"".into());
    v.recorded_at = Some("2026-03-01T08:30:00Z".into());
    v.noise.gyro_rps = 0.004;
    write_vehicle(&path, &v).expect("written");
    assert_eq!(read_vehicle(&path).expect("read"), v);
}

#[test]
fn bad_recorded_at_names_the_file_and_the_format() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("vehicle.toml");
    std::fs::write(
        &path,
        "wheelbase_m = 2.6\ntrack_front_m = 1.5\ntrack_rear_m = 1.5\ngnss_lever_arm_m = 0\n\
         ticks_per_rev = 96\nwheel_circumference_m = 1.9\nsteering_ratio = 16\n\
         vehicle_id = \"car-1\"\nrecorded_at = \"01/03/2026\"\n",
    )
    .expect("file");
    let e = read_vehicle(&path).expect_err("bad date").to_string();
    assert!(
        e.contains("vehicle.toml") && e.contains("YYYY-MM-DD"),
        "{e}"
    );
    // A TOML date-time literal (unquoted) is a type error with its line.
    std::fs::write(
        &path,
        "wheelbase_m = 2.6\ntrack_front_m = 1.5\ntrack_rear_m = 1.5\ngnss_lever_arm_m = 0\n\
         ticks_per_rev = 96\nwheel_circumference_m = 1.9\nsteering_ratio = 16\n\
         recorded_at = 2026-03-01\n",
    )
    .expect("file");
    let e = read_vehicle(&path).expect_err("unquoted date").to_string();
    assert!(e.contains("vehicle.toml") && e.contains("line 8"), "{e}");
}
