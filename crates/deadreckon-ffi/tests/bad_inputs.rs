//! Bad inputs at the boundary are statuses with a message, never crashes:
//! null handles and pointers, NaN and infinite values, time going
//! backwards, unknown sensors, malformed lines, bad configuration and state.

mod common;

use std::ptr::{null, null_mut};

use common::*;
use deadreckon_ffi::*;

fn started_filter() -> (*mut DrFilter, f64) {
    let d = drive(30.0);
    let f = new_filter(&vehicle_toml(&d), DrOptions::default());
    let evs = events(&d);
    let mut poses = Vec::new();
    for ev in &evs {
        assert_eq!(push_event(f, ev), DrStatus::Ok, "{}", last_error());
        drain(f, &mut poses);
    }
    assert!(!poses.is_empty());
    (f, evs.last().unwrap().t_s)
}

#[test]
fn null_handles_and_pointers_are_errors() {
    let (f, _) = started_filter();
    let mut pose = std::mem::MaybeUninit::<DrPose>::uninit();
    let mut len = 0usize;
    let mut b = false;
    // SAFETY: every pointer is null or valid.
    unsafe {
        let calls: Vec<(&str, DrStatus)> = vec![
            (
                "wheel_ticks",
                dr_push_wheel_ticks(null_mut(), 1.0, 1, 1, 1, 1),
            ),
            (
                "wheel_speeds",
                dr_push_wheel_speeds(null_mut(), 1.0, 1.0, 1.0, 1.0, 1.0),
            ),
            ("yaw_rate", dr_push_yaw_rate(null_mut(), 1.0, 0.0)),
            ("speed", dr_push_speed(null_mut(), 1.0, 0.0)),
            ("steering", dr_push_steering(null_mut(), 1.0, 0.0)),
            (
                "gnss",
                dr_push_gnss(null_mut(), 1.0, 0.0, 0.0, 1.0, null(), null()),
            ),
            ("line", dr_push_line(null_mut(), c"{}".as_ptr(), 2)),
            ("line text", dr_push_line(f, null(), 3)),
            ("next_pose", dr_next_pose(null_mut(), pose.as_mut_ptr())),
            ("next_pose out", dr_next_pose(f, null_mut())),
            ("latest_pose", dr_latest_pose(null(), pose.as_mut_ptr())),
            ("latest_pose out", dr_latest_pose(f, null_mut())),
            ("is_started", dr_is_started(null(), &mut b)),
            ("learned", dr_learned(null(), null_mut())),
            ("gate_counts", dr_gate_counts(null(), null_mut())),
            ("gate_counts out", dr_gate_counts(f, null_mut())),
            ("finish", dr_finish(null_mut())),
            ("save", dr_save_state(null(), null_mut(), 0, &mut len)),
            ("save len", dr_save_state(f, null_mut(), 0, null_mut())),
            ("restore", dr_filter_restore(null(), 0, &mut null_mut())),
            (
                "restore out",
                dr_filter_restore(b"{}".as_ptr(), 2, null_mut()),
            ),
            (
                "new vehicle",
                dr_filter_new(null(), 0, null(), 0, null(), &mut null_mut()),
            ),
            (
                "new out",
                dr_filter_new(c"x".as_ptr(), 1, null(), 0, null(), null_mut()),
            ),
            (
                "from files",
                dr_filter_new_from_files(null(), null(), null(), &mut null_mut()),
            ),
        ];
        for (what, s) in calls {
            assert_eq!(s, DrStatus::NullArgument, "{what}");
        }
        assert_eq!(last_error(), "vehicle_path is null");
        assert!(dr_filter_warning(null()).is_null());
        assert_eq!(dr_filter_free(null_mut()), DrStatus::Ok);
    }
    free(f);
}

