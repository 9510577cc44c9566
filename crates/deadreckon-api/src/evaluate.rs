//! The parameters `evaluate` measures when none are given: one rule for
//! every metric (drift, reset, RPE, APE, sliding outages), for the command
//! line and the Python bindings alike; and the RPE or APE of one of the
//! drive's tracks against another ([`evo_metric`]).

use deadreckon_core::ekf::{FilterOptions, Timing};
use deadreckon_core::evo::{self, TrajectoryError};
use deadreckon_core::metrics::{self, DriftResult, ResetResult, Summary};
use deadreckon_core::outage::{self, OutageEvaluation};
use deadreckon_core::timing::{Corrections, Which};
use deadreckon_core::{track, Drive, Params};

use crate::Error;

/// The one rule for "no --params" (issue 29, item 6), the same in `run`,
/// `evaluate`, `report`, `compare` and Python, as the commands print it:
/// nominal circumferences are off by a few per cent on real cars
/// (comma2k19's dead-reckoned track ends 1 km from the filtered one with
/// them), so the drive is calibrated on itself.
pub const RULE: &str = "without --params, the parameters are calibrated on the drive itself \
     (RTS with its GNSS for a car, against its GNSS for a differential drive, against its \
     tracker for a tricycle; in-sample: calibrate on another drive or part for a held-out \
     figure), or nominal when the drive has no GNSS fix; --params nominal for the nominal ones";

/// The GNSS-aided time before the first sliding outage window, s: the
/// default of `evaluate --warmup`, `batch --warmup` and Python's `warmup`.
pub const OUTAGE_WARMUP_S: f64 = 5.0;

/// What `"params_source"` says of parameters calibrated on the drive.
pub const CALIBRATED_HERE: &str = "calibrated on this drive";

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
    /// Which parameters are applied, as `"params_source"` says it: the
    /// file, `nominal`, or [`CALIBRATED_HERE`] with the method.
    pub source: String,
    /// What the parameters' binding to the vehicle let through, or that
    /// the file names no vehicle ([`crate::binding`]).
    pub note: Option<String>,
    /// The 95 % error bound's factor: the file's `[bound]`, or fitted on
    /// the drive itself with the parameters calibrated on it (in-sample).
    pub bound: deadreckon_core::bound::BoundFit,
    /// The given file stores corrections, applied to the streams with its
    /// parameters ([`crate::report_labels::given_line`] says so).
    pub file_corrected: bool,
}

/// The one function every command calls for its parameters ([`RULE`]):
/// `spec` (`nominal` or a params.toml, bound to the drive's vehicle unless
/// `allow_other`) with the corrections it stores applied, or without it
/// the calibration on the drive itself ([`default_parameters`]).
pub fn parameters(
    spec: Option<&str>,
    drive: Drive,
    which: Which,
    allow_other: bool,
) -> Result<(Parameters, Drive), Error> {
    match spec {
        Some(p) => given_parameters_bound(p, drive, allow_other),
        None => default_parameters(&drive, which),
    }
}

/// [`parameters`] for a comparison through GNSS outages (`compare`): with
/// `spec`, the same; without it, [`RULE`]'s calibration
/// ([`default_parameters`]) on the drive with the fixes inside `windows`
/// hidden, and the corrections it applied there applied to the whole drive
/// as `run` applies a params.toml's ([`applied_corrections`]), so both
/// estimators read the drive the parameters hold on.
pub fn parameters_outages_hidden(
    spec: Option<&str>,
    drive: Drive,
    which: Which,
    allow_other: bool,
    windows: &[(f64, f64)],
) -> Result<(Parameters, Drive), Error> {
    if spec.is_some() {
        return parameters(spec, drive, which, allow_other);
    }
    let (mut chosen, _) = default_parameters(&drive.without_gnss_in(windows), which)?;
    // Calibrated (not nominal for want of fixes): say the outages were hidden.
    let drive = match &chosen.corrections {
        Some(c) => {
            chosen.label = format!("{}, outages hidden", chosen.label);
            chosen.source = format!("{}, outages hidden", chosen.source);
            applied_corrections(c)?.apply_to(drive)
        }
        None => drive,
    };
    Ok((chosen, drive))
}

