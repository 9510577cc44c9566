//! `params.toml` of a kinematic shape (tricycle, differential drive): the
//! shape, how the calibration ran, then one `[[param]]` table per parameter in
//! the shape's order with its value, standard error, whether it was
//! estimated and, if not, why; and the correlation of the estimated ones.
//!
//! ```toml
//! shape = "tricycle"
//! method = "truth"
//! converged = true
//! windows_used = 54
//! min_speed_mps = 0.05
//!
//! [[param]]
//! name = "ktraction_m"
//! value = 0.01073
//! std = 0.00016
//! estimated = true
//!
//! [[param]]
//! name = "axle_length_m"
//! value = 1.4
//! estimated = false
//! reason = "no turns: …"
//! ```

use std::path::Path;

use deadreckon_core::kinematics::{KinematicCalibration, ParamEstimate, Shape};
use deadreckon_core::{Rule, Value};
use serde::{Deserialize, Serialize};

use crate::{atomic_write, IoError};

/// The contents of a kinematic `params.toml`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KinematicParamsFile {
    /// The vehicle shape the parameters belong to.
    pub shape: Shape,
    /// How they were obtained (`truth`, `nominal`, …).
    pub method: String,
    /// Whether the fit converged (false when nothing was estimated).
    pub converged: bool,
    /// Calibration windows used.
    pub windows_used: usize,
    /// Speed threshold applied, m/s.
    pub min_speed_mps: f64,
    /// The yaw rate a differential drive integrates (`gyro`, `odometry`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw_source: Option<String>,
    /// The parameters, in the shape's order.
    pub param: Vec<ParamEstimate>,
    /// Correlation of the estimated parameters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub correlation: Option<Correlation>,
    /// A differential drive's parameters chosen on held-back GNSS: each
    /// candidate's value, both held-back figures and the decision.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held_back: Option<deadreckon_core::kinematics::diff_drive::HeldBackParams>,
    /// The 95 % error bound's factor (`[bound]`: `method`, `k`, `windows`,
    /// `outage_s`, `step_s`; docs/bound.md), when one was fitted (a
    /// differential drive's calibration).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound: Option<toml::Table>,
}

/// A correlation matrix with the names of its rows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Correlation {
    /// Parameter names, the rows and columns.
    pub names: Vec<String>,
    /// The matrix, row by row.
    pub matrix: Vec<Vec<f64>>,
}

impl KinematicParamsFile {
    /// The file for a calibration of `shape` by `method`.
    pub fn from_calibration(shape: Shape, method: &str, c: &KinematicCalibration) -> Self {
        KinematicParamsFile {
            shape,
            method: method.into(),
            converged: c.converged,
            windows_used: c.windows_used,
            min_speed_mps: c.min_speed_mps,
            yaw_source: None,
            param: c.params.clone(),
            correlation: (!c.correlated.is_empty()).then(|| Correlation {
                names: c.correlated.clone(),
                matrix: c.correlation.clone(),
            }),
            held_back: c.held_back.clone(),
            bound: None,
        }
    }

    /// The values in file order.
    pub fn values(&self) -> Vec<f64> {
        self.param.iter().map(|p| p.value).collect()
    }

    /// Checks the parameters against a shape's names (same set, same order),
    /// finite values and finite non-negative standard errors.
    pub fn check(&self, path: &Path, shape: Shape, names: &[&str]) -> Result<(), IoError> {
        let bad = |source: deadreckon_core::Error| IoError::Invalid {
            path: path.to_path_buf(),
            source,
        };
        let said = |key: &'static str, m: String| {
            bad(deadreckon_core::Error::param(
                key,
                Value::Unstated,
                Rule::Said(m),
            ))
        };
        if self.shape != shape {
            return Err(said(
                "shape",
                format!(
                    "parameters of a {} used for a {}",
                    self.shape.name(),
                    shape.name()
                ),
            ));
        }
        let have: Vec<&str> = self.param.iter().map(|p| p.name.as_str()).collect();
        if have != names {
            return Err(said(
                "param",
                format!(
                    "a {} needs the parameters {names:?} in that order, the file has {have:?}",
                    shape.name()
                ),
            ));
        }
        for p in &self.param {
            if !p.value.is_finite() {
                return Err(bad(deadreckon_core::Error::param(
                    p.name.clone(),
                    p.value,
                    Rule::Finite,
                )));
            }
            if let Some(s) = p.std {
                if !(s.is_finite() && s >= 0.0) {
                    return Err(bad(deadreckon_core::Error::param(
                        format!("std of {}", p.name),
                        s,
                        Rule::NonNegative { zero_means: None },
                    )));
                }
            }
            if !p.estimated && p.reason.is_none() {
                return Err(said(
                    "reason",
                    format!("{} is not estimated but the file gives no reason", p.name),
                ));
            }
        }
        Ok(())
    }
}

