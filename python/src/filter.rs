//! `deadreckon.Filter`: the four-wheel filter's step API
//! (`deadreckon_core::filter`): `predict_to` and one `update_*` per sensor,
//! each returning the innovation, its variance, the NIS and whether the χ²
//! gate accepted it.

use std::path::PathBuf;

use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::drive::GnssFix;
use deadreckon_core::ekf::{self, FilterOptions};
use deadreckon_core::filter::{AugmentedFilter, CarFilter};
use deadreckon_core::model::{Mat, State};
use deadreckon_core::{Params, Vehicle};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::calib::params_arg;
use crate::drive::{vehicle_arg, Drive};
use crate::pyjson::to_py;
use crate::{to_py_err, DeadreckonError};

/// The outcome of one measurement update.
#[pyclass(frozen, get_all, module = "deadreckon._native")]
#[derive(Clone)]
pub struct Update {
    /// The sensor: wheel_fl, wheel_fr, wheel_rl, wheel_rr, gyro, speed, steering, gnss, course.
    pub sensor: String,
    /// Innovation z − h(x̂⁻) (east component for GNSS).
    pub innovation: f64,
    /// Innovation variance (east for GNSS).
    pub variance: f64,
    /// Normalised innovation squared.
    pub nis: f64,
    /// False when the χ² gate rejected the measurement (state unchanged).
    pub accepted: bool,
}

#[pymethods]
impl Update {
    fn __repr__(&self) -> String {
        format!(
            "Update(sensor={:?}, innovation={}, variance={}, nis={}, accepted={})",
            self.sensor,
            self.innovation,
            self.variance,
            self.nis,
            if self.accepted { "True" } else { "False" }
        )
    }
}

impl From<deadreckon_core::filter::Update> for Update {
    fn from(u: deadreckon_core::filter::Update) -> Self {
        Update {
            sensor: u.sensor.name().to_string(),
            innovation: u.y,
            variance: u.s,
            nis: u.nis,
            accepted: u.accepted,
        }
    }
}

enum Inner {
    Car(Box<CarFilter>),
    Augmented(Box<AugmentedFilter>),
}

/// Calls `$body` with `$f` bound to whichever filter is inside.
macro_rules! with_filter {
    ($self:expr, $f:ident => $body:expr) => {
        match &mut $self.inner {
            Inner::Car($f) => $body,
            Inner::Augmented($f) => $body,
        }
    };
}

/// The four-wheel EKF, one step at a time.
#[pyclass(module = "deadreckon._native")]
pub struct Filter {
    inner: Inner,
}

/// The native drive of a `Drive` or of the Python `deadreckon.Drive` around it.
fn native_drive<'py>(obj: &Bound<'py, PyAny>) -> Option<Bound<'py, Drive>> {
    if let Ok(d) = obj.cast::<Drive>() {
        return Some(d.clone());
    }
    obj.getattr("_native")
        .ok()
        .and_then(|n| n.cast_into::<Drive>().ok())
}

pub fn vehicle_of(vehicle: &Bound<'_, PyAny>) -> PyResult<Vehicle> {
    if let Some(d) = native_drive(vehicle) {
        return Ok(d.get().inner.vehicle.clone());
    }
    if vehicle.is_instance_of::<PyDict>() {
        let text: String = vehicle
            .py()
            .import("json")?
            .call_method1("dumps", (vehicle,))?
            .extract()?;
        return vehicle_arg(Some(&text), None);
    }
    let p: PathBuf = vehicle.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(
            "vehicle: expected a Drive, a dict of vehicle.toml keys or a vehicle.toml path",
        )
    })?;
    vehicle_arg(None, Some(p))
}

fn prior_of(prior_std: Option<&Bound<'_, PyAny>>, vehicle: &Vehicle) -> PyResult<Params> {
    match prior_std {
        Some(p) => Ok(params_arg(p, vehicle)?.0),
        None => Ok(CalibrationOptions::default().prior_std),
    }
}

fn array1<'py, const N: usize>(
    py: Python<'py>,
    v: &nalgebra::SVector<f64, N>,
) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_slice(py, v.as_slice())
}

fn array2<'py, const N: usize>(
    py: Python<'py>,
    m: &nalgebra::SMatrix<f64, N, N>,
) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((N, N), |(i, j)| m[(i, j)]).into_pyarray(py)
}

