//! Results out: the poses, the learned parameters, the gate counts; the end
//! of a stream.

use crate::handle::{with_filter, DrFilter};
use crate::status::{guard, DrStatus, Fail};
use crate::types::{DrGateCounts, DrLearned, DrPose};
use deadreckon_core::online::LearnTargets;

/// The output `out` (null: an error), checked before anything is computed.
///
/// # Safety
/// `out` is null or writable.
unsafe fn output<'a, T>(out: *mut T) -> Result<&'a mut T, Fail> {
    // SAFETY: the caller's contract.
    unsafe { out.as_mut() }.ok_or_else(|| Fail::null("out"))
}

/// Takes the oldest pose not yet taken into `*out`: `DR_STATUS_OK`, or
/// `DR_STATUS_NO_POSE` (not an error) when none is waiting. Each filter
/// epoch gives one pose, as `deadreckon stream` prints one line:
/// `while (dr_next_pose(f, &p) == DR_STATUS_OK) { … }` after each push.
///
/// # Safety
/// `filter` is null or a live handle used by this thread only; `out` is
/// null or writable.
#[no_mangle]
pub unsafe extern "C" fn dr_next_pose(filter: *mut DrFilter, out: *mut DrPose) -> DrStatus {
    // The common answer after a push, without the guard's work: nothing
    // can panic here.
    // SAFETY: the caller's contract.
    if let Some(f) = unsafe { filter.as_ref() } {
        if f.poses.is_empty() && !f.in_call() && !out.is_null() {
            return DrStatus::NoPose;
        }
    }
    // SAFETY: the caller's contract, passed on.
    unsafe { next_pose(filter, out) }
}

/// `dr_next_pose` past its fast path (apart, so that the fast path has no
/// frame to set up).
///
/// # Safety
/// As `dr_next_pose`.
#[inline(never)]
unsafe fn next_pose(filter: *mut DrFilter, out: *mut DrPose) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter, |f| {
            let out = output(out)?;
            match f.poses.pop_front() {
                Some(p) => {
                    *out = p.point.into();
                    Ok(DrStatus::Ok)
                }
                None => Ok(DrStatus::NoPose),
            }
        })
    })
}

/// The newest pose (taken or not) into `*out`; `DR_STATUS_NOT_AVAILABLE`
/// before the first epoch.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_latest_pose(filter: *const DrFilter, out: *mut DrPose) -> DrStatus {
    // SAFETY: the caller's contract, passed on; the handle is only read.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            let out = output(out)?;
            *out = f
                .latest
                .map(|p| p.point)
                .ok_or_else(|| {
                    Fail::new(
                        DrStatus::NotAvailable,
                        "no pose yet: the filter has run no epoch",
                    )
                })?
                .into();
            Ok(DrStatus::Ok)
        })
    })
}

/// Takes the oldest pose not yet taken into `*out` and its 95 % error
/// bound, m, into `*bound_95_m` (`deadreckon stream`'s `bound_95_m`: the
/// filter's covariance inflated by the params.toml's `[bound]` factor,
/// with the last fix's declared accuracy; docs/bound.md); otherwise as
/// `dr_next_pose`. A function of its own so that `DrPose` keeps its layout.
///
/// # Safety
/// As `dr_next_pose`; `bound_95_m` is null or writable.
#[no_mangle]
pub unsafe extern "C" fn dr_next_pose_with_bound(
    filter: *mut DrFilter,
    out: *mut DrPose,
    bound_95_m: *mut f64,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter, |f| {
            let out = output(out)?;
            let bound = output(bound_95_m)?;
            match f.poses.pop_front() {
                Some(p) => {
                    *out = p.point.into();
                    *bound = p.bound_95_m;
                    Ok(DrStatus::Ok)
                }
                None => Ok(DrStatus::NoPose),
            }
        })
    })
}

/// The 95 % error bound of the newest pose (`dr_latest_pose`'s), m, into
/// `*out`; `DR_STATUS_NOT_AVAILABLE` before the first epoch.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_latest_bound(filter: *const DrFilter, out: *mut f64) -> DrStatus {
    // SAFETY: the caller's contract, passed on; the handle is only read.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            let out = output(out)?;
            *out = f.latest.map(|p| p.bound_95_m).ok_or_else(|| {
                Fail::new(
                    DrStatus::NotAvailable,
                    "no pose yet: the filter has run no epoch",
                )
            })?;
            Ok(DrStatus::Ok)
        })
    })
}

/// Whether the filter has started (from GNSS: the first fix and the
/// direction of the first 10 m), into `*out`.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_is_started(filter: *const DrFilter, out: *mut bool) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            *output(out)? = f.online.is_started();
            Ok(DrStatus::Ok)
        })
    })
}

/// The parameters learned so far with their standard errors into `*out`;
/// `DR_STATUS_NOT_AVAILABLE` unless the filter learns (`DrOptions::learn`)
/// and has started.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_learned(filter: *const DrFilter, out: *mut DrLearned) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            let out = output(out)?;
            let l = f.online.learned(&LearnTargets::default()).ok_or_else(|| {
                Fail::new(
                    DrStatus::NotAvailable,
                    if f.online.is_started() {
                        "no learned parameters: the filter was not created to learn them"
                    } else {
                        "no learned parameters yet: the filter has not started"
                    },
                )
            })?;
            *out = l.into();
            Ok(DrStatus::Ok)
        })
    })
}

/// The χ² gate's counts per sensor into `*out`; `DR_STATUS_NOT_AVAILABLE`
/// before the start.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_gate_counts(
    filter: *const DrFilter,
    out: *mut DrGateCounts,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            let out = output(out)?;
            let s = f.online.stats().ok_or_else(|| {
                Fail::new(
                    DrStatus::NotAvailable,
                    "no gate counts yet: the filter has not started",
                )
            })?;
            *out = s.gates.into();
            Ok(DrStatus::Ok)
        })
    })
}

/// Ends the stream: runs the epochs still waiting for later events, those
/// of the events a params.toml's stored delays or slip hold back included
/// (their poses are queued for `dr_next_pose`; save a state to resume from
/// before this, not after). A stream that never started (no GNSS start) is
/// `DR_STATUS_FILTER`, saying why.
///
/// # Safety
/// As `dr_next_pose`.
#[no_mangle]
pub unsafe extern "C" fn dr_finish(filter: *mut DrFilter) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    guard(|| unsafe {
        with_filter(filter, |f| {
            f.finish()?;
            Ok(DrStatus::Ok)
        })
    })
}
