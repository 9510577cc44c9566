//! `deadreckon.Drive`: a drive in memory, read from any source the command
//! line reads or built from columns (pandas DataFrames on the Python side).

use std::path::PathBuf;
use std::sync::Arc;

use deadreckon_core::drive::{GnssFix, Scalar, TruthPose, WheelSpeeds, WheelTicks, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::Vehicle;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::columns::{Columns, ColumnsOut};
use crate::{to_py_err, DeadreckonError};

/// A drive: vehicle, wheels, gyro, CAN speed, steering, GNSS and truth.
#[pyclass(frozen, module = "deadreckon._native")]
pub struct Drive {
    /// The drive, shared with the computations that run without the GIL.
    pub inner: Arc<deadreckon_core::Drive>,
}

/// Reads a drive (see `Drive.read`).
#[pyfunction]
#[pyo3(signature = (path, mapping=None))]
pub fn read_drive(py: Python<'_>, path: PathBuf, mapping: Option<PathBuf>) -> PyResult<Drive> {
    let d = py
        .detach(|| deadreckon_api::read_drive(&path, mapping.as_deref()))
        .map_err(to_py_err)?;
    Ok(Drive { inner: Arc::new(d) })
}

/// A drive given as a `Drive` or read from a path (with reading options),
/// shared so it can be used without the GIL.
pub fn drive_arg(
    py: Python<'_>,
    source: &Bound<'_, PyAny>,
    options: &deadreckon_io::ReadOptions,
    mapping: Option<PathBuf>,
) -> PyResult<Arc<deadreckon_core::Drive>> {
    if let Ok(d) = source.cast::<Drive>() {
        return Ok(d.get().inner.clone());
    }
    let path: PathBuf = source.extract().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err("expected a deadreckon.Drive or a path")
    })?;
    let d = py
        .detach(|| deadreckon_api::read_drive_with(&path, options, mapping.as_deref()))
        .map_err(to_py_err)?;
    Ok(Arc::new(d))
}

/// The cross-stream plausibility checks on a drive read by [`drive_arg`]
/// (`skip`: none), as the command line runs them: an error raises, naming the
/// path (or "the drive" for a `Drive`); the warnings are returned for the
/// result's `checks`.
pub fn checked(
    source: &Bound<'_, PyAny>,
    drive: &deadreckon_core::Drive,
    skip: bool,
) -> PyResult<deadreckon_api::checks::Checks> {
    let what = source
        .extract::<PathBuf>()
        .unwrap_or_else(|_| PathBuf::from("the drive"));
    deadreckon_api::checks::check(&what, drive, skip).map_err(to_py_err)
}

/// The vehicle from a JSON object of vehicle.toml's keys, or a vehicle.toml path.
pub fn vehicle_arg(vehicle_json: Option<&str>, vehicle_path: Option<PathBuf>) -> PyResult<Vehicle> {
    let v = match (vehicle_json, vehicle_path) {
        (Some(j), _) => serde_json::from_str::<Vehicle>(j)
            .map_err(|e| DeadreckonError::new_err(format!("vehicle: {e}")))?,
        (None, Some(p)) => deadreckon_io::read_vehicle(&p).map_err(to_py_err)?,
        (None, None) => return Err(DeadreckonError::new_err("a drive needs a vehicle")),
    };
    v.validate().map_err(|e| {
        DeadreckonError::new_err(format!("vehicle: {}", deadreckon_api::chain_text(&e)))
    })?;
    Ok(v)
}

/// Positions of a stream in east/north or latitude/longitude (converted later).
fn positions(c: &Columns<'_>) -> PyResult<(Vec<f64>, Vec<f64>, bool)> {
    if c.has("east_m") || c.has("north_m") || !(c.has("lat_deg") || c.has("lon_deg")) {
        Ok((c.col("east_m")?, c.col("north_m")?, false))
    } else {
        Ok((c.col("lat_deg")?, c.col("lon_deg")?, true))
    }
}

fn scalar(c: Option<Columns<'_>>, column: &str) -> PyResult<Vec<Scalar>> {
    let Some(c) = c else { return Ok(Vec::new()) };
    let (t, v) = (c.col("t_s")?, c.col(column)?);
    Ok(t.into_iter()
        .zip(v)
        .map(|(t_s, value)| Scalar { t_s, value })
        .collect())
}

#[pymethods]
impl Drive {
    /// Reads a drive directory, comma2k19 segment, ROS bag, MCAP file or
    /// tricycle log (`mapping`: a topic-mapping TOML file for ROS recordings).
    #[staticmethod]
    #[pyo3(signature = (path, mapping=None))]
    fn read(py: Python<'_>, path: PathBuf, mapping: Option<PathBuf>) -> PyResult<Drive> {
        read_drive(py, path, mapping)
    }

