//! TOML files, track writers, atomic writes and the geodetic conversion.

use std::path::Path;

use deadreckon_core::vehicle::Origin;
use deadreckon_core::{Params, ParamsWithStd, Track, TrackPoint, Vehicle};
use deadreckon_io::{
    atomic_write, geo, read_params, read_params_with_extra, read_truth_params, read_vehicle,
    write_params, write_track_csv, write_track_geojson, write_track_geojson_with,
    write_truth_params, write_vehicle, GeoJsonOptions, IoError,
};

fn params() -> ParamsWithStd {
    ParamsWithStd {
        params: Params {
            gyro_bias_rps: -1.0 / 3.0 * 1e-3,
            speed_scale: 1.0123456789012345,
            circumference_fl_m: 1.9,
            circumference_fr_m: 1.91,
            circumference_rl_m: 1.92,
            circumference_rr_m: 1.93,
        },
        std: Params {
            gyro_bias_rps: 1e-6,
            speed_scale: 0.001,
            circumference_fl_m: 2e-4,
            circumference_fr_m: 0.0,
            circumference_rl_m: 3e-4,
            circumference_rr_m: 1.0 / 7.0,
        },
    }
}

fn entries(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

#[test]
fn vehicle_round_trip_with_origin_and_noise() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("vehicle.toml");
    let mut v = Vehicle::paper_car();
    v.origin = Some(Origin {
        lat_deg: 49.123456789012,
        lon_deg: -2.5,
        height_m: 0.0,
    });
    v.noise.steering = 1.0 / 3.0;
    write_vehicle(&path, &v).expect("written");
    assert_eq!(read_vehicle(&path).expect("read"), v);
}

#[test]
fn vehicle_noise_table_is_optional_and_partial() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("vehicle.toml");
    std::fs::write(
        &path,
        "wheelbase_m = 2.6\ntrack_front_m = 1.5\ntrack_rear_m = 1.5\ngnss_lever_arm_m = 0\n\
         ticks_per_rev = 96\nwheel_circumference_m = 1.9\nsteering_ratio = 16\n\
         [noise]\ngyro_rps = 0.01\n",
    )
    .expect("file");
    let v = read_vehicle(&path).expect("read");
    assert_eq!(v.noise.gyro_rps, 0.01);
    assert_eq!(
        v.noise.speed_mps,
        deadreckon_core::vehicle::Noise::default().speed_mps
    );
    assert_eq!(v.origin, None);
}

#[test]
fn vehicle_invalid_value_is_reported() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("vehicle.toml");
    let mut v = Vehicle::paper_car();
    write_vehicle(&path, &v).expect("written");
    let text = std::fs::read_to_string(&path)
        .expect("read")
        .replace("wheelbase_m = 2.58", "wheelbase_m = -1.0");
    std::fs::write(&path, text).expect("file");
    let e = read_vehicle(&path).expect_err("negative wheelbase");
    assert!(e.to_string().contains("wheelbase_m"), "{e}");
    v.wheelbase_m = f64::NAN;
    assert!(matches!(
        write_vehicle(&path, &v),
        Err(IoError::Invalid { .. })
    ));
}

#[test]
fn params_round_trip_with_extra_table() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("params.toml");
    let mut extra = toml::Table::new();
    extra.insert("method".into(), toml::Value::String("rts".into()));
    let mut run = toml::Table::new();
    run.insert("iterations".into(), toml::Value::Integer(7));
    extra.insert("run".into(), toml::Value::Table(run));
    write_params(&path, &params(), Some(&extra)).expect("written");
    assert_eq!(read_params(&path).expect("read"), params());
    let (p, back_extra) = read_params_with_extra(&path).expect("read");
    assert_eq!(p, params());
    assert_eq!(back_extra, extra);
    let text = std::fs::read_to_string(&path).expect("read");
    assert!(text.starts_with("gyro_bias_rps = "), "{text}");
    assert!(text.contains("[std]"), "{text}");
}

