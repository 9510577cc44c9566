//! Arbitrary routes and values: the simulator returns a valid drive or an
//! error, never panics, and its ticks always equal the floor of the true
//! revolutions.

use deadreckon_core::drive::Wheels;
use deadreckon_sim::{simulate, Scenario, Segment};
use proptest::prelude::*;

fn segment() -> impl Strategy<Value = Segment> {
    prop_oneof![
        (-5.0..200.0f64, prop::option::of(-10.0..90.0f64)).prop_map(
            |(length_m, speed_limit_kmh)| Segment::Straight {
                length_m,
                speed_limit_kmh
            }
        ),
        (
            -400.0..400.0f64,
            -1.0..60.0f64,
            prop::option::of(-1.0..30.0f64)
        )
            .prop_map(|(angle_deg, radius_m, transition_m)| Segment::Turn {
                angle_deg,
                radius_m,
                speed_limit_kmh: None,
                transition_m
            }),
        (-1.0..10.0f64).prop_map(|duration_s| Segment::Stop { duration_s }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn any_route_gives_a_valid_drive_or_an_error(
        segments in prop::collection::vec(segment(), 0..6),
        closed in any::<bool>(),
        laps in 0u32..3,
        duration in prop::option::of(-1.0..40.0f64),
        seed in any::<u64>(),
    ) {
        let mut s = Scenario::builtin("calibration").unwrap().with_laps(laps);
        s.route.segments = segments;
        s.route.closed = closed;
        s.duration_s = duration;
        if let Ok(out) = simulate(&s, seed) {
            prop_assert!(out.drive.validate().is_ok());
            // When the drive is cut while moving, the last wheel epoch precedes the
            // end of the truth: compare only drives that end at standstill.
            if out.drive.truth.last().and_then(|p| p.speed_mps) != Some(0.0) {
                return Ok(());
            }
            let Wheels::Ticks(t) = &out.drive.wheels else { panic!("ticks expected") };
            let sum = t.iter().fold(0i64, |a, w| a + w.rl);
            let n = f64::from(out.drive.vehicle.ticks_per_rev);
            let expected = (out.stats.wheel_distance_m[2] / out.truth_params.circumference_rl_m * n).floor() as i64;
            prop_assert!((sum - expected).abs() <= 1);
        }
    }
}
