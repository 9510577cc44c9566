//! The handle behind `DrFilter*`: the [`Online`] filter of `deadreckon
//! stream`, the poses it emitted and not yet taken, and the boundary's
//! checks (time order, values, a call interrupted by a panic).

use std::collections::VecDeque;
use std::ffi::CString;

use deadreckon_core::bound_pose::Pose;
use deadreckon_core::ekf::Event;
use deadreckon_core::online::Online;

use crate::status::{DrStatus, Fail};

/// A filter (opaque to C): create it with `dr_filter_new` (or
/// `dr_filter_new_from_files`, `dr_filter_restore`), free it with
/// `dr_filter_free`. Use a handle from one thread at a time.
pub struct DrFilter {
    /// Boxed: the boundary's own fields, read on every call, then share a
    /// cache line or two instead of sitting behind the filter's kilobytes.
    pub(crate) online: Box<Online>,
    /// Poses emitted (with their 95 % bounds) and not yet taken by
    /// `dr_next_pose`, oldest first.
    pub(crate) poses: VecDeque<Pose>,
    /// The newest pose emitted.
    pub(crate) latest: Option<Pose>,
    /// The time of the newest event taken (unknown after a restore).
    last_t_s: Option<f64>,
    /// Lines given to `dr_push_line`, for the line number in its errors.
    pub(crate) lines: u64,
    /// The warning of the params.toml (a slip stored without its mean force,
    /// which a stream cannot apply).
    pub(crate) warning: Option<CString>,
    /// True while a call runs: still true at the next call only if a panic
    /// left the previous one half done.
    in_call: bool,
}

impl DrFilter {
    pub(crate) fn new(online: Online, warning: Option<String>) -> Self {
        DrFilter {
            online: Box::new(online),
            poses: VecDeque::new(),
            latest: None,
            last_t_s: None,
            lines: 0,
            warning: warning.map(|w| CString::new(w.replace('\0', "")).unwrap_or_default()),
            in_call: false,
        }
    }

    /// Takes one event: the time order checked here (also after the start,
    /// where the filter drops readings it does not use), then the filter.
    #[inline(always)]
    pub(crate) fn push(&mut self, ev: &Event) -> Result<(), Fail> {
        if let Some(last) = self.last_t_s {
            if ev.t_s < last {
                return Err(filter_fail(&deadreckon_core::Error::OutOfOrder {
                    t_s: ev.t_s,
                    previous_t_s: last,
                }));
            }
        }
        let (poses, latest) = (&mut self.poses, &mut self.latest);
        self.online
            .push_poses(*ev, &mut |p| {
                *latest = Some(p);
                poses.push_back(p);
            })
            .map_err(|e| filter_fail(&e))?;
        self.last_t_s = Some(ev.t_s);
        Ok(())
    }

    /// True when a panic interrupted a call on this handle.
    #[inline]
    pub(crate) fn in_call(&self) -> bool {
        self.in_call
    }

    /// Runs what waits at the end of a stream, what the stored corrections
    /// hold back included ([`Online::end`]).
    pub(crate) fn finish(&mut self) -> Result<(), Fail> {
        let (poses, latest) = (&mut self.poses, &mut self.latest);
        self.online
            .end_poses(&mut |p| {
                *latest = Some(p);
                poses.push_back(p);
            })
            .map_err(|e| filter_fail(&e))
    }
}

/// The filter's error as a failure, with its whole chain of causes; events
/// out of time order are `DrStatus::TimeBackwards` (also when the filter
/// finds them: after a restore the boundary does not know the last time).
pub(crate) fn filter_fail(e: &deadreckon_core::Error) -> Fail {
    let status = match e {
        deadreckon_core::Error::OutOfOrder { .. } => DrStatus::TimeBackwards,
        _ => DrStatus::Filter,
    };
    Fail::new(status, deadreckon_api::chain_text(e))
}

/// Runs `body` on the handle `h`: a null handle and a handle a panic
/// interrupted are errors.
///
/// # Safety
/// `h` is null or a live handle of this library used by no other thread.
#[inline(always)]
pub(crate) unsafe fn with_filter(
    h: *mut DrFilter,
    body: impl FnOnce(&mut DrFilter) -> Result<DrStatus, Fail>,
) -> Result<DrStatus, Fail> {
    // SAFETY: the caller's contract.
    let f = unsafe { h.as_mut() }.ok_or_else(|| Fail::null("the filter handle"))?;
    if f.in_call {
        return Err(Fail::new(
            DrStatus::Panic,
            "an earlier call on this filter was interrupted by an internal error: free it",
        ));
    }
    f.in_call = true;
    let result = body(f);
    f.in_call = false;
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::status::guard;
    use deadreckon_core::ekf::FilterOptions;
    use deadreckon_core::online::Start;
    use deadreckon_core::Params;

    /// A handle on a simulated car's filter, for `Box::from_raw` at the end.
    fn handle() -> *mut DrFilter {
        let sc = deadreckon_sim::Scenario::builtin("evaluation")
            .unwrap()
            .with_duration_s(5.0);
        let v = deadreckon_sim::simulate(&sc, 1).unwrap().drive.vehicle;
        let opts = FilterOptions::default();
        let online = Online::new(&v, &Params::nominal(&v), &opts, Start::Gnss).unwrap();
        Box::into_raw(Box::new(DrFilter::new(online, None)))
    }

    #[test]
    fn a_handle_a_panic_interrupted_refuses_every_later_call() {
        let h = handle();
        // SAFETY: a live handle of this thread.
        let s = guard(|| unsafe { with_filter(h, |_| panic!("half way through an update")) });
        assert_eq!(s, DrStatus::Panic);
        // SAFETY: as above.
        let s = guard(|| unsafe { with_filter(h, |_| Ok(DrStatus::Ok)) });
        assert_eq!(s, DrStatus::Panic);
        // SAFETY: the handle from Box::into_raw, freed once.
        drop(unsafe { Box::from_raw(h) });
    }

    #[test]
    fn a_failed_call_leaves_the_handle_usable() {
        let h = handle();
        // SAFETY: a live handle of this thread.
        let s = guard(|| unsafe {
            with_filter(h, |_| Err(Fail::new(DrStatus::BadEvent, "a bad line")))
        });
        assert_eq!(s, DrStatus::BadEvent);
        // SAFETY: as above.
        let s = guard(|| unsafe { with_filter(h, |_| Ok(DrStatus::Ok)) });
        assert_eq!(s, DrStatus::Ok);
        // SAFETY: the handle from Box::into_raw, freed once.
        drop(unsafe { Box::from_raw(h) });
    }
}