#[test]
fn params_without_std_table_have_zero_std() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("params.toml");
    std::fs::write(
        &path,
        "gyro_bias_rps = 0.001\nspeed_scale = 1\ncircumference_fl_m = 1.9\n\
         circumference_fr_m = 1.9\ncircumference_rl_m = 1.9\ncircumference_rr_m = 1.9\n",
    )
    .expect("file");
    let p = read_params(&path).expect("read");
    assert_eq!(p.params.speed_scale, 1.0);
    assert_eq!(p.std.to_array(), [0.0; 6]);
}

#[test]
fn params_missing_key_is_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("params.toml");
    write_params(&path, &params(), None).expect("written");
    let text = std::fs::read_to_string(&path).expect("read");
    let cut: String = text
        .lines()
        .filter(|l| !l.starts_with("circumference_rr_m"))
        .collect::<Vec<_>>()
        .join("\n");
    // Removes the key from both the top level and [std]; the top level is reported first.
    std::fs::write(&path, cut).expect("file");
    let e = read_params(&path).expect_err("missing key");
    assert!(matches!(e, IoError::Toml { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(
        msg.contains("params.toml") && msg.contains("`circumference_rr_m`"),
        "{msg}"
    );

    write_params(&path, &params(), None).expect("written");
    let text = std::fs::read_to_string(&path).expect("read");
    let (top, std) = text.split_once("[std]").expect("std table");
    let std: String = std
        .lines()
        .filter(|l| !l.starts_with("speed_scale"))
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(&path, format!("{top}[std]{std}")).expect("file");
    let msg = read_params(&path).expect_err("missing std key").to_string();
    assert!(msg.contains("`std.speed_scale`"), "{msg}");
}

#[test]
fn params_bad_toml_and_bad_values() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("params.toml");
    std::fs::write(&path, "gyro_bias_rps = [\n").expect("file");
    let e = read_params(&path).expect_err("bad toml");
    assert!(matches!(e, IoError::Toml { .. }), "{e:?}");
    assert!(e.to_string().contains("line"), "{e}");

    let mut bad = params();
    bad.params.speed_scale = 0.0;
    assert!(matches!(
        write_params(&path, &bad, None),
        Err(IoError::Invalid { .. })
    ));
    let mut bad = params();
    bad.std.speed_scale = f64::NAN;
    assert!(matches!(
        write_params(&path, &bad, None),
        Err(IoError::Invalid { .. })
    ));
    let mut clash = toml::Table::new();
    clash.insert("speed_scale".into(), toml::Value::Float(2.0));
    assert!(write_params(&path, &params(), Some(&clash)).is_err());
}

#[test]
fn truth_params_round_trip_and_unknown_key() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("truth_params.toml");
    let p = params().params;
    write_truth_params(&path, &p).expect("written");
    assert_eq!(read_truth_params(&path).expect("read"), p);
    let text = std::fs::read_to_string(&path).expect("read") + "extra_key = 1\n";
    std::fs::write(&path, text).expect("file");
    let msg = read_truth_params(&path)
        .expect_err("unknown key")
        .to_string();
    assert!(
        msg.contains("truth_params.toml") && msg.contains("extra_key"),
        "{msg}"
    );
    let msg = read_truth_params(&dir.path().join("none.toml"))
        .expect_err("missing")
        .to_string();
    assert!(msg.contains("none.toml"), "{msg}");
}

fn track(name: &str, origin: Option<Origin>, n: usize) -> Track {
    Track {
        name: name.into(),
        origin,
        points: (0..n)
            .map(|i| TrackPoint {
                t_s: i as f64 * 0.5,
                east_m: 10.0 * i as f64,
                north_m: -5.0 * i as f64,
                yaw_rad: 0.1,
                speed_mps: 20.0,
                yaw_rate_rps: 0.01,
                cov_pose: [4.0, 0.5, 0.0, 0.5, 9.0, 0.0, 0.0, 0.0, 0.0001],
            })
            .collect(),
    }
}