    /// Builds a drive from columns: `streams` maps a drive-format file stem
    /// (`wheel_ticks`, `wheel_speeds`, `yaw_rate`, `speed`, `steering`,
    /// `gnss`, `truth`) to a dict of column name → float64 array (NaN: an
    /// absent optional value). The result passes `Drive::validate`; the CSV
    /// readers' unit range checks are not applied.
    #[staticmethod]
    #[pyo3(signature = (streams, vehicle_json=None, vehicle_path=None))]
    fn _from_columns(
        streams: Bound<'_, PyDict>,
        vehicle_json: Option<&str>,
        vehicle_path: Option<PathBuf>,
    ) -> PyResult<Drive> {
        let mut vehicle = vehicle_arg(vehicle_json, vehicle_path)?;
        let get = |name: &'static str| -> PyResult<Option<Columns<'_>>> {
            match streams.get_item(name)? {
                Some(d) if !d.is_none() => Ok(Some(Columns::new(name, d.cast_into()?)?)),
                _ => Ok(None),
            }
        };
        for k in streams.keys() {
            let k: String = k.extract()?;
            if ![
                "wheel_ticks",
                "wheel_speeds",
                "yaw_rate",
                "speed",
                "steering",
                "gnss",
                "truth",
            ]
            .contains(&k.as_str())
            {
                return Err(DeadreckonError::new_err(format!("unknown stream `{k}`")));
            }
        }
        let wheels = match (get("wheel_ticks")?, get("wheel_speeds")?) {
            (Some(c), None) => {
                let t = c.col("t_s")?;
                let (fl, fr, rl, rr) = (
                    c.int_col("fl")?,
                    c.int_col("fr")?,
                    c.int_col("rl")?,
                    c.int_col("rr")?,
                );
                Wheels::Ticks(
                    (0..c.len)
                        .map(|i| WheelTicks {
                            t_s: t[i],
                            fl: fl[i],
                            fr: fr[i],
                            rl: rl[i],
                            rr: rr[i],
                        })
                        .collect(),
                )
            }
            (None, Some(c)) => {
                let t = c.col("t_s")?;
                let (fl, fr) = (c.col("fl_mps")?, c.col("fr_mps")?);
                let (rl, rr) = (c.col("rl_mps")?, c.col("rr_mps")?);
                Wheels::Speeds(
                    (0..c.len)
                        .map(|i| WheelSpeeds {
                            t_s: t[i],
                            fl_mps: fl[i],
                            fr_mps: fr[i],
                            rl_mps: rl[i],
                            rr_mps: rr[i],
                        })
                        .collect(),
                )
            }
            (Some(_), Some(_)) => {
                return Err(DeadreckonError::new_err(
                    "both wheel_ticks and wheel_speeds given: a drive has one wheel stream",
                ))
            }
            (None, None) => {
                return Err(DeadreckonError::new_err(
                    "a drive needs wheel_ticks or wheel_speeds",
                ))
            }
        };
        let (mut gnss, gnss_geo) = match get("gnss")? {
            Some(c) => {
                let t = c.col("t_s")?;
                let (a, b, geo) = positions(&c)?;
                let std = c.col("std_m")?;
                let course = c.opt_col("course_deg")?;
                let speed = c.opt_col("speed_mps")?;
                let fixes = (0..c.len)
                    .map(|i| GnssFix {
                        t_s: t[i],
                        east_m: a[i],
                        north_m: b[i],
                        std_m: std[i],
                        course_deg: course.as_ref().and_then(|v| v[i]),
                        speed_mps: speed.as_ref().and_then(|v| v[i]),
                    })
                    .collect::<Vec<_>>();
                (fixes, geo)
            }
            None => (Vec::new(), false),
        };
        let (mut truth, truth_geo) = match get("truth")? {
            Some(c) => {
                let t = c.col("t_s")?;
                let (a, b, geo) = positions(&c)?;
                let yaw = c.col("yaw_rad")?;
                let speed = c.opt_col("speed_mps")?;
                let poses = (0..c.len)
                    .map(|i| TruthPose {
                        t_s: t[i],
                        east_m: a[i],
                        north_m: b[i],
                        yaw_rad: yaw[i],
                        speed_mps: speed.as_ref().and_then(|v| v[i]),
                    })
                    .collect::<Vec<_>>();
                (poses, geo)
            }
            None => (Vec::new(), false),
        };
        // Latitude/longitude about [origin], else the first fix (as the reader does).
        let gnss_geo = gnss_geo && !gnss.is_empty();
        let truth_geo = truth_geo && !truth.is_empty();
        if gnss_geo || truth_geo {
            let origin = match vehicle.origin {
                Some(o) => o,
                None => {
                    if gnss_geo != truth_geo && !gnss.is_empty() && !truth.is_empty() {
                        return Err(DeadreckonError::new_err(
                            "latitude/longitude in one of gnss and truth, east/north in the other: the vehicle needs an origin (lat_deg, lon_deg) to relate them",
                        ));
                    }
                    let (lat_deg, lon_deg) = if gnss_geo {
                        (gnss[0].east_m, gnss[0].north_m)
                    } else {
                        (truth[0].east_m, truth[0].north_m)
                    };
                    Origin {
                        lat_deg,
                        lon_deg,
                        height_m: 0.0,
                    }
                }
            };
            if gnss_geo {
                for g in &mut gnss {
                    (g.east_m, g.north_m) =
                        deadreckon_core::geo::geodetic_to_en(&origin, g.east_m, g.north_m);
                }
            }
            if truth_geo {
                for t in &mut truth {
                    (t.east_m, t.north_m) =
                        deadreckon_core::geo::geodetic_to_en(&origin, t.east_m, t.north_m);
                }
            }
            vehicle.origin = Some(origin);
        }
        let drive = deadreckon_core::Drive {
            vehicle,
            wheels,
            yaw_rate: scalar(get("yaw_rate")?, "yaw_rate_rps")?,
            speed: scalar(get("speed")?, "speed_mps")?,
            steering: scalar(get("steering")?, "steering_wheel_rad")?,
            gnss,
            truth,
            imu: Default::default(),
        };
        drive.validate().map_err(|e| {
            DeadreckonError::new_err(format!("invalid drive: {}", deadreckon_api::chain_text(&e)))
        })?;
        Ok(Drive {
            inner: Arc::new(drive),
        })
    }

