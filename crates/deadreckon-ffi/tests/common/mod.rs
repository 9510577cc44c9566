//! Shared by the boundary tests: a short simulated drive, filters made
//! through the C API, events pushed through it, poses drained from it.
#![allow(dead_code)] // each test file uses its part

use std::ffi::CStr;

use deadreckon_core::ekf::{DriveEvents, Event};
use deadreckon_core::Drive;
use deadreckon_ffi::*;

/// The built-in evaluation scenario cut to `duration_s` (seed 1): wheel
/// ticks, gyro, CAN speed, steering, GNSS with its speed.
pub fn drive(duration_s: f64) -> Drive {
    let sc = deadreckon_sim::Scenario::builtin("evaluation")
        .unwrap()
        .with_duration_s(duration_s);
    deadreckon_sim::simulate(&sc, 1).unwrap().drive
}

pub fn events(d: &Drive) -> Vec<Event> {
    DriveEvents::all(d).collect()
}

pub fn vehicle_toml(d: &Drive) -> String {
    toml::to_string(&d.vehicle).unwrap()
}

pub fn last_error() -> String {
    // SAFETY: the library's NUL-terminated per-thread message.
    unsafe { CStr::from_ptr(dr_last_error()) }
        .to_string_lossy()
        .into_owned()
}

/// A filter from the vehicle's text with nominal parameters.
pub fn new_filter(vehicle_toml: &str, options: DrOptions) -> *mut DrFilter {
    let mut f = std::ptr::null_mut();
    // SAFETY: valid text, options and out pointer.
    let s = unsafe {
        dr_filter_new(
            vehicle_toml.as_ptr().cast(),
            vehicle_toml.len(),
            std::ptr::null(),
            0,
            &options,
            &mut f,
        )
    };
    assert_eq!(s, DrStatus::Ok, "{}", last_error());
    f
}

/// One event through the typed function of its sensor.
pub fn push_event(f: *mut DrFilter, ev: &Event) -> DrStatus {
    // SAFETY: `f` is a live handle of this thread.
    unsafe { deadreckon_ffi::push_typed(f, ev) }
}

/// One event as a line of the event schema.
pub fn push_line(f: *mut DrFilter, line: &str) -> DrStatus {
    // SAFETY: `f` is a live handle of this thread; the line is valid text.
    unsafe { dr_push_line(f, line.as_ptr().cast(), line.len()) }
}

/// Every pose waiting.
pub fn drain(f: *mut DrFilter, into: &mut Vec<DrPose>) {
    let mut p = std::mem::MaybeUninit::<DrPose>::uninit();
    loop {
        // SAFETY: a live handle and a writable pose.
        match unsafe { dr_next_pose(f, p.as_mut_ptr()) } {
            // SAFETY: written on DR_STATUS_OK.
            DrStatus::Ok => into.push(unsafe { p.assume_init() }),
            DrStatus::NoPose => return,
            s => panic!("dr_next_pose: {s:?}: {}", last_error()),
        }
    }
}

/// The state's bytes.
pub fn save(f: *mut DrFilter) -> Vec<u8> {
    let mut len = 0;
    // SAFETY: a live handle; a null buffer asks for the size.
    let s = unsafe { dr_save_state(f, std::ptr::null_mut(), 0, &mut len) };
    assert_eq!(s, DrStatus::BufferTooSmall);
    let mut buf = vec![0u8; len];
    // SAFETY: `len` writable bytes.
    let s = unsafe { dr_save_state(f, buf.as_mut_ptr(), buf.len(), &mut len) };
    assert_eq!(s, DrStatus::Ok, "{}", last_error());
    assert_eq!(len, buf.len());
    buf
}

pub fn restore(bytes: &[u8]) -> *mut DrFilter {
    let mut f = std::ptr::null_mut();
    // SAFETY: readable bytes, writable out.
    let s = unsafe { dr_filter_restore(bytes.as_ptr(), bytes.len(), &mut f) };
    assert_eq!(s, DrStatus::Ok, "{}", last_error());
    f
}

pub fn free(f: *mut DrFilter) {
    // SAFETY: a live handle, not used again.
    assert_eq!(unsafe { dr_filter_free(f) }, DrStatus::Ok);
}
