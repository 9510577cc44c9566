//! The tricycle log read for the kinematic model: signed cumulative ticks,
//! signed steering counts, the tracker pose as the reference, the header as
//! the nominal parameters.

mod common;

use std::path::Path;

use deadreckon_core::kinematics::KinematicModel;
use deadreckon_import::tricycle::{
    parse_tricycle, read_tricycle_kinematic, tricycle_kinematic, TricycleOptions,
};
use deadreckon_import::ImportError;

#[test]
fn real_log_forward_then_reverse_net_12_m_of_37_m_path() {
    let d = read_tricycle_kinematic(
        &common::data("tricycle-tracker/dataset.txt"),
        &TricycleOptions::default(),
    )
    .unwrap();
    assert_eq!(d.samples.len(), 2434);
    assert_eq!(d.geometry.ticks_per_rev, 5000);
    assert_eq!(d.nominal.mount.x_m, 1.5);
    let per_tick = d.nominal.ktraction_m / 5000.0;
    let net = d.samples.last().unwrap().ticks as f64 * per_tick;
    let path = d.path_m(0, d.samples.len() - 1);
    assert!((net - 12.0).abs() < 1.0, "net {net} m");
    assert!((path - 37.0).abs() < 1.5, "path {path} m");
    // Signed steering: both ways, up to about 1.1 rad of wheel angle at Ksteer 0.56.
    let (lo, hi) = (0..d.samples.len())
        .map(|i| d.encoder_angle(i))
        .fold((f64::MAX, f64::MIN), |(a, b), e| (a.min(e), b.max(e)));
    assert!(lo < -1.0 && hi > 1.0, "encoder angle {lo}..{hi}");
    // The reference is the tracker's pose as recorded.
    let r = d.samples[0].reference.unwrap();
    assert!((r.x_m - 6.50242e-05).abs() < 1e-12 && (r.yaw_rad - 0.000941697).abs() < 1e-12);
}

#[test]
fn non_increasing_time_and_implausible_steps_name_the_line() {
    let header = "#kinematic_model: traction_drive_wheel\n#parameters: [ Ksteer Ktraction axis_length steer_offset ]\n\
        #parameter_values: 0.1 0.0106141 1.4 0\n#joints_max_enc: [ steering traction_wheel ]\n#joints_max_enc_values: 8192 5000\n";
    let rec =
        |t: f64, c: u32| format!("time: {t} ticks: 5 {c} model_pose: 0 0 0 tracker_pose: 0 0 0\n");
    for (body, line) in [
        (rec(0.0, 0) + &rec(0.04, 10) + &rec(0.04, 20), "line 8"),
        (rec(0.0, 0) + &rec(0.04, 2_000_000), "line 7"),
    ] {
        let text = format!("{header}{body}");
        let log = parse_tricycle(text.as_bytes(), Path::new("t.txt")).unwrap();
        let e =
            tricycle_kinematic(&log, Path::new("t.txt"), &TricycleOptions::default()).unwrap_err();
        assert!(matches!(e, ImportError::Invalid { .. }), "{e}");
        assert!(e.to_string().contains(line), "{e}");
    }
}
