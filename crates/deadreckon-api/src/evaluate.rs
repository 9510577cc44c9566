//! The parameters `evaluate` measures when none are given: one rule for
//! every metric (drift, reset, RPE, APE, sliding outages), for the command
//! line and the Python bindings alike.

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::timing::{Corrections, Which};
use deadreckon_core::{Drive, Params};

use crate::Error;

/// The rule, as the commands print it.
pub const RULE: &str = "without parameters, evaluate calibrates with RTS on the drive itself \
     (in-sample: calibrate on another drive or part for a held-out figure), or takes the \
     nominal ones when the drive has no GNSS fix";

/// Parameters to evaluate and where they come from.
#[derive(Debug, Clone)]
pub struct Parameters {
    /// The six parameters.
    pub params: Params,
    /// What they are (`rts (12 passes)`, `nominal (no GNSS fix)`, a file name).
    pub label: String,
    /// The timing and mounting corrections estimated and applied before
    /// the calibration (`None`: none estimated here).
    pub corrections: Option<Corrections>,
}

/// [`RULE`]: the RTS calibration on `drive` after the corrections `which`
/// asks for (returned with the drive they were applied to), or the nominal
/// parameters of a drive without GNSS fixes.
pub fn default_parameters(drive: &Drive, which: Which) -> Result<(Parameters, Drive), Error> {
    if drive.gnss.is_empty() {
        return Ok((
            Parameters {
                params: Params::nominal(&drive.vehicle),
                label: "nominal (no GNSS fix to calibrate on)".into(),
                corrections: None,
            },
            drive.clone(),
        ));
    }
    let copts = CalibrationOptions::default();
    let (drive, corrections) = crate::corrections::estimate_and_apply(drive, &copts, which)?;
    let c = calibrate::calibrate(&drive, &copts).map_err(|source| Error::Calibration {
        what: "RTS calibration with GNSS",
        source,
    })?;
    Ok((
        Parameters {
            params: c.estimate.params,
            label: format!("rts ({} passes)", c.iterations),
            corrections: Some(corrections),
        },
        drive,
    ))
}
