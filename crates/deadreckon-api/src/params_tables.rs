//! Every key of params.toml beside the six parameters and `[std]`, as one
//! serde type ([`ParamsTables`]): what `calibrate --out` (and `stream
//! --learn`, and `demo`) write and what every `--params` reads back, through
//! the same structs. Each table is a struct that refuses keys it does not
//! know (a misspelt key is an error, not silently ignored); every table and
//! key is optional, so files written before a table existed still read.
//!
//! The file's layout (the keys sorted within each table, as before the
//! tables were typed):
//!
//! ```toml
//! gyro_bias_rps = …              # the six parameters (deadreckon-io)
//! converged = true               # method, passes, convergence
//! iterations = 2
//! method = "rts"                 # rts, zupt, truth (calibrate), online (stream --learn)
//! [bound]                        # the 95 % error bound's factor (crate::bound)
//! [delays.gnss]                  # each stream's delay: delay_s applied, std_s or not_estimated
//! [gyro_scale]                   # scale_error, std, turns, or not_estimated
//! [held_back]                    # --corrections auto's judgement (shown, not read back)
//! [held_back.delay_gnss]         #   one table per candidate
//! [imu]                          # tilt_deg, std_deg, up, or not_estimated
//! [model]                        # the model additions applied (core's ModelOptions)
//! [not_estimated]                # parameter = why
//! [side_slip]                    # the rear axle's slip gradient (shown)
//! [steering]                     # ratio, offset, understeer (shown)
//! [traction]                     # slip_per_mps2, std, axle, mean_force_mps2, or not_estimated
//! [vehicle]                      # the vehicle calibrated for (crate::binding)
//! [std]                          # the six standard errors (deadreckon-io)
//! ```

use std::collections::BTreeMap;

use deadreckon_core::bound::{BoundFit, Method as BoundMethod};
use deadreckon_core::kinematics::steering::SteeringCalibration;
use deadreckon_core::kinematics::ParamEstimate;
use deadreckon_core::model_options::ModelOptions;
use deadreckon_core::side_slip::SideSlip;
use deadreckon_core::timing::{Corrections, Stream};
use serde::{Deserialize, Serialize};

use crate::binding::VehicleRecord;

/// Every key and table of params.toml beside the six parameters and
/// `[std]` (those are [`deadreckon_core::ParamsWithStd`], laid out by
/// `deadreckon-io`). `None` (or empty): not in the file.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParamsTables {
    /// How the parameters were found: `rts`, `zupt`, `truth` (calibrate)
    /// or `online` (`stream --learn`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub method: Option<String>,
    /// Smoothing passes run.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub iterations: Option<usize>,
    /// Whether the passes converged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub converged: Option<bool>,
    /// `stream --learn`: whether the learned parameters are valid yet.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub valid: Option<bool>,
    /// `stream --learn`: how much of the learning is done, %.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub calibrated_pct: Option<f64>,
    /// The parameters no sample informed, each with why (`[not_estimated]`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub not_estimated: BTreeMap<String, String>,
    /// The steering's calibration (`[steering]`, shown: what the commands
    /// apply is `[model]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering: Option<SteeringTable>,
    /// The rear axle's side-slip gradient (`[side_slip]`, shown).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side_slip: Option<SideSlipTable>,
    /// Each stream's delay (`[delays.<stream>]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub delays: Option<DelaysTable>,
    /// The driven axle's slip (`[traction]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub traction: Option<TractionTable>,
    /// The IMU's tilt (`[imu]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub imu: Option<ImuTable>,
    /// The gyro's scale error (`[gyro_scale]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro_scale: Option<GyroScaleTable>,
    /// `--corrections auto`'s judgement (`[held_back]`; shown, not read
    /// back: what is applied is the values of the other tables).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub held_back: Option<HeldBackTable>,
    /// The model additions applied to the vehicle (`[model]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model: Option<ModelOptions>,
    /// The vehicle the parameters were calibrated for (`[vehicle]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub vehicle: Option<VehicleRecord>,
    /// The 95 % error bound's factor (`[bound]`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound: Option<BoundTable>,
}

/// One estimate of the steering or side-slip tables: its value, whether the
/// drive determined it, its standard error (when estimated) and why not.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimateTable {
    /// The value: fitted, or the nominal value when not estimated.
    pub value: f64,
    /// Whether the drive determined it (only then is it taken).
    pub estimated: bool,
    /// Standard error, when estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Why not, when not estimated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

impl EstimateTable {
    /// The table of `p`.
    pub fn of(p: &ParamEstimate) -> Self {
        EstimateTable {
            value: p.value,
            estimated: p.estimated,
            std: p.std,
            reason: p.reason.clone(),
        }
    }

