//! Creating, saving, restoring and freeing a filter; the last error.

use std::ffi::{c_char, CStr};
use std::path::Path;

use deadreckon_api::stream::{self, StreamOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::Vehicle;

use crate::handle::{with_filter, DrFilter};
use crate::status::{guard, last_error_ptr, DrStatus, Fail};
use crate::types::DrOptions;

/// The text of `len` bytes at `ptr`, UTF-8 (`what` names it in errors).
///
/// # Safety
/// `ptr` is null or points to `len` readable bytes.
pub(crate) unsafe fn text_arg<'a>(
    ptr: *const c_char,
    len: usize,
    what: &str,
    status: DrStatus,
) -> Result<&'a str, Fail> {
    if ptr.is_null() {
        return Err(Fail::null(what));
    }
    // SAFETY: the caller's contract.
    let bytes = unsafe { std::slice::from_raw_parts(ptr.cast::<u8>(), len) };
    std::str::from_utf8(bytes).map_err(|e| Fail::new(status, format!("{what} is not UTF-8: {e}")))
}

/// A NUL-terminated path.
///
/// # Safety
/// `ptr` is null or a NUL-terminated string.
unsafe fn path_arg<'a>(ptr: *const c_char, what: &str) -> Result<&'a str, Fail> {
    if ptr.is_null() {
        return Err(Fail::null(what));
    }
    // SAFETY: the caller's contract.
    unsafe { CStr::from_ptr(ptr) }
        .to_str()
        .map_err(|e| Fail::new(DrStatus::BadConfig, format!("{what} is not UTF-8: {e}")))
}

