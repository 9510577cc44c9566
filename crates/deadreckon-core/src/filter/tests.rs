//! Unit tests of the step filter.

use super::*;

fn filter() -> CarFilter {
    let v = Vehicle::paper_car();
    let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
    CarFilter::new(&v, &Params::nominal(&v), None, 0.0, x0, p0).unwrap()
}

#[test]
fn a_wheel_reading_far_outside_the_gate_is_rejected_and_counted() {
    let mut f = filter();
    f.predict_to(0.02);
    let before = *f.state();
    let u = f.update_wheel_ticks(0, 500.0, 0.02).unwrap().unwrap();
    assert!(!u.accepted && u.nis > 1e3);
    assert_eq!(*f.state(), before);
    assert_eq!(f.gates().rejected(SensorKind::Wheel(0)), 1);
    assert_eq!(f.gates().accepted(SensorKind::Wheel(0)), 0);
}

#[test]
fn consecutive_rejections_end_in_a_recovery() {
    let mut f = filter();
    let max = Vehicle::paper_car().noise.max_rejections as u64;
    let mut t = 0.0;
    for _ in 0..=max {
        t += 0.02;
        f.predict_to(t);
        f.update_wheel_ticks(2, 5000.0, 0.02).unwrap();
    }
    let rl = SensorKind::Wheel(2);
    assert_eq!(f.gates().rejected(rl), max);
    assert_eq!(f.gates().recovered(rl), 1);
    assert_eq!(f.gates().accepted(rl), 1);
}

#[test]
fn absent_wheels_are_never_used() {
    let mut v = Vehicle::paper_car();
    v.wheels_present = [true, false, true, false];
    let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
    let mut f = CarFilter::new(&v, &Params::nominal(&v), None, 0.0, x0, Mat::identity()).unwrap();
    f.predict_to(0.02);
    assert!(f.update_wheel_speed(1, 10.0).unwrap().is_none());
    assert!(f.update_wheel_ticks(3, 5.0, 0.02).unwrap().is_none());
    assert!(f.update_wheel_speed(0, 10.0).unwrap().is_some());
}

fn augmented() -> AugmentedFilter {
    let v = Vehicle::paper_car();
    let sd = Params {
        gyro_bias_rps: 0.01,
        speed_scale: 0.05,
        circumference_fl_m: 0.01,
        circumference_fr_m: 0.01,
        circumference_rl_m: 0.01,
        circumference_rr_m: 0.01,
    };
    let x0 = State::from([0.0, 0.0, 0.3, 10.0, 0.05]);
    let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
    AugmentedFilter::new(&v, &Params::nominal(&v), Some(&sd), 0.0, x0, p0).unwrap()
}

fn epoch(f: &mut AugmentedFilter, k: usize) {
    for (i, z) in [5.0, 6.0, 5.0, 4.0].into_iter().enumerate() {
        f.update_wheel_ticks(i, z + (k % 3) as f64, 0.02).unwrap();
    }
    f.update_gyro(0.05 + 1e-3 * k as f64).unwrap();
    f.update_speed(10.1).unwrap();
    f.update_steering(0.2).unwrap();
    if k.is_multiple_of(10) {
        let fix = GnssFix {
            t_s: f.time_s(),
            east_m: 0.2 * k as f64,
            north_m: 0.05,
            std_m: 0.5,
            course_deg: None,
            speed_mps: None,
        };
        f.update_gnss(&fix).unwrap();
    }
}

#[test]
fn scalar_updates_keep_the_covariance_exactly_symmetric() {
    let mut a = augmented();
    for k in 1..200 {
        a.predict_to(0.02 * k as f64);
        epoch(&mut a, k);
        let p = a.covariance();
        assert_eq!(*p, p.transpose(), "epoch {k}");
    }
}

#[test]
fn the_augmented_layout_holds_the_parameters() {
    let v = Vehicle::paper_car();
    let p = Params::nominal(&v);
    let sd = Params {
        gyro_bias_rps: 0.01,
        speed_scale: 0.05,
        circumference_fl_m: 0.01,
        circumference_fr_m: 0.01,
        circumference_rl_m: 0.01,
        circumference_rr_m: 0.01,
    };
    let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
    let f = AugmentedFilter::new(&v, &p, Some(&sd), 0.0, x0, Mat::identity()).unwrap();
    let got = f.params_std().unwrap();
    assert!((got.circumference_fl_m - 0.01).abs() < 1e-12);
    assert!((f.params().circumference_rr_m - p.circumference_rr_m).abs() < 1e-12);
    assert!(AugmentedFilter::new(&v, &p, None, 0.0, x0, Mat::identity()).is_err());
    assert!(filter().params_std().is_none());
}
