//! Sliding outages for a kinematic shape, on drives with a reference and no
//! GNSS: each window starts from the reference pose at its first sample,
//! dead-reckons for the outage length, and its error is the distance between
//! the dead-reckoned measured point (with the calibrated mounting) and the
//! reference at its last sample.

use serde::{Deserialize, Serialize};

use super::KinematicModel;
use crate::metrics::Summary;
use crate::{Error, Need, Rule, Value};

/// One outage window.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct KinematicWindow {
    /// Start, s (drive clock).
    pub start_s: f64,
    /// End (the last sample within the outage length), s.
    pub end_s: f64,
    /// Distance the driven wheel(s) travelled (nominal scale), m.
    pub path_m: f64,
    /// Position error of the measured point at the end, m.
    pub final_error_m: f64,
}

/// The windows of [`evaluate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct KinematicOutages {
    /// Outage length, s.
    pub outage_s: f64,
    /// Step between window starts, s.
    pub step_s: f64,
    /// The windows, in time order.
    pub windows: Vec<KinematicWindow>,
}

impl KinematicOutages {
    /// Summary of the final errors.
    pub fn final_error(&self) -> Summary {
        Summary::of(
            &self
                .windows
                .iter()
                .map(|w| w.final_error_m)
                .collect::<Vec<_>>(),
        )
    }
}

/// Dead reckons `model` with `params` through outages of `outage_s` starting
/// every `step_s` from the first sample with a reference; a window is kept
/// when the drive lasts its whole length.
pub fn evaluate<M: KinematicModel>(
    model: &M,
    params: &[f64],
    outage_s: f64,
    step_s: f64,
) -> Result<KinematicOutages, Error> {
    if !(outage_s.is_finite() && outage_s > 0.0 && step_s.is_finite() && step_s > 0.0) {
        return Err(Error::param(
            "outage length and step (s)",
            Value::Numbers(vec![outage_s, step_s]),
            Rule::Positive,
        ));
    }
    if params.len() != model.names().len() || params.iter().any(|v| !v.is_finite()) {
        return Err(Error::param(
            "parameters",
            Value::Count(params.len()),
            Rule::FiniteCount(model.names().len()),
        ));
    }
    let n = model.len();
    let refs: Vec<usize> = (0..n).filter(|&i| model.reference(i).is_some()).collect();
    let (Some(&first), Some(&last)) = (refs.first(), refs.last()) else {
        return Err(Need::ReferencePoses.into());
    };
    let (t0, t_last) = (model.time(first), model.time(last));
    let mut windows = Vec::new();
    let mut k = 0usize;
    loop {
        let ts = t0 + k as f64 * step_s;
        k += 1;
        if ts + outage_s > t_last {
            break;
        }
        // First reference at or after ts, last one within the outage.
        let ia = refs.partition_point(|&i| model.time(i) < ts);
        let ib = refs.partition_point(|&i| model.time(i) <= ts + outage_s);
        if ib == 0 || ia >= ib - 1 {
            continue;
        }
        let (a, b) = (refs[ia], refs[ib - 1]);
        let (Some(start), Some(end)) = (model.reference(a), model.reference(b)) else {
            continue;
        };
        let (p, _) = model.predict(params, &start, a, b, false);
        windows.push(KinematicWindow {
            start_s: model.time(a),
            end_s: model.time(b),
            path_m: model.path_m(a, b),
            final_error_m: (p.x_m - end.x_m).hypot(p.y_m - end.y_m),
        });
    }
    if windows.is_empty() {
        return Err(Need::OutageWindow {
            outage_s,
            warmup_s: 0.0,
            span_s: (t0, t_last),
            moving_from_s: None,
        }
        .into());
    }
    Ok(KinematicOutages {
        outage_s,
        step_s,
        windows,
    })
}
