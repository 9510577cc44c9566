//! A kinematic shape's sliding-outage evaluation as `evaluate` runs it:
//! [`evaluate_tricycle`], [`evaluate_diff`] and their result
//! ([`Evaluated`]), the yaw source's choice ([`diff_yaw`]) and the
//! tricycle's tracks ([`tricycle_tracks`]).

use std::path::Path;

use deadreckon_core::kinematics::diff_drive::{
    self, evaluate_diff_drive, DiffDriveDrive, DiffDriveOutages, OutageStart, YawSource,
};
use deadreckon_core::kinematics::tricycle::TricycleParams;
use deadreckon_core::kinematics::{self, KinematicOptions, KinematicOutages, Shape};
use deadreckon_core::{Drive, Track};

use super::{
    calibrate_diff, load_params, load_params_file_with_std, load_tricycle_from, yaw_name,
    CalibrateOptions, LoadedParams,
};
use crate::error::While;
use crate::Error;

/// Sliding-outage evaluation of a kinematic shape, as `evaluate` prints it.
#[derive(Debug, Clone)]
pub struct Evaluated {
    /// The shape.
    pub shape: Shape,
    /// Outage length, s.
    pub length_s: f64,
    /// Where the parameters came from.
    pub source: String,
    /// A differential drive's warm-up (and alignment span), s.
    pub align_s: Option<f64>,
    /// The windows and their errors.
    pub evaluation: KinematicOutages,
    /// A differential drive's outages: how they started, the filter's fix
    /// counts and predicted errors.
    pub diff: Option<DiffDriveOutages>,
    /// The 95 % error bound's factor (issue 31): the differential drive's
    /// filter only (`None`: no covariance to bound, the tricycle's
    /// kinematics and the alignment start; [`crate::bound::NO_COVARIANCE`]).
    pub bound: Option<deadreckon_core::bound::BoundFit>,
}

impl Evaluated {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        let mut v = crate::json::kinematic_outages_json(self.shape, &self.evaluation, &self.source);
        v["params_source"] = self.source.clone().into();
        if let Some(align) = self.align_s {
            v["align_s"] = align.into();
        }
        if let Some(d) = &self.diff {
            v["start"] = d.start.name().into();
            match d.start {
                OutageStart::Align => {
                    v["reference"] =
                        "gnss (hidden fixes; start aligned to the preceding fixes)".into();
                }
                OutageStart::Filter(_) => {
                    v["reference"] =
                        "gnss (hidden fixes; start from the GNSS-aided filter, fix wander carried)"
                            .into();
                    v["fixes_used"] = d.fixes_used.into();
                    v["fixes_rejected"] = d.fixes_rejected.into();
                    v["fix_jumps"] = d.fix_jumps.into();
                    if let Some((predicted, achieved)) = d.rms_per_axis() {
                        v["predicted_rms_per_axis_m"] = predicted.into();
                        v["achieved_rms_per_axis_m"] = achieved.into();
                    }
                }
            }
        }
        crate::bound::add_kinematic_bound(&mut v, self.diff.as_ref(), self.bound.as_ref());
        v
    }

    /// The text: windows, their start, the final-error line.
    pub fn lines(&self) -> Vec<String> {
        let n = self.evaluation.windows.len();
        let len = self.length_s;
        let source = &self.source;
        let start = self.diff.as_ref().map(|d| d.start);
        let mut out = vec![match (self.align_s, start) {
            (Some(a), Some(OutageStart::Align)) => format!("{n} outage windows of {len} s, each started from {a} s of dead reckoning aligned to the fixes (parameters: {source})"),
            (Some(a), Some(OutageStart::Filter(_))) => format!("{n} outage windows of {len} s (the first {a} s in), each started from the GNSS-aided filter (parameters: {source})"),
            _ => format!("{n} outage windows of {len} s from the reference pose (parameters: {source})"),
        }];
        out.extend(crate::text::summary_table(&[(
            "final error (m)",
            self.evaluation.final_error(),
        )]));
        if let Some(d) = self.diff.as_ref().filter(|d| d.start != OutageStart::Align) {
            out.push(format!(
                "filter: {} fixes used, {} rejected by the gate, {} jumps of the fixes taken",
                d.fixes_used, d.fixes_rejected, d.fix_jumps
            ));
            if let Some((predicted, achieved)) = d.rms_per_axis() {
                out.push(format!(
                    "final error per axis (RMS): predicted {predicted:.3} m, achieved {achieved:.3} m"
                ));
            }
        }
        out.extend(crate::bound::kinematic_bound_lines(
            self.diff.as_ref(),
            self.bound.as_ref(),
        ));
        out
    }
}

