//! Status codes, the per-thread last error and the guard every exported
//! function runs its body in (no panic crosses the boundary).

use std::cell::RefCell;
use std::ffi::{c_char, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What a call did. `DR_STATUS_OK` (0) is success; `DR_STATUS_NO_POSE` says
/// that no pose is waiting and is not an error; every other value is an
/// error whose message `dr_last_error` returns on the same thread.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DrStatus {
    /// Success.
    Ok = 0,
    /// `dr_next_pose`: no pose is waiting (not an error).
    NoPose = 1,
    /// A handle or a pointer that must not be null was null.
    NullArgument = 2,
    /// A value was NaN or infinite (or a GNSS `std_m` not positive).
    NotFinite = 3,
    /// An event's time is before the previous event's.
    TimeBackwards = 4,
    /// An event line names a sensor the schema does not have.
    UnknownSensor = 5,
    /// An event line that is not a valid event (`docs/events.md`).
    BadEvent = 6,
    /// The vehicle, the parameters or the options were refused (unreadable,
    /// not TOML, a missing key, a value out of range, unknown timing).
    BadConfig = 7,
    /// State bytes that are not a saved state.
    BadState = 8,
    /// The filter refused the call (e.g. `dr_finish` before the GNSS start,
    /// learning refused with table I's noise under per-reading timing).
    Filter = 9,
    /// Nothing to report yet: no pose before the first epoch, no learned
    /// parameters unless learning and started, no counts before the start.
    NotAvailable = 10,
    /// The buffer given to `dr_save_state` is too small (the size needed is
    /// written to `len`).
    BufferTooSmall = 11,
    /// An internal error (a panic) was caught; a handle it happened in
    /// refuses every later call with this status: free it.
    Panic = 12,
}

/// A failed call: its status and message, boxed so that a call's
/// `Result<DrStatus, Fail>` is two words, returned in registers on the hot
/// path of every push.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Fail(Box<Failure>);

/// What [`Fail`] holds.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Failure {
    pub(crate) status: DrStatus,
    pub(crate) message: String,
}

impl std::ops::Deref for Fail {
    type Target = Failure;
    fn deref(&self) -> &Failure {
        &self.0
    }
}

impl Fail {
    #[cold]
    pub(crate) fn new(status: DrStatus, message: impl Into<String>) -> Self {
        Fail(Box::new(Failure {
            status,
            message: message.into(),
        }))
    }

    #[cold]
    pub(crate) fn null(what: &str) -> Self {
        Fail::new(DrStatus::NullArgument, format!("{what} is null"))
    }
}

thread_local! {
    /// The message of the last call that failed on this thread.
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

fn set_last_error(message: &str) {
    // An interior NUL (never in our messages) would cut the C string: drop it.
    let c = CString::new(message.replace('\0', "")).unwrap_or_default();
    LAST_ERROR.with(|e| *e.borrow_mut() = c);
}

/// The message of the last call that failed on this thread, as a pointer
/// to a NUL-terminated string that stays valid until the next failing call
/// on this thread ("" when none has failed). Successful calls leave it as is.
pub(crate) fn last_error_ptr() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Runs `body`, turning its failure into a status and the last error, and a
/// panic into `DrStatus::Panic` (with the panic's message).
#[inline(always)]
pub(crate) fn guard(body: impl FnOnce() -> Result<DrStatus, Fail>) -> DrStatus {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(status)) => status,
        Ok(Err(fail)) => {
            set_last_error(&fail.message);
            fail.status
        }
        Err(payload) => {
            let what = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no message".into());
            set_last_error(&format!("internal error (a panic, caught): {what}"));
            // The payload's own drop must not unwind out of here either.
            let _ = catch_unwind(AssertUnwindSafe(move || drop(payload)));
            DrStatus::Panic
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn last_error() -> String {
        // SAFETY: the pointer is to this thread's NUL-terminated message.
        unsafe { std::ffi::CStr::from_ptr(last_error_ptr()) }
            .to_string_lossy()
            .into_owned()
    }

    #[test]
    fn a_panic_is_caught_and_becomes_a_status_with_its_message() {
        let s = guard(|| panic!("boom at {}", 3));
        assert_eq!(s, DrStatus::Panic);
        assert_eq!(last_error(), "internal error (a panic, caught): boom at 3");
    }

    #[test]
    fn a_failure_sets_the_message_and_a_success_leaves_it() {
        let s = guard(|| Err(Fail::new(DrStatus::NotFinite, "t_s is NaN")));
        assert_eq!(s, DrStatus::NotFinite);
        assert_eq!(last_error(), "t_s is NaN");
        assert_eq!(guard(|| Ok(DrStatus::Ok)), DrStatus::Ok);
        assert_eq!(last_error(), "t_s is NaN");
    }

    #[test]
    fn the_last_error_is_per_thread() {
        let _ = guard(|| Err(Fail::new(DrStatus::BadEvent, "here")));
        let other = std::thread::spawn(|| {
            let _ = guard(|| Err(Fail::new(DrStatus::BadConfig, "there")));
            last_error()
        })
        .join()
        .unwrap();
        assert_eq!(other, "there");
        assert_eq!(last_error(), "here");
    }
}
