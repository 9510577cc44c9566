//! `calibrate`, `run` and `evaluate`: the commands' computations and their
//! `--json` objects (built by `deadreckon_api::json`, as the CLI prints them).

use std::path::PathBuf;

use deadreckon_api::calibration::{CalibrationRequest, RequestWords};
use deadreckon_api::json;
use deadreckon_api::options::parse_timing;
use deadreckon_api::params_file::ParamsFile;
use deadreckon_core::calibrate::Method;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::metrics;
use deadreckon_core::{evo, outage, track, Params};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::columns::ColumnsOut;
use crate::drive::{checked, drive_arg};
use crate::pyjson::to_py;
use crate::{to_py_err, DeadreckonError};

/// The `--corrections` word of `run_tracks` and `evaluate`
/// ([`deadreckon_api::options::parse_corrections`]).
fn corrections_which(s: &str) -> PyResult<deadreckon_core::timing::Which> {
    deadreckon_api::options::parse_corrections(s).map_err(to_py_err)
}

/// The drive with the corrections the params.toml `file` stores applied
/// (none without a file: `nominal` or a dict), as the CLI's `--params`.
fn with_stored(file: Option<&ParamsFile>, drive: deadreckon_core::Drive) -> deadreckon_core::Drive {
    match file {
        Some(f) => f.corrections.apply(&drive),
        None => drive,
    }
}

fn err(e: impl std::fmt::Display) -> PyErr {
    DeadreckonError::new_err(e.to_string())
}

/// `calibrate --json` as a dict; the options are the command's words, and
/// those not given (`None`) are [`CalibrationRequest::default`]'s
/// ([`CalibrationRequest::from_words`]: no default is restated here).
#[pyfunction]
#[pyo3(signature = (source, method=None, state=None, iteration=None, max_iterations=None, timing=None, min_speed=None, mapping=None, corrections=None, skip_checks=false))]
#[allow(clippy::too_many_arguments)]
pub fn calibrate(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    method: Option<&str>,
    state: Option<&str>,
    iteration: Option<&str>,
    max_iterations: Option<usize>,
    timing: Option<&str>,
    min_speed: Option<f64>,
    mapping: Option<PathBuf>,
    corrections: Option<&str>,
    skip_checks: bool,
) -> PyResult<Py<PyAny>> {
    let request = CalibrationRequest::from_words(&RequestWords {
        method,
        state,
        iteration,
        max_iterations,
        timing,
        min_speed_mps: min_speed,
        corrections,
    })
    .map_err(to_py_err)?;
    let m = request.options.method;
    // Only the truth calibration reads truth.csv (as `calibrate` does).
    let read = deadreckon_io::ReadOptions::default();
    let read = if m == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let what = source
        .extract::<PathBuf>()
        .map(|p| p.display().to_string())
        .unwrap_or_else(|_| "the drive".into());
    let drive = drive_arg(py, source, &read, mapping)?;
    let checks = checked(source, &drive, skip_checks)?;
    let cc = py
        .detach(|| deadreckon_api::calibration::calibrate(&drive, &request, &what))
        .map_err(to_py_err)?;
    let mut v = cc.json();
    // Python's calibrate is the car's: the shape found, as the command says it.
    v["shape_found"] = deadreckon_api::shape::of_drive(&drive).json();
    checks.annotate(&mut v);
    to_py(py, &v)
}

/// `nominal`, a params.toml path, or a dict with the six parameters (extra
/// keys, such as those of `calibrate`'s dict, are ignored); with its label.
pub fn params_arg(
    p: &Bound<'_, PyAny>,
    vehicle: &deadreckon_core::Vehicle,
) -> PyResult<(Params, String)> {
    params_file_arg(p, vehicle).map(|(params, label, _)| (params, label))
}

