//! Tests of `outage`'s windows and hidden-fix scores.
use super::*;
use crate::drive::{Scalar, WheelTicks, Wheels};
use crate::Vehicle;

fn drive() -> Drive {
    Drive {
        vehicle: Vehicle::paper_car(),
        wheels: Wheels::Ticks(
            (0..=500)
                .map(|k| WheelTicks {
                    t_s: 100.0 + k as f64 * 0.02,
                    fl: 1,
                    fr: 1,
                    rl: 1,
                    rr: 1,
                })
                .collect(),
        ),
        yaw_rate: vec![Scalar {
            t_s: 100.0,
            value: 0.0,
        }],
        speed: Vec::new(),
        steering: Vec::new(),
        gnss: Vec::new(),
        truth: Vec::new(),
        imu: Default::default(),
    }
}

/// Issue 12: a window after the end of the drive was accepted (compare
/// printed a four-wheel error for it and "NaN … never" for TedriS).
#[test]
fn a_window_outside_the_drive_was_accepted() {
    let d = drive();
    assert!(check_windows(&d, &[(101.0, 105.0)]).is_ok());
    for w in [
        (200.0, 280.0),
        (99.0, 101.0),
        (105.0, 104.0),
        (f64::NAN, 104.0),
    ] {
        let e = check_windows(&d, &[w]).unwrap_err().to_string();
        assert!(e.contains("outage window"), "{e}");
    }
    let e = check_windows(&d, &[(200.0, 280.0)])
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("100.000–110.000 s"),
        "the message names the drive's span: {e}"
    );
}

#[test]
fn a_hidden_fix_is_scored_by_the_dead_reckonings_own_prediction() {
    // The car heading east (the lever along east), pose variances 1 and
    // 4 m², no heading variance; the fix's own noise 1 m: S = diag(2, 5).
    let mut d = drive();
    d.vehicle.gnss_lever_arm_m = 1.0;
    let fix = crate::drive::GnssFix {
        t_s: 105.0,
        east_m: 0.0,
        north_m: 0.0,
        std_m: 1.0,
        course_deg: None,
        speed_mps: None,
    };
    let p3 = [[1.0, 0.0, 0.0], [0.0, 4.0, 0.0], [0.0, 0.0, 0.0]];
    let at: AtFix = (State::zeros(), p3, None);
    let ll = fix_log_likelihood(&d, &fix, &at, [2.0, -5.0]);
    let want =
        -(2.0 * std::f64::consts::PI).ln() - 0.5 * 10f64.ln() - 0.5 * (4.0 / 2.0 + 25.0 / 5.0);
    assert!((ll - want).abs() < 1e-12, "{ll} {want}");
    // The same offset is less likely under a prediction that claims
    // less: the white-fix filter's over-confidence costs it.
    let tight = [[0.01, 0.0, 0.0], [0.0, 0.01, 0.0], [0.0, 0.0, 0.0]];
    assert!(fix_log_likelihood(&d, &fix, &(State::zeros(), tight, None), [2.0, -5.0]) < ll);
}
