//! TedriS: train a model on a drive, run a drive through GNSS outages.

use std::path::PathBuf;

use deadreckon_tedris::{
    ModelKind, Outage, ReferenceSource, RunOptions, TedrisConfig, TedrisModel, Variant,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::calib::track_columns;
use crate::drive::{checked, drive_arg};
use crate::pyjson::to_py;
use crate::{to_py_err, DeadreckonError};

fn reference_source(s: &str) -> PyResult<Option<ReferenceSource>> {
    Ok(match s {
        "auto" => None,
        "course" => Some(ReferenceSource::GnssCourse),
        "track" => Some(ReferenceSource::GnssTrack),
        "gyro" => Some(ReferenceSource::Gyro),
        _ => {
            return Err(DeadreckonError::new_err(format!(
                "unknown reference `{s}` (auto, course, track, gyro)"
            )))
        }
    })
}

/// `tedris train`: the model as JSON text (what `--out` writes) and the
/// summary `tedris train --json` prints.
#[pyfunction]
#[pyo3(signature = (source, reference="auto", variant=None, model="auto", config_json=None, from_s=None, until_s=None, mapping=None, skip_checks=false, params=None))]
#[allow(clippy::too_many_arguments)]
pub fn tedris_train(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    reference: &str,
    variant: Option<&str>,
    model: &str,
    config_json: Option<&str>,
    from_s: Option<f64>,
    until_s: Option<f64>,
    mapping: Option<PathBuf>,
    skip_checks: bool,
    params: Option<String>,
) -> PyResult<(String, Py<PyAny>)> {
    deadreckon_api::load::check_range_named(from_s, until_s, ["from_s", "until_s"])
        .map_err(|e| DeadreckonError::new_err(e.to_string()))?;
    let drive = drive_arg(py, source, &Default::default(), mapping)?;
    let checks = checked(source, &drive, skip_checks)?;
    let drive = if from_s.is_some() || until_s.is_some() {
        std::sync::Arc::new(drive.time_range(from_s, until_s))
    } else {
        drive
    };
    let variant = match variant {
        None => None,
        Some("paper") => Some(Variant::Paper),
        Some("extended") => Some(Variant::Extended),
        Some(v) => {
            return Err(DeadreckonError::new_err(format!(
                "unknown variant `{v}` (paper, extended)"
            )))
        }
    };
    let config = match config_json {
        Some(text) => Some(
            serde_json::from_str::<TedrisConfig>(text)
                .map_err(|e| DeadreckonError::new_err(format!("TedriS configuration: {e}")))?,
        ),
        None => None,
    };
    let model = match model {
        "auto" => None,
        "paper" => Some(ModelKind::Paper),
        "distance" => Some(ModelKind::Distance),
        "arx" => Some(ModelKind::Arx),
        "baseline" => Some(ModelKind::Baseline),
        "speed" => Some(ModelKind::Speed),
        m => {
            return Err(DeadreckonError::new_err(format!(
                "unknown model `{m}` (auto, paper, distance, arx, baseline, speed)"
            )))
        }
    };
    let options = deadreckon_api::tedris::TrainOptions {
        reference: reference_source(reference)?,
        config,
        variant,
        model,
        params,
        ..Default::default()
    };
    let (m, source) = py
        .detach(|| deadreckon_api::tedris::train(&drive, &options))
        .map_err(to_py_err)?;
    let text = serde_json::to_string_pretty(&m).map_err(to_py_err)?;
    let mut summary = deadreckon_api::json::tedris_train_json(&m, source);
    checks.annotate(&mut summary);
    Ok((text, to_py(py, &summary)?))
}

/// `tedris run --json` as a dict, plus `track`: the predicted track's columns.
#[pyfunction]
#[pyo3(signature = (source, model_json, outages, reference="auto", threshold_m=1.0, mapping=None, skip_checks=false, params=None))]
#[allow(clippy::too_many_arguments)]
pub fn tedris_run<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    model_json: &str,
    outages: Vec<(f64, f64)>,
    reference: &str,
    threshold_m: f64,
    mapping: Option<PathBuf>,
    skip_checks: bool,
    params: Option<String>,
) -> PyResult<Bound<'py, PyDict>> {
    let m = TedrisModel::from_json(model_json)
        .map_err(|e| DeadreckonError::new_err(format!("the model: {e}")))?;
    let outages: Vec<Outage> = outages
        .iter()
        .map(|(a, b)| format!("{a}:{b}").parse())
        .collect::<Result<_, _>>()
        .map_err(to_py_err)?;
    if outages.is_empty() {
        return Err(DeadreckonError::new_err(
            "at least one outage window is needed",
        ));
    }
    if !(threshold_m.is_finite() && threshold_m > 0.0) {
        return Err(DeadreckonError::new_err(
            "threshold_m must be a positive number",
        ));
    }
    let drive = drive_arg(py, source, &Default::default(), mapping)?;
    let checks = checked(source, &drive, skip_checks)?;
    let opts = RunOptions {
        source: reference_source(reference)?,
        threshold_m: Some(threshold_m),
    };
    let (r, corrections) = py
        .detach(|| {
            deadreckon_api::tedris::run_outages(
                &drive,
                &m,
                &outages,
                &opts,
                None,
                params.as_deref(),
            )
        })
        .map_err(to_py_err)?;
    let mut v = deadreckon_api::tedris::run_json(&r, &m, None, corrections.as_deref());
    if let Some(o) = v.as_object_mut() {
        o.remove("track");
    }
    checks.annotate(&mut v);
    let out: Bound<'py, PyDict> = to_py(py, &v)?.into_bound(py).cast_into()?;
    out.set_item("track", track_columns(py, &r.track)?)?;
    Ok(out)
}
