//! Drive directories: round trips, and one test per validation error.

mod common;

use std::path::Path;

use common::{put, small_drive, small_drive_speeds};
use deadreckon_core::drive::Wheels;
use deadreckon_core::vehicle::Origin;
use deadreckon_io::{
    files, geo, read_drive, read_drive_with, write_drive, IoError, ReadOptions, WheelFile,
};

fn written(drive: &deadreckon_core::Drive) -> tempfile::TempDir {
    let dir = tempfile::tempdir().expect("temp dir");
    write_drive(dir.path(), drive).expect("drive written");
    dir
}

/// Reads `dir`, expecting an error; returns it with its message.
fn read_err(dir: &Path) -> (IoError, String) {
    match read_drive(dir) {
        Ok(_) => panic!("expected an error"),
        Err(e) => {
            let msg = e.to_string();
            (e, msg)
        }
    }
}

fn assert_mentions(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} should mention {p:?}");
    }
}

#[test]
fn round_trip_ticks_is_exact() {
    let drive = small_drive();
    let dir = written(&drive);
    assert_eq!(read_drive(dir.path()).expect("read back"), drive);
}

#[test]
fn round_trip_speeds_is_exact() {
    let drive = small_drive_speeds();
    let dir = written(&drive);
    assert!(!dir.path().join(files::WHEEL_TICKS).exists());
    assert_eq!(read_drive(dir.path()).expect("read back"), drive);
}

#[test]
fn round_trip_minimal_drive_omits_empty_streams_and_columns() {
    let mut drive = small_drive();
    drive.yaw_rate.clear();
    drive.speed.clear();
    drive.steering.clear();
    drive.truth.clear();
    for g in &mut drive.gnss {
        g.course_deg = None;
        g.speed_mps = None;
    }
    let dir = written(&drive);
    for f in [files::YAW_RATE, files::SPEED, files::STEERING, files::TRUTH] {
        assert!(!dir.path().join(f).exists(), "{f} should be omitted");
    }
    let gnss = std::fs::read_to_string(dir.path().join(files::GNSS)).expect("gnss");
    assert!(gnss.starts_with("t_s,east_m,north_m,std_m\n"), "{gnss}");
    assert_eq!(read_drive(dir.path()).expect("read back"), drive);
}

#[test]
fn rewriting_removes_stale_stream_files() {
    let dir = written(&small_drive());
    let mut ticks_only = small_drive_speeds();
    ticks_only.gnss.clear();
    write_drive(dir.path(), &ticks_only).expect("rewritten");
    assert!(!dir.path().join(files::WHEEL_TICKS).exists());
    assert!(!dir.path().join(files::GNSS).exists());
    assert_eq!(read_drive(dir.path()).expect("read back"), ticks_only);
}