/// Whether the TOML file at `path` is a kinematic parameter file (has a
/// top-level `shape` key). Unreadable or unparsable files are `false`: the
/// reader that is tried next reports the error.
pub fn is_kinematic_params(path: &Path) -> bool {
    std::fs::read_to_string(path)
        .ok()
        .and_then(|t| t.parse::<toml::Table>().ok())
        .is_some_and(|t| t.contains_key("shape"))
}

/// Reads a kinematic `params.toml` (unknown keys are errors).
pub fn read_kinematic_params(path: &Path) -> Result<KinematicParamsFile, IoError> {
    let text = std::fs::read_to_string(path).map_err(|e| IoError::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    toml::from_str(&text).map_err(|e| IoError::Toml {
        path: path.to_path_buf(),
        message: e.to_string().trim_end().to_string(),
    })
}

/// Writes a kinematic `params.toml` atomically.
pub fn write_kinematic_params(path: &Path, f: &KinematicParamsFile) -> Result<(), IoError> {
    let text = toml::to_string(f).map_err(|e| IoError::Toml {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    atomic_write(path, |w| w.write_all(text.as_bytes()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file() -> KinematicParamsFile {
        KinematicParamsFile {
            shape: Shape::Tricycle,
            method: "truth".into(),
            converged: false,
            windows_used: 0,
            min_speed_mps: 2.0,
            yaw_source: None,
            param: vec![
                ParamEstimate {
                    name: "a_m".into(),
                    value: 1.5,
                    std: Some(0.1),
                    estimated: true,
                    reason: None,
                },
                ParamEstimate {
                    name: "b".into(),
                    value: 0.1,
                    std: None,
                    estimated: false,
                    reason: Some("0 of 3 windows above the speed threshold".into()),
                },
            ],
            correlation: Some(Correlation {
                names: vec!["a_m".into()],
                matrix: vec![vec![1.0]],
            }),
            held_back: None,
            bound: None,
        }
    }

    #[test]
    fn round_trips_and_keeps_not_estimated_with_its_reason() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.toml");
        write_kinematic_params(&p, &file()).unwrap();
        assert!(is_kinematic_params(&p));
        let text = std::fs::read_to_string(&p).unwrap();
        assert!(
            text.contains("estimated = false") && text.contains("reason = "),
            "{text}"
        );
        let back = read_kinematic_params(&p).unwrap();
        assert_eq!(back, file());
        back.check(&p, Shape::Tricycle, &["a_m", "b"]).unwrap();
        assert!(back.check(&p, Shape::DiffDrive, &["a_m", "b"]).is_err());
        assert!(back.check(&p, Shape::Tricycle, &["b", "a_m"]).is_err());
    }

    #[test]
    fn unknown_keys_and_missing_reasons_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.toml");
        let mut f = file();
        write_kinematic_params(&p, &f).unwrap();
        let text = std::fs::read_to_string(&p).unwrap() + "\nbogus = 1\n";
        std::fs::write(&p, text).unwrap();
        assert!(matches!(
            read_kinematic_params(&p),
            Err(IoError::Toml { .. })
        ));
        f.param[1].reason = None;
        assert!(f.check(&p, Shape::Tricycle, &["a_m", "b"]).is_err());
    }
}