#[test]
fn nan_and_infinite_values_are_errors_and_change_nothing() {
    let (f, t) = started_filter();
    let before = save(f);
    let nan = f64::NAN;
    let inf = f64::INFINITY;
    let t1 = t + 0.01;
    // SAFETY: a live handle; pointers valid.
    unsafe {
        let calls = [
            ("t_s", dr_push_yaw_rate(f, nan, 0.0)),
            ("t_s inf", dr_push_speed(f, inf, 1.0)),
            (
                "wheel speed",
                dr_push_wheel_speeds(f, t1, 1.0, nan, 1.0, 1.0),
            ),
            ("yaw rate", dr_push_yaw_rate(f, t1, -inf)),
            ("speed", dr_push_speed(f, t1, nan)),
            ("steering", dr_push_steering(f, t1, inf)),
            ("east", dr_push_gnss(f, t1, nan, 0.0, 1.0, null(), null())),
            ("std 0", dr_push_gnss(f, t1, 0.0, 0.0, 0.0, null(), null())),
            (
                "std negative",
                dr_push_gnss(f, t1, 0.0, 0.0, -1.0, null(), null()),
            ),
            ("course", dr_push_gnss(f, t1, 0.0, 0.0, 1.0, &nan, null())),
            (
                "gnss speed",
                dr_push_gnss(f, t1, 0.0, 0.0, 1.0, null(), &inf),
            ),
        ];
        for (what, s) in calls {
            assert_eq!(s, DrStatus::NotFinite, "{what}: {}", last_error());
        }
        assert!(
            last_error().starts_with("dr_push_gnss at t="),
            "{}",
            last_error()
        );
        // JSON has no NaN: in a line, a std_m of 0 is the value refused;
        // a number too large for a double is a malformed line.
        let line = format!(r#"{{"t_s":{t1},"sensor":"gnss","east_m":0,"north_m":0,"std_m":0}}"#);
        assert_eq!(push_line(f, &line), DrStatus::NotFinite, "{}", last_error());
        let line = format!(r#"{{"t_s":{t1},"sensor":"speed","speed_mps":1e999}}"#);
        assert_eq!(push_line(f, &line), DrStatus::BadEvent, "{}", last_error());
    }
    assert_eq!(save(f), before, "a refused value changed the state");
    free(f);
}

#[test]
fn time_going_backwards_is_an_error_before_and_after_the_start() {
    // Before the start (waiting for GNSS).
    let d = drive(30.0);
    let v = vehicle_toml(&d);
    let f = new_filter(&v, DrOptions::default());
    // SAFETY: a live handle.
    unsafe {
        assert_eq!(dr_push_yaw_rate(f, 1.0, 0.0), DrStatus::Ok);
        assert_eq!(dr_push_yaw_rate(f, 0.5, 0.0), DrStatus::TimeBackwards);
        assert!(
            last_error().contains("t=0.5 s comes after one at t=1 s"),
            "{}",
            last_error()
        );
        // Equal times are fine.
        assert_eq!(dr_push_speed(f, 1.0, 0.0), DrStatus::Ok);
    }
    free(f);
    // After the start.
    let (f, t) = started_filter();
    let before = save(f);
    // SAFETY: a live handle.
    unsafe {
        assert_eq!(
            dr_push_wheel_ticks(f, t - 1.0, 1, 1, 1, 1),
            DrStatus::TimeBackwards
        );
    }
    let line = format!(
        r#"{{"t_s":{},"sensor":"yaw_rate","yaw_rate_rps":0.0}}"#,
        t - 5.0
    );
    assert_eq!(push_line(f, &line), DrStatus::TimeBackwards);
    assert!(
        last_error().starts_with("events: line 1: "),
        "{}",
        last_error()
    );
    assert_eq!(save(f), before);
    free(f);
    // Right after a restore the filter itself finds it.
    let g = restore(&before);
    // SAFETY: a live handle.
    let s = unsafe { dr_push_yaw_rate(g, t - 1.0, 0.0) };
    assert_eq!(s, DrStatus::TimeBackwards, "{}", last_error());
    free(g);
}

#[test]
fn unknown_sensors_and_malformed_lines_are_errors_naming_the_line() {
    let (f, t) = started_filter();
    let t1 = t + 0.01;
    let lidar = format!(r#"{{"t_s":{t1},"sensor":"lidar","range_m":3.0}}"#);
    assert_eq!(push_line(f, &lidar), DrStatus::UnknownSensor);
    assert!(
        last_error().starts_with("events: line 1, column "),
        "{}",
        last_error()
    );
    assert!(last_error().contains("lidar"), "{}", last_error());
    assert_eq!(push_line(f, "   "), DrStatus::Ok, "a blank line is skipped");
    let cases = [
        "{not json",
        r#"{"t_s":1.0,"sensor":"speed"}"#,
        r#"{"t_s":1.0,"sensor":"speed","speed_mps":1.0,"extra":2}"#,
        r#"{"sensor":"speed","speed_mps":1.0}"#,
        r#"{"t_s":"soon","sensor":"speed","speed_mps":1.0}"#,
    ];
    for (i, line) in cases.iter().enumerate() {
        assert_eq!(push_line(f, line), DrStatus::BadEvent, "{line}");
        let want = format!("events: line {}, column ", i + 3);
        assert!(last_error().starts_with(&want), "{line}: {}", last_error());
    }
    // Bytes that are not UTF-8.
    let bad = [b'{', 0xff, b'}'];
    // SAFETY: a live handle, 3 readable bytes.
    assert_eq!(
        unsafe { dr_push_line(f, bad.as_ptr().cast(), 3) },
        DrStatus::BadEvent
    );
    free(f);
}

#[test]
fn bad_configuration_and_state_are_refused_without_a_handle() {
    let d = drive(30.0);
    let v = vehicle_toml(&d);
    let new = |vehicle: &str, params: Option<&str>, o: DrOptions| {
        let mut f = std::ptr::dangling_mut::<DrFilter>(); // must be overwritten
        let (pp, pl) = params.map_or((null(), 0), |p| (p.as_ptr().cast(), p.len()));
        // SAFETY: valid text and pointers.
        let s =
            unsafe { dr_filter_new(vehicle.as_ptr().cast(), vehicle.len(), pp, pl, &o, &mut f) };
        assert!(
            f.is_null() || s == DrStatus::Ok,
            "the handle is null on failure"
        );
        if !f.is_null() {
            free(f);
        }
        s
    };
    let o = DrOptions::default();
    assert_eq!(new("wheelbase_m = [", None, o), DrStatus::BadConfig);
    assert!(
        last_error().starts_with("vehicle.toml: "),
        "{}",
        last_error()
    );
    let typo = v.replacen("wheelbase_m", "wheelbase", 1);
    assert_eq!(new(&typo, None, o), DrStatus::BadConfig);
    let bad_timing = DrOptions {
        timing: 7,
        learn: false,
    };
    assert_eq!(new(&v, None, bad_timing), DrStatus::BadConfig);
    assert!(last_error().contains("timing 7"), "{}", last_error());
    assert_eq!(new(&v, Some("gyro_bias_rps = 0.0"), o), DrStatus::BadConfig);
    assert!(last_error().contains("params.toml"), "{}", last_error());
    let params = "gyro_bias_rps = 0.001\nspeed_scale = 1.0\ncircumference_fl_m = 1.9\n\
                  circumference_fr_m = 1.9\ncircumference_rl_m = 1.9\ncircumference_rr_m = 1.9\n";
    assert_eq!(new(&v, Some(params), o), DrStatus::Ok);
    // Files: a missing one names itself.
    let mut f = null_mut();
    // SAFETY: NUL-terminated paths, writable out.
    let s = unsafe {
        dr_filter_new_from_files(
            c"/nonexistent/vehicle.toml".as_ptr(),
            null(),
            null(),
            &mut f,
        )
    };
    assert_eq!(s, DrStatus::BadConfig);
    assert!(
        last_error().contains("/nonexistent/vehicle.toml"),
        "{}",
        last_error()
    );
    // State bytes that are not a state.
    for bytes in [&b"{}"[..], b"not json", &[0xff, 0xfe]] {
        let mut f = null_mut();
        // SAFETY: readable bytes, writable out.
        let s = unsafe { dr_filter_restore(bytes.as_ptr(), bytes.len(), &mut f) };
        assert_eq!(s, DrStatus::BadState);
        assert!(f.is_null());
    }
}

#[test]
fn before_the_start_results_are_not_available_and_finish_says_why() {
    let d = drive(30.0);
    let f = new_filter(
        &vehicle_toml(&d),
        DrOptions {
            timing: DR_TIMING_WHEEL,
            learn: true,
        },
    );
    let mut pose = std::mem::MaybeUninit::uninit();
    let mut gates = std::mem::MaybeUninit::uninit();
    let mut learned = std::mem::MaybeUninit::uninit();
    let mut started = true;
    // SAFETY: a live handle and writable outputs.
    unsafe {
        assert_eq!(dr_is_started(f, &mut started), DrStatus::Ok);
        assert!(!started);
        assert_eq!(dr_latest_pose(f, pose.as_mut_ptr()), DrStatus::NotAvailable);
        assert_eq!(
            dr_gate_counts(f, gates.as_mut_ptr()),
            DrStatus::NotAvailable
        );
        assert_eq!(dr_learned(f, learned.as_mut_ptr()), DrStatus::NotAvailable);
        assert_eq!(dr_next_pose(f, pose.as_mut_ptr()), DrStatus::NoPose);
        assert_eq!(dr_finish(f), DrStatus::Filter);
        assert!(last_error().contains("GNSS"), "{}", last_error());
    }
    free(f);
}

#[test]
fn a_buffer_too_small_gets_the_size_and_no_bytes() {
    let (f, _) = started_filter();
    let need = save(f).len();
    let mut buf = vec![7u8; need - 1];
    let mut len = 0;
    // SAFETY: `buf.len()` writable bytes.
    let s = unsafe { dr_save_state(f, buf.as_mut_ptr(), buf.len(), &mut len) };
    assert_eq!(s, DrStatus::BufferTooSmall);
    assert_eq!(len, need);
    assert!(buf.iter().all(|b| *b == 7), "nothing written");
    free(f);
}

/// A params.toml's stored delays are applied (issue 29: no warning any
/// more); a slip stored without its mean forward force (an older file)
/// cannot be, and the filter's warning says so, as `stream` does.
#[test]
fn a_params_file_with_stored_corrections_gives_stream_s_warning() {
    let d = drive(30.0);
    let v = vehicle_toml(&d);
    let base = "gyro_bias_rps = 0.0\nspeed_scale = 1.0\ncircumference_fl_m = 1.9\n\
                circumference_fr_m = 1.9\ncircumference_rl_m = 1.9\ncircumference_rr_m = 1.9\n\
                [delays.gnss]\ndelay_s = 0.1\n";
    let old_slip = format!("{base}[traction]\nslip_per_mps2 = 0.003\n");
    for (params, warned) in [(base.to_string(), false), (old_slip, true)] {
        let mut f = null_mut();
        // SAFETY: valid text, writable out.
        let s = unsafe {
            dr_filter_new(
                v.as_ptr().cast(),
                v.len(),
                params.as_ptr().cast(),
                params.len(),
                null(),
                &mut f,
            )
        };
        assert_eq!(s, DrStatus::Ok, "{}", last_error());
        // SAFETY: a live handle; the warning lives as long.
        let w = unsafe { dr_filter_warning(f) };
        assert_eq!(!w.is_null(), warned, "{params}");
        if warned {
            // SAFETY: not null, NUL-terminated, lives as long as the handle.
            let w = unsafe { std::ffi::CStr::from_ptr(w) }
                .to_string_lossy()
                .into_owned();
            assert!(w.contains("mean_force_mps2"), "{w}");
        }
        free(f);
    }
}
