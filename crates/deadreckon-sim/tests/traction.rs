//! The driven axle's slip ([`deadreckon_core::traction`]) on a simulated
//! drive with speed changes: none where the simulator has none, and a slip
//! written into one axle's wheel speeds (in proportion to the forward
//! specific force the drive's accelerometer reads) found on that axle and
//! removed.

use deadreckon_core::drive::Wheels;
use deadreckon_core::traction::{self, Axle};
use deadreckon_core::Drive;
use deadreckon_sim::{simulate, Scenario};

fn drive() -> Drive {
    let text = r#"
name = "speed-changes"
vehicle = "paper-car"

[route]
segments = [
  { kind = "straight", length_m = 400, speed_limit_kmh = 50 },
  { kind = "straight", length_m = 800, speed_limit_kmh = 90 },
  { kind = "straight", length_m = 300, speed_limit_kmh = 40 },
  { kind = "straight", length_m = 700, speed_limit_kmh = 80 },
  { kind = "straight", length_m = 300, speed_limit_kmh = 50 },
]

[speed]
max_accel_mps2 = 1.5
max_decel_mps2 = 2.0
start_stop_s = 0
end_stop_s = 0

[sensors.wheels]
kind = "speeds"
rate_hz = 83
offset_s = 0.004

[sensors.gyro]
rate_hz = 100
offset_s = 0.001
noise_std = 0.003
tilt_deg = [-3.0, 1.0]

[sensors.gnss]
rate_hz = 10
std_m = 0.5
velocity_std_mps = 0.05
"#;
    simulate(&Scenario::from_toml_str(text).unwrap(), 3)
        .unwrap()
        .drive
}

/// `drive` with the wheels of `axle` reading `1 + k·f` times their speed,
/// `f` the accelerometer's forward reading at the row's time (nearest sample).
fn with_slip(drive: &Drive, axle: Axle, k: f64) -> Drive {
    let acc = &drive.imu.accel;
    let mut d = drive.clone();
    let Wheels::Speeds(ws) = &mut d.wheels else {
        panic!("wheel speeds expected")
    };
    for w in ws.iter_mut() {
        let i = acc.partition_point(|a| a.t_s < w.t_s).min(acc.len() - 1);
        let s = 1.0 + k * acc[i].x;
        match axle {
            Axle::Front => {
                w.fl_mps *= s;
                w.fr_mps *= s;
            }
            Axle::Rear => {
                w.rl_mps *= s;
                w.rr_mps *= s;
            }
        }
    }
    d
}

#[test]
fn no_slip_is_found_where_the_simulator_has_none() {
    let d = drive();
    let t = traction::estimate(&d).expect("accelerometer");
    eprintln!("{t:?}");
    assert!(t.is_estimated(), "{t:?}");
    assert!(t.slip_per_mps2.abs() <= 3.0 * t.std, "{t:?}");
}

#[test]
fn a_driven_axle_s_slip_is_found_on_that_axle_and_removed() {
    let d = drive();
    for (axle, k) in [(Axle::Front, 0.004), (Axle::Rear, 0.003)] {
        let slipped = with_slip(&d, axle, k);
        let t = traction::estimate(&slipped).expect("accelerometer");
        eprintln!("{axle:?} {k}: {t:?}");
        assert!(t.is_estimated(), "{t:?}");
        assert_eq!(t.axle, axle);
        // The front's ratio to the rear rises with the force when the front
        // slips, falls when the rear does; a rear slip `k` divides the ratio
        // by `1 + k·f`, a slope of about `−k`.
        assert!(
            (t.slip_per_mps2.abs() - k).abs() <= 3.0 * t.std + 0.02 * k,
            "{t:?}"
        );
        let fixed = traction::apply(&slipped, t.slip_per_mps2);
        let again = traction::estimate(&fixed).expect("accelerometer");
        assert!(again.slip_per_mps2.abs() <= 3.0 * again.std, "{again:?}");
        // The other axle is left as read.
        let (Wheels::Speeds(a), Wheels::Speeds(b)) = (&slipped.wheels, &fixed.wheels) else {
            panic!()
        };
        for (a, b) in a.iter().zip(b) {
            match axle {
                Axle::Front => assert_eq!((a.rl_mps, a.rr_mps), (b.rl_mps, b.rr_mps)),
                Axle::Rear => assert_eq!((a.fl_mps, a.fr_mps), (b.fl_mps, b.fr_mps)),
            }
        }
    }
}

#[test]
fn an_implausible_slip_is_rejected_not_clamped() {
    let slipped = with_slip(&drive(), Axle::Front, 0.05);
    let t = traction::estimate(&slipped).expect("accelerometer");
    assert!(!t.is_estimated(), "{t:?}");
    assert!(
        t.status.reason().unwrap().contains("not tyre slip"),
        "{t:?}"
    );
}

#[test]
fn an_accelerometer_on_its_side_gives_no_slip() {
    let mut d = with_slip(&drive(), Axle::Front, 0.004);
    for a in &mut d.imu.accel {
        std::mem::swap(&mut a.x, &mut a.z);
    }
    let t = traction::estimate(&d).expect("accelerometer");
    assert!(!t.is_estimated(), "{t:?}");
    assert!(t.status.reason().unwrap().contains("not along z"), "{t:?}");
}