fn params_dict<'py>(py: Python<'py>, p: &Params) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for (name, v) in Params::NAMES.iter().zip(p.to_array()) {
        d.set_item(name, v)?;
    }
    Ok(d)
}

#[pymethods]
impl Filter {
    /// A filter at `t0_s` with car state `x0` (east_m, north_m, yaw_rad,
    /// speed_mps, yaw_rate_rps) and 5×5 covariance `p0`; `params` the six
    /// parameters (default nominal); `augmented` estimates them as states
    /// starting with standard deviations `prior_std` (default the
    /// calibration's).
    #[new]
    #[pyo3(signature = (vehicle, t0_s, x0, p0, params=None, augmented=false, prior_std=None))]
    fn new(
        vehicle: &Bound<'_, PyAny>,
        t0_s: f64,
        x0: PyReadonlyArray1<'_, f64>,
        p0: PyReadonlyArray2<'_, f64>,
        params: Option<&Bound<'_, PyAny>>,
        augmented: bool,
        prior_std: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let vehicle = vehicle_of(vehicle)?;
        let params = match params {
            Some(p) => params_arg(p, &vehicle)?.0,
            None => Params::nominal(&vehicle),
        };
        let x0 = x0.as_slice()?;
        let p0 = p0.as_array();
        if x0.len() != 5 || p0.shape() != [5, 5] {
            return Err(DeadreckonError::new_err(
                "x0 must have 5 elements and p0 be 5×5 (east_m, north_m, yaw_rad, speed_mps, yaw_rate_rps)",
            ));
        }
        let x = State::from_column_slice(x0);
        let p = Mat::from_fn(|i, j| p0[[i, j]]);
        let inner = if augmented {
            let prior = prior_of(prior_std, &vehicle)?;
            Inner::Augmented(Box::new(
                AugmentedFilter::new(&vehicle, &params, Some(&prior), t0_s, x, p)
                    .map_err(to_py_err)?,
            ))
        } else {
            Inner::Car(Box::new(
                CarFilter::new(&vehicle, &params, None, t0_s, x, p).map_err(to_py_err)?,
            ))
        };
        Ok(Filter { inner })
    }

    /// The filter the batch run starts with on `drive` (initialised from its
    /// GNSS, as `run` and `calibrate` do).
    #[staticmethod]
    #[pyo3(signature = (drive, params=None, augmented=false, prior_std=None))]
    fn from_drive(
        drive: &Bound<'_, PyAny>,
        params: Option<&Bound<'_, PyAny>>,
        augmented: bool,
        prior_std: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let drive = native_drive(drive)
            .ok_or_else(|| pyo3::exceptions::PyTypeError::new_err("expected a deadreckon.Drive"))?;
        let d = &drive.get().inner;
        let params = match params {
            Some(p) => params_arg(p, &d.vehicle)?.0,
            None => Params::nominal(&d.vehicle),
        };
        let opts = FilterOptions::default();
        let inner = if augmented {
            let prior = prior_of(prior_std, &d.vehicle)?;
            Inner::Augmented(Box::new(
                ekf::augmented_filter(d, &params, &prior, &opts).map_err(to_py_err)?,
            ))
        } else {
            Inner::Car(Box::new(
                ekf::car_filter(d, &params, &opts).map_err(to_py_err)?,
            ))
        };
        Ok(Filter { inner })
    }

    /// Predicts the state to `t_s` (no-op for a time not after the filter's).
    fn predict_to(&mut self, t_s: f64) -> PyResult<()> {
        if !t_s.is_finite() {
            return Err(DeadreckonError::new_err("predict_to: time must be finite"));
        }
        with_filter!(self, f => { f.predict_to(t_s); });
        Ok(())
    }

    /// Ticks of wheel `i` (0 FL, 1 FR, 2 RL, 3 RR) over `interval_s`;
    /// None when the wheel has no sensor.
    fn update_wheel_ticks(
        &mut self,
        i: usize,
        ticks: f64,
        interval_s: f64,
    ) -> PyResult<Option<Update>> {
        check_wheel(i)?;
        Ok(
            with_filter!(self, f => f.update_wheel_ticks(i, ticks, interval_s))
                .map_err(to_py_err)?
                .map(Into::into),
        )
    }

