//! The real ROS1 bags of shared/data/husky-gps-bag, read directly.

use deadreckon_core::drive::{Scalar, Wheels};
use deadreckon_core::Drive;
use deadreckon_ros::{list_topics, read_rosbag, Mapping, StreamKind, YawAxis};

const HUSKY: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/husky-gps-bag/husky_gps.bag"
);
const JACKAL: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/husky-gps-bag/jackal_no_gps.bag"
);

fn speeds(d: &Drive) -> &[deadreckon_core::drive::WheelSpeeds] {
    match &d.wheels {
        Wheels::Speeds(v) => v,
        Wheels::Ticks(_) => panic!("odometry must give wheel speeds"),
    }
}

/// Distance travelled by integrating the mean wheel speed.
fn odometry_distance_m(d: &Drive) -> f64 {
    let s = speeds(d);
    s.windows(2)
        .map(|w| 0.5 * (w[0].rl_mps + w[0].rr_mps).abs() * (w[1].t_s - w[0].t_s))
        .sum()
}

fn rate_hz(ts: &[f64]) -> f64 {
    (ts.len() - 1) as f64 / (ts[ts.len() - 1] - ts[0])
}

/// Pearson correlation of the yaw rate (linearly interpolated) with the odometry
/// yaw rate (v_r − v_l) / track at the odometry times.
fn yaw_correlation(d: &Drive, yaw: &[Scalar], track: f64) -> f64 {
    let mut pairs = Vec::new();
    let mut j = 0;
    for s in speeds(d) {
        while j + 1 < yaw.len() && yaw[j + 1].t_s < s.t_s {
            j += 1;
        }
        if j + 1 >= yaw.len() || yaw[j].t_s > s.t_s {
            continue;
        }
        let (a, b) = (yaw[j], yaw[j + 1]);
        let g = a.value + (b.value - a.value) * (s.t_s - a.t_s) / (b.t_s - a.t_s);
        pairs.push(((s.rr_mps - s.rl_mps) / track, g));
    }
    let n = pairs.len() as f64;
    let (mx, my) = (
        pairs.iter().map(|p| p.0).sum::<f64>() / n,
        pairs.iter().map(|p| p.1).sum::<f64>() / n,
    );
    let sxy: f64 = pairs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    let sxx: f64 = pairs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let syy: f64 = pairs.iter().map(|p| (p.1 - my).powi(2)).sum();
    sxy / (sxx * syy).sqrt()
}

#[test]
fn husky_bag_streams_rates_and_distance() {
    let (drive, report) = read_rosbag(HUSKY, &Mapping::husky()).unwrap();
    drive.validate().unwrap();
    let w: Vec<f64> = speeds(&drive).iter().map(|s| s.t_s).collect();
    let imu: Vec<f64> = drive.yaw_rate.iter().map(|s| s.t_s).collect();
    let fix: Vec<f64> = drive.gnss.iter().map(|s| s.t_s).collect();
    let span = w[w.len() - 1] - w[0];
    eprintln!("{}", serde_json::to_string_pretty(&report).unwrap());
    eprintln!(
        "span {span:.1} s, odom {:.2} Hz, imu {:.2} Hz, fix {:.2} Hz",
        rate_hz(&w),
        rate_hz(&imu),
        rate_hz(&fix)
    );
    assert!((span - 395.0).abs() < 5.0, "span {span}");
    assert!((rate_hz(&w) - 10.0).abs() < 0.5);
    assert!((rate_hz(&imu) - 30.0).abs() < 1.5);
    assert!((rate_hz(&fix) - 2.5).abs() < 0.2);
    let dist = odometry_distance_m(&drive);
    eprintln!("odometry distance {dist:.1} m");
    assert!((dist - 359.0).abs() < 359.0 * 0.03, "distance {dist}");
    // SBAS fixes: covariance 0.81 m² on the diagonal at first (std 0.9 m), later 1 to 3 m².
    assert!(
        (drive.gnss[0].std_m - 0.9).abs() < 1e-9,
        "{:?}",
        drive.gnss[0]
    );
    assert!(drive.gnss.iter().all(|g| g.std_m > 0.5 && g.std_m < 5.0));
    assert_eq!(report.streams[2].covariance_missing, 0);
    let o = drive.vehicle.origin.expect("origin from the first fix");
    assert!(
        (o.lat_deg - 42.3758).abs() < 0.01 && (o.lon_deg + 71.1474).abs() < 0.01,
        "{o:?}"
    );
    assert_eq!(drive.gnss[0].east_m, 0.0);
    // GNSS path length, sampled every 10 s (about 10 m, well above the fix noise),
    // agrees with the odometry distance within 10 %.
    let g10: Vec<_> = drive.gnss.iter().step_by(25).collect();
    let gd: f64 = g10
        .windows(2)
        .map(|p| (p[1].east_m - p[0].east_m).hypot(p[1].north_m - p[0].north_m))
        .sum();
    eprintln!("gnss path {gd:.1} m");
    assert!((gd - dist).abs() < 0.1 * dist, "gnss {gd} odometry {dist}");
    let total: u64 = report.streams.iter().map(|s| s.messages).sum();
    assert_eq!(
        total,
        report.streams.iter().map(|s| s.accepted).sum::<u64>() + report.dropped()
    );
}

#[test]
fn husky_imu_axis() {
    let mut m = Mapping::husky();
    let track = m.vehicle.track_rear_m;
    let mut best = (YawAxis::Z, f64::NEG_INFINITY);
    for axis in YawAxis::ALL {
        m.streams[1].yaw_axis = Some(axis);
        let (d, _) = read_rosbag(HUSKY, &m).unwrap();
        let r = yaw_correlation(&d, &d.yaw_rate, track);
        eprintln!("axis {axis:?}: correlation {r:.3}");
        if r > best.1 {
            best = (axis, r);
        }
    }
    assert_eq!(
        best.0,
        Mapping::husky().streams[1].yaw_axis.unwrap(),
        "best axis {best:?}"
    );
    assert!(best.1 > 0.8, "{best:?}");
}

