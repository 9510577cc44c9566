//! One track as the text files trajectory tools read (TUM, KITTI), parsed
//! back, and the choice of a track format by extension.

use std::path::Path;

use deadreckon_core::{Track, TrackPoint};
use deadreckon_io::{
    kitti_times_path, write_track_kitti, write_track_tum, TrackFormat, TUM_HEADER,
};

fn track(n: usize) -> Track {
    Track {
        name: "dead-reckoned".into(),
        points: (0..n)
            .map(|k| {
                let t = k as f64;
                TrackPoint {
                    t_s: 1_533_198_887.25 + 0.02 * t,
                    east_m: 10.0 * t + 0.1234567,
                    north_m: -3.0 * t,
                    yaw_rad: -2.5 + 1.3 * t,
                    speed_mps: 10.0,
                    yaw_rate_rps: 0.1,
                    cov_pose: [0.0; 9],
                }
            })
            .collect(),
        origin: None,
    }
}

fn numbers(line: &str) -> Vec<f64> {
    line.split(' ').map(|x| x.parse().unwrap()).collect()
}

#[test]
fn tum_lines_are_timestamp_position_and_unit_quaternion() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.tum");
    let tr = track(4);
    write_track_tum(&path, &tr).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], TUM_HEADER);
    assert!(lines[1].starts_with("# deadreckon track `dead-reckoned`"));
    assert_eq!(lines.len(), 2 + 4);
    // Nine decimals print the double as it is (a Unix time is only held to
    // about 0.2 µs).
    assert_eq!(
        lines[3],
        "1533198887.269999981 10.123457 -3.000000 0.000000 0.000000000 0.000000000 -0.564642473 0.825335615"
    );
    for (line, p) in lines[2..].iter().zip(&tr.points) {
        let v = numbers(line);
        assert_eq!(v.len(), 8);
        assert!((v[0] - p.t_s).abs() < 1e-6 && (v[1] - p.east_m).abs() <= 5e-7);
        assert!((v[2] - p.north_m).abs() <= 5e-7 && v[3] == 0.0);
        let (qz, qw) = (v[6], v[7]);
        assert!((qx_qy_zero(&v) && (qz * qz + qw * qw - 1.0).abs() < 1e-8));
        let yaw = 2.0 * qz.atan2(qw);
        assert!(deadreckon_core::angle::wrap(yaw - p.yaw_rad).abs() < 1e-8);
    }
}

fn qx_qy_zero(v: &[f64]) -> bool {
    v[4] == 0.0 && v[5] == 0.0
}

#[test]
fn kitti_lines_are_3x4_poses_and_the_times_go_beside_them() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.kitti");
    let tr = track(3);
    write_track_kitti(&path, &tr).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 3, "no header, one line per pose");
    for (line, p) in lines.iter().zip(&tr.points) {
        let m = numbers(line);
        assert_eq!(m.len(), 12);
        let (s, c) = p.yaw_rad.sin_cos();
        let expect = [
            c, -s, 0.0, p.east_m, s, c, 0.0, p.north_m, 0.0, 0.0, 1.0, 0.0,
        ];
        for (a, b) in m.iter().zip(expect) {
            assert!((a - b).abs() <= 5e-7, "{line}");
        }
    }
    let times_path = kitti_times_path(&path);
    assert_eq!(times_path, dir.path().join("run.times.txt"));
    let times: Vec<f64> = std::fs::read_to_string(times_path)
        .unwrap()
        .lines()
        .map(|l| l.parse().unwrap())
        .collect();
    assert_eq!(times.len(), 3);
    assert!((times[2] - 1_533_198_887.29).abs() < 1e-6);
}

#[test]
fn empty_or_non_finite_tracks_are_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("t.tum");
    let e = write_track_tum(&path, &track(0)).unwrap_err().to_string();
    assert!(e.contains("t.tum") && e.contains("no poses"), "{e}");
    let mut bad = track(3);
    bad.points[1].north_m = f64::NAN;
    let e = write_track_kitti(&dir.path().join("t.kitti"), &bad)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("t.kitti") && e.contains("non-finite pose at t = 1533198887.27"),
        "{e}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn formats_by_extension_and_unknown_ones_refused() {
    let f = |p: &str| TrackFormat::from_path(Path::new(p));
    assert_eq!(f("a.tum").unwrap(), TrackFormat::Tum);
    assert_eq!(f("a.kitti").unwrap(), TrackFormat::Kitti);
    assert_eq!(f("a.json").unwrap(), TrackFormat::GeoJson);
    assert!(f("a.kitti").unwrap().holds_one_track() && !f("a.csv").unwrap().holds_one_track());
    let e = f("a.txt").unwrap_err().to_string();
    assert!(
        e.contains("a.txt") && e.contains(".txt") && e.contains(".kitti"),
        "{e}"
    );
    assert!(f("track")
        .unwrap_err()
        .to_string()
        .contains("(no extension)"));
}