    /// Speed of wheel `i`, m/s; None when the wheel has no sensor.
    fn update_wheel_speed(&mut self, i: usize, speed_mps: f64) -> PyResult<Option<Update>> {
        check_wheel(i)?;
        Ok(with_filter!(self, f => f.update_wheel_speed(i, speed_mps))
            .map_err(to_py_err)?
            .map(Into::into))
    }

    /// One raw gyro reading, rad/s.
    fn update_gyro(&mut self, yaw_rate_rps: f64) -> PyResult<Update> {
        Ok(with_filter!(self, f => f.update_gyro(yaw_rate_rps))
            .map_err(to_py_err)?
            .into())
    }

    /// One CAN speed reading, m/s.
    fn update_speed(&mut self, speed_mps: f64) -> PyResult<Update> {
        Ok(with_filter!(self, f => f.update_speed(speed_mps))
            .map_err(to_py_err)?
            .into())
    }

    /// One steering-wheel angle, rad.
    fn update_steering(&mut self, steering_wheel_rad: f64) -> PyResult<Update> {
        Ok(
            with_filter!(self, f => f.update_steering(steering_wheel_rad))
                .map_err(to_py_err)?
                .into(),
        )
    }

    /// One GNSS fix of the antenna, m, with its standard deviation per coordinate.
    fn update_gnss(&mut self, east_m: f64, north_m: f64, std_m: f64) -> PyResult<Update> {
        if !(east_m.is_finite() && north_m.is_finite() && std_m.is_finite() && std_m > 0.0) {
            return Err(DeadreckonError::new_err(
                "update_gnss: east_m and north_m finite, std_m positive",
            ));
        }
        let t_s = with_filter!(self, f => f.time_s());
        let fix = GnssFix {
            t_s,
            east_m,
            north_m,
            std_m,
            course_deg: None,
            speed_mps: None,
        };
        Ok(with_filter!(self, f => f.update_gnss(&fix))
            .map_err(to_py_err)?
            .into())
    }

    /// A GNSS course as a yaw (rad, counter-clockwise from east); used above
    /// 3 m/s only (None below or without a speed).
    #[pyo3(signature = (course_yaw_rad, speed_mps=None))]
    fn update_course(
        &mut self,
        course_yaw_rad: f64,
        speed_mps: Option<f64>,
    ) -> PyResult<Option<Update>> {
        Ok(
            with_filter!(self, f => f.update_course(course_yaw_rad, speed_mps))
                .map_err(to_py_err)?
                .map(Into::into),
        )
    }

    /// The filter's time, s.
    #[getter]
    fn time_s(&mut self) -> f64 {
        with_filter!(self, f => f.time_s())
    }

    /// The state: 5 car states, then with `augmented` the six parameters'
    /// states (gyro bias, speed scale, four inverse circumferences).
    #[getter]
    fn state<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        with_filter!(self, f => array1(py, f.state()))
    }

    /// The state covariance.
    #[getter]
    fn covariance<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        with_filter!(self, f => array2(py, f.covariance()))
    }

    /// The six parameters in use (estimated ones with `augmented`).
    #[getter]
    fn params<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let p = with_filter!(self, f => f.params());
        params_dict(py, &p)
    }

    /// Their standard deviations with `augmented`, else None.
    #[getter]
    fn params_std<'py>(&mut self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let p = with_filter!(self, f => f.params_std());
        p.map(|p| params_dict(py, &p)).transpose()
    }

    /// The χ² gate counters: {sensor: {accepted, rejected, recovered}}.
    #[getter]
    fn gates(&mut self, py: Python<'_>) -> PyResult<Py<PyAny>> {
        let g = with_filter!(self, f => *f.gates());
        to_py(py, &deadreckon_api::json::gates_json(&g))
    }

    fn __repr__(&mut self) -> String {
        let (kind, t) = match &self.inner {
            Inner::Car(f) => ("5 states", f.time_s()),
            Inner::Augmented(f) => ("11 states", f.time_s()),
        };
        format!("<deadreckon.Filter: {kind} at t = {t} s>")
    }
}

fn check_wheel(i: usize) -> PyResult<()> {
    if i < 4 {
        Ok(())
    } else {
        Err(DeadreckonError::new_err(format!(
            "wheel index {i}: 0 FL, 1 FR, 2 RL, 3 RR"
        )))
    }
}
