//! TedriS and the calibrated four-wheel EKF through the same GNSS outages (moved
//! unchanged from the command line's `compare`). Neither method sees GNSS
//! inside the outages, not even for calibration or training.

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::compared::{Against, OutageResult};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::{outage, Drive, Params};
use deadreckon_tedris::{Outage, TedrisConfig, TedrisModel};

use crate::Error;

/// The comparison through a set of outages.
pub struct Comparison {
    /// Where the four-wheel parameters came from.
    pub params_source: String,
    /// The four-wheel parameters the filter ran with.
    pub params: Params,
    /// Where the TedriS model came from.
    pub model_source: String,
    /// The four-wheel reference (the truth, or the hidden fixes at the antenna).
    pub four_wheel_reference: Against,
    /// The TedriS reference (compared at the rear axle).
    pub tedris_reference: Against,
    /// Per outage: the window, the four-wheel errors, TedriS's errors (one
    /// type for both: the point compared is in it).
    pub rows: Vec<(Outage, Option<OutageResult>, Option<OutageResult>)>,
    /// The TedriS model used.
    pub model: TedrisModel,
    /// TedriS's track through the drive, GNSS hidden in the outages.
    pub tedris_track: deadreckon_core::Track,
    /// The four-wheel filter's χ² gate counters over the run.
    pub four_wheel_gates: deadreckon_core::filter::GateCounts,
    /// What TedriS refused or found over the run.
    pub tedris_checks: deadreckon_tedris::machine::MachineChecks,
}

/// The outages a report and the demo compare through when none are given:
/// `len` s (at most a fifth of the drive) centred at a quarter, half and
/// three quarters of the drive.
pub fn default_windows(drive: &Drive, len: f64) -> Result<Vec<Outage>, Error> {
    let (t0, t1) = drive.time_span().ok_or(Error::EmptyDrive)?;
    let len = len.min(0.2 * (t1 - t0));
    Ok([0.25, 0.5, 0.75]
        .iter()
        .map(|f| {
            let a = t0 + f * (t1 - t0) - 0.5 * len;
            Outage {
                start_s: a,
                end_s: a + len,
            }
        })
        .collect())
}

/// Runs both methods through `outages`. Without `params`, the four-wheel
/// parameters are calibrated (RTS) on the drive with the outages hidden, no
/// corrections estimated (the demo and the report's TedriS section; `compare`
/// passes the parameters of `deadreckon_api::evaluate`'s rule for "no
/// --params", with the corrections applied to `drive`); without `model`,
/// TedriS is trained on the drive with the outages hidden.
pub fn compare(
    drive: &Drive,
    outages: &[Outage],
    params: Option<(Params, String)>,
    model: Option<(TedrisModel, String)>,
) -> Result<Comparison, Error> {
    let windows: Vec<(f64, f64)> = outages.iter().map(|o| (o.start_s, o.end_s)).collect();
    let hidden = drive.without_gnss_in(&windows);
    let (params, params_source) = match params {
        Some(p) => p,
        None => {
            let c = calibrate::calibrate(&hidden, &CalibrationOptions::default())
                .map_err(Error::HiddenCalibration)?;
            (
                c.estimate.params,
                format!("RTS on the drive, outages hidden ({} passes)", c.iterations),
            )
        }
    };
    let fw = outage::through_windows(drive, &params, &windows, &FilterOptions::default())?;
    let (model, model_source) = match model {
        Some(m) => m,
        None => {
            let (m, _) = deadreckon_tedris::train(&hidden, TedrisConfig::default(), None)
                .map_err(Error::HiddenTraining)?;
            (m, "trained on the drive, outages hidden".into())
        }
    };
    let td = deadreckon_tedris::run_outages(drive, &model, outages)?;
    let mut rows = Vec::new();
    for o in outages {
        let f = fw.windows.iter().find(|w| w.start_s == o.start_s).cloned();
        let t = td
            .outages
            .iter()
            .find(|e| e.start_s() == o.start_s)
            .map(|e| e.result.clone());
        rows.push((*o, f, t));
    }
    Ok(Comparison {
        params_source,
        params,
        model_source,
        four_wheel_reference: fw.reference,
        tedris_reference: td.reference,
        rows,
        model,
        tedris_track: td.track,
        four_wheel_gates: fw.gates,
        tedris_checks: td.machine.checks(),
    })
}