#[test]
fn lat_lon_files_match_east_north_within_a_millimetre() {
    let drive = small_drive();
    let origin = Origin {
        lat_deg: 49.4,
        lon_deg: 2.8,
        height_m: 0.0,
    };
    // Spread the positions over about a kilometre.
    let mut drive = drive;
    for (i, g) in drive.gnss.iter_mut().enumerate() {
        g.east_m = 400.0 * i as f64 - 300.0;
        g.north_m = 250.0 * i as f64 + 20.0;
    }
    let dir = written(&drive);
    let mut gnss = String::from("course_deg,t_s,lat_deg,lon_deg,std_m,speed_mps\n");
    for g in &drive.gnss {
        let (lat, lon) = geo::en_to_geodetic(&origin, g.east_m, g.north_m);
        let course = g.course_deg.map(|c| c.to_string()).unwrap_or_default();
        let speed = g.speed_mps.map(|c| c.to_string()).unwrap_or_default();
        gnss += &format!("{course},{},{lat},{lon},{},{speed}\n", g.t_s, g.std_m);
    }
    put(dir.path(), files::GNSS, &gnss);
    let mut truth = String::from("t_s,lat_deg,lon_deg,yaw_rad\n");
    for t in &drive.truth {
        let (lat, lon) = geo::en_to_geodetic(&origin, t.east_m, t.north_m);
        truth += &format!("{},{lat},{lon},{}\n", t.t_s, t.yaw_rad);
    }
    put(dir.path(), files::TRUTH, &truth);

    // With [origin] in vehicle.toml.
    let mut with_origin = drive.clone();
    with_origin.vehicle.origin = Some(origin);
    deadreckon_io::write_vehicle(&dir.path().join(files::VEHICLE), &with_origin.vehicle)
        .expect("vehicle");
    let back = read_drive(dir.path()).expect("lat/lon drive");
    assert_eq!(back.vehicle.origin, Some(origin));
    for (a, b) in back.gnss.iter().zip(&drive.gnss) {
        assert!(
            (a.east_m - b.east_m).abs() < 1e-3,
            "{} vs {}",
            a.east_m,
            b.east_m
        );
        assert!((a.north_m - b.north_m).abs() < 1e-3);
        assert_eq!(
            (a.t_s, a.course_deg, a.speed_mps),
            (b.t_s, b.course_deg, b.speed_mps)
        );
    }
    for (a, b) in back.truth.iter().zip(&drive.truth) {
        assert!((a.east_m - b.east_m).abs() < 1e-3);
        assert!((a.north_m - b.north_m).abs() < 1e-3);
        assert_eq!(a.yaw_rad, b.yaw_rad);
    }

    // Without [origin]: the first GNSS fix is the origin, and is recorded.
    deadreckon_io::write_vehicle(&dir.path().join(files::VEHICLE), &drive.vehicle)
        .expect("vehicle");
    let back = read_drive(dir.path()).expect("lat/lon drive");
    let first = back.vehicle.origin.expect("origin recorded");
    let (lat0, lon0) = geo::en_to_geodetic(&origin, drive.gnss[0].east_m, drive.gnss[0].north_m);
    assert!((first.lat_deg - lat0).abs() < 1e-12 && (first.lon_deg - lon0).abs() < 1e-12);
    assert!(back.gnss[0].east_m.abs() < 1e-9 && back.gnss[0].north_m.abs() < 1e-9);
    // Distances are kept (the frames differ by a rotation of about 5e-5 rad).
    let d = (back.gnss[2].east_m - back.gnss[0].east_m)
        .hypot(back.gnss[2].north_m - back.gnss[0].north_m);
    assert!((d - 800f64.hypot(500.0)).abs() < 0.01, "{d}");
}

#[test]
fn lat_lon_truth_without_origin_but_east_north_gnss_is_refused() {
    let drive = small_drive();
    let dir = written(&drive);
    put(
        dir.path(),
        files::TRUTH,
        "t_s,lat_deg,lon_deg,yaw_rad\n100,49,2,0\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::NeedsOrigin { .. }), "{e:?}");
    assert_mentions(&msg, &["truth.csv", "origin"]);
}

#[test]
fn columns_are_found_by_name_and_extra_columns_ignored() {
    let drive = small_drive();
    let dir = written(&drive);
    put(
        dir.path(),
        files::WHEEL_TICKS,
        "rr, note ,fl,t_s,fr,rl\n3,a,0,0.5,1,0\n3,b,1,0.52,2,-1\n",
    );
    let back = read_drive(dir.path()).expect("shuffled columns");
    match back.wheels {
        Wheels::Ticks(v) => {
            assert_eq!(v.len(), 2);
            assert_eq!(
                (v[1].t_s, v[1].fl, v[1].fr, v[1].rl, v[1].rr),
                (0.52, 1, 2, -1, 3)
            );
        }
        Wheels::Speeds(_) => panic!("ticks expected"),
    }
}

#[test]
fn utf8_bom_and_blank_lines_are_accepted() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::SPEED,
        "\u{feff}t_s,speed_mps\n\n100,1\n\n100.5,2\n",
    );
    let back = read_drive(dir.path()).expect("BOM");
    assert_eq!(back.speed.len(), 2);
}

#[test]
fn header_only_optional_stream_is_empty() {
    let dir = written(&small_drive());
    put(dir.path(), files::STEERING, "t_s,steering_wheel_rad\n");
    assert!(read_drive(dir.path())
        .expect("empty stream")
        .steering
        .is_empty());
}