    /// The streams as dicts of numpy columns, keyed like `_from_columns`
    /// (only the streams the drive has; empty optional values are NaN).
    fn _columns<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = &self.inner;
        let out = PyDict::new(py);
        let opt = |x: Option<f64>| x.unwrap_or(f64::NAN);
        match &d.wheels {
            Wheels::Ticks(w) => {
                let mut c = ColumnsOut::new(py);
                c.add("t_s", w, |r| r.t_s)?
                    .add("fl", w, |r| r.fl as f64)?
                    .add("fr", w, |r| r.fr as f64)?
                    .add("rl", w, |r| r.rl as f64)?
                    .add("rr", w, |r| r.rr as f64)?;
                out.set_item("wheel_ticks", c.finish())?;
            }
            Wheels::Speeds(w) => {
                let mut c = ColumnsOut::new(py);
                c.add("t_s", w, |r| r.t_s)?
                    .add("fl_mps", w, |r| r.fl_mps)?
                    .add("fr_mps", w, |r| r.fr_mps)?
                    .add("rl_mps", w, |r| r.rl_mps)?
                    .add("rr_mps", w, |r| r.rr_mps)?;
                out.set_item("wheel_speeds", c.finish())?;
            }
        }
        for (name, col, v) in [
            ("yaw_rate", "yaw_rate_rps", &d.yaw_rate),
            ("speed", "speed_mps", &d.speed),
            ("steering", "steering_wheel_rad", &d.steering),
        ] {
            if !v.is_empty() {
                let mut c = ColumnsOut::new(py);
                c.add("t_s", v, |r| r.t_s)?.add(col, v, |r| r.value)?;
                out.set_item(name, c.finish())?;
            }
        }
        if !d.gnss.is_empty() {
            let g = &d.gnss;
            let mut c = ColumnsOut::new(py);
            c.add("t_s", g, |r| r.t_s)?
                .add("east_m", g, |r| r.east_m)?
                .add("north_m", g, |r| r.north_m)?
                .add("std_m", g, |r| r.std_m)?
                .add("course_deg", g, |r| opt(r.course_deg))?
                .add("speed_mps", g, |r| opt(r.speed_mps))?;
            out.set_item("gnss", c.finish())?;
        }
        if !d.truth.is_empty() {
            let t = &d.truth;
            let mut c = ColumnsOut::new(py);
            c.add("t_s", t, |r| r.t_s)?
                .add("east_m", t, |r| r.east_m)?
                .add("north_m", t, |r| r.north_m)?
                .add("yaw_rad", t, |r| r.yaw_rad)?
                .add("speed_mps", t, |r| opt(r.speed_mps))?;
            out.set_item("truth", c.finish())?;
        }
        Ok(out)
    }

    /// The vehicle (vehicle.toml's keys) as JSON text.
    fn _vehicle_json(&self) -> PyResult<String> {
        serde_json::to_string(&self.inner.vehicle).map_err(to_py_err)
    }

    /// Number of wheel rows.
    fn __len__(&self) -> usize {
        self.inner.wheels.len()
    }

    fn __repr__(&self) -> String {
        let d = &self.inner;
        let kind = match d.wheels {
            Wheels::Ticks(_) => "wheel ticks",
            Wheels::Speeds(_) => "wheel speeds",
        };
        let n = d.wheels.len();
        if n == 0 {
            return format!("<deadreckon.Drive: no {kind}>");
        }
        format!(
            "<deadreckon.Drive: {} rows of {kind} from {:.3} s to {:.3} s, {} gyro, {} speed, {} steering, {} GNSS, {} truth>",
            n,
            d.wheels.t_s(0),
            d.wheels.t_s(n - 1),
            d.yaw_rate.len(),
            d.speed.len(),
            d.steering.len(),
            d.gnss.len(),
            d.truth.len()
        )
    }
}