    /// The value when marked estimated (an error naming `key` when it is
    /// not finite).
    pub fn estimated_value(&self, key: &str) -> Result<Option<f64>, String> {
        if !self.estimated {
            return Ok(None);
        }
        if !self.value.is_finite() {
            return Err(format!("`{key}.value` = {} is not finite", self.value));
        }
        Ok(Some(self.value))
    }
}

/// `[steering]`: the ratio, offset and understeer gradient, and the samples
/// they were fitted on.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteeringTable {
    /// `steering_ratio`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering_ratio: Option<EstimateTable>,
    /// `steering_offset_rad`, rad.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering_offset_rad: Option<EstimateTable>,
    /// `understeer_gradient_rad_per_mps2`, rad per m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub understeer_gradient_rad_per_mps2: Option<EstimateTable>,
    /// Samples fitted on.
    #[serde(default)]
    pub samples: usize,
}

impl SteeringTable {
    /// The table of `st`.
    pub fn of(st: &SteeringCalibration) -> Self {
        SteeringTable {
            steering_ratio: Some(EstimateTable::of(&st.ratio)),
            steering_offset_rad: Some(EstimateTable::of(&st.offset)),
            understeer_gradient_rad_per_mps2: st.understeer.as_ref().map(EstimateTable::of),
            samples: st.samples,
        }
    }
}

/// `[side_slip]`: the rear axle's slip gradient and the blocks used.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SideSlipTable {
    /// `rear_slip_gradient_rad_per_mps2`, rad per m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rear_slip_gradient_rad_per_mps2: Option<EstimateTable>,
    /// Blocks fitted on.
    #[serde(default)]
    pub blocks: usize,
}

impl SideSlipTable {
    /// The table of `s`.
    pub fn of(s: &SideSlip) -> Self {
        SideSlipTable {
            rear_slip_gradient_rad_per_mps2: Some(EstimateTable::of(&s.gradient)),
            blocks: s.blocks,
        }
    }
}

/// `[delays]`: one table per stream ([`Stream::name`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DelaysTable {
    /// The gyro's delay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gyro: Option<DelayTable>,
    /// The speed's delay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<DelayTable>,
    /// The steering's delay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub steering: Option<DelayTable>,
    /// The GNSS receiver's delay.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gnss: Option<DelayTable>,
}

impl DelaysTable {
    /// The stream's table.
    pub fn get(&self, s: Stream) -> Option<&DelayTable> {
        match s {
            Stream::Gyro => self.gyro.as_ref(),
            Stream::Speed => self.speed.as_ref(),
            Stream::Steering => self.steering.as_ref(),
            Stream::Gnss => self.gnss.as_ref(),
        }
    }

    /// The stream's table, to set.
    pub fn get_mut(&mut self, s: Stream) -> &mut Option<DelayTable> {
        match s {
            Stream::Gyro => &mut self.gyro,
            Stream::Speed => &mut self.speed,
            Stream::Steering => &mut self.steering,
            Stream::Gnss => &mut self.gnss,
        }
    }
}

/// `[delays.<stream>]`: the delay applied, s, with its standard error when
/// estimated or why it was not.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DelayTable {
    /// The delay applied, s (0: none).
    pub delay_s: f64,
    /// Its standard error, s (when estimated).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_s: Option<f64>,
    /// Why it was not estimated or not applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_estimated: Option<String>,
}

/// `[traction]`: the driven axle's slip per m/s² of forward specific force.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TractionTable {
    /// The slip per m/s² (the sign names the axle).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slip_per_mps2: Option<f64>,
    /// Its standard error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// The driven axle, `front` or `rear`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub axle: Option<String>,
    /// The calibration drive's mean forward specific force, m/s².
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mean_force_mps2: Option<f64>,
    /// Why it was not estimated or not applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_estimated: Option<String>,
}

/// `[imu]`: the IMU's tilt and the vertical in its axes.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ImuTable {
    /// The tilt, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tilt_deg: Option<f64>,
    /// Its standard error, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std_deg: Option<f64>,
    /// The vertical in the IMU's axes (a unit vector): what is applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub up: Option<Vec<f64>>,
    /// Why it was not estimated or not applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_estimated: Option<String>,
}

/// `[gyro_scale]`: the gyro's relative scale error.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GyroScaleTable {
    /// The relative scale error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub scale_error: Option<f64>,
    /// Its standard error.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub std: Option<f64>,
    /// Turns it was fitted on.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub turns: Option<usize>,
    /// Why it was not estimated or not applied.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_estimated: Option<String>,
}

/// `[held_back]`: `--corrections auto`'s windows, the error without
/// corrections, and one table per candidate (its key:
/// [`deadreckon_core::held_back::Candidate::key`]).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct HeldBackTable {
    /// Held-back windows.
    pub windows: usize,
    /// Their length, s.
    pub window_s: f64,
    /// The held-back error without corrections, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub without_m: Option<f64>,
    /// Why nothing was judged.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub not_judged: Option<String>,
    /// Each candidate's judgement, by its key.
    #[serde(flatten)]
    pub candidates: BTreeMap<String, JudgedTable>,
}

