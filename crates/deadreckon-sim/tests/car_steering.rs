//! The car's steering ratio and steering-wheel offset calibrated against the
//! truth on simulated drives (the built-in calibration scenario with a true
//! ratio 4% above the nominal and a 1.7° offset). Seeded.

use deadreckon_core::kinematics::steering::calibrate_steering;
use deadreckon_core::reference::Reference;
use deadreckon_sim::{simulate, Scenario};

#[test]
fn steering_ratio_within_1_percent_and_offset_within_0_2_degrees() {
    for seed in [1u64, 2, 3] {
        let mut sc = Scenario::builtin("calibration").unwrap();
        let nominal = sc.vehicle.steering_ratio;
        let true_ratio = 1.04 * nominal;
        let true_offset = 0.03;
        let st = sc
            .sensors
            .steering
            .as_mut()
            .expect("the scenario has steering");
        st.true_ratio = Some(true_ratio);
        st.wheel_offset_rad = true_offset;
        let out = simulate(&sc, seed).unwrap();
        let reference = Reference::from_truth(&out.drive.truth).unwrap();
        let c = calibrate_steering(&out.drive, &reference, 2.0).unwrap();
        let (r, o) = (&c.ratio, &c.offset);
        eprintln!(
            "seed {seed}: ratio {:.4} ± {:.4} (true {true_ratio:.4}), offset {:.3}° ± {:.3}° (true {:.3}°), {} readings, rms {:.5} rad",
            r.value,
            r.std.unwrap_or(f64::NAN),
            o.value.to_degrees(),
            o.std.unwrap_or(f64::NAN).to_degrees(),
            true_offset.to_degrees(),
            c.samples,
            c.rms_rad
        );
        assert!(r.estimated && o.estimated, "seed {seed}: {c:?}");
        // Issue target 1% and 0.2°; measured at most 0.24% and 0.11° on
        // these seeds.
        assert!(
            (r.value / true_ratio - 1.0).abs() < 0.005,
            "seed {seed}: {c:?}"
        );
        assert!(
            (o.value - true_offset).abs().to_degrees() < 0.15,
            "seed {seed}: {c:?}"
        );
    }
}

/// A straight drive determines the offset but not the ratio, and says so.
#[test]
fn straight_drive_reports_the_ratio_as_not_estimated() {
    let mut sc = Scenario::builtin("calibration").unwrap();
    sc.route
        .segments
        .retain(|s| matches!(s, deadreckon_sim::Segment::Straight { .. }));
    sc.route.closed = false;
    let st = sc.sensors.steering.as_mut().unwrap();
    st.wheel_offset_rad = 0.03;
    let out = simulate(&sc.with_laps(1), 5).unwrap();
    let reference = Reference::from_truth(&out.drive.truth).unwrap();
    let c = calibrate_steering(&out.drive, &reference, 2.0).unwrap();
    eprintln!("{c:?}");
    assert!(!c.ratio.estimated && c.ratio.std.is_none(), "{c:?}");
    assert!(
        c.ratio.reason.as_deref().unwrap().contains("no turns"),
        "{c:?}"
    );
    assert!(
        c.offset.estimated && (c.offset.value - 0.03).abs() < 0.0035,
        "{c:?}"
    );
    // Nothing above the threshold: nothing estimated.
    let c = calibrate_steering(&out.drive, &reference, 1e3).unwrap();
    assert!(!c.ratio.estimated && !c.offset.estimated, "{c:?}");
    assert!(calibrate_steering(&out.drive, &reference, f64::NAN).is_err());
}
