//! Calibrating (and evaluating) many drives in parallel on one machine.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::time::Instant;

use deadreckon_api::calibration::{self, CalibrationRequest, CarCalibration};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics::Summary;
use deadreckon_core::timing::Which;
use deadreckon_core::{outage, Drive};
use rayon::prelude::*;

use crate::FleetError;

/// Sliding GNSS outages to evaluate each drive through, with its own
/// calibrated parameters (as `evaluate --outage` does).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OutageOptions {
    /// Length of each outage, s.
    pub length_s: f64,
    /// Step between outage windows, s.
    pub step_s: f64,
    /// GNSS-aided time before the first window, s.
    pub warmup_s: f64,
}

/// How a batch runs.
#[derive(Debug, Clone)]
pub struct BatchOptions {
    /// The calibration of every drive: the one request of
    /// [`deadreckon_api::calibration`], whose corrections default here to
    /// [`Which::None`]: a delay estimated anew on each drive moves that
    /// drive's gyro bias and speed scale by more than their standard
    /// errors say (they do not include the delay's uncertainty), and the
    /// history then flags an unchanged car (docs/fleet.md).
    pub request: CalibrationRequest,
    /// Also evaluate each drive through sliding outages.
    pub outage: Option<OutageOptions>,
    /// Worker threads; 0 for one per core.
    pub threads: usize,
}

impl Default for BatchOptions {
    fn default() -> Self {
        BatchOptions {
            request: CalibrationRequest {
                // `batch` shows no error bound: not fitted (a second
                // second per 10-minute drive).
                fit_bound: false,
                ..CalibrationRequest::with_corrections(Which::None)
            },
            outage: None,
            threads: 0,
        }
    }
}

/// Whether a parameter was estimated on a drive: the one rule of
/// [`deadreckon_api::calibration::ParamStatus`].
pub use deadreckon_api::calibration::ParamStatus;

/// The outage evaluation of one drive.
#[derive(Debug, Clone)]
pub struct OutageResult {
    /// The options it was run with.
    pub options: OutageOptions,
    /// What the errors are measured against (`truth` or the hidden GNSS).
    pub reference: &'static str,
    /// Position error at the end of each window, m.
    pub final_error_m: Summary,
    /// Drift in % of the distance travelled in each window.
    pub drift_pct: Summary,
}

/// What a successful drive gives.
#[derive(Debug, Clone)]
pub struct DriveCalibration {
    /// The car's calibration, as `calibrate` makes it (its parameters,
    /// standard errors and status, passes, the filter's counts, the
    /// corrections): the CSV row renders its fields.
    pub car: CarCalibration,
    /// Length of the drive, s (first to last wheel row).
    pub duration_s: f64,
    /// The outage evaluation, when asked for.
    pub outage: Option<OutageResult>,
}

impl DriveCalibration {
    /// The corrections estimated and applied (`None` when the request
    /// asked for none).
    pub fn corrections(&self) -> Option<&deadreckon_core::timing::Corrections> {
        (self.car.which() != Which::None).then_some(&self.car.corrections)
    }
}

/// One drive of a batch: where, which vehicle, and what came of it.
#[derive(Debug, Clone)]
pub struct DriveResult {
    /// The drive as given.
    pub path: PathBuf,
    /// `vehicle_id` of its `vehicle.toml` (none when absent or unread).
    pub vehicle_id: Option<String>,
    /// `recorded_at` of its `vehicle.toml`.
    pub recorded_at: Option<String>,
    /// The calibration, or the error message (reading, calibrating,
    /// evaluating), with the file and line where the reader gave them.
    pub outcome: Result<DriveCalibration, String>,
    /// Wall-clock time spent on this drive, s.
    pub elapsed_s: f64,
}

