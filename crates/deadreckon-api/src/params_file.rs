//! A car's params.toml read once and validated once, and written by the
//! same type: the six parameters and `[std]` (`deadreckon-io`, whose errors
//! name the file, line and column) and every other table as one serde type
//! ([`ParamsTables`]: `[vehicle]`, the corrections `[delays]`, `[imu]`,
//! `[traction]`, `[gyro_scale]`, `[model]`, the error bound's `[bound]`, and
//! what is shown: method, passes, `[steering]`, `[side_slip]`,
//! `[held_back]`, `[not_estimated]`). Every `--params` (and Python's
//! `params=` path, and `stream`'s) goes through [`ParamsFile::read`]; the
//! file is written by [`ParamsFile::write`] (`calibrate --out` makes its
//! [`ParamsFile`] with [`crate::calibrate::CarCalibration::params_file`]),
//! and what it writes reads back equal.
//!
//! Files written before a table existed still read: no `[vehicle]` (no
//! record: the binding says so), no corrections (nothing applied), no
//! `[bound]` (the filter's covariance alone). A key no table knows is an
//! error naming it.

use std::path::Path;

use deadreckon_core::bound::BoundFit;
use deadreckon_core::ParamsWithStd;

use crate::binding::VehicleRecord;
use crate::corrections::Stored;
use crate::error::While;
pub use crate::params_tables::ParamsTables;
use crate::Error;

/// A params.toml, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamsFile {
    /// The six parameters and their standard errors.
    pub estimate: ParamsWithStd,
    /// Every other key and table, as written and read.
    pub tables: ParamsTables,
    /// The corrections the tables store, checked
    /// ([`crate::corrections::stored_of`]): applied with the parameters.
    pub corrections: Stored,
    /// The 95 % error bound's factor (`[bound]`, checked; the filter's
    /// covariance alone without one).
    pub bound: BoundFit,
}

/// A TOML error in a table of params.toml as one line: the message and,
/// when it has one, the key (`in `delays.gnss.delay_s``), under the table
/// `within` (empty: the top level).
pub(crate) fn toml_message(within: &str, e: &toml::de::Error) -> String {
    let text = e.to_string();
    let mut parts = text.trim_end().splitn(2, "\nin `");
    let message = parts.next().unwrap_or_default().trim_end().to_string();
    match parts.next() {
        Some(key) if within.is_empty() => format!("{message} (in `{key})"),
        Some(key) => format!("{message} (in `{within}.{key})"),
        None if within.is_empty() => message,
        None => format!("{message} (in `{within}`)"),
    }
}

/// Another shape's parameter file given for a car: the reader's error with
/// what to do (`--shape`, or calibrate the car), in the command's words.
#[derive(Debug, thiserror::Error)]
#[error("{source}: give it with --shape {}, or calibrate the car (deadreckon calibrate DRIVE --out FILE)", shape.replace('_', "-"))]
pub struct OtherShape {
    /// The file's `shape` key.
    pub shape: String,
    /// The reader's error.
    pub source: deadreckon_io::IoError,
}

/// The reader's error of `name`, with [`OtherShape`]'s hint for another
/// shape's file.
fn read_error(e: deadreckon_io::IoError, name: &str) -> Error {
    let what = format!("reading parameters {name}");
    match &e {
        deadreckon_io::IoError::OtherShape { shape, .. } => Error::While {
            what,
            source: Box::new(OtherShape {
                shape: shape.clone(),
                source: e,
            }),
        },
        _ => Error::While {
            what,
            source: Box::new(e),
        },
    }
}

impl ParamsFile {
    /// The file of `estimate` and `tables`, checked as a read file is:
    /// the vehicle's lengths, the stored corrections, the bound.
    pub fn new(estimate: ParamsWithStd, tables: ParamsTables, name: &str) -> Result<Self, Error> {
        if let Some(v) = &tables.vehicle {
            v.check(name)?;
        }
        let corrections = crate::corrections::stored_of(&tables)
            .map_err(|e| Error::Invalid(format!("parameters {name}: {e}")))?;
        let bound = match &tables.bound {
            Some(b) => b
                .fit()
                .map_err(|e| Error::Invalid(format!("{name}: {e}")))?,
            None => BoundFit::FILTER,
        };
        Ok(ParamsFile {
            estimate,
            tables,
            corrections,
            bound,
        })
    }

    /// Reads and checks the params.toml `spec` (a path; `nominal` is the
    /// caller's). Errors name the file and, through their sources, the
    /// line and column.
    pub fn read(spec: &str) -> Result<ParamsFile, Error> {
        let (estimate, extra) = deadreckon_io::read_params_with_extra(Path::new(spec))
            .map_err(|e| read_error(e, spec))?;
        ParamsFile::from_parts(spec, estimate, extra)
    }

