use super::*;
use crate::drive::{Axes, GnssFix, Scalar, TruthPose, WheelTicks};
use crate::timing::KnownCorrections;
use crate::vehicle::Vehicle;

/// A drive with every stream, odd timestamps (a −0.0 among them, which a
/// shift by −0.0 would turn into +0.0) and a truth.
fn drive() -> Drive {
    let mut d = Drive::empty(Vehicle::paper_car());
    let t = |k: usize| {
        if k == 0 {
            -0.0
        } else {
            0.013 * k as f64 + 0.1 / 3.0
        }
    };
    d.wheels = Wheels::Ticks(
        (0..50)
            .map(|k| WheelTicks {
                t_s: t(k),
                fl: k as i64,
                fr: 2,
                rl: 3,
                rr: 4,
            })
            .collect(),
    );
    let scalar = |k: usize| Scalar {
        t_s: t(k) + 0.001,
        value: (k as f64).sin(),
    };
    d.yaw_rate = (0..80).map(scalar).collect();
    d.speed = (0..70).map(scalar).collect();
    d.steering = (0..60).map(scalar).collect();
    d.gnss = (0..9)
        .map(|k| GnssFix {
            t_s: t(k * 5),
            east_m: k as f64,
            north_m: 1.0,
            std_m: 0.5,
            course_deg: None,
            speed_mps: Some(3.0),
        })
        .collect();
    d.truth = (0..40)
        .map(|k| TruthPose {
            t_s: t(k),
            east_m: 0.5 * k as f64,
            north_m: 0.0,
            yaw_rad: 0.1,
            speed_mps: None,
        })
        .collect();
    let axes = |k: usize| Axes {
        t_s: t(k),
        x: 0.01,
        y: -0.02,
        z: (k as f64).cos(),
    };
    d.imu.gyro = (0..80).map(axes).collect();
    d.imu.accel = (0..80).map(axes).collect();
    d
}

/// `{:?}` tells −0.0 from +0.0, which `==` does not.
fn bits(d: &Drive) -> String {
    format!("{d:?}")
}

/// Every correction the working drives make, applied to a lent drive,
/// gives the drive a copy would have given (bit for bit), and the drive
/// given back is the drive lent (bit for bit, the −0.0 timestamp too).
#[test]
fn a_lent_drive_corrected_is_the_copy_corrected_and_comes_back_as_it_was() {
    let cases = [
        KnownCorrections::default(),
        KnownCorrections {
            delays_s: [0.02, 0.0, -0.0, 0.1],
            ..Default::default()
        },
        KnownCorrections {
            delays_s: [0.0, 0.05, 0.03, 0.0],
            up: Some([0.0, 0.6, 0.8]),
            ..Default::default()
        },
        KnownCorrections {
            delays_s: [0.07, 0.0, 0.0, 0.0],
            gyro_scale_error: 0.01,
            ..Default::default()
        },
    ];
    for k in cases {
        for with_truth in [false, true] {
            let original = drive();
            let mut copy = if with_truth {
                original.clone()
            } else {
                original.clone_without_truth()
            };
            copy = k.apply_to(copy);
            let mut source = original.clone();
            let (working, loan) = lend(&mut source, k.changes(), with_truth);
            let working = k.apply_to(working);
            assert_eq!(bits(&working), bits(&copy), "{k:?}");
            give_back(&mut source, working, loan);
            assert_eq!(bits(&source), bits(&original), "{k:?}");
        }
    }
}

/// A stream lent with its times and shifted comes back with its own
/// times, not shifted back (`t − d + d` is not `t` bit for bit).
#[test]
fn shifted_times_come_back_as_they_were_not_shifted_back() {
    let original = drive();
    let mut source = original.clone();
    let changes = Changes {
        speed: Change::Times,
        ..Default::default()
    };
    let (mut working, loan) = lend(&mut source, changes, false);
    assert!(source.speed.is_empty(), "moved, not copied");
    let d = 0.1 / 7.0;
    working.speed.iter_mut().for_each(|s| s.t_s -= d);
    // Undoing the shift arithmetically would not restore every time.
    let undone: Vec<f64> = working.speed.iter().map(|s| s.t_s + d).collect();
    assert!(undone
        .iter()
        .zip(&original.speed)
        .any(|(u, s)| u.to_bits() != s.t_s.to_bits()));
    give_back(&mut source, working, loan);
    assert_eq!(bits(&source), bits(&original));
}

#[test]
fn changes_of_a_zero_delay_leave_the_stream_alone_but_minus_zero_does_not() {
    let c = Changes::of_delays([0.0, -0.0, 0.5, 0.0]);
    assert_eq!(c.yaw_rate, Change::None);
    assert_eq!(c.speed, Change::Times);
    assert_eq!(c.steering, Change::Times);
    assert_eq!(c.gnss, Change::None);
    assert_eq!(c.yaw_values(true).yaw_rate, Change::Values);
    assert_eq!(c.and(Changes::default()), c);
}
