//! The state machine: phases, JSON round trip of state and model, bad input.

use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::input::{drive_input, Event};
use deadreckon_tedris::{
    Geometry, HeadingSample, Outage, Phase, ReferenceSource, Tedris, TedrisConfig, TedrisModel,
    WheelSample,
};

fn feed(m: &mut Tedris, events: &[Event]) -> Vec<deadreckon_tedris::Estimate> {
    let mut out = Vec::new();
    for e in events {
        match e {
            Event::Wheel(w) => out.push(m.push_wheel(*w).unwrap()),
            Event::Heading(h) => m.push_heading(*h).unwrap(),
            Event::Fix(f) => m.push_fix(*f).unwrap(),
        }
    }
    out
}

#[test]
fn phases_follow_section_3_3_and_state_round_trips_through_json() {
    let sc = Scenario::builtin("tedris-robot").unwrap();
    let drive = simulate(&sc, 7).unwrap().drive;
    let blank = [(200.0, 260.0)];
    let input = drive_input(&drive, Some(ReferenceSource::Gyro), &blank).unwrap();
    let mut m = Tedris::new(TedrisConfig::robot(), input.geometry).unwrap();
    let split = input.events.iter().position(|e| e.t_s() >= 150.0).unwrap();
    let first = feed(&mut m, &input.events[..split]);
    assert!(first.iter().any(|e| e.phase == Phase::Training));
    assert!(
        first.iter().any(|e| e.phase == Phase::Update),
        "training completes on the robot drive"
    );
    // Save and restore the whole state; both copies then give the same estimates.
    let json = m.to_json().unwrap();
    let mut restored = Tedris::from_json(&json).unwrap();
    let a = feed(&mut m, &input.events[split..]);
    let b = feed(&mut restored, &input.events[split..]);
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x.east_m - y.east_m).abs() < 1e-9 && (x.yaw_rad - y.yaw_rad).abs() < 1e-12);
    }
    // GNSS (here the gyro) lost → prediction; back → training, then update again.
    let phase_at = |t: f64| a.iter().find(|e| e.t_s >= t).unwrap().phase;
    assert_eq!(phase_at(230.0), Phase::Predicting);
    assert_eq!(phase_at(260.5), Phase::Training);
    assert_eq!(phase_at(300.0), Phase::Update);
    // The model alone round-trips too.
    let model = m.model().unwrap().clone();
    let text = serde_json::to_string(&model).unwrap();
    let back: TedrisModel = serde_json::from_str(&text).unwrap();
    back.validate().unwrap();
    assert_eq!(back.chosen, model.chosen);
    assert_eq!(
        back.fits[0].global.coefficients,
        model.fits[0].global.coefficients
    );
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let g = Geometry {
        track_rear_m: 1.5,
        lever_arm_m: 1.0,
        heading_is_course: true,
    };
    let mut m = Tedris::new(TedrisConfig::default(), g).unwrap();
    assert!(m
        .push_wheel(WheelSample {
            t_s: f64::NAN,
            left_m: 0.1,
            right_m: 0.1
        })
        .is_err());
    m.push_wheel(WheelSample {
        t_s: 1.0,
        left_m: 0.1,
        right_m: 0.1,
    })
    .unwrap();
    assert!(m
        .push_wheel(WheelSample {
            t_s: 1.0,
            left_m: 0.1,
            right_m: 0.1
        })
        .is_err());
    assert!(m
        .push_wheel(WheelSample {
            t_s: 2.0,
            left_m: f64::INFINITY,
            right_m: 0.1
        })
        .is_err());
    assert!(m
        .push_heading(HeadingSample {
            t_s: 1.0,
            yaw_rad: f64::NAN
        })
        .is_err());
    assert_eq!(m.rejected(), 4);
    // Without any reference or model the machine is blind but still answers.
    let e = m
        .push_wheel(WheelSample {
            t_s: 2.0,
            left_m: 0.1,
            right_m: 0.2,
        })
        .unwrap();
    assert_eq!(e.phase, Phase::Blind);
    assert!(e.yaw_rad.is_finite());
    assert!(Tedris::from_json("{not json").is_err());
    assert!(Tedris::new(
        TedrisConfig {
            tau_samples: 0,
            ..TedrisConfig::default()
        },
        g
    )
    .is_err());
    assert!(Tedris::new(
        TedrisConfig::default(),
        Geometry {
            track_rear_m: -1.0,
            ..g
        }
    )
    .is_err());
    assert!("10:5".parse::<Outage>().is_err());
    assert!("a:b".parse::<Outage>().is_err());
    assert_eq!(
        "10:90".parse::<Outage>().unwrap(),
        Outage {
            start_s: 10.0,
            end_s: 90.0
        }
    );
}

#[test]
fn a_tampered_model_is_rejected() {
    let sc = Scenario::builtin("tedris-robot").unwrap();
    let drive = simulate(&sc, 3).unwrap().drive;
    let (model, _) =
        deadreckon_tedris::train(&drive, TedrisConfig::robot(), Some(ReferenceSource::Gyro))
            .unwrap();
    let mut bad = model.clone();
    bad.fits[0].global_beta[1] = f64::NAN;
    bad.fits[0].global.coefficients[1].estimate = f64::NAN;
    assert!(bad.validate().is_err());
    let mut bad = model.clone();
    bad.fits.clear();
    assert!(bad.validate().is_err());
    assert!(deadreckon_tedris::run_outages(&drive, &bad, &[]).is_err());
    // Too short a drive to train is an error.
    let mut short = drive.clone();
    if let deadreckon_core::drive::Wheels::Ticks(v) = &mut short.wheels {
        v.truncate(50);
    }
    short.yaw_rate.truncate(50);
    short.truth.truncate(500);
    short.gnss.truncate(5);
    assert!(
        deadreckon_tedris::train(&short, TedrisConfig::robot(), Some(ReferenceSource::Gyro))
            .is_err()
    );
}