/// A tricycle (the log at `path`, or `drive` read from it) over sliding
/// outages from the tracker pose, scored at the tracked point with the
/// calibrated mounting; without `params`, calibrated on the evaluated range
/// itself (said in the source).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_tricycle(
    path: &Path,
    drive: Option<&Drive>,
    params: Option<&str>,
    length_s: f64,
    step_s: f64,
    from_s: Option<f64>,
    until_s: Option<f64>,
) -> Result<Evaluated, Error> {
    let shape = Shape::Tricycle;
    let drive = load_tricycle_from(path, drive, from_s, until_s)?;
    let (params, source) = match params {
        Some(p) => load_params(p, shape, &drive)?,
        None => {
            let o = KinematicOptions {
                min_speed_mps: shape.default_min_speed_mps(),
                ..Default::default()
            };
            let c = kinematics::calibrate(&drive, &o)
                .doing(|| "calibrating against the tracker".to_string())?;
            (
                c.values(),
                format!(
                    "{} (truth: the tracker, over the evaluated range)",
                    crate::evaluate::CALIBRATED_HERE
                ),
            )
        }
    };
    let evaluation = kinematics::evaluate(&drive, &params, length_s, step_s)?;
    Ok(Evaluated {
        shape,
        length_s,
        source,
        align_s: None,
        evaluation,
        diff: None,
        bound: None,
    })
}

/// The yaw source a differential drive is evaluated with: the one asked
/// for, else the params file's, else the gyro.
pub fn diff_yaw(params: Option<&str>, asked: Option<YawSource>) -> YawSource {
    if let Some(y) = asked {
        return y;
    }
    let file_yaw = params
        .filter(|p| *p != "nominal")
        .and_then(|p| deadreckon_io::read_kinematic_params(Path::new(p)).ok())
        .and_then(|f| f.yaw_source);
    match file_yaw.as_deref() {
        Some("odometry") => YawSource::Odometry,
        _ => YawSource::Gyro,
    }
}

/// A differential drive over sliding GNSS outages (with `params`, else
/// calibrated against the fixes of the evaluated range, as
/// [`crate::evaluate::RULE`] says), the first `align_s` in,
/// each started as `start` says (the alignment spans the preceding
/// `align_s`; the filter's priors on the scales and the bias are the
/// params file's standard errors where it states them) and scored against
/// the hidden fix at its end.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_diff(
    drive: &Drive,
    params: Option<&str>,
    yaw: YawSource,
    length_s: f64,
    step_s: f64,
    align_s: f64,
    start: &OutageStart,
    from_s: Option<f64>,
    until_s: Option<f64>,
) -> Result<Evaluated, Error> {
    let (calibrated_here, spec) = (params.is_none(), params);
    let LoadedParams {
        values: params,
        std,
        source,
    } = match params {
        // The one rule for no parameters (crate::evaluate::RULE): calibrated
        // against the fixes of the evaluated range itself.
        None => {
            let o = CalibrateOptions {
                from_s,
                until_s,
                ..Default::default()
            };
            let c = calibrate_diff(drive, Path::new("the drive"), yaw, &o)?;
            LoadedParams {
                values: c.calibration.values(),
                std: c
                    .calibration
                    .params
                    .iter()
                    .map(|p| if p.estimated { p.std } else { None })
                    .collect(),
                source: format!("{} (gnss)", crate::evaluate::CALIBRATED_HERE),
            }
        }
        Some("nominal") => LoadedParams {
            values: DiffDriveDrive::nominal(),
            std: vec![None; diff_drive::N_PARAMS],
            source: "nominal".to_string(),
        },
        Some(spec) => load_params_file_with_std(
            spec,
            Shape::DiffDrive,
            &diff_drive::NAMES,
            Some(yaw_name(yaw)),
        )?,
    };
    // The filter refines the scales and the bias from their stated
    // standard errors (the defaults where none is stated).
    let start = match start {
        OutageStart::Filter(noise) => OutageStart::Filter(noise.with_param_std(&std)),
        OutageStart::Align => OutageStart::Align,
    };
    let dd = super::diff_drive(drive, yaw, from_s, until_s)?;
    let diff = evaluate_diff_drive(&dd, &params, length_s, step_s, align_s, &start)?;
    let bound = diff_bound(&dd, &params, &start, align_s, calibrated_here, spec)?;
    Ok(Evaluated {
        shape: Shape::DiffDrive,
        length_s,
        source: format!("{source}, yaw {}", yaw_name(yaw)),
        align_s: Some(align_s),
        evaluation: diff.outages.clone(),
        diff: Some(diff),
        bound,
    })
}