/// [`params_arg`] with the params.toml itself when `p` names one, read and
/// checked once: its stored corrections and `[bound]` come from it too.
fn params_file_arg(
    p: &Bound<'_, PyAny>,
    vehicle: &deadreckon_core::Vehicle,
) -> PyResult<(Params, String, Option<ParamsFile>)> {
    if let Ok(d) = p.cast::<PyDict>() {
        let mut a = [0.0; 6];
        for (i, name) in Params::NAMES.iter().enumerate() {
            a[i] = d
                .get_item(name)?
                .ok_or_else(|| err(format!("params: missing `{name}`")))?
                .extract()?;
        }
        let params = Params::from_array(a);
        params
            .validate()
            .map_err(|e| err(format!("params: {}", deadreckon_api::chain_text(&e))))?;
        return Ok((params, "given".into(), None));
    }
    let spec: PathBuf = p.extract()?;
    let label = spec.display().to_string();
    if label == "nominal" {
        return Ok((Params::nominal(vehicle), label, None));
    }
    // Read and checked once (deadreckon_api::params_file), bound to their
    // vehicle as the command line's --params (deadreckon_api::binding):
    // another vehicle's file is refused.
    let file = ParamsFile::read(&label).map_err(to_py_err)?;
    let params = file.estimate.params;
    deadreckon_api::binding::check(&label, file.vehicle(), &params, vehicle, false)
        .map_err(to_py_err)?;
    Ok((params, label, Some(file)))
}

/// Every track of a drive (dead-reckoned, filtered, smoothed, and truth),
/// as `{name: {column: array}}` with the track CSV's columns.
#[pyfunction]
#[pyo3(signature = (source, params=None, timing="wheel", init_pose=None, mapping=None, corrections="auto"))]
pub fn run_tracks<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    timing: &str,
    init_pose: Option<(f64, f64, f64)>,
    mapping: Option<PathBuf>,
    corrections: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let which = corrections_which(corrections)?;
    let drive = drive_arg(py, source, &Default::default(), mapping)?;
    // The one rule for no params (deadreckon_api::evaluate::RULE): calibrated
    // on the drive itself, as `run` does; a file's stored corrections applied.
    // The 95 % bound's factor as `run` takes it: a file's `[bound]` (a
    // dict's: the filter's covariance alone), or fitted with the calibration.
    let (params, drive, bound) = match params {
        Some(p) => {
            let (params, _, file) = params_file_arg(p, &drive.vehicle)?;
            let bound = file
                .as_ref()
                .map_or(deadreckon_core::bound::BoundFit::FILTER, |f| f.bound);
            (params, with_stored(file.as_ref(), (*drive).clone()), bound)
        }
        None => {
            let (c, d) = py
                .detach(|| deadreckon_api::evaluate::default_parameters(&drive, which))
                .map_err(to_py_err)?;
            (c.params, d, c.bound)
        }
    };
    if let Some((e, n, y)) = init_pose {
        if !(e.is_finite() && n.is_finite() && y.is_finite()) {
            return Err(err(
                "init_pose needs three finite numbers (east_m, north_m, yaw_rad)",
            ));
        }
    }
    let opts = FilterOptions {
        timing: parse_timing(timing).map_err(to_py_err)?,
        ..Default::default()
    };
    let tracks = py
        .detach(|| deadreckon_api::tracks::drive_tracks(&drive, &params, &opts, init_pose))
        .map_err(to_py_err)?;
    let bounds = deadreckon_api::tracks::bounds_95_m(&drive, &tracks, &bound, &opts, init_pose);
    let out = PyDict::new(py);
    for (t, b) in tracks.iter().zip(&bounds) {
        let c = track_columns(py, t)?;
        // The CSV's `bound_95_m`: NaN where it is empty.
        let b = if b.is_empty() {
            vec![f64::NAN; t.points.len()]
        } else {
            b.clone()
        };
        c.set_item("bound_95_m", numpy::PyArray1::from_vec(py, b))?;
        out.set_item(&t.name, c)?;
    }
    Ok(out)
}

