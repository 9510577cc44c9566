//! The node's pipeline without the network: messages arriving out of stamp
//! order within the reorder window give the filter the same events, and so
//! the same epochs bit for bit, as the messages converted in stamp order (the
//! bag reader's path); without a window, the messages that come after a newer
//! one are late, counted and not applied.

use std::time::Instant;

use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::online::{Online, Start};
use deadreckon_core::{Params, TrackPoint};
use deadreckon_ros::ros2::{
    Header, Imu, NavSatFix, NavSatStatus, Odometry, Time, TwistWithCovariance, Vector3,
};
use deadreckon_ros::{Converter, Mapping, Message};
use deadreckon_ros2::{Pipeline, Sink};

const LAT0_DEG: f64 = 42.3758;
const LON0_DEG: f64 = -71.1474;

fn header(t_s: f64) -> Header {
    Header {
        stamp: Time {
            sec: t_s.floor() as i32,
            nanosec: ((t_s - t_s.floor()) * 1e9).round() as u32,
        },
        frame_id: String::new(),
    }
}

/// A Husky-like robot on a 20 m circle at 1 m/s for 60 s: odometry at 10 Hz,
/// IMU at 30 Hz (yaw rate on +y, the Husky mapping's axis), fixes at 2.5 Hz;
/// (stream index of the Husky mapping, stamp, message), in stamp order.
fn messages() -> Vec<(usize, f64, Message)> {
    let (v_mps, w_rps) = (1.0, 0.05);
    let t0 = 1.5e9;
    let mut out = Vec::new();
    for k in 0..600 {
        let t = t0 + 0.1 * k as f64 + 0.0004;
        let mut m = Odometry {
            header: header(t),
            ..Default::default()
        };
        m.twist = TwistWithCovariance::default();
        m.twist.twist.linear.x = v_mps;
        m.twist.twist.angular.z = w_rps;
        out.push((0, t, Message::from(&m)));
    }
    for k in 0..1800 {
        let t = t0 + k as f64 / 30.0 + 0.0251;
        let m = Imu {
            header: header(t),
            angular_velocity: Vector3 {
                x: 0.0,
                y: w_rps + 0.002 * (k as f64).sin(),
                z: 0.0,
            },
            ..Default::default()
        };
        out.push((1, t, Message::from(&m)));
    }
    for k in 0..150 {
        let dt = 0.4 * k as f64 + 0.0003;
        let (yaw, r) = (w_rps * dt, v_mps / w_rps);
        let (east, north) = (r * yaw.sin(), r * (1.0 - yaw.cos()));
        let m = NavSatFix {
            header: header(t0 + dt),
            status: NavSatStatus {
                status: 1,
                service: 1,
            },
            latitude: LAT0_DEG + north / 111_132.0,
            longitude: LON0_DEG + east / (111_320.0 * LAT0_DEG.to_radians().cos()),
            altitude: 7.3,
            position_covariance: [0.81, 0.0, 0.0, 0.0, 0.81, 0.0, 0.0, 0.0, 3.0],
            position_covariance_type: 2,
        };
        out.push((2, t0 + dt, Message::from(&m)));
    }
    // Stamp order, ties in the mapping's order (wheels, gyro, GNSS).
    out.sort_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(&b.0)));
    out
}

fn online(mapping: &Mapping) -> Online {
    let v = &mapping.vehicle;
    Online::new(
        v,
        &Params::nominal(v),
        &FilterOptions::default(),
        Start::Gnss,
    )
    .unwrap()
}

/// The epochs of the messages converted in stamp order and given to the filter.
fn in_stamp_order(mapping: &Mapping, msgs: &[(usize, f64, Message)]) -> Vec<TrackPoint> {
    let mut conv = Converter::new(mapping);
    let mut f = online(mapping);
    let mut points = Vec::new();
    for (i, t, m) in msgs {
        if let Some(ev) = conv.push(*i, *t, m).and_then(|s| s.event()) {
            f.push(ev, &mut |p| points.push(p)).unwrap();
        }
    }
    f.finish(&mut |p| points.push(p)).unwrap();
    points
}

#[derive(Default)]
struct Collect {
    fed: usize,
    points: Vec<TrackPoint>,
}

impl Sink for Collect {
    fn fed(&mut self, _received: Instant) {
        self.fed += 1;
    }
    fn epoch(&mut self, p: TrackPoint) {
        self.points.push(p);
    }
}

/// The messages in the order they arrive after a delay of 0 to `max_s`
/// each (seeded xorshift).
fn arrival_order(msgs: &[(usize, f64, Message)], max_s: f64) -> Vec<(usize, f64, Message)> {
    let mut state: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut arrivals: Vec<(f64, (usize, f64, Message))> = msgs
        .iter()
        .map(|m| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let u = (state >> 11) as f64 / (1u64 << 53) as f64;
            (m.1 + max_s * u, *m)
        })
        .collect();
    arrivals.sort_by(|a, b| a.0.total_cmp(&b.0));
    arrivals.into_iter().map(|(_, m)| m).collect()
}

fn through_pipeline(
    mapping: &Mapping,
    msgs: &[(usize, f64, Message)],
    window_s: f64,
) -> (Pipeline, Collect) {
    let mut pipe = Pipeline::new(mapping, window_s);
    let mut f = online(mapping);
    let mut sink = Collect::default();
    let now = Instant::now();
    for (i, t, m) in msgs {
        // The record time is not used: every stream takes the header stamp.
        pipe.receive(*i, *t + 1000.0, *m, now);
        pipe.release(&mut f, &mut sink).unwrap();
    }
    assert_eq!(pipe.finish(&mut f, &mut sink).unwrap(), None);
    (pipe, sink)
}

#[test]
fn messages_out_of_order_within_the_window_give_the_epochs_of_stamp_order() {
    let mapping = Mapping::husky();
    let msgs = messages();
    let expected = in_stamp_order(&mapping, &msgs);
    // 2 Hz of fixes over 60 s: the filter starts after the first 10 m.
    assert!(expected.len() > 450, "{} epochs", expected.len());
    // Delays of up to 50 ms reorder neighbours of every stream.
    let arrived = arrival_order(&msgs, 0.05);
    assert_ne!(
        arrived.iter().map(|m| m.1).collect::<Vec<_>>(),
        msgs.iter().map(|m| m.1).collect::<Vec<_>>()
    );
    let (pipe, got) = through_pipeline(&mapping, &arrived, 0.1);
    assert_eq!(pipe.late(), &[0, 0, 0]);
    assert_eq!(got.fed, msgs.len());
    assert_eq!(got.points, expected, "bit for bit");
}

#[test]
fn without_a_window_messages_after_a_newer_one_are_late_counted_and_not_applied() {
    let mapping = Mapping::husky();
    let msgs = messages();
    let arrived = arrival_order(&msgs, 0.05);
    let (pipe, got) = through_pipeline(&mapping, &arrived, 0.0);
    let late: u64 = pipe.late().iter().sum();
    assert!(late > 100, "{:?} late", pipe.late());
    for (i, r) in pipe.reports().iter().enumerate() {
        // Every message not late reached the conversion, and was used.
        assert_eq!(r.messages + pipe.late()[i], [600, 1800, 150][i], "{r:?}");
        assert_eq!(r.accepted, r.messages, "{r:?}");
    }
    assert_eq!(got.fed as u64 + late, msgs.len() as u64);
    // The epochs are in time order: nothing was applied out of order.
    assert!(got.points.windows(2).all(|w| w[0].t_s < w[1].t_s));
}
