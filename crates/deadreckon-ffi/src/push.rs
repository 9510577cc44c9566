//! Events in: one typed function per sensor, and one for a line of the event
//! schema (`docs/events.md`). Each completed filter epoch queues a pose for
//! `dr_next_pose`.

use std::ffi::c_char;

use deadreckon_core::ekf::{Event, Measurement};
use deadreckon_io::events;
use deadreckon_io::IoError;

use crate::handle::{with_filter, DrFilter};
use crate::status::{guard, DrStatus, Fail};

/// Checks the values of a typed event as a line's are checked, then pushes it.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
// Inlined into each typed function, where the value check folds to the
// one sensor's values.
#[inline(always)]
unsafe fn push_event(
    filter: *mut DrFilter,
    what: &str,
    measurement: Measurement,
    t_s: f64,
) -> DrStatus {
    let ev = Event { t_s, measurement };
    // Outside the guard (it cannot panic), where it folds to this sensor.
    let finite = events::values_ok(&ev);
    // Not `move`: the closure holds references, so that catch_unwind does
    // not copy the event around (measured: about 40 instructions a push).
    let ev = &ev;
    guard(|| {
        // SAFETY: the caller's contract.
        unsafe {
            with_filter(filter, |f| {
                if !finite {
                    return Err(Fail::new(
                        DrStatus::NotFinite,
                        format!("{what} at t={t_s} s: {}", events::NOT_FINITE),
                    ));
                }
                f.push(ev)
                    .map_err(|e| Fail::new(e.status, format!("{what}: {}", e.message)))?;
                Ok(DrStatus::Ok)
            })
        }
    })
}

/// Wheel ticks of each wheel since the previous wheel row, at `t_s` (s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_wheel_ticks(
    filter: *mut DrFilter,
    t_s: f64,
    fl: i64,
    fr: i64,
    rl: i64,
    rr: i64,
) -> DrStatus {
    let m = Measurement::WheelTicks { fl, fr, rl, rr };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_wheel_ticks", m, t_s) }
}

/// Wheel speeds, m/s, at `t_s` (s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_wheel_speeds(
    filter: *mut DrFilter,
    t_s: f64,
    fl_mps: f64,
    fr_mps: f64,
    rl_mps: f64,
    rr_mps: f64,
) -> DrStatus {
    let m = Measurement::WheelSpeeds {
        fl_mps,
        fr_mps,
        rl_mps,
        rr_mps,
    };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_wheel_speeds", m, t_s) }
}

/// The raw gyro yaw rate, rad/s counter-clockwise, at `t_s` (s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_yaw_rate(
    filter: *mut DrFilter,
    t_s: f64,
    yaw_rate_rps: f64,
) -> DrStatus {
    let m = Measurement::YawRate { yaw_rate_rps };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_yaw_rate", m, t_s) }
}

/// A three-axis gyro reading, rad/s about the sensor's x (forward), y
/// (left), z (up), at `t_s` (s): the yaw rate when the params.toml stores an
/// IMU tilt (projected on its vertical; one-axis yaw rates are then dropped
/// from the first of these on), ignored otherwise.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_gyro3(
    filter: *mut DrFilter,
    t_s: f64,
    x_rps: f64,
    y_rps: f64,
    z_rps: f64,
) -> DrStatus {
    let m = Measurement::Gyro {
        x_rps,
        y_rps,
        z_rps,
    };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_gyro3", m, t_s) }
}

/// An accelerometer reading, m/s² of specific force along the gyro's x, y,
/// z, at `t_s` (s): used for a driven-axle slip the params.toml stores,
/// ignored otherwise.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_accel(
    filter: *mut DrFilter,
    t_s: f64,
    x_mps2: f64,
    y_mps2: f64,
    z_mps2: f64,
) -> DrStatus {
    let m = Measurement::Accel {
        x_mps2,
        y_mps2,
        z_mps2,
    };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_accel", m, t_s) }
}

/// The CAN vehicle speed, m/s, at `t_s` (s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_speed(
    filter: *mut DrFilter,
    t_s: f64,
    speed_mps: f64,
) -> DrStatus {
    let m = Measurement::Speed { speed_mps };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_speed", m, t_s) }
}

/// The steering-wheel angle, rad, left positive, at `t_s` (s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
#[no_mangle]
pub unsafe extern "C" fn dr_push_steering(
    filter: *mut DrFilter,
    t_s: f64,
    steering_wheel_rad: f64,
) -> DrStatus {
    let m = Measurement::Steering { steering_wheel_rad };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_steering", m, t_s) }
}