/// One track's columns (those of the track CSV but `track`).
pub fn track_columns<'py>(py: Python<'py>, t: &track::Track) -> PyResult<Bound<'py, PyDict>> {
    let p = &t.points;
    // No uncertainty (TedriS, the reference): NaN, as the CSV leaves them empty.
    let none = deadreckon_io::carries_no_covariance(t);
    let unc = |v: f64| if none { f64::NAN } else { v };
    let mut c = ColumnsOut::new(py);
    c.add("t_s", p, |r| r.t_s)?
        .add("east_m", p, |r| r.east_m)?
        .add("north_m", p, |r| r.north_m)?
        .add("yaw_rad", p, |r| r.yaw_rad)?
        .add("speed_mps", p, |r| r.speed_mps)?
        .add("yaw_rate_rps", p, |r| r.yaw_rate_rps)?
        .add("std_east_m", p, |r| unc(r.std_east_m()))?
        .add("std_north_m", p, |r| unc(r.std_north_m()))?
        .add("std_yaw_rad", p, |r| unc(r.std_yaw_rad()))?
        .add("cov_en_m2", p, |r| unc(r.cov_pose[1]))?;
    Ok(c.finish())
}

/// `evaluate --json` as a dict; the options are the command's.
#[pyfunction]
#[pyo3(signature = (source, params=None, metric="drift", outage=None, step=None, warmup=None, segment_m=100.0, threshold_m=1.0, track="dead-reckoned", reference="truth", delta_m=100.0, pairs_from="estimate", max_diff_s=evo::DEFAULT_MAX_DIFF_S, timing="wheel", mapping=None, corrections="auto", skip_checks=false, shape=None))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    params: Option<&Bound<'_, PyAny>>,
    metric: &str,
    outage: Option<f64>,
    step: Option<f64>,
    warmup: Option<f64>,
    segment_m: f64,
    threshold_m: f64,
    track: &str,
    reference: &str,
    delta_m: f64,
    pairs_from: &str,
    max_diff_s: f64,
    timing: &str,
    mapping: Option<PathBuf>,
    corrections: &str,
    skip_checks: bool,
    shape: Option<&str>,
) -> PyResult<Py<PyAny>> {
    let which = corrections_which(corrections)?;
    let drive = drive_arg(py, source, &Default::default(), mapping)?;
    let checks = checked(source, &drive, skip_checks)?;
    let timing = parse_timing(timing).map_err(to_py_err)?;
    // The shape found from the data, as the commands find it
    // (deadreckon_api::shape); `shape` overrides it.
    let (kinematic, found) = kinematic_evaluate(py, source, &drive, params, outage, step, shape)?;
    if let Some(mut v) = kinematic {
        checks.annotate(&mut v);
        return to_py(py, &v);
    }
    if outage.is_none() && !["drift", "reset-1m", "rpe", "ape"].contains(&metric) {
        return Err(err(format!(
            "unknown metric `{metric}` (drift, reset-1m, rpe, ape)"
        )));
    }
    // One rule for every metric (deadreckon_api::evaluate::RULE), as the
    // command applies it.
    // The file read once: its parameters, its stored corrections and the
    // error bound's factor, as the command takes it (its `[bound]`, or
    // without a file fitted with the calibration on the drive).
    let given = params
        .map(|p| params_file_arg(p, &drive.vehicle))
        .transpose()?;
    let (params, label, drive, corr, params_source, bound) = py.detach(|| -> PyResult<_> {
        Ok(match given {
            Some((p, l, file)) => {
                let bound = file
                    .as_ref()
                    .map_or(deadreckon_core::bound::BoundFit::FILTER, |f| f.bound);
                let stored = with_stored(file.as_ref(), (*drive).clone());
                (p, l.clone(), stored, None, l, bound)
            }
            None => {
                let (c, d) = deadreckon_api::evaluate::default_parameters(&drive, which)
                    .map_err(to_py_err)?;
                (c.params, c.label, d, c.corrections, c.source, c.bound)
            }
        })
    })?;
    if let Some(len) = outage {
        let base = FilterOptions {
            timing,
            ..Default::default()
        };
        let mut v = py.detach(|| -> PyResult<serde_json::Value> {
            let ev = outage::evaluate(
                &drive,
                &params,
                len,
                step.unwrap_or(len / 2.0),
                warmup.unwrap_or(deadreckon_api::evaluate::OUTAGE_WARMUP_S),
                &base,
            )
            .map_err(to_py_err)?;
            let mut v = json::outage_json(len, &label, &ev);
            deadreckon_api::bound::add_outage_bound(&mut v, &ev, &bound, None);
            v["shape_found"] = found.json();
            if let Some(c) = &corr {
                v["corrections"] = deadreckon_api::corrections::corrections_json(c);
            }
            v["params_source"] = params_source.clone().into();
            Ok(v)
        })?;
        checks.annotate(&mut v);
        return to_py(py, &v);
    }
    let mut v = py.detach(|| -> PyResult<serde_json::Value> {
        match metric {
            "drift" => {
                let r = metrics::drift(&drive, &params, segment_m, timing).map_err(to_py_err)?;
                Ok(json::drift_json(&r, segment_m))
            }
            "reset-1m" => {
                let r = metrics::reset_on_error(&drive, &params, threshold_m, timing)
                    .map_err(to_py_err)?;
                Ok(json::reset_json(&r, threshold_m))
            }
            "rpe" | "ape" => {
                let q = json::EvoQuery {
                    metric,
                    track,
                    reference,
                    max_diff_s,
                    delta_m,
                    pairs_from,
                };
                let r = deadreckon_api::evaluate::evo_metric(&drive, &params, timing, &q)
                    .map_err(to_py_err)?;
                Ok(json::evo_json(&q, &r))
            }
            m => Err(err(format!(
                "unknown metric `{m}` (drift, reset-1m, rpe, ape)"
            ))),
        }
    })?;
    v["params"] = label.into();
    v["params_source"] = params_source.into();
    v["shape_found"] = found.json();
    if let Some(c) = &corr {
        v["corrections"] = deadreckon_api::corrections::corrections_json(c);
    }
    checks.annotate(&mut v);
    to_py(py, &v)
}

