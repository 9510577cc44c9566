//! The result of a car calibration ([`CarCalibration`], made by
//! [`crate::calibration::calibrate`]) and what the commands show of it: the
//! `--json` object (its `Serialize`), the params.toml tables
//! ([`crate::params_tables`]), the text table,
//! the stack parameter files.

use deadreckon_core::calibrate::{Calibration, Method};
use deadreckon_core::kinematics::steering::SteeringCalibration;
use deadreckon_core::timing::{Corrections, Which};
use serde_json::Value;

use crate::calibration::{CalibrationRequest, ParamStatus};
use crate::params_file::ParamsFile;
use crate::params_tables::{BoundTable, ParamsTables, SideSlipTable, SteeringTable};
use crate::Error;

/// A car calibration with everything the commands show of it: the one
/// type behind `calibrate --json`, Python's dict, params.toml, the text
/// table and `batch`'s CSV row.
#[derive(Debug, Clone)]
pub struct CarCalibration {
    /// What was asked: the method, its options and the corrections.
    pub request: CalibrationRequest,
    /// The calibration: parameters, standard errors, samples, passes, the
    /// filter's counts and the wheels' health, the manoeuvres and what the
    /// drive lacked.
    pub calibration: Calibration,
    /// The corrections estimated (and applied as `request.corrections`
    /// asked), with the held-back judgement.
    pub corrections: Corrections,
    /// The steering ratio and offset (against the truth with the truth
    /// method; with the understeer gradient against the smoothed states with
    /// the RTS method).
    pub steering: Option<SteeringCalibration>,
    /// The streams the drive had none of (named when a parameter is not
    /// estimated).
    pub absent: crate::json::Absent,
    /// The vehicle calibrated for, recorded in params.toml
    /// ([`crate::binding`]).
    pub vehicle: crate::binding::VehicleRecord,
    /// The 95 % error bound's factor, fitted on the drive's own hidden
    /// fixes with the calibrated parameters (`[bound]` in params.toml).
    pub bound: deadreckon_core::bound::BoundFit,
    /// When that bound reaches 1 m in the fit's windows.
    pub bound_reach_1m: Option<deadreckon_core::bound::Reach>,
}

impl serde::Serialize for CarCalibration {
    /// The `calibrate --json` object ([`CarCalibration::json`]).
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json().serialize(s)
    }
}

impl CarCalibration {
    /// The method's word (`rts`, `zupt`, `truth`).
    pub fn method_name(&self) -> &'static str {
        self.request.method_name()
    }

    /// Whether each of the six parameters was estimated
    /// ([`ParamStatus::of_samples`], the one rule).
    pub fn status(&self) -> [ParamStatus; 6] {
        self.calibration.samples.map(ParamStatus::of_samples)
    }

    /// The corrections asked for.
    pub fn which(&self) -> Which {
        self.request.corrections
    }
}

impl CarCalibration {
    /// The parameters no sample above the speed threshold informed, with why
    /// (they keep their nominal value and are reported as not estimated).
    pub fn not_estimated(&self) -> Vec<(&'static str, String)> {
        crate::json::not_estimated(
            &self.calibration,
            self.request.options.min_speed_mps,
            self.absent,
        )
    }

    /// The `--json` object of `calibrate` (without `"checks"`).
    pub fn json(&self) -> Value {
        let mut v = crate::json::calibrate_json(
            self.method_name(),
            &self.calibration,
            self.request.options.min_speed_mps,
            self.absent,
            self.steering.as_ref(),
        );
        v["corrections"] = crate::corrections::corrections_json(&self.corrections);
        v["bound"] = crate::bound::bound_json(&self.bound);
        v
    }

    /// The tables params.toml holds beside the parameters: method, passes,
    /// convergence, the parameters not estimated, the steering and side
    /// slip, the corrections (when any were asked for), the vehicle and the
    /// error bound.
    pub fn params_tables(&self) -> ParamsTables {
        let c = &self.calibration;
        let mut t = ParamsTables {
            method: Some(self.method_name().to_string()),
            iterations: Some(c.iterations),
            converged: Some(c.converged),
            not_estimated: self
                .not_estimated()
                .into_iter()
                .map(|(k, why)| (k.to_string(), why))
                .collect(),
            steering: self.steering.as_ref().map(SteeringTable::of),
            side_slip: c.side_slip.as_ref().map(SideSlipTable::of),
            vehicle: Some(self.vehicle.clone()),
            bound: Some(BoundTable::of(&self.bound)),
            ..Default::default()
        };
        if self.which() != Which::None {
            crate::params_tables::corrections_tables(&self.corrections, &mut t);
        }
        t
    }

    /// The params.toml of this calibration (`name` names it in errors):
    /// the parameters with their standard errors and
    /// [`CarCalibration::params_tables`], checked as a file read back is.
    pub fn params_file(&self, name: &str) -> Result<ParamsFile, Error> {
        ParamsFile::new(self.calibration.estimate, self.params_tables(), name)
    }