#[test]
fn track_csv_has_the_contract_columns() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("track.csv");
    write_track_csv(
        &path,
        &[track("smoothed", None, 3), track("dead, reckoned", None, 2)],
    )
    .expect("written");
    let text = std::fs::read_to_string(&path).expect("read");
    let mut lines = text.lines();
    assert_eq!(
        lines.next(),
        Some(
            "t_s,track,east_m,north_m,yaw_rad,speed_mps,yaw_rate_rps,\
             std_east_m,std_north_m,std_yaw_rad,cov_en_m2,bound_95_m"
        )
    );
    assert_eq!(
        lines.next(),
        Some(
            "0.000000000,smoothed,0.000000000,-0.000000000,0.100000000,20.000000,0.010000000,\
             2.000000e0,3.000000e0,1.000000e-2,5.000000e-1,"
        )
    );
    assert_eq!(text.lines().count(), 6);
    assert!(text.contains("\"dead, reckoned\""), "{text}");
}

#[test]
fn track_csv_wrote_tiny_numbers_with_40_digits() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("track.csv");
    let mut t = track("filtered", None, 1);
    t.points[0].east_m = 3.0938451861793925e-23;
    t.points[0].yaw_rate_rps = -1.5e-30;
    write_track_csv(&path, &[t]).expect("written");
    let text = std::fs::read_to_string(&path).expect("read");
    let row = text.lines().nth(1).expect("a row");
    let fields: Vec<&str> = row.split(',').collect();
    assert_eq!(fields[2], "0.000000000", "{row}");
    assert_eq!(fields[6], "-0.000000000", "{row}");
    assert!(fields.iter().all(|f| f.len() <= 14), "{row}");
}

#[test]
fn track_geojson_line_strings_and_points() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("track.geojson");
    let origin = Origin {
        lat_deg: 49.4,
        lon_deg: 2.8,
        height_m: 0.0,
    };
    let tracks = [
        track("smoothed", Some(origin), 5),
        track("one", Some(origin), 1),
    ];
    write_track_geojson(&path, &tracks).expect("written");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
    assert_eq!(json["type"], "FeatureCollection");
    let features = json["features"].as_array().expect("features");
    assert_eq!(features.len(), 2);
    let f = &features[0];
    assert_eq!(f["geometry"]["type"], "LineString");
    assert_eq!(f["properties"]["name"], "smoothed");
    assert_eq!(f["properties"]["points"], 5);
    assert_eq!(f["properties"]["t_start_s"], 0.0);
    assert_eq!(f["properties"]["t_end_s"], 2.0);
    let first = &f["geometry"]["coordinates"][0];
    assert!((first[0].as_f64().expect("lon") - 2.8).abs() < 1e-12);
    assert!((first[1].as_f64().expect("lat") - 49.4).abs() < 1e-12);
    let last = &f["geometry"]["coordinates"][4];
    let (lon, lat) = (
        last[0].as_f64().expect("lon"),
        last[1].as_f64().expect("lat"),
    );
    let (e, n) = geo::geodetic_to_en(&origin, lat, lon);
    // Coordinates are rounded to 1e-8 degrees: within 1.2 mm.
    assert!(
        (e - 40.0).abs() < 1.2e-3 && (n + 20.0).abs() < 1.2e-3,
        "{e} {n}"
    );
    assert_eq!(features[1]["geometry"]["type"], "Point");
    // Compact, with at most 8 decimals per coordinate.
    let text = std::fs::read_to_string(&path).expect("read");
    assert_eq!(text.lines().count(), 1);
    let coords = &text[text.find("\"coordinates\"").expect("coordinates")..];
    let coords = &coords[..coords.find(']').expect("end")];
    for number in coords.split(|c: char| !(c.is_ascii_digit() || c == '.')) {
        if let Some((_, decimals)) = number.split_once('.') {
            assert!(decimals.len() <= 8, "{number} in {coords}");
        }
    }

    let opts = GeoJsonOptions::default().point_every_s(1.0);
    write_track_geojson_with(&path, &tracks[..1], &opts).expect("written");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&path).expect("read")).expect("json");
    // Line + points at t = 0, 1, 2.
    assert_eq!(json["features"].as_array().expect("features").len(), 4);
    assert_eq!(json["features"][2]["properties"]["t_s"], 1.0);
}

#[test]
fn track_geojson_needs_an_origin_and_writes_nothing_without() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("track.geojson");
    let e = write_track_geojson(&path, &[track("filtered", None, 3)]).expect_err("no origin");
    assert!(matches!(e, IoError::NeedsOrigin { .. }), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains("filtered") && msg.contains("origin"), "{msg}");
    assert!(entries(dir.path()).is_empty());
}