/// `evaluate` of a drive whose shape (found from the data, or `shape`) is a
/// tricycle or a differential drive, as the command runs it; `None` for a
/// car.
fn kinematic_evaluate(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    drive: &deadreckon_core::Drive,
    params: Option<&Bound<'_, PyAny>>,
    outage: Option<f64>,
    step: Option<f64>,
    shape: Option<&str>,
) -> PyResult<(Option<serde_json::Value>, deadreckon_api::shape::Found)> {
    use deadreckon_api::{kinematic, shape as sh};
    use deadreckon_core::kinematics::diff_drive::{OutageStart, DEFAULT_WARMUP_S};
    use deadreckon_core::kinematics::Shape;
    let asked = match shape {
        None => None,
        Some("car") => Some(Shape::FourWheel),
        Some("diff-drive") => Some(Shape::DiffDrive),
        Some("tricycle") => Some(Shape::Tricycle),
        Some(other) => {
            return Err(err(format!(
                "unknown shape `{other}` (car, diff-drive, tricycle)"
            )))
        }
    };
    let path = source
        .extract::<PathBuf>()
        .unwrap_or_else(|_| PathBuf::from("the drive"));
    let found = sh::detect(&path, Some(drive), asked);
    if found.shape == Shape::FourWheel {
        return Ok((None, found));
    }
    let Some(len) = outage else {
        return Err(err(format!(
            "a {} is evaluated over sliding outages: give outage=LEN (and step=S)",
            sh::words(found.shape)
        )));
    };
    let spec: Option<String> = params.map(|p| p.extract()).transpose()?;
    let step = step.unwrap_or(len / 2.0);
    let ev = py
        .detach(|| match found.shape {
            Shape::Tricycle => {
                // A tricycle log is read through its own kinematics.
                let own = sh::of_path(&path).is_none().then_some(drive);
                kinematic::evaluate_tricycle(&path, own, spec.as_deref(), len, step, None, None)
            }
            _ => {
                let yaw = kinematic::diff_yaw(spec.as_deref(), None);
                kinematic::evaluate_diff(
                    drive,
                    spec.as_deref(),
                    yaw,
                    len,
                    step,
                    DEFAULT_WARMUP_S,
                    &OutageStart::Filter(Default::default()),
                    None,
                    None,
                )
            }
        })
        .map_err(to_py_err)?;
    let mut v = ev.json();
    v["shape_found"] = found.json();
    Ok((Some(v), found))
}