#[test]
fn both_wheel_files_are_ambiguous_unless_an_option_picks_one() {
    let dir = written(&small_drive());
    let speeds = small_drive_speeds();
    let other = written(&speeds);
    std::fs::copy(
        other.path().join(files::WHEEL_SPEEDS),
        dir.path().join(files::WHEEL_SPEEDS),
    )
    .expect("copy");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::AmbiguousWheels { .. }), "{e:?}");
    assert_mentions(&msg, &["wheel_ticks.csv", "wheel_speeds.csv"]);
    let opts = ReadOptions::default().prefer_wheels(WheelFile::Speeds);
    let back = read_drive_with(dir.path(), &opts).expect("speeds picked");
    assert_eq!(back.wheels, speeds.wheels);
    let opts = ReadOptions::default().prefer_wheels(WheelFile::Ticks);
    let back = read_drive_with(dir.path(), &opts).expect("ticks picked");
    assert_eq!(back.wheels, small_drive().wheels);
}

#[test]
fn error_missing_wheel_file() {
    let dir = written(&small_drive());
    std::fs::remove_file(dir.path().join(files::WHEEL_TICKS)).expect("removed");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::MissingFile { .. }), "{e:?}");
    assert_mentions(&msg, &["wheel_ticks.csv", "wheel_speeds.csv"]);
}

#[test]
fn error_missing_vehicle_toml() {
    let dir = written(&small_drive());
    std::fs::remove_file(dir.path().join(files::VEHICLE)).expect("removed");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::MissingFile { .. }), "{e:?}");
    assert_mentions(&msg, &["vehicle.toml"]);
}

#[test]
fn whitespace_around_fields_is_trimmed_and_a_blank_optional_field_is_empty() {
    let drive = small_drive();
    let dir = written(&drive);
    put(
        dir.path(),
        files::WHEEL_TICKS,
        " t_s ,\tfl, fr ,rl,rr\n 0.5 ,0, 1 ,\t0,3\n0.52 , 1,2,-1 , 3\n",
    );
    put(
        dir.path(),
        files::GNSS,
        "t_s,east_m,north_m,std_m,course_deg\n0.5, 1.5 ,2,0.8,  \n0.6,1.6,2, 0.8 ,\t90 \n",
    );
    let back = read_drive(dir.path()).expect("padded fields");
    match back.wheels {
        Wheels::Ticks(v) => assert_eq!(
            (v[1].t_s, v[1].fl, v[1].fr, v[1].rl, v[1].rr),
            (0.52, 1, 2, -1, 3)
        ),
        Wheels::Speeds(_) => panic!("ticks expected"),
    }
    assert_eq!(back.gnss.len(), 2);
    assert_eq!((back.gnss[0].east_m, back.gnss[0].course_deg), (1.5, None));
    assert_eq!(back.gnss[1].course_deg, Some(90.0));
}

#[test]
fn error_bad_number() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::YAW_RATE,
        "t_s,yaw_rate_rps\n0,0.1\n0.1,0.2x\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::BadNumber { line: 3, .. }), "{e:?}");
    assert_mentions(&msg, &["yaw_rate.csv", "line 3", "yaw_rate_rps", "0.2x"]);
}

#[test]
fn error_float_in_integer_tick_column() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::WHEEL_TICKS,
        "t_s,fl,fr,rl,rr\n0,1,1,1,1\n0.02,1,3.5,1,1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::BadNumber { line: 3, .. }), "{e:?}");
    assert_mentions(&msg, &["wheel_ticks.csv", "line 3", "`fr`", "integer"]);
}

#[test]
fn error_empty_required_field() {
    let dir = written(&small_drive());
    put(dir.path(), files::SPEED, "t_s,speed_mps\n0,\n");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::BadNumber { line: 2, .. }), "{e:?}");
    assert_mentions(&msg, &["speed.csv", "line 2", "speed_mps"]);
}

#[test]
fn error_nan() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::GNSS,
        "t_s,east_m,north_m,std_m\n0,1,2,0.1\n1,NaN,2,0.1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::NonFinite { line: 3, .. }), "{e:?}");
    assert_mentions(&msg, &["gnss.csv", "line 3", "east_m", "NaN"]);
}

#[test]
fn error_infinite_time() {
    let dir = written(&small_drive());
    put(dir.path(), files::SPEED, "t_s,speed_mps\ninf,1\n");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::NonFinite { line: 2, .. }), "{e:?}");
    assert_mentions(&msg, &["speed.csv", "line 2", "t_s"]);
}

