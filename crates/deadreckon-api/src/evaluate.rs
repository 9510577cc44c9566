//! The parameters `evaluate` measures when none are given: one rule for
//! every metric (drift, reset, RPE, APE, sliding outages), for the command
//! line and the Python bindings alike; and the RPE or APE of one of the
//! drive's tracks against another ([`evo_metric`]).

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::{FilterOptions, Timing};
use deadreckon_core::evo::{self, TrajectoryError};
use deadreckon_core::timing::{Corrections, Which};
use deadreckon_core::{track, Drive, Params};

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

/// `evaluate --metric rpe|ape`: every track of the drive (dead-reckoned,
/// filtered, smoothed, truth) with `params`, then the metric `q` asks for of
/// `q.track` against `q.reference`, on the values the TUM/KITTI files carry
/// (so evo on the files agrees).
pub fn evo_metric(
    drive: &Drive,
    params: &Params,
    timing: Timing,
    q: &crate::json::EvoQuery<'_>,
) -> Result<TrajectoryError, Error> {
    let pairs_from = match q.pairs_from {
        "estimate" => evo::PairsFrom::Estimate,
        "reference" => evo::PairsFrom::Reference,
        other => {
            return Err(Error::UnknownOption {
                what: "pairs_from",
                value: other.to_string(),
                allowed: "estimate, reference",
            })
        }
    };
    let opts = FilterOptions {
        timing,
        ..Default::default()
    };
    let mut all = track::drive_tracks(drive, params, &opts, None)?;
    all.extend(track::Track::from_truth(drive));
    let reference = &evo::as_written(track::find(&all, q.reference)?);
    let estimate = &evo::as_written(track::find(&all, q.track)?);
    let step = || format!("{} of `{}` against `{}`", q.metric, q.track, q.reference);
    match q.metric {
        "rpe" => evo::rpe(
            reference,
            estimate,
            &evo::RpeOptions {
                delta_m: q.delta_m,
                max_diff_s: q.max_diff_s,
                pairs_from,
            },
        ),
        "ape" => evo::ape(reference, estimate, q.max_diff_s),
        other => {
            return Err(Error::UnknownOption {
                what: "metric",
                value: other.to_string(),
                allowed: "rpe, ape",
            })
        }
    }
    .map_err(|source| Error::Step {
        step: step(),
        source,
    })
}