#[test]
fn atomic_write_into_a_file_parent_fails_and_creates_nothing() {
    let dir = tempfile::tempdir().expect("temp dir");
    let file = dir.path().join("plain");
    std::fs::write(&file, "keep").expect("file");
    let target = file.join("x.csv");
    let e = atomic_write(&target, |w| w.write_all(b"data")).expect_err("parent is a file");
    assert!(matches!(e, IoError::Io { .. }), "{e:?}");
    assert!(e.to_string().contains("x.csv"), "{e}");
    assert_eq!(entries(dir.path()), vec!["plain".to_string()]);
    assert_eq!(std::fs::read_to_string(&file).expect("read"), "keep");
    // The same through the typed writers.
    assert!(write_track_csv(&target, &[]).is_err());
    assert!(write_params(&target, &params(), None).is_err());
    assert_eq!(entries(dir.path()), vec!["plain".to_string()]);
}

#[test]
fn atomic_write_failure_keeps_the_old_file_and_no_temp() {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("data.csv");
    atomic_write(&path, |w| w.write_all(b"old\n")).expect("written");
    let e = atomic_write(&path, |w| {
        w.write_all(b"half a fi")?;
        Err(std::io::Error::other("disk full"))
    })
    .expect_err("failed write");
    assert!(e.to_string().contains("disk full"), "{e}");
    assert_eq!(std::fs::read_to_string(&path).expect("read"), "old\n");
    assert_eq!(entries(dir.path()), vec!["data.csv".to_string()]);
}

#[cfg(unix)]
#[test]
fn atomic_write_gives_new_files_normal_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("p.txt");
    atomic_write(&path, |w| w.write_all(b"x")).expect("written");
    let mode = std::fs::metadata(&path).expect("meta").permissions().mode();
    assert_eq!(mode & 0o777, 0o644);
}

/// Pins `map_3d` against closed-form WGS84 values (NIMA TR8350.2 constants).
#[test]
fn geodetic_conversion_matches_wgs84_closed_forms() {
    const A: f64 = 6_378_137.0;
    const F: f64 = 1.0 / 298.257_223_563;
    let e2 = F * (2.0 - F);
    for (lat0, lon0) in [(0.0_f64, 0.0_f64), (45.0, 7.0), (49.4, 2.8), (-33.9, 151.2)] {
        let origin = Origin {
            lat_deg: lat0,
            lon_deg: lon0,
            height_m: 0.0,
        };
        let phi = lat0.to_radians();
        let w = (1.0 - e2 * phi.sin().powi(2)).sqrt();
        let meridian = A * (1.0 - e2) / w.powi(3); // radius of curvature M
        let normal = A / w; // prime vertical radius N
        let d = 1e-5_f64; // degrees
        let (e, n) = geo::geodetic_to_en(&origin, lat0 + d, lon0);
        assert!(e.abs() < 1e-6, "{e}");
        assert!((n - meridian * d.to_radians()).abs() < 1e-5, "{n}");
        let (e, n) = geo::geodetic_to_en(&origin, lat0, lon0 + d);
        assert!(
            (e - normal * phi.cos() * d.to_radians()).abs() < 1e-5,
            "{e}"
        );
        assert!(n.abs() < 1e-3, "{n}");
        // The inverse, within a few kilometres.
        let (lat, lon) = geo::en_to_geodetic(&origin, 1500.0, -2500.0);
        let (e, n) = geo::geodetic_to_en(&origin, lat, lon);
        assert!(
            (e - 1500.0).abs() < 1e-3 && (n + 2500.0).abs() < 1e-3,
            "{e} {n}"
        );
    }
    // One degree of longitude on the equator: the chord of a circle of radius a.
    let (e, n) = geo::geodetic_to_en(
        &Origin {
            lat_deg: 0.0,
            lon_deg: 0.0,
            height_m: 0.0,
        },
        0.0,
        1.0,
    );
    assert!((e - A * 1f64.to_radians().sin()).abs() < 1e-6, "{e}");
    assert!(n.abs() < 1e-6);
}