/// Checks the options before any drive is read.
pub fn validate(options: &BatchOptions) -> Result<(), FleetError> {
    if let Some(o) = &options.outage {
        if !(o.length_s.is_finite() && o.length_s > 0.0) {
            return Err(FleetError::Options(format!(
                "outage length must be a positive number of seconds, got {}",
                o.length_s
            )));
        }
        if !(o.step_s.is_finite() && o.step_s > 0.0) {
            return Err(FleetError::Options(format!(
                "outage step must be a positive number of seconds, got {}",
                o.step_s
            )));
        }
        if !(o.warmup_s.is_finite() && o.warmup_s >= 0.0) {
            return Err(FleetError::Options(format!(
                "outage warm-up must be a non-negative number of seconds, got {}",
                o.warmup_s
            )));
        }
    }
    Ok(())
}

/// Calibrates one drive already read with the one function of
/// [`deadreckon_api::calibration`] (the corrections the request asks for
/// estimated and applied first), then evaluates the outages on the
/// corrected drive.
pub fn calibrate_drive(drive: &Drive, options: &BatchOptions) -> Result<DriveCalibration, String> {
    let (car, corrected) = calibration::calibrate_corrected(drive, &options.request, "the drive")
        .map_err(|e| deadreckon_api::chain_text(&e))?;
    let drive = corrected.as_ref().unwrap_or(drive);
    let outage = match &options.outage {
        None => None,
        Some(o) => {
            let base = FilterOptions {
                timing: options.request.options.filter.timing,
                ..Default::default()
            };
            let ev = outage::evaluate(
                drive,
                &car.calibration.estimate.params,
                o.length_s,
                o.step_s,
                o.warmup_s,
                &base,
            )
            .map_err(|e| format!("evaluating through {} s outages: {e}", o.length_s))?;
            Some(OutageResult {
                options: *o,
                reference: ev.reference.name(),
                final_error_m: ev.final_error(),
                drift_pct: ev.drift_pct(),
            })
        }
    };
    let n = drive.wheels.len();
    let duration_s = if n > 0 {
        drive.wheels.t_s(n - 1) - drive.wheels.t_s(0)
    } else {
        0.0
    };
    Ok(DriveCalibration {
        car,
        duration_s,
        outage,
    })
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic".into()
    }
}

/// Reads and calibrates one drive; every failure, a panic included, becomes
/// the result's error.
pub fn run_one<L>(path: &Path, load: &L, options: &BatchOptions) -> DriveResult
where
    L: Fn(&Path) -> Result<Drive, String> + Sync,
{
    let start = Instant::now();
    let mut vehicle_id = None;
    let mut recorded_at = None;
    let outcome = catch_unwind(AssertUnwindSafe(|| {
        let drive = load(path)?;
        vehicle_id = drive.vehicle.vehicle_id.clone();
        recorded_at = drive.vehicle.recorded_at.clone();
        calibrate_drive(&drive, options)
    }))
    .unwrap_or_else(|p| Err(format!("internal error (panic): {}", panic_text(&*p))));
    DriveResult {
        path: path.to_path_buf(),
        vehicle_id,
        recorded_at,
        outcome,
        elapsed_s: start.elapsed().as_secs_f64(),
    }
}

/// Runs the batch on `options.threads` threads: one result per path, in the
/// order of `paths` whatever order they finish in. `load` reads a drive (its
/// error text should name the file and line); `done` is called once per
/// finished drive, from the worker threads (a progress bar). Only a thread
/// pool that cannot be built stops the batch.
pub fn run<L, D>(
    paths: &[PathBuf],
    load: &L,
    options: &BatchOptions,
    done: &D,
) -> Result<Vec<DriveResult>, FleetError>
where
    L: Fn(&Path) -> Result<Drive, String> + Sync,
    D: Fn(&DriveResult) + Sync,
{
    validate(options)?;
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.threads)
        .build()
        .map_err(|e| FleetError::ThreadPool(e.to_string()))?;
    Ok(pool.install(|| {
        paths
            .par_iter()
            .with_max_len(1)
            .map(|p| {
                let r = run_one(p, load, options);
                done(&r);
                r
            })
            .collect()
    }))
}