/// One candidate's judgement in `[held_back]` (the numbers that are not
/// finite left out).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JudgedTable {
    /// Its estimate's distance from none, in standard errors.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<f64>,
    /// The held-back error with it, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub with_m: Option<f64>,
    /// The held-back error it was compared against, m.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub against_m: Option<f64>,
    /// The paired t statistic.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub t: Option<f64>,
    /// The receiver's wander: the paired t statistic of the hidden fixes'
    /// log-likelihood (`held_back::Judged::score_t`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub score_t: Option<f64>,
    /// Whether it was applied.
    pub applied: bool,
    /// Applied by significance alone (written only when true).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub by_significance: bool,
}

/// `[bound]`: the 95 % error bound's factor ([`BoundFit`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BoundTable {
    /// `conformal` or `filter`.
    pub method: BoundMethod,
    /// The factor on the filter's covariance.
    pub k: f64,
    /// Windows it was fitted on.
    pub windows: usize,
    /// Their length, s.
    pub outage_s: f64,
    /// The step between them, s.
    pub step_s: f64,
}

impl BoundTable {
    /// The table of `fit`.
    pub fn of(fit: &BoundFit) -> Self {
        BoundTable {
            method: fit.method,
            k: fit.k,
            windows: fit.windows,
            outage_s: fit.outage_s,
            step_s: fit.step_s,
        }
    }

    /// The bound, checked: `k` finite and non-negative.
    pub fn fit(&self) -> Result<BoundFit, String> {
        if !(self.k.is_finite() && self.k >= 0.0) {
            return Err(format!(
                "`bound.k` = {} must be finite and non-negative",
                self.k
            ));
        }
        Ok(BoundFit {
            method: self.method,
            k: self.k,
            windows: self.windows,
            outage_s: self.outage_s,
            step_s: self.step_s,
        })
    }
}

/// A finite number, else nothing (params.toml leaves out what was not
/// computed).
fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The tables of the corrections `c` (`[delays]`, `[traction]`, `[imu]`,
/// `[gyro_scale]`, `[held_back]`, `[model]`): each estimated value with its
/// standard error, or why it was not estimated or applied.
pub fn corrections_tables(c: &Corrections, t: &mut ParamsTables) {
    let mut delays = DelaysTable::default();
    for s in Stream::ALL {
        let d = c.delays.get(s);
        *delays.get_mut(s) = Some(DelayTable {
            delay_s: d.applied_s(),
            std_s: d.status.is_estimated().then_some(d.std_s),
            not_estimated: if d.status.is_estimated() {
                None
            } else {
                d.status.reason().map(str::to_string)
            },
        });
    }
    t.delays = Some(delays);
    t.traction = c.traction.as_ref().map(|tr| {
        if tr.is_estimated() {
            TractionTable {
                slip_per_mps2: Some(tr.slip_per_mps2),
                std: Some(tr.std),
                axle: Some(tr.axle.name().to_string()),
                mean_force_mps2: finite(tr.mean_force_mps2),
                not_estimated: None,
            }
        } else {
            TractionTable {
                not_estimated: tr.status.reason().map(str::to_string),
                ..Default::default()
            }
        }
    });
    t.imu = c.tilt.as_ref().map(|tilt| {
        if tilt.is_estimated() {
            ImuTable {
                tilt_deg: Some(tilt.tilt_rad.to_degrees()),
                std_deg: Some(tilt.std_rad.to_degrees()),
                up: Some(tilt.up.to_vec()),
                not_estimated: None,
            }
        } else {
            ImuTable {
                not_estimated: tilt.status.reason().map(str::to_string),
                ..Default::default()
            }
        }
    });
    t.gyro_scale = c.gyro_scale.as_ref().map(|g| {
        if g.is_estimated() {
            GyroScaleTable {
                scale_error: Some(g.scale_error),
                std: Some(g.std),
                turns: Some(g.turns),
                not_estimated: None,
            }
        } else {
            GyroScaleTable {
                not_estimated: g.status.reason().map(str::to_string),
                ..Default::default()
            }
        }
    });
    t.held_back = c.held_back.as_ref().map(|h| HeldBackTable {
        windows: h.windows,
        window_s: h.window_s,
        without_m: finite(h.without_m),
        not_judged: h.not_judged.clone(),
        candidates: h
            .judged
            .iter()
            .map(|j| {
                (
                    j.correction.key(),
                    JudgedTable {
                        z: finite(j.z),
                        with_m: finite(j.with_m),
                        against_m: finite(j.against_m),
                        t: finite(j.t),
                        score_t: finite(j.score_t),
                        applied: j.applied,
                        by_significance: j.by_significance,
                    },
                )
            })
            .collect(),
    });
    t.model = (!c.model.is_empty()).then_some(c.model);
}