#[test]
fn jackal_bag_no_gnss() {
    let (drive, report) = read_rosbag(JACKAL, &Mapping::jackal()).unwrap();
    drive.validate().unwrap();
    eprintln!("{}", serde_json::to_string_pretty(&report).unwrap());
    assert!(drive.gnss.is_empty());
    let w: Vec<f64> = speeds(&drive).iter().map(|s| s.t_s).collect();
    let imu: Vec<f64> = drive.yaw_rate.iter().map(|s| s.t_s).collect();
    eprintln!("odom {:.2} Hz, imu {:.2} Hz", rate_hz(&w), rate_hz(&imu));
    assert!((rate_hz(&w) - 50.0).abs() < 2.5);
    assert!((rate_hz(&imu) - 50.0).abs() < 2.5);
    let span = w[w.len() - 1] - w[0];
    assert!((span - 61.0).abs() < 3.0, "span {span}");
    let dist = odometry_distance_m(&drive);
    eprintln!("jackal distance {dist:.1} m");
    assert!((dist - 84.0).abs() < 84.0 * 0.05, "distance {dist}");
    // The Jackal's skid-steer odometry overstates turns (ω_odom ≈ 1.2 rad/s while the
    // gyro reads 0.2): the correlation is lower than the Husky's, and +z is still best.
    let track = Mapping::jackal().vehicle.track_rear_m;
    let r = yaw_correlation(&drive, &drive.yaw_rate, track);
    eprintln!("jackal yaw correlation (+z): {r:.3}");
    assert!(r > 0.4, "{r}");
    let mut m = Mapping::jackal();
    for axis in YawAxis::ALL.into_iter().filter(|a| *a != YawAxis::Z) {
        m.streams[1].yaw_axis = Some(axis);
        let (d, _) = read_rosbag(JACKAL, &m).unwrap();
        assert!(
            yaw_correlation(&d, &d.yaw_rate, track) < r - 0.2,
            "{axis:?}"
        );
    }
}

#[test]
fn husky_topics() {
    let topics = list_topics(HUSKY).unwrap();
    for t in &topics {
        eprintln!(
            "{} {} {} msgs {:?} Hz",
            t.topic,
            t.msg_type,
            t.messages,
            t.rate_hz()
        );
    }
    let names: Vec<&str> = topics.iter().map(|t| t.topic.as_str()).collect();
    assert_eq!(
        names,
        ["/fix", "/husky_velocity_controller/odom", "/imu/data"]
    );
    assert_eq!(topics[0].msg_type, "sensor_msgs/NavSatFix");
    assert!(topics
        .iter()
        .all(|t| t.encoding == "ros1" && t.md5sum.as_ref().is_some_and(|m| m.len() == 32)));
}

#[test]
fn missing_topic_and_wrong_type_are_errors() {
    let mut m = Mapping::husky();
    m.streams[2].topic = "/gps/fix".into();
    let e = read_rosbag(HUSKY, &m).unwrap_err().to_string();
    assert!(e.contains("/gps/fix") && e.contains("husky_gps.bag"), "{e}");
    m.require_topics = false;
    let (d, r) = read_rosbag(HUSKY, &m).unwrap();
    assert!(d.gnss.is_empty() && r.streams[2].messages == 0);
    let mut m = Mapping::husky();
    m.streams[1].kind = StreamKind::PoseTruth;
    m.streams[1].yaw_axis = None;
    let e = read_rosbag(HUSKY, &m).unwrap_err().to_string();
    assert!(
        e.contains("sensor_msgs/Imu") && e.contains("/imu/data"),
        "{e}"
    );
}

/// Values decoded from husky_gps.bag by an independent Python decoder (struct +
/// bz2, written for this test): the first odometry, IMU and fix messages.
#[test]
fn husky_first_messages_match_an_independent_decoder() {
    let (drive, _) = read_rosbag(HUSKY, &Mapping::husky()).unwrap();
    let s = speeds(&drive);
    let track = 0.555;
    let check = |k: usize, t: f64, v: f64, w: f64| {
        assert!((s[k].t_s - t).abs() < 1e-6, "{k}: {}", s[k].t_s);
        assert!((s[k].rl_mps - (v - w * track / 2.0)).abs() < 1e-15, "{k}");
        assert!((s[k].rr_mps - (v + w * track / 2.0)).abs() < 1e-15, "{k}");
    };
    check(
        0,
        1432235498.0 + 0.027976030,
        0.17779841518092315,
        0.00085541027636822,
    );
    check(
        100,
        1432235508.0 + 0.026186619,
        0.9951041911886689,
        -0.008515868664624573,
    );
    // IMU: header stamp, and ω_y (the yaw axis of the Husky mapping).
    assert!((drive.yaw_rate[0].t_s - (1432235497.0 + 0.988949113)).abs() < 1e-6);
    assert_eq!(drive.yaw_rate[0].value, -0.010768940672278404);
    // Second fix about the first: the local flat-earth offset (exact to µm over 0.15 m).
    let g = drive.gnss[1];
    assert!((g.t_s - (1432235498.0 + 0.438950061)).abs() < 1e-6);
    assert!(
        (g.east_m - -0.13726913335708293).abs() < 1e-4
            && (g.north_m - 0.0740537240561158).abs() < 1e-4,
        "{g:?}"
    );
    let o = drive.vehicle.origin.unwrap();
    assert_eq!((o.lat_deg, o.lon_deg), (42.375812, -71.14739466666667));
}