/// A GNSS fix of the antenna at `t_s` (s): east and north of the drive's
/// origin (m), its horizontal standard deviation `std_m` (m, > 0), and,
/// when the receiver gives them (else null), its course (degrees clockwise
/// from north) and ground speed (m/s).
///
/// # Safety
/// `filter` is null or a live handle used by this thread only;
/// `course_deg` and `speed_mps` are null or readable.
#[no_mangle]
pub unsafe extern "C" fn dr_push_gnss(
    filter: *mut DrFilter,
    t_s: f64,
    east_m: f64,
    north_m: f64,
    std_m: f64,
    course_deg: *const f64,
    speed_mps: *const f64,
) -> DrStatus {
    // SAFETY: null or readable (the caller's contract).
    let (course_deg, speed_mps) =
        unsafe { (course_deg.as_ref().copied(), speed_mps.as_ref().copied()) };
    let m = Measurement::Gnss {
        east_m,
        north_m,
        std_m,
        course_deg,
        speed_mps,
    };
    // SAFETY: the caller's contract, passed on.
    unsafe { push_event(filter, "dr_push_gnss", m, t_s) }
}

/// One line of the event schema (`docs/events.md`, what `deadreckon events`
/// prints), `len` bytes without its newline; a blank line is skipped. Lines
/// are counted over the calls for the line number in errors (`events: line
/// N, column C: …`). An unknown `sensor` is `DR_STATUS_UNKNOWN_SENSOR`, any
/// other malformed line `DR_STATUS_BAD_EVENT`.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only; `line`
/// points to `len` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn dr_push_line(
    filter: *mut DrFilter,
    line: *const c_char,
    len: usize,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter, |f| {
            f.lines += 1;
            let n = f.lines;
            if line.is_null() {
                return Err(Fail::null("line"));
            }
            // The message is formatted only on failure: this runs per line.
            let bytes = std::slice::from_raw_parts(line.cast::<u8>(), len);
            let text = std::str::from_utf8(bytes).map_err(|e| {
                Fail::new(
                    DrStatus::BadEvent,
                    format!("events: line {n} is not UTF-8: {e}"),
                )
            })?;
            if text.trim().is_empty() {
                return Ok(DrStatus::Ok);
            }
            let ev = events::parse_line(text, "events", n).map_err(|e| {
                let status = match &e {
                    // serde's word for a tag no variant has.
                    IoError::BadEvent { msg, .. } if msg.starts_with("unknown variant") => {
                        DrStatus::UnknownSensor
                    }
                    _ if e.to_string().contains(events::NOT_FINITE) => DrStatus::NotFinite,
                    _ => DrStatus::BadEvent,
                };
                Fail::new(status, e.to_string())
            })?;
            f.push(&ev)
                .map_err(|e| Fail::new(e.status, format!("events: line {n}: {}", e.message)))?;
            Ok(DrStatus::Ok)
        })
    })
}

/// One [`Event`] through the typed C function of its sensor: for Rust
/// callers of the C API (the crate's tests, the benchmark against the Rust
/// loop). Not part of the C header.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only.
pub unsafe fn push_typed(filter: *mut DrFilter, ev: &Event) -> DrStatus {
    let t = ev.t_s;
    // SAFETY: the caller's contract, passed on.
    unsafe {
        match ev.measurement {
            Measurement::WheelTicks { fl, fr, rl, rr } => {
                dr_push_wheel_ticks(filter, t, fl, fr, rl, rr)
            }
            Measurement::WheelSpeeds {
                fl_mps,
                fr_mps,
                rl_mps,
                rr_mps,
            } => dr_push_wheel_speeds(filter, t, fl_mps, fr_mps, rl_mps, rr_mps),
            Measurement::YawRate { yaw_rate_rps } => dr_push_yaw_rate(filter, t, yaw_rate_rps),
            Measurement::Gyro {
                x_rps,
                y_rps,
                z_rps,
            } => dr_push_gyro3(filter, t, x_rps, y_rps, z_rps),
            Measurement::Accel {
                x_mps2,
                y_mps2,
                z_mps2,
            } => dr_push_accel(filter, t, x_mps2, y_mps2, z_mps2),
            Measurement::Speed { speed_mps } => dr_push_speed(filter, t, speed_mps),
            Measurement::Steering { steering_wheel_rad } => {
                dr_push_steering(filter, t, steering_wheel_rad)
            }
            Measurement::Gnss {
                east_m,
                north_m,
                std_m,
                course_deg,
                speed_mps,
            } => {
                let (c, v) = (course_deg.as_ref(), speed_mps.as_ref());
                let ptr = |x: Option<&f64>| x.map_or(std::ptr::null(), |x| x as *const f64);
                dr_push_gnss(filter, t, east_m, north_m, std_m, ptr(c), ptr(v))
            }
        }
    }
}