fn config_fail(e: &(dyn std::error::Error + 'static)) -> Fail {
    Fail::new(DrStatus::BadConfig, deadreckon_api::chain_text(e))
}

/// The filter `deadreckon stream` opens with these options (no state file).
fn open(
    vehicle: &Vehicle,
    start: stream::StartParams,
    options: *const DrOptions,
) -> Result<DrFilter, Fail> {
    // SAFETY: null or a valid DrOptions (the callers' contract).
    let options = unsafe { options.as_ref() }.copied().unwrap_or_default();
    let o = StreamOptions {
        filter: FilterOptions {
            timing: options.timing()?,
            ..Default::default()
        },
        state: None,
        learn: options.learn,
        params_out: None,
        save_every_s: None,
        skip_bad_lines: false,
        last_part: false,
    };
    let online = stream::open(vehicle, &start.params, &start.prior, &start.stored, &o)
        .map_err(|e| config_fail(&e))?
        .with_bound(start.bound);
    let warning = stream::corrections_warning("params.toml", &online);
    Ok(DrFilter::new(online, warning))
}

/// Hands a new filter to the caller through `out` (null on failure).
///
/// # Safety
/// `out` is null or writable.
unsafe fn create(
    out: *mut *mut DrFilter,
    make: impl FnOnce() -> Result<DrFilter, Fail>,
) -> DrStatus {
    guard(|| {
        if out.is_null() {
            return Err(Fail::null("out"));
        }
        // SAFETY: `out` is writable (the caller's contract).
        unsafe { *out = std::ptr::null_mut() };
        let f = make()?;
        // SAFETY: as above.
        unsafe { *out = Box::into_raw(Box::new(f)) };
        Ok(DrStatus::Ok)
    })
}

/// The default options: wheel timing, not learning.
#[no_mangle]
pub extern "C" fn dr_default_options() -> DrOptions {
    DrOptions::default()
}

/// A filter from the text of a vehicle.toml and, optionally, of a
/// params.toml (`params_toml` null: the vehicle's nominal parameters), with
/// `options` (null: the defaults). The filter starts from GNSS as `deadreckon
/// stream` does; a params.toml's `[std]` is the learning prior. On success
/// `*out` is the new handle (free it with `dr_filter_free`); on failure null.
///
/// # Safety
/// `vehicle_toml` points to `vehicle_len` bytes, `params_toml` is null or
/// points to `params_len` bytes, `options` is null or valid, `out` writable.
#[no_mangle]
pub unsafe extern "C" fn dr_filter_new(
    vehicle_toml: *const c_char,
    vehicle_len: usize,
    params_toml: *const c_char,
    params_len: usize,
    options: *const DrOptions,
    out: *mut *mut DrFilter,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    unsafe {
        create(out, || {
            let v = text_arg(
                vehicle_toml,
                vehicle_len,
                "vehicle_toml",
                DrStatus::BadConfig,
            )?;
            let vehicle = deadreckon_io::parse_vehicle(v, Path::new("vehicle.toml"))
                .map_err(|e| config_fail(&e))?;
            let start = if params_toml.is_null() {
                stream::start_params("nominal", &vehicle)
            } else {
                let p = text_arg(params_toml, params_len, "params_toml", DrStatus::BadConfig)?;
                stream::start_params_from_text(p, "params.toml")
            }
            .map_err(|e| config_fail(&e))?;
            open(&vehicle, start, options)
        })
    }
}

/// [`dr_filter_new`] from files: `vehicle_path` a vehicle.toml, `params_path`
/// null (nominal parameters) or a params.toml, read as `deadreckon stream
/// --vehicle V --params P` reads them.
///
/// # Safety
/// `vehicle_path` is a NUL-terminated string, `params_path` null or one,
/// `options` null or valid, `out` writable.
#[no_mangle]
pub unsafe extern "C" fn dr_filter_new_from_files(
    vehicle_path: *const c_char,
    params_path: *const c_char,
    options: *const DrOptions,
    out: *mut *mut DrFilter,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    unsafe {
        create(out, || {
            let v = path_arg(vehicle_path, "vehicle_path")?;
            let vehicle = deadreckon_io::read_vehicle(Path::new(v))
                .map_err(|e| config_fail(&e))
                .map_err(|f| Fail::new(f.status, format!("reading {v}: {}", f.message)))?;
            let spec = if params_path.is_null() {
                "nominal"
            } else {
                path_arg(params_path, "params_path")?
            };
            let start = stream::start_params(spec, &vehicle).map_err(|e| config_fail(&e))?;
            open(&vehicle, start, options)
        })
    }
}

/// A filter from the bytes `dr_save_state` returned, or from the file
/// `deadreckon stream --state FILE` writes (the same bytes): the state,
/// covariance, parameters, counters and the timing scheme's pending readings,
/// so the stream continues as if never cut. Poses not taken before the save
/// are not in it.
///
/// # Safety
/// `bytes` points to `len` readable bytes, `out` is writable.
#[no_mangle]
pub unsafe extern "C" fn dr_filter_restore(
    bytes: *const u8,
    len: usize,
    out: *mut *mut DrFilter,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on.
    unsafe {
        create(out, || {
            let text = text_arg(bytes.cast(), len, "the state", DrStatus::BadState)?;
            let online = stream::state_from_text(text, "bytes")
                .map_err(|e| Fail::new(DrStatus::BadState, deadreckon_api::chain_text(&e)))?;
            Ok(DrFilter::new(online, None))
        })
    }
}

/// Writes the filter's whole state to `buf` (`cap` bytes) and its size to
/// `*len`. With `buf` null or `cap` too small nothing is written to `buf`,
/// `*len` is the size needed and the status `DR_STATUS_BUFFER_TOO_SMALL`
/// (call once with null to learn the size). The bytes are those `deadreckon
/// stream --state` writes (JSON text, no NUL).
///
/// # Safety
/// `filter` is null or a live handle, `buf` null or `cap` writable bytes,
/// `len` writable.
#[no_mangle]
pub unsafe extern "C" fn dr_save_state(
    filter: *const DrFilter,
    buf: *mut u8,
    cap: usize,
    len: *mut usize,
) -> DrStatus {
    // SAFETY: the caller's contract, passed on; the handle is only read.
    guard(|| unsafe {
        with_filter(filter.cast_mut(), |f| {
            let len = len.as_mut().ok_or_else(|| Fail::null("len"))?;
            let text = stream::state_text(&f.online)
                .map_err(|e| Fail::new(DrStatus::Filter, deadreckon_api::chain_text(&e)))?;
            *len = text.len();
            if buf.is_null() || cap < text.len() {
                return Err(Fail::new(
                    DrStatus::BufferTooSmall,
                    format!("the state takes {} bytes, the buffer has {cap}", text.len()),
                ));
            }
            std::ptr::copy_nonoverlapping(text.as_ptr(), buf, text.len());
            Ok(DrStatus::Ok)
        })
    })
}

/// Frees a filter (null: nothing). The handle is invalid afterwards.
///
/// # Safety
/// `filter` is null or a live handle not used after this call.
#[no_mangle]
pub unsafe extern "C" fn dr_filter_free(filter: *mut DrFilter) -> DrStatus {
    guard(|| {
        if !filter.is_null() {
            // SAFETY: a handle from Box::into_raw, freed once (the contract).
            drop(unsafe { Box::from_raw(filter) });
        }
        Ok(DrStatus::Ok)
    })
}

/// The message of the last call that failed on this thread (NUL-terminated,
/// "" if none has). Valid until the next failing call on this thread; do not
/// free it.
#[no_mangle]
pub extern "C" fn dr_last_error() -> *const c_char {
    last_error_ptr()
}

/// The warning of the params.toml the filter was made with (a driven-axle
/// slip stored without the mean forward specific force it is applied at,
/// which a stream cannot apply; `deadreckon stream` prints the same), or
/// null. The other stored corrections (delays, IMU tilt, gyro scale) are
/// applied to the events. Valid as long as the handle.
///
/// # Safety
/// `filter` is null or a live handle.
#[no_mangle]
pub unsafe extern "C" fn dr_filter_warning(filter: *const DrFilter) -> *const c_char {
    // SAFETY: the caller's contract.
    unsafe { filter.as_ref() }
        .and_then(|f| f.warning.as_ref())
        .map_or(std::ptr::null(), |w| w.as_ptr())
}
