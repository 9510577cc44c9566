//! A car's params.toml read once and validated once: the six parameters
//! and `[std]` (`deadreckon-io`, whose errors name the file, line and
//! column), the vehicle it was calibrated for (`[vehicle]`), the
//! corrections it stores (`[delays]`, `[imu]`, `[traction]`,
//! `[gyro_scale]`) and the error bound's factor (`[bound]`), each checked
//! by its one reader. Every `--params` (and Python's `params=` path) goes
//! through [`ParamsFile::read`]; the file is written by
//! [`crate::calibrate::CarCalibration::write`], and what it writes reads
//! back here.
//!
//! Files written before a table existed still read: no `[vehicle]` (no
//! record: the binding says so), no corrections (nothing applied), no
//! `[bound]` (the filter's covariance alone).

use std::path::Path;

use deadreckon_core::bound::BoundFit;
use deadreckon_core::ParamsWithStd;

use crate::binding::VehicleRecord;
use crate::corrections::Stored;
use crate::error::While;
use crate::Error;

/// A params.toml, read and checked.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamsFile {
    /// The six parameters and their standard errors.
    pub estimate: ParamsWithStd,
    /// The vehicle the parameters were calibrated for (`None`: a file
    /// written before the record existed).
    pub vehicle: Option<VehicleRecord>,
    /// The corrections the file stores, applied with its parameters.
    pub corrections: Stored,
    /// The 95 % error bound's factor.
    pub bound: BoundFit,
    /// Every other key and table (method, passes, steering, side slip,
    /// the held-back judgement, what was not estimated): shown, not read
    /// back.
    pub rest: toml::Table,
}

impl ParamsFile {
    /// Reads and checks the params.toml `spec` (a path; `nominal` is the
    /// caller's). Errors name the file and, through their sources, the
    /// line and column.
    pub fn read(spec: &str) -> Result<ParamsFile, Error> {
        let (estimate, extra) = deadreckon_io::read_params_with_extra(Path::new(spec))
            .doing(|| format!("reading parameters {spec}"))?;
        ParamsFile::from_parts(spec, estimate, extra)
    }

    /// [`ParamsFile::read`] on the text of a params.toml (embedders hand it
    /// over as text); `name` names it in errors.
    pub fn parse(text: &str, name: &str) -> Result<ParamsFile, Error> {
        let (estimate, extra) = deadreckon_io::parse_params_with_extra(text, Path::new(name))
            .doing(|| format!("reading parameters {name}"))?;
        ParamsFile::from_parts(name, estimate, extra)
    }

    /// The tables beside the parameters checked, each by its one reader.
    fn from_parts(
        spec: &str,
        estimate: ParamsWithStd,
        mut extra: toml::Table,
    ) -> Result<ParamsFile, Error> {
        let vehicle = VehicleRecord::from_extra(spec, &extra)?;
        let corrections = crate::corrections::stored_corrections(&extra)
            .map_err(|e| Error::Invalid(format!("parameters {spec}: {e}")))?;
        let bound = crate::bound::bound_from_extra(&extra)
            .map_err(|e| Error::Invalid(format!("{spec}: {e}")))?;
        extra.remove("vehicle");
        extra.remove("bound");
        Ok(ParamsFile {
            estimate,
            vehicle,
            corrections,
            bound,
            rest: extra,
        })
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
        assert_eq!(f.rest["method"].as_str(), Some("rts"));
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
}