    /// [`CarCalibration::params_tables`] as the TOML table written beside
    /// the parameters.
    pub fn params_extra(&self) -> toml::Table {
        toml::Table::try_from(self.params_tables()).unwrap_or_default()
    }

    /// The provenance line of the stack parameter files.
    pub fn provenance(&self, source: &str) -> String {
        let c = &self.calibration;
        format!(
            "Calibrated on {source} with --method {} ({} passes, {}).",
            self.method_name(),
            c.iterations,
            if c.converged {
                "converged"
            } else {
                "NOT converged"
            }
        )
    }

    /// The text of `calibrate`: the parameters, what was not estimated, the
    /// steering, the passes (RTS, with the `state` and `iteration` words),
    /// the filter's counts, the corrections, wheel health and what the drive
    /// lacked.
    pub fn lines(&self, state: &str, iteration: &str) -> Vec<String> {
        let c = &self.calibration;
        let mut out = vec![
            crate::text::params_header(),
            crate::text::params_row(self.method_name(), &c.estimate),
        ];
        for (k, why) in self.not_estimated() {
            out.push(format!("{k}: NOT ESTIMATED ({why})"));
        }
        let slip = self.calibration.side_slip.as_ref().map(|s| &s.gradient);
        let steering = self.steering.iter().flat_map(|st| {
            [&st.ratio, &st.offset]
                .into_iter()
                .chain(st.understeer.as_ref())
        });
        for p in steering.chain(slip) {
            out.push(match (&p.reason, p.std) {
                (None, Some(s)) => format!("{}: {:.5} ± {s:.5}", p.name, p.value),
                (Some(r), _) => format!("{}: NOT ESTIMATED ({r}), {} kept", p.name, p.value),
                (None, None) => format!("{}: {:.5}", p.name, p.value),
            });
        }
        if self.request.options.method == Method::Rts {
            out.push(format!(
                "{} smoothing passes ({state} state, {iteration} iteration), {}",
                c.iterations,
                if c.converged {
                    "converged"
                } else {
                    "NOT converged: raise --max-iterations"
                }
            ));
        }
        if let Some(st) = &c.filter_stats {
            out.push(crate::text::stats_line(st));
        }
        if self.request.options.method == Method::Rts {
            out.push(crate::text::chords_line(c.gnss_chords.as_ref()));
        }
        if self.which() != Which::None {
            out.extend(crate::text::corrections_lines(&self.corrections));
        }
        if let Some(h) = &c.wheel_health {
            out.extend(crate::text::wheel_health_lines(h));
        }
        out.extend(crate::bound::calibrate_lines(
            &self.bound,
            self.bound_reach_1m.as_ref(),
        ));
        if let Some(mv) = &c.manoeuvres {
            out.push(format!(
                "drive: {:.0} s, {:.0} s above {} m/s ({:.0} s left turns, {:.0} s right turns, {:.0} s straight), {} stops ({:.0} s)",
                mv.duration_s,
                mv.above_threshold_s,
                self.request.options.min_speed_mps,
                mv.left_turn_s,
                mv.right_turn_s,
                mv.straight_s,
                mv.stops,
                mv.stopped_s
            ));
            let lacks = mv.lacking();
            if !lacks.is_empty() {
                out.push("the drive lacked (drive more before trusting these):".into());
            }
            for l in lacks {
                out.push(format!(
                    "  {}: weakens {} ({})",
                    l.what,
                    l.weakens.join(", "),
                    l.why
                ));
            }
        }
        out
    }
}

/// The file formats a car calibration is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Export {
    /// deadreckon's params.toml (a file).
    Params,
    /// Autoware's imu_corrector and vehicle_velocity_converter parameter
    /// files (into a directory).
    Autoware,
    /// Eagleye's configuration keys and saved velocity scale factor (into a
    /// directory).
    Eagleye,
}

impl CarCalibration {
    /// Writes the calibration of the drive `source` (its path, for the
    /// provenance; `noise`: its vehicle's noise) to `out` in `format`;
    /// returns the files written.
    pub fn write(
        &self,
        out: &std::path::Path,
        format: Export,
        noise: &deadreckon_core::vehicle::Noise,
        source: &str,
    ) -> Result<Vec<std::path::PathBuf>, Error> {
        use crate::error::While;
        use deadreckon_io::stack_params;
        let export = || stack_params::StackExport {
            estimate: &self.calibration.estimate,
            samples: self.calibration.samples,
            noise,
            provenance: self.provenance(source),
        };
        let context = || format!("writing {}", out.display());
        match format {
            Export::Params => {
                self.params_file(&out.display().to_string())?.write(out)?;
                Ok(vec![out.to_path_buf()])
            }
            Export::Autoware => stack_params::write_autoware(out, &export()).doing(context),
            Export::Eagleye => stack_params::write_eagleye(out, &export()).doing(context),
        }
    }
}
