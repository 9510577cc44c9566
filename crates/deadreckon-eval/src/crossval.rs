//! Calibrate on one drive, evaluate on another (the paper's tables III and
//! IV, as `demo` prints them): every accuracy figure out of sample.

use deadreckon_core::calibrate::{self, Calibration, CalibrationOptions, Method};
use deadreckon_core::ekf::Timing;
use deadreckon_core::metrics;
use deadreckon_core::{Drive, Params, ParamsWithStd};

use crate::report::Source;
use crate::Error;

/// One calibration method's results.
pub struct MethodResult {
    /// Where the parameters come from (its `name()` is the method's).
    pub source: Source,
    /// Calibration (None for nominal).
    pub calibration: Option<Calibration>,
    /// Parameters used.
    pub params: ParamsWithStd,
    /// Drift evaluation.
    pub drift: metrics::DriftResult,
    /// Reset-on-1 m evaluation.
    pub reset: metrics::ResetResult,
}

/// Calibrates with every method on `cal` and evaluates on `eval`: the
/// paper's tables III and IV, never measured on the drive calibrated on.
pub fn calibrate_and_evaluate(cal: &Drive, eval: &Drive) -> Result<Vec<MethodResult>, Error> {
    let nominal = Params::nominal(&cal.vehicle);
    let mut out = Vec::new();
    for (source, method) in [
        (Source::Nominal, None),
        (Source::Zupt, Some(Method::Zupt)),
        (Source::Rts, Some(Method::Rts)),
        (Source::Truth, Some(Method::Truth)),
    ] {
        let name = source.name();
        let calibration = match method {
            None => None,
            Some(m) => Some(
                calibrate::calibrate(
                    cal,
                    &CalibrationOptions {
                        method: m,
                        ..Default::default()
                    },
                )
                .map_err(|source| Error::Calibration {
                    method: name,
                    source,
                })?,
            ),
        };
        let params = calibration
            .as_ref()
            .map(|c| c.estimate)
            .unwrap_or(ParamsWithStd {
                params: nominal,
                std: Params::from_array([0.0; 6]),
            });
        let drift = metrics::drift(eval, &params.params, 100.0, Timing::WheelEpochs)?;
        let reset = metrics::reset_on_error(eval, &params.params, 1.0, Timing::WheelEpochs)?;
        out.push(MethodResult {
            source,
            calibration,
            params,
            drift,
            reset,
        });
    }
    Ok(out)
}
