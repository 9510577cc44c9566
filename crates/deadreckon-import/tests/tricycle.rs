//! The tricycle-with-tracker log.

mod common;

use std::path::Path;

use deadreckon_core::drive::Wheels;
use deadreckon_import::tricycle::{
    parse_tricycle, read_tricycle, tick_delta, tricycle_drive, TricycleOptions,
};
use deadreckon_import::{ImportError, TimeOrderPolicy};

const HEADER: &str = "#kinematic_model: traction_drive_wheel\n\
#parameters: [ Ksteer Ktraction axis_length steer_offset ]\n\
#parameter_values: 0.1 0.0106141 1.4 0 \n\
#joints_max_enc: [ steering traction_wheel ]\n\
#joints_max_enc_values: 8192 5000 \n\
#laser wrt base_link \n\
#\ttranslation:\t[ 1.5, 0, 0 ],\n\
#\trotation:\t [ 0, 0, 0, 1 ]\n";

fn line(t: f64, steer: u32, traction: u32) -> String {
    format!("time: {t} ticks: {steer} {traction} model_pose: 0 0 0 tracker_pose: 1.5 0 0\n")
}

#[test]
fn tick_delta_handles_the_wrap_both_ways() {
    assert_eq!(tick_delta(4_294_962_835, 526), 4987);
    assert_eq!(tick_delta(526, 4_294_962_835), -4987);
    assert_eq!(tick_delta(u32::MAX, 0), 1);
    assert_eq!(tick_delta(10, 3), -7);
    assert_eq!(tick_delta(7, 7), 0);
}

#[test]
fn synthetic_wrap_gives_correct_per_row_deltas() {
    let mut text = HEADER.to_string();
    for (k, c) in [u32::MAX - 20, u32::MAX - 5, 9, 100, 90].iter().enumerate() {
        text += &line(k as f64 * 0.04, 0, *c);
    }
    let log = parse_tricycle(text.as_bytes(), Path::new("synthetic.txt")).unwrap();
    let imp = tricycle_drive(
        &log,
        Path::new("synthetic.txt"),
        &TricycleOptions::default(),
    )
    .unwrap();
    let Wheels::Ticks(t) = &imp.drive.wheels else {
        panic!()
    };
    assert_eq!(
        t.iter().map(|w| w.fl).collect::<Vec<_>>(),
        vec![0, 15, 15, 91, -10]
    );
    assert!(t.iter().all(|w| w.fl == w.fr && w.rl == 0 && w.rr == 0));
    // The tracker sensor at (1.5, 0) heading east puts the base at the origin.
    assert!(imp.drive.truth[0].east_m.abs() < 1e-12);
}

#[test]
fn implausible_jump_is_an_error_or_gated_and_counted() {
    let mut text = HEADER.to_string();
    // 1,000,000 ticks = 2.1 m in 0.04 s = 53 m/s.
    for (k, c) in [0u32, 100, 1_000_100, 1_000_200].iter().enumerate() {
        text += &line(k as f64 * 0.04, 0, *c);
    }
    let log = parse_tricycle(text.as_bytes(), Path::new("jump.txt")).unwrap();
    let e = tricycle_drive(&log, Path::new("jump.txt"), &TricycleOptions::default()).unwrap_err();
    match &e {
        ImportError::Stream {
            stream,
            index: 2,
            message,
            ..
        } => {
            assert_eq!(stream, "wheel_ticks");
            assert!(message.contains("line 11"), "{message}");
        }
        other => panic!("{other}"),
    }
    let o = TricycleOptions {
        policy: TimeOrderPolicy::Gate,
        ..Default::default()
    };
    let imp = tricycle_drive(&log, Path::new("jump.txt"), &o).unwrap();
    let r = imp.report.stream("wheel_ticks").unwrap();
    assert_eq!((r.kept, r.gated_invalid), (3, 1));
    let Wheels::Ticks(t) = &imp.drive.wheels else {
        panic!()
    };
    assert_eq!(
        t.iter().map(|w| w.fl).collect::<Vec<_>>(),
        vec![0, 100, 100]
    );
}

#[test]
fn malformed_lines_name_line_and_column() {
    let cases = [
        (
            "time: 1.0 ticks: 290 42 model_pose: 0 0 0 tracker_pose: 0 0\n",
            9,
            60,
        ),
        (
            "time: 1.0 ticks: 290 -42 model_pose: 0 0 0 tracker_pose: 0 0 0\n",
            9,
            22,
        ),
        (
            "time: 1.0 ticks: 290 4294967296 model_pose: 0 0 0 tracker_pose: 0 0 0\n",
            9,
            22,
        ),
        (
            "time: x ticks: 290 42 model_pose: 0 0 0 tracker_pose: 0 0 0\n",
            9,
            7,
        ),
        (
            "time: 1.0 tick: 290 42 model_pose: 0 0 0 tracker_pose: 0 0 0\n",
            9,
            11,
        ),
        (
            "time: 1.0 ticks: 290 42 model_pose: 0 0 nan tracker_pose: 0 0 0\n",
            9,
            41,
        ),
        (
            "time: 1.0 ticks: 290 42 model_pose: 0 0 0 tracker_pose: 0 0 0 7\n",
            9,
            63,
        ),
    ];
    for (bad, line, column) in cases {
        let text = format!("{HEADER}{bad}");
        match parse_tricycle(text.as_bytes(), Path::new("bad.txt")) {
            Err(ImportError::Parse {
                line: l,
                column: c,
                ref message,
                ..
            }) => {
                assert_eq!((l, c), (line, column), "{bad}: {message}")
            }
            other => panic!("{bad}: {other:?}"),
        }
    }
    let e = parse_tricycle(
        b"time: 1 ticks: 1 2 model_pose: 0 0 0 tracker_pose: 0 0 0\n",
        Path::new("h.txt"),
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("h.txt:1:1") && e.contains("kinematic_model"),
        "{e}"
    );
}

#[test]
fn real_log_reads_with_its_wraps() {
    let path = common::data("tricycle-tracker/dataset.txt");
    let imp = read_tricycle(&path, &TricycleOptions::default()).unwrap();
    println!("{}", imp.report);
    let d = &imp.drive;
    let Wheels::Ticks(t) = &d.wheels else {
        panic!()
    };
    assert_eq!(t.len(), 2434);
    assert_eq!(imp.report.total_gated(), 0);
    // The counter starts at 4294859756 and ends at 5543456 after wrapping once:
    // net ticks = 5543456 + 2^32 - 4294859756.
    let net: i64 = t.iter().map(|w| w.fl).sum();
    assert_eq!(net, 5_543_456 + (1i64 << 32) - 4_294_859_756);
    assert!(t.iter().any(|w| w.fl < 0), "the log has backward steps");
    assert!((d.vehicle.wheelbase_m - 1.4).abs() < 1e-12);
    assert!((d.vehicle.steering_ratio - 10.0).abs() < 1e-12);
    assert_eq!(d.vehicle.ticks_per_rev, 5000);
    // The first sensor pose is near (0, 0) heading ~0: the base is 1.5 m behind it.
    assert!((d.truth[0].east_m + 1.5).abs() < 0.01);
    // Steering: encoder 290 -> 2π·290/8192 rad at the encoder, 0.022 rad at the wheel.
    assert!((d.steering[0].value - std::f64::consts::TAU * 290.0 / 8192.0).abs() < 1e-12);
    // Encoder values above 4096 are negative angles.
    assert!(d.steering.iter().any(|s| s.value < 0.0));
}