/// The differential drive's 95 % bound factor (issue 31): none from the
/// alignment (no covariance); the `[bound]` table of a params file that
/// has one, else the filter's covariance alone (`nominal` too); fitted on
/// the evaluated drive's own windows against its hidden fixes when the
/// parameters were calibrated on it (in-sample, as a car's `evaluate`
/// without `--params`: [`deadreckon_core::bound_diff::fit_diff_drive`]).
fn diff_bound(
    dd: &DiffDriveDrive,
    params: &[f64],
    start: &OutageStart,
    align_s: f64,
    calibrated_here: bool,
    spec: Option<&str>,
) -> Result<Option<deadreckon_core::bound::BoundFit>, Error> {
    use deadreckon_core::bound::BoundFit;
    let OutageStart::Filter(noise) = start else {
        return Ok(None);
    };
    if calibrated_here {
        return Ok(Some(deadreckon_core::bound_diff::fit_diff_drive(
            dd, params, noise, align_s,
        )));
    }
    let stored = match spec.filter(|s| *s != "nominal") {
        Some(file) => {
            let text = std::fs::read_to_string(file).doing(|| format!("reading {file}"))?;
            let t: toml::Table =
                toml::from_str(&text).map_err(|e| Error::Invalid(format!("{file}: {e}")))?;
            crate::bound::bound_from_extra(&t)
                .map_err(|e| Error::Invalid(format!("{file}: {e}")))?
        }
        None => BoundFit::FILTER,
    };
    Ok(Some(stored))
}

/// A tricycle's tracks (dead-reckoned through its own kinematics from the
/// first tracker pose, and the tracker's) with `params`, or without them
/// calibrated against the tracker ([`crate::evaluate::RULE`]); and which
/// parameters were applied (`"params_source"`).
pub fn tricycle_tracks(
    path: &Path,
    drive: Option<&Drive>,
    params: Option<&str>,
) -> Result<(Vec<Track>, String), Error> {
    let drive = load_tricycle_from(path, drive, None, None)?;
    let (p, source) = match params {
        Some(spec) => (
            load_params(spec, Shape::Tricycle, &drive)?.0,
            spec.to_string(),
        ),
        None => {
            let o = KinematicOptions {
                min_speed_mps: Shape::Tricycle.default_min_speed_mps(),
                ..Default::default()
            };
            let c = kinematics::calibrate(&drive, &o)
                .doing(|| "calibrating against the tracker".to_string())?;
            (
                c.values(),
                format!("{} (truth: the tracker)", crate::evaluate::CALIBRATED_HERE),
            )
        }
    };
    let params = TricycleParams::from_slice(&p)?;
    Ok((drive.tracks(&params)?, source))
}