#[test]
fn error_unsorted_time() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::SPEED,
        "t_s,speed_mps\n0,1\n0.2,1\n0.1,1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(
        matches!(e, IoError::TimeNotIncreasing { line: 4, .. }),
        "{e:?}"
    );
    assert_mentions(&msg, &["speed.csv", "line 4", "t_s", "is before", "0.2"]);
}

#[test]
fn error_duplicate_time() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::SPEED,
        "t_s,speed_mps\n0,1\n0.1,1\n0.1,1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(
        matches!(e, IoError::TimeNotIncreasing { line: 4, .. }),
        "{e:?}"
    );
    assert_mentions(&msg, &["speed.csv", "line 4", "t_s", "duplicates"]);
}

#[test]
fn error_missing_column() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::TRUTH,
        "t_s,east_m,north_m,speed_mps\n0,0,0,1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::MissingColumn { .. }), "{e:?}");
    assert_mentions(&msg, &["truth.csv", "line 1", "yaw_rad"]);
}

#[test]
fn error_duplicate_column() {
    let dir = written(&small_drive());
    put(dir.path(), files::SPEED, "t_s,speed_mps,t_s\n0,1,0\n");
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::DuplicateColumn { .. }), "{e:?}");
    assert_mentions(&msg, &["speed.csv", "line 1", "t_s"]);
}

#[test]
fn error_wrong_field_count() {
    let dir = written(&small_drive());
    put(dir.path(), files::SPEED, "t_s,speed_mps\n0,1\n0.1,1,7\n");
    let (e, msg) = read_err(dir.path());
    assert!(
        matches!(
            e,
            IoError::WrongFieldCount {
                line: 3,
                expected: 2,
                found: 3,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&msg, &["speed.csv", "line 3"]);
}

#[test]
fn error_too_few_wheel_rows() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::WHEEL_TICKS,
        "t_s,fl,fr,rl,rr\n0,1,1,1,1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(
        matches!(
            e,
            IoError::TooFewRows {
                found: 1,
                min: 2,
                ..
            }
        ),
        "{e:?}"
    );
    assert_mentions(&msg, &["wheel_ticks.csv"]);
}

#[test]
fn error_degrees_in_yaw_rate() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::YAW_RATE,
        "t_s,yaw_rate_rps\n0,0.1\n0.1,-12.5\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::OutOfRange { line: 3, .. }), "{e:?}");
    assert_mentions(
        &msg,
        &["yaw_rate.csv", "line 3", "yaw_rate_rps", "degrees/s"],
    );
}

#[test]
fn error_degrees_in_steering() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::STEERING,
        "t_s,steering_wheel_rad\n0,12.5\n0.1,-90\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::OutOfRange { line: 3, .. }), "{e:?}");
    assert_mentions(
        &msg,
        &["steering.csv", "line 3", "steering_wheel_rad", "degrees"],
    );
}

#[test]
fn error_degrees_in_truth_yaw() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::TRUTH,
        "t_s,east_m,north_m,yaw_rad\n0,0,0,6.29\n1,0,0,45\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::OutOfRange { line: 3, .. }), "{e:?}");
    assert_mentions(&msg, &["truth.csv", "line 3", "yaw_rad", "degrees"]);
}

#[test]
fn error_out_of_range_gnss_columns() {
    let cases = [
        ("t_s,east_m,north_m,std_m\n0,0,0,0\n", "std_m"),
        ("t_s,east_m,north_m,std_m\n0,0,0,1500\n", "std_m"),
        (
            "t_s,east_m,north_m,std_m,course_deg\n0,0,0,1,-181\n",
            "course_deg",
        ),
        (
            "t_s,east_m,north_m,std_m,course_deg\n0,0,0,1,361\n",
            "course_deg",
        ),
        (
            "t_s,east_m,north_m,std_m,speed_mps\n0,0,0,1,120\n",
            "speed_mps",
        ),
        ("t_s,lat_deg,lon_deg,std_m\n0,91,0,1\n", "lat_deg"),
        ("t_s,lat_deg,lon_deg,std_m\n0,45,-181,1\n", "lon_deg"),
    ];
    let dir = written(&small_drive());
    for (text, column) in cases {
        put(dir.path(), files::GNSS, text);
        let (e, msg) = read_err(dir.path());
        assert!(matches!(e, IoError::OutOfRange { line: 2, .. }), "{e:?}");
        assert_mentions(&msg, &["gnss.csv", "line 2", column]);
    }
    // Negative course down to -180 is accepted as given.
    put(
        dir.path(),
        files::GNSS,
        "t_s,east_m,north_m,std_m,course_deg\n0,0,0,1,-180\n",
    );
    let back = read_drive(dir.path()).expect("course -180");
    assert_eq!(back.gnss[0].course_deg, Some(-180.0));
}

