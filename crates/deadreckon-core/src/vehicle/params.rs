//! The six calibrated parameters of eq. (9) ([`Params`]) and their
//! standard errors ([`ParamsWithStd`], the `params.toml` contract).

use serde::{Deserialize, Serialize};

use super::Vehicle;
use crate::{Error, Rule};

/// The six calibrated parameters p of eq. (9), stored as circumferences (the
/// estimator works on inverse circumferences internally).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Params {
    /// b_gyro: gyro bias, rad/s (gyro = true yaw rate + bias).
    pub gyro_bias_rps: f64,
    /// a_v: CAN speed scale factor (CAN speed = a_v · true speed).
    pub speed_scale: f64,
    /// ρ_FL: front-left wheel circumference, m.
    pub circumference_fl_m: f64,
    /// ρ_FR: front-right wheel circumference, m.
    pub circumference_fr_m: f64,
    /// ρ_RL: rear-left wheel circumference, m.
    pub circumference_rl_m: f64,
    /// ρ_RR: rear-right wheel circumference, m.
    pub circumference_rr_m: f64,
}

impl Params {
    /// The nominal parameters of a vehicle: no gyro bias, unit scale, nominal circumferences.
    pub fn nominal(vehicle: &Vehicle) -> Self {
        let c = vehicle.wheel_circumference_m;
        Params {
            gyro_bias_rps: 0.0,
            speed_scale: 1.0,
            circumference_fl_m: c,
            circumference_fr_m: c,
            circumference_rl_m: c,
            circumference_rr_m: c,
        }
    }

    /// The four circumferences in the order FL, FR, RL, RR.
    pub fn circumferences(&self) -> [f64; 4] {
        [
            self.circumference_fl_m,
            self.circumference_fr_m,
            self.circumference_rl_m,
            self.circumference_rr_m,
        ]
    }

    /// Sets the four circumferences from the order FL, FR, RL, RR.
    pub fn set_circumferences(&mut self, c: [f64; 4]) {
        self.circumference_fl_m = c[0];
        self.circumference_fr_m = c[1];
        self.circumference_rl_m = c[2];
        self.circumference_rr_m = c[3];
    }

    /// The parameters as an array: bias, scale, FL, FR, RL, RR.
    pub fn to_array(&self) -> [f64; 6] {
        let c = self.circumferences();
        [self.gyro_bias_rps, self.speed_scale, c[0], c[1], c[2], c[3]]
    }

    /// The inverse of [`Params::to_array`].
    pub fn from_array(a: [f64; 6]) -> Self {
        Params {
            gyro_bias_rps: a[0],
            speed_scale: a[1],
            circumference_fl_m: a[2],
            circumference_fr_m: a[3],
            circumference_rl_m: a[4],
            circumference_rr_m: a[5],
        }
    }

    /// Names of the parameters in [`Params::to_array`] order (the `params.toml` keys).
    pub const NAMES: [&'static str; 6] = [
        "gyro_bias_rps",
        "speed_scale",
        "circumference_fl_m",
        "circumference_fr_m",
        "circumference_rl_m",
        "circumference_rr_m",
    ];

    /// Checks the parameters are usable: finite, positive scale and circumferences.
    pub fn validate(&self) -> Result<(), Error> {
        let a = self.to_array();
        for (i, v) in a.iter().enumerate() {
            if !v.is_finite() || (i > 0 && *v <= 0.0) {
                let rule = if i == 0 { Rule::Finite } else { Rule::Positive };
                return Err(Error::param(Params::NAMES[i], *v, rule));
            }
        }
        Ok(())
    }
}

/// Calibrated parameters with their standard errors (the `params.toml` contract).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ParamsWithStd {
    /// The estimates.
    #[serde(flatten)]
    pub params: Params,
    /// One standard error for each estimate (same keys).
    pub std: Params,
}