    /// [`ParamsFile::read`] on the text of a params.toml (embedders hand it
    /// over as text); `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<ParamsFile, Error> {
        let (estimate, extra) = deadreckon_io::parse_params_with_extra(text, Path::new(name))
            .map_err(|e| read_error(e, name))?;
        ParamsFile::from_parts(name, estimate, extra)
    }

    /// The tables beside the parameters read as [`ParamsTables`] and
    /// checked.
    fn from_parts(
        spec: &str,
        estimate: ParamsWithStd,
        extra: toml::Table,
    ) -> Result<ParamsFile, Error> {
        let tables: ParamsTables = extra.try_into().map_err(|e: toml::de::Error| {
            Error::Invalid(format!("parameters {spec}: {}", toml_message("", &e)))
        })?;
        ParamsFile::new(estimate, tables, spec)
    }

    /// The vehicle the parameters were calibrated for (`None`: a file
    /// written before the record existed).
    pub fn vehicle(&self) -> Option<&VehicleRecord> {
        self.tables.vehicle.as_ref()
    }

    /// The tables as the TOML table written beside the parameters.
    pub fn tables_toml(&self) -> toml::Table {
        toml::Table::try_from(&self.tables).unwrap_or_default()
    }

    /// Writes the file to `path` atomically: the six parameters, the
    /// tables (their keys sorted), `[std]` (`deadreckon_io::write_params`).
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let extra =
            toml::Table::try_from(&self.tables).doing(|| format!("writing {}", path.display()))?;
        deadreckon_io::write_params(path, &self.estimate, Some(&extra))
            .doing(|| format!("writing {}", path.display()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_golden_params_toml_of_main_reads() {
        // tests/golden/params.toml is the contract of files written before:
        // no [vehicle], no corrections, no [bound].
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/golden/params.toml"
        );
        let f = ParamsFile::read(path).unwrap();
        let want = deadreckon_io::read_params(Path::new(path)).unwrap();
        assert_eq!(f.estimate, want);
        assert_eq!(f.bound, BoundFit::FILTER);
        assert!(f.corrections.is_empty());
        assert_eq!(f.tables.method.as_deref(), Some("rts"));
    }

    #[test]
    fn a_bad_stored_delay_names_the_file_and_the_key() {
        let text = "gyro_bias_rps = 0.0\nspeed_scale = 1.0\ncircumference_fl_m = 1.9\n\
                    circumference_fr_m = 1.9\ncircumference_rl_m = 1.9\ncircumference_rr_m = 1.9\n\
                    [delays.gnss]\ndelay_s = \"late\"\n";
        let e = ParamsFile::parse(text, "p.toml").unwrap_err().to_string();
        assert!(
            e.contains("p.toml") && e.contains("delays.gnss.delay_s"),
            "{e}"
        );
    }

    #[test]
    fn a_toml_error_names_the_line_and_column() {
        let e = ParamsFile::parse("gyro_bias_rps = \n", "p.toml").unwrap_err();
        let text = crate::chain_text(&e);
        assert!(text.contains("p.toml") && text.contains("line 1"), "{text}");
    }

    /// A file with every table params.toml has (delays, imu, traction,
    /// gyro_scale, model, held_back, side_slip, steering, bound, vehicle,
    /// not_estimated) and the top-level keys.
    fn every_table() -> ParamsFile {
        use crate::params_tables::*;
        use deadreckon_core::bound::Method;
        use deadreckon_core::model_options::ModelOptions;
        use deadreckon_core::{Params, Vehicle};
        let car = Vehicle::paper_car();
        let p = Params::nominal(&car);
        let estimate = ParamsWithStd {
            params: Params {
                gyro_bias_rps: -0.002985435049023309,
                speed_scale: 0.9870421412355947,
                ..p
            },
            std: Params::from_array([2.2e-5, 3.4e-4, 6.7e-4, 6.7e-4, 6.7e-4, 6.8e-4]),
        };
        let est = |value: f64, estimated: bool| EstimateTable {
            value,
            estimated,
            std: estimated.then_some(value.abs() * 0.01),
            reason: (!estimated).then(|| "the drive's turns do not determine it".into()),
        };
        let delay = |d: f64, std: Option<f64>| DelayTable {
            delay_s: d,
            std_s: std,
            not_estimated: std.is_none().then(|| "measured, not applied".into()),
        };
        let judged = |z: f64, applied: bool| JudgedTable {
            z: Some(z),
            with_m: Some(0.61),
            against_m: Some(0.65),
            t: Some(-2.03),
            score_t: None,
            applied,
            by_significance: !applied,
        };
        let tables = ParamsTables {
            method: Some("rts".into()),
            iterations: Some(2),
            converged: Some(true),
            valid: None,
            calibrated_pct: None,
            not_estimated: [(
                "circumference_fl_m".to_string(),
                "no wheel ticks".to_string(),
            )]
            .into_iter()
            .collect(),
            steering: Some(SteeringTable {
                steering_ratio: Some(est(15.97, true)),
                steering_offset_rad: Some(est(0.0005, true)),
                understeer_gradient_rad_per_mps2: Some(est(-0.0001, false)),
                samples: 43622,
            }),
            side_slip: Some(SideSlipTable {
                rear_slip_gradient_rad_per_mps2: Some(est(0.0049, true)),
                blocks: 52,
            }),
            delays: Some(DelaysTable {
                gyro: Some(delay(-0.014270758897754136, Some(0.0042))),
                speed: Some(delay(0.0, None)),
                steering: Some(delay(0.0, None)),
                gnss: Some(delay(-0.019550107882926094, Some(0.0058))),
            }),
            traction: Some(TractionTable {
                slip_per_mps2: Some(0.003249681965174863),
                std: Some(0.00024),
                axle: Some("front".into()),
                mean_force_mps2: Some(-0.5863462682035062),
                not_estimated: None,
            }),
            imu: Some(ImuTable {
                tilt_deg: Some(3.7538549307418845),
                std_deg: Some(0.772),
                up: Some(vec![
                    -0.06392911147965831,
                    0.01412177289838458,
                    0.9978545205768363,
                ]),
                not_estimated: None,
            }),
            gyro_scale: Some(GyroScaleTable {
                scale_error: Some(0.0021),
                std: Some(0.0004),
                turns: Some(12),
                not_estimated: None,
            }),
            held_back: Some(HeldBackTable {
                windows: 19,
                window_s: 20.0,
                without_m: Some(0.6481510145627312),
                not_judged: None,
                candidates: [
                    ("delay_gnss".to_string(), judged(-3.35, true)),
                    ("imu".to_string(), judged(1.2, false)),
                ]
                .into_iter()
                .collect(),
            }),
            model: Some(ModelOptions {
                rear_slip_gradient_rad_per_mps2: Some(0.0049),
                gyro_bias_walk_rps_per_sqrt_s: Some(3e-6),
                ..Default::default()
            }),
            vehicle: Some(VehicleRecord::of(&car)),
            bound: Some(BoundTable {
                method: Method::Conformal,
                k: 0.4088,
                windows: 55,
                outage_s: 30.0,
                step_s: 10.0,
            }),
        };
        ParamsFile::new(estimate, tables, "p.toml").unwrap()
    }

    #[test]
    fn a_file_with_every_table_reads_back_as_written() {
        let file = every_table();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("params.toml");
        file.write(&path).unwrap();
        let back = ParamsFile::read(&path.to_string_lossy()).unwrap();
        assert_eq!(back, file);
        // Every table is in the text, and what is applied is read from it.
        let text = std::fs::read_to_string(&path).unwrap();
        for table in [
            "[delays.gnss]",
            "[imu]",
            "[traction]",
            "[gyro_scale]",
            "[model]",
            "[held_back]",
            "[held_back.delay_gnss]",
            "[side_slip]",
            "[steering.steering_ratio]",
            "[bound]",
            "[vehicle]",
            "[not_estimated]",
            "[std]",
        ] {
            assert!(text.contains(table), "{table} missing:\n{text}");
        }
        let c = &back.corrections;
        assert_eq!(c.delays_s[3], -0.019550107882926094);
        assert_eq!(c.traction_slip_per_mps2, 0.003249681965174863);
        assert_eq!(c.gyro_scale_error, 0.0021);
        assert_eq!(c.up.unwrap()[2], 0.9978545205768363);
        assert_eq!(c.model.gyro_bias_walk_rps_per_sqrt_s, Some(3e-6));
        assert_eq!(back.bound.k, 0.4088);
        // The same through the text an embedder hands over.
        assert_eq!(ParamsFile::parse(&text, "p.toml").unwrap(), file);
    }

    #[test]
    fn a_misspelt_key_is_refused_with_its_name() {
        let text = "gyro_bias_rps = 0.0\nspeed_scale = 1.0\ncircumference_fl_m = 1.9\n\
                    circumference_fr_m = 1.9\ncircumference_rl_m = 1.9\ncircumference_rr_m = 1.9\n";
        for (extra, key) in [
            ("[delays.gnss]\ndelay_s = 0.01\nstd = 0.001\n", "std"),
            ("[gyro_scal]\nscale_error = 0.01\n", "gyro_scal"),
            ("[bound]\nmethod = \"conformal\"\nk = 1.0\nwindows = 3\noutage_s = 30.0\nstep_s = 10.0\nwindow = 2\n", "window"),
        ] {
            let e = ParamsFile::parse(&format!("{text}{extra}"), "p.toml")
                .unwrap_err()
                .to_string();
            assert!(e.contains("p.toml") && e.contains(&format!("`{key}`")), "{e}");
        }
    }
}