#[test]
fn error_km_per_hour_in_wheel_speeds() {
    let dir = written(&small_drive_speeds());
    put(
        dir.path(),
        files::WHEEL_SPEEDS,
        "t_s,fl_mps,fr_mps,rl_mps,rr_mps\n0,1,1,1,1\n1,1,1,1,130\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::OutOfRange { line: 3, .. }), "{e:?}");
    assert_mentions(&msg, &["wheel_speeds.csv", "line 3", "rr_mps", "km/h"]);
}

#[test]
fn error_bad_toml_in_vehicle() {
    let dir = written(&small_drive());
    put(
        dir.path(),
        files::VEHICLE,
        "wheelbase_m = 2.5\ntrack_front_m = = 1\n",
    );
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::Toml { .. }), "{e:?}");
    assert_mentions(&msg, &["vehicle.toml", "line 2"]);
}

#[test]
fn error_unknown_vehicle_key() {
    let dir = written(&small_drive());
    let mut text = std::fs::read_to_string(dir.path().join(files::VEHICLE)).expect("read");
    text = text.replace("gyro_rps", "gyro_rsp");
    put(dir.path(), files::VEHICLE, &text);
    let (e, msg) = read_err(dir.path());
    assert!(matches!(e, IoError::Toml { .. }), "{e:?}");
    assert_mentions(&msg, &["vehicle.toml", "gyro_rsp"]);
}

#[test]
fn write_refuses_what_would_not_read_back() {
    let mut drive = small_drive();
    drive.truth[4].yaw_rad = 20.0;
    let dir = tempfile::tempdir().expect("temp dir");
    let target = dir.path().join("drive");
    let e = write_drive(&target, &drive).expect_err("unwrapped yaw refused");
    assert!(matches!(e, IoError::OutOfRange { line: 6, .. }), "{e:?}");
    assert!(!target.exists(), "nothing written");

    let mut drive = small_drive();
    drive.yaw_rate[1].t_s = drive.yaw_rate[0].t_s;
    let e = write_drive(&target, &drive).expect_err("invalid drive refused");
    assert!(matches!(e, IoError::Invalid { .. }), "{e:?}");
    assert!(!target.exists(), "nothing written");
}

#[test]
fn failed_drive_write_creates_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("a_file");
    std::fs::write(&file, "x").expect("file");
    let e = write_drive(&file.join("drive"), &small_drive()).expect_err("parent is a file");
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .expect("list")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(names, vec![std::ffi::OsString::from("a_file")]);
    assert_eq!(std::fs::read_to_string(&file).expect("read"), "x");
}

#[test]
fn blank_lines_count_in_line_numbers() {
    let dir = written(&small_drive());
    put(dir.path(), files::SPEED, "t_s,speed_mps\n\n0,1\n\n0,1\n");
    let (e, msg) = read_err(dir.path());
    assert!(
        matches!(e, IoError::TimeNotIncreasing { line: 5, .. }),
        "{e:?}"
    );
    assert_mentions(&msg, &["speed.csv", "line 5", "t_s"]);
    put(
        dir.path(),
        files::SPEED,
        "t_s,speed_mps\r\n0,1\r\n\r\n1,1\r\n1,1\r\n",
    );
    let (e, _) = read_err(dir.path());
    assert!(
        matches!(e, IoError::TimeNotIncreasing { line: 5, .. }),
        "{e:?}"
    );
}

#[test]
fn preferring_a_missing_wheel_file_uses_the_other() {
    let drive = small_drive();
    let dir = written(&drive);
    let opts = ReadOptions::default().prefer_wheels(WheelFile::Speeds);
    assert_eq!(
        read_drive_with(dir.path(), &opts).expect("ticks used"),
        drive
    );
}