/// The corrections `c` applied (those estimated and, with `auto`, chosen),
/// as the params.toml a calibration writes stores them
/// ([`crate::params_tables::corrections_tables`]) and `--params` reads
/// them back ([`crate::corrections::stored_of`]).
pub fn applied_corrections(c: &Corrections) -> Result<crate::corrections::Stored, Error> {
    let mut t = crate::params_tables::ParamsTables::default();
    crate::params_tables::corrections_tables(c, &mut t);
    crate::corrections::stored_of(&t).map_err(Error::Invalid)
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
                source: "nominal (no GNSS fix to calibrate on)".into(),
                note: None,
                bound: deadreckon_core::bound::BoundFit::FILTER,
                file_corrected: false,
            },
            drive.clone(),
        ));
    }
    let request = crate::calibration::CalibrationRequest::with_corrections(which);
    let (car, corrected) = crate::calibration::calibrate_corrected(drive, &request, "the drive")?;
    let c = car.calibration;
    Ok((
        Parameters {
            params: c.estimate.params,
            label: format!("rts ({} passes)", c.iterations),
            corrections: Some(car.corrections),
            source: format!("{CALIBRATED_HERE}: rts ({} passes)", c.iterations),
            note: None,
            bound: car.bound,
            file_corrected: false,
        },
        corrected.unwrap_or_else(|| drive.clone()),
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
    let all = crate::tracks::drive_tracks(drive, params, &opts, None)?;
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

/// `params.toml` or `nominal` given by the user, with the drive the
/// corrections the file stores were applied to.
pub fn given_parameters(spec: &str, drive: Drive) -> Result<(Parameters, Drive), Error> {
    given_parameters_bound(spec, drive, false)
}

/// [`given_parameters`], another vehicle's file taken when `allow_other`
/// ([`crate::load::params_bound`]).
pub fn given_parameters_bound(
    spec: &str,
    drive: Drive,
    allow_other: bool,
) -> Result<(Parameters, Drive), Error> {
    let (params, drive, note, file) = crate::load::params_file_corrected(spec, drive, allow_other)?;
    Ok((
        Parameters {
            params,
            label: spec.to_string(),
            corrections: None,
            source: spec.to_string(),
            note,
            file_corrected: file.as_ref().is_some_and(|f| !f.corrections.is_empty()),
            bound: file.map_or(deadreckon_core::bound::BoundFit::FILTER, |f| f.bound),
        },
        drive,
    ))
}

/// What `evaluate` measures on a car's drive.
#[derive(Debug, Clone, Copy)]
pub enum Metric<'a> {
    /// Drift per `segment_m` of path, reset to the truth at each segment.
    Drift {
        /// Segment length, m.
        segment_m: f64,
    },
    /// Distance travelled before the error reaches `threshold_m`, then reset.
    Reset {
        /// Error threshold, m.
        threshold_m: f64,
    },
    /// evo's RPE or APE of one track against another.
    Evo(crate::json::EvoQuery<'a>),
    /// Sliding GNSS outages.
    Outages {
        /// Outage length, s.
        length_s: f64,
        /// Step between windows, s.
        step_s: f64,
        /// GNSS-aided time before the first window, s.
        warmup_s: f64,
    },
}

/// A metric's result.
#[derive(Debug, Clone)]
pub enum Measured<'a> {
    /// Drift per segment, with the segment length.
    Drift(DriftResult, f64),
    /// Distances before the threshold, with the threshold.
    Reset(ResetResult, f64),
    /// RPE or APE, with what was asked.
    Evo(crate::json::EvoQuery<'a>, evo::TrajectoryError),
    /// Sliding outages, with their length.
    Outages(f64, OutageEvaluation),
}

/// What `evaluate` measured on a car's drive, and with which parameters.
#[derive(Debug, Clone)]
pub struct Evaluation<'a> {
    /// Where the parameters come from.
    pub source: String,
    /// Which parameters were applied (`"params_source"`,
    /// [`Parameters::source`]).
    pub params_source: String,
    /// The corrections estimated before the calibration, if any.
    pub corrections: Option<Corrections>,
    /// The result.
    pub measured: Measured<'a>,
    /// The 95 % error bound's factor (outages).
    pub bound: deadreckon_core::bound::BoundFit,
    /// The user's alert limit: when the bound reaches it in each outage, m.
    pub alert_m: Option<f64>,
}

/// Measures `metric` on `drive` with `parameters` (their drive: corrected
/// as they ask).
pub fn measure<'a>(
    drive: &Drive,
    parameters: Parameters,
    timing: Timing,
    metric: Metric<'a>,
) -> Result<Evaluation<'a>, Error> {
    let params = &parameters.params;
    let measured = match metric {
        Metric::Drift { segment_m } => {
            Measured::Drift(metrics::drift(drive, params, segment_m, timing)?, segment_m)
        }
        Metric::Reset { threshold_m } => Measured::Reset(
            metrics::reset_on_error(drive, params, threshold_m, timing)?,
            threshold_m,
        ),
        Metric::Evo(q) => Measured::Evo(q, evo_metric(drive, params, timing, &q)?),
        Metric::Outages {
            length_s,
            step_s,
            warmup_s,
        } => {
            let base = FilterOptions {
                timing,
                ..Default::default()
            };
            Measured::Outages(
                length_s,
                outage::evaluate(drive, params, length_s, step_s, warmup_s, &base)?,
            )
        }
    };
    Ok(Evaluation {
        source: parameters.label,
        params_source: parameters.source,
        corrections: parameters.corrections,
        measured,
        bound: parameters.bound,
        alert_m: None,
    })
}

