//! `deadreckon.Online`: the online filter of `deadreckon stream`
//! (`deadreckon_core::online`): JSON-line events in (docs/events.md), one
//! pose per completed epoch out, optionally learning the six parameters.

use deadreckon_core::bound_pose::Pose;
use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::online::{LearnTargets, Online as CoreOnline, Start};
use deadreckon_core::Params;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::calib::params_arg;
use crate::columns::ColumnsOut;
use crate::filter::vehicle_of;
use crate::pyjson::to_py;
use crate::{to_py_err, DeadreckonError};

/// The online filter: `push_lines` events, get poses.
#[pyclass(module = "deadreckon._native")]
pub struct Online {
    inner: CoreOnline,
    lines: u64,
}

fn poses<'py>(py: Python<'py>, p: &[Pose]) -> PyResult<Bound<'py, PyDict>> {
    let mut c = ColumnsOut::new(py);
    c.add("t_s", p, |r| r.point.t_s)?
        .add("east_m", p, |r| r.point.east_m)?
        .add("north_m", p, |r| r.point.north_m)?
        .add("yaw_rad", p, |r| r.point.yaw_rad)?
        .add("speed_mps", p, |r| r.point.speed_mps)?
        .add("yaw_rate_rps", p, |r| r.point.yaw_rate_rps)?
        .add("std_east_m", p, |r| r.point.std_east_m())?
        .add("std_north_m", p, |r| r.point.std_north_m())?
        .add("std_yaw_rad", p, |r| r.point.std_yaw_rad())?
        .add("bound_95_m", p, |r| r.bound_95_m)?;
    Ok(c.finish())
}

#[pymethods]
impl Online {
    /// An online filter for `vehicle` (a Drive, a dict of vehicle.toml's keys
    /// or its path), starting from GNSS, as `deadreckon stream` does; a
    /// params.toml path's stored corrections are applied to the events, and
    /// its `[bound]` factor gives each pose its `bound_95_m`.
    #[new]
    #[pyo3(signature = (vehicle, params=None, timing="wheel", learn=false, prior_std=None))]
    fn new(
        vehicle: &Bound<'_, PyAny>,
        params: Option<&Bound<'_, PyAny>>,
        timing: &str,
        learn: bool,
        prior_std: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let vehicle = vehicle_of(vehicle)?;
        // A params.toml's stored corrections (delays, IMU tilt, gyro scale,
        // slip) are applied to the events, as `deadreckon stream` does.
        let (stored, bound) = match params {
            Some(p) if p.cast::<PyDict>().is_err() => {
                let spec: std::path::PathBuf = p.extract()?;
                // Read once, as `deadreckon stream` reads it.
                let spec = spec.to_string_lossy();
                if spec == "nominal" {
                    (Default::default(), deadreckon_core::bound::BoundFit::FILTER)
                } else {
                    let file =
                        deadreckon_api::params_file::ParamsFile::read(&spec).map_err(to_py_err)?;
                    (file.corrections, file.bound)
                }
            }
            _ => (Default::default(), deadreckon_core::bound::BoundFit::FILTER),
        };
        let params = match params {
            Some(p) => params_arg(p, &vehicle)?.0,
            None => Params::nominal(&vehicle),
        };
        let opts = FilterOptions {
            timing: deadreckon_api::options::parse_timing(timing).map_err(to_py_err)?,
            ..Default::default()
        };
        let inner = if learn {
            let prior = match prior_std {
                Some(p) => params_arg(p, &vehicle)?.0,
                None => CalibrationOptions::default().prior_std,
            };
            CoreOnline::learning(&vehicle, &params, &prior, &opts, Start::Gnss)
        } else {
            CoreOnline::new(&vehicle, &params, &opts, Start::Gnss)
        }
        .map_err(to_py_err)?;
        let inner = inner
            .with_corrections(&stored)
            .map_err(to_py_err)?
            .with_bound(bound);
        Ok(Online { inner, lines: 0 })
    }

    /// Takes JSON-line events (time order; blank lines skipped); returns the
    /// poses of the epochs they completed as columns. A bad line raises
    /// `DeadreckonError` naming its line (counted over all calls).
    fn push_lines<'py>(
        &mut self,
        py: Python<'py>,
        lines: Vec<String>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mut out = Vec::new();
        for line in &lines {
            self.lines += 1;
            if line.trim().is_empty() {
                continue;
            }
            let ev =
                deadreckon_io::events::parse_line(line, "events", self.lines).map_err(to_py_err)?;
            let n = self.lines;
            self.inner
                .push_poses(ev, &mut |p| out.push(p))
                .map_err(|e| {
                    DeadreckonError::new_err(format!(
                        "events: line {n}: {}",
                        deadreckon_api::chain_text(&e)
                    ))
                })?;
        }
        poses(py, &out)
    }

    /// Ends the stream: the poses of the last epochs, those of the events
    /// a params.toml's stored delays or slip held back included (save the
    /// state with `to_json` before this to resume, not after).
    fn finish<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let mut out = Vec::new();
        self.inner
            .end_poses(&mut |p| out.push(p))
            .map_err(to_py_err)?;
        poses(py, &out)
    }

    /// True once the filter runs (after its GNSS start).
    #[getter]
    fn is_started(&self) -> bool {
        self.inner.is_started()
    }

    /// With `learn`: the parameters learned so far, their std, `valid` and
    /// `calibrated_pct`; else None.
    fn learned(&self, py: Python<'_>) -> PyResult<Option<Py<PyAny>>> {
        let Some(l) = self.inner.learned(&LearnTargets::default()) else {
            return Ok(None);
        };
        let mut m = serde_json::Map::new();
        let mut std = serde_json::Map::new();
        for (i, name) in Params::NAMES.iter().enumerate() {
            m.insert((*name).into(), l.params.to_array()[i].into());
            std.insert((*name).into(), l.std.to_array()[i].into());
        }
        m.insert("std".into(), std.into());
        m.insert("valid".into(), l.valid.into());
        m.insert("calibrated_pct".into(), l.calibrated_pct.into());
        to_py(py, &serde_json::Value::Object(m)).map(Some)
    }

    /// The state as JSON text (what `stream --state` writes), to resume later.
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner).map_err(to_py_err)
    }

    /// Resumes from `to_json`'s text.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let inner: CoreOnline = serde_json::from_str(text)
            .map_err(|e| DeadreckonError::new_err(format!("online state: {e}")))?;
        Ok(Online { inner, lines: 0 })
    }
}