#[test]
fn heights_were_taken_as_0_by_the_csv_reader_and_the_track_writers() {
    // A drive 2,000 m above the ellipsoid, positions out to 100 km.
    let origin = Origin {
        lat_deg: 46.0,
        lon_deg: 8.0,
        height_m: 2_000.0,
    };
    let mut drive = small_drive();
    let far = [(0.0, 100e3), (100e3, 0.0), (-70e3, -70e3)];
    for (i, g) in drive.gnss.iter_mut().enumerate() {
        (g.east_m, g.north_m) = far[i % far.len()];
    }
    let dir = written(&drive);
    let mut with_origin = drive.clone();
    with_origin.vehicle.origin = Some(origin);
    deadreckon_io::write_vehicle(&dir.path().join(files::VEHICLE), &with_origin.vehicle)
        .expect("vehicle");
    let lat_lon = |height: &dyn Fn(usize) -> String| {
        let mut gnss = String::from("t_s,lat_deg,lon_deg,height_m,std_m\n");
        for (i, g) in drive.gnss.iter().enumerate() {
            let (lat, lon) = geo::en_to_geodetic(&origin, g.east_m, g.north_m);
            gnss += &format!("{},{lat},{lon},{},{}\n", g.t_s, height(i), g.std_m);
        }
        gnss
    };
    // Heights given (one left empty: the origin's), and no height column.
    for gnss in [
        lat_lon(&|i| if i == 1 { String::new() } else { "2000".into() }),
        lat_lon(&|_| "2000".into()).replace(",height_m", ",h"),
    ] {
        put(dir.path(), files::GNSS, &gnss);
        let back = read_drive(dir.path()).expect("lat/lon drive");
        assert_eq!(back.vehicle.origin, Some(origin));
        for (a, b) in back.gnss.iter().zip(&drive.gnss) {
            assert!(
                (a.east_m - b.east_m).abs() < 1e-6 && (a.north_m - b.north_m).abs() < 1e-6,
                "({}, {}) vs ({}, {})",
                a.east_m,
                a.north_m,
                b.east_m,
                b.north_m
            );
        }
    }
    // Read as if at height 0 (what the reader did): 31 m off at 100 km.
    put(dir.path(), files::GNSS, &lat_lon(&|_| "0".into()));
    let low = read_drive(dir.path()).expect("lat/lon drive");
    let off = (low.gnss[0].north_m - 100e3).abs();
    assert!((25.0..40.0).contains(&off), "{off} m");
    // A height in millimetres is refused with its line.
    put(dir.path(), files::GNSS, &lat_lon(&|_| "2000000".into()));
    let (_, msg) = read_err(dir.path());
    assert_mentions(&msg, &["gnss.csv", "line 2", "height_m", "ellipsoid"]);

    // Written back: the GeoJSON of the positions read gives the same
    // latitude/longitude to its 1e-8° rounding.
    let track = deadreckon_core::Track {
        name: "fixes".into(),
        points: drive
            .gnss
            .iter()
            .map(|g| deadreckon_core::TrackPoint {
                t_s: g.t_s,
                east_m: g.east_m,
                north_m: g.north_m,
                yaw_rad: 0.0,
                speed_mps: 0.0,
                yaw_rate_rps: 0.0,
                cov_pose: [0.0; 9],
            })
            .collect(),
        origin: Some(origin),
    };
    let out = dir.path().join("t.geojson");
    deadreckon_io::write_track_geojson(&out, &[track]).expect("geojson");
    let v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&out).unwrap()).unwrap();
    let coords = v["features"][0]["geometry"]["coordinates"]
        .as_array()
        .unwrap();
    for (c, g) in coords.iter().zip(&drive.gnss) {
        let (lat, lon) = geo::en_to_geodetic(&origin, g.east_m, g.north_m);
        assert!(
            (c[0].as_f64().unwrap() - lon).abs() < 1e-8,
            "{c} vs {lat}, {lon}"
        );
        assert!(
            (c[1].as_f64().unwrap() - lat).abs() < 1e-8,
            "{c} vs {lat}, {lon}"
        );
    }
}