impl Evaluation<'_> {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        let mut v = match &self.measured {
            Measured::Outages(len, ev) => {
                let mut v = crate::json::outage_json(*len, &self.source, ev);
                crate::bound::add_outage_bound(&mut v, ev, &self.bound, self.alert_m);
                v
            }
            Measured::Drift(r, seg) => crate::json::drift_json(r, *seg),
            Measured::Reset(r, th) => crate::json::reset_json(r, *th),
            Measured::Evo(q, r) => crate::json::evo_json(q, r),
        };
        if !matches!(self.measured, Measured::Outages(..)) {
            v["params"] = self.source.clone().into();
        }
        if let Some(c) = &self.corrections {
            v["corrections"] = crate::corrections::corrections_json(c);
        }
        v["params_source"] = self.params_source.clone().into();
        v
    }

    /// The text.
    pub fn lines(&self) -> Vec<String> {
        let gated = |g| format!("rejected by the χ² gates: {}", crate::text::gated_text(g));
        match &self.measured {
            Measured::Outages(_, ev) => {
                let mut out =
                    crate::text::outage_lines(ev, &self.source, self.corrections.as_ref());
                // The bound's row ends the summary table (the title, the
                // table's header and four rows), its lines follow.
                let at = 6.min(out.len());
                let lines = crate::bound::outage_bound_lines(ev, &self.bound, self.alert_m);
                out.splice(at..at, lines);
                out
            }
            Measured::Drift(r, seg) => {
                let s = Summary::of(&r.errors_pct());
                vec![
                    format!("drift per {seg} m over {} segments: mean {:.3}%, std {:.3}%, median {:.3}%, max {:.3}%", s.n, s.mean, s.std, s.median, s.max),
                    gated(&r.gates),
                ]
            }
            Measured::Reset(r, th) => {
                let s = Summary::of(&r.distances_m);
                vec![
                    format!("distance before {th} m of error over {} resets: mean {:.1} m, median {:.1} m, min {:.1} m, max {:.1} m", s.n, s.mean, s.median, s.min, s.max),
                    gated(&r.gates),
                ]
            }
            Measured::Evo(q, r) => crate::text::evo_lines(q, r),
        }
    }
}
