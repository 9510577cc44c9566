//! Vehicle dynamics (`[dynamics]` of a scenario, off by default): tyre side
//! slip and understeer from a quasi-steady single-track ("bicycle") model
//! with load-sensitive cornering stiffness and load transfer.
//!
//! Without this table the truth is the exact kinematic bicycle model: the body
//! points along the path of the rear-axle centre M. With it, the route is
//! still the path of M, but the body is turned against it by the **rear side
//! slip** β_r, the angle the velocity of M makes with the body x axis:
//!
//! - course of M = ψ_body + β_r, so ψ_body = path course − β_r, and the yaw
//!   rate every stream sees (gyro, wheels, antenna) is d/dt ψ_body;
//! - β_r = −sign(v) · F_yr / C_r, the rear axle's lateral force over its
//!   cornering stiffness. In a left turn (lateral acceleration a_y = v·κ·v > 0)
//!   the rear slides outwards: β_r < 0. For small a_y, β_r = −g · a_y with g
//!   the **rear side-slip gradient** ([`DynamicsSpec::rear_slip_gradient_rad_per_mps2`]);
//! - the road-wheel angle needed is the direction of the front axle's velocity
//!   plus the front slip angle α_f = F_yf / C_f: δ ≈ L·κ + K_us · a_y, the
//!   understeer gradient K_us ([`DynamicsSpec::understeer_gradient_rad_per_mps2`]).
//!   The steering wheel reads r_s · δ (plus its noise and offset).
//!
//! Forces (quasi-steady: no yaw acceleration term): F_yr = m·(l_f/L)·a_y and
//! F_yf·cos δ = m·(l_r/L)·a_y, with l_f, l_r the distances of the centre of
//! gravity from the front and rear axles (l_r/L = the front axle's share of
//! the weight). Each tyre's cornering stiffness depends on its vertical load
//! F_z: C(F_z) = C₀ · x · (1 − ε·(x − 1)), x = F_z/F_z0 (F_z0 its static
//! load, ε the load sensitivity). The loads move with the longitudinal
//! acceleration (m·a_x·h/L from the front axle to the rear) and the lateral
//! one (m·a_y·h split between the axles by the roll-stiffness share, over
//! each track, from the inner wheels to the outer): an axle under lateral load
//! transfer loses stiffness as 1 − ε·d², so the slip grows faster than a_y
//! in hard corners.
//!
//! Every wheel rolls the component of its ground velocity along its own axis
//! (rigid body): the rear wheels v·cos β_r ∓ (l_R/2)·ψ̇, the front wheels their
//! speed times cos α_f.

use deadreckon_core::Vehicle;
use serde::{Deserialize, Serialize};

/// Standard gravity, m/s² (ISO 80000-3 / CGPM 1901 conventional value).
const G_MPS2: f64 = 9.806_65;

/// The vehicle dynamics of a scenario (`[dynamics]`). Every key is optional;
/// the defaults describe a 1.5 t front-heavy compact car with a rear
/// side-slip gradient of about 0.0048 rad per m/s² (1.0° at 0.38 g).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// Mass, kg (default 1500).
    #[serde(default = "default_mass")]
    pub mass_kg: f64,
    /// Share of the static weight on the front axle, 0–1 (default 0.58).
    #[serde(default = "default_front_share")]
    pub front_load_share: f64,
    /// Height of the centre of gravity above the ground, m (default 0.55).
    #[serde(default = "default_cg_height")]
    pub cg_height_m: f64,
    /// Cornering stiffness of the front axle (both tyres) at its static
    /// load, N/rad (default 110000).
    #[serde(default = "default_c_front")]
    pub cornering_stiffness_front_n_per_rad: f64,
    /// Cornering stiffness of the rear axle (both tyres) at its static load,
    /// N/rad (default 130000).
    #[serde(default = "default_c_rear")]
    pub cornering_stiffness_rear_n_per_rad: f64,
    /// Load sensitivity ε of the cornering stiffness, unitless (default
    /// 0.3): a tyre carrying x times its static load has
    /// x·(1 − ε·(x − 1)) times its static stiffness.
    #[serde(default = "default_load_sensitivity")]
    pub load_sensitivity: f64,
    /// Share of the lateral load transfer taken by the front axle, 0–1
    /// (default 0.6: its share of the roll stiffness).
    #[serde(default = "default_roll_front_share")]
    pub roll_stiffness_front_share: f64,
}

fn default_mass() -> f64 {
    1500.0
}
fn default_front_share() -> f64 {
    0.58
}
fn default_cg_height() -> f64 {
    0.55
}
fn default_c_front() -> f64 {
    110_000.0
}
fn default_c_rear() -> f64 {
    130_000.0
}
fn default_load_sensitivity() -> f64 {
    0.3
}
fn default_roll_front_share() -> f64 {
    0.6
}

impl Default for DynamicsSpec {
    fn default() -> Self {
        DynamicsSpec {
            mass_kg: default_mass(),
            front_load_share: default_front_share(),
            cg_height_m: default_cg_height(),
            cornering_stiffness_front_n_per_rad: default_c_front(),
            cornering_stiffness_rear_n_per_rad: default_c_rear(),
            load_sensitivity: default_load_sensitivity(),
            roll_stiffness_front_share: default_roll_front_share(),
        }
    }
}

impl DynamicsSpec {
    /// The rear side-slip gradient g at small lateral acceleration, rad per
    /// m/s²: β_r ≈ −g·a_y. It is m·(l_f/L)/C_r, the rear axle's share of the
    /// mass over its stiffness (load transfer only adds to it, in a_y³).
    /// The vehicle is where the model's geometry comes from; at small a_y
    /// only the weight split matters.
    pub fn rear_slip_gradient_rad_per_mps2(&self, vehicle: &Vehicle) -> f64 {
        let _ = vehicle;
        self.mass_kg * (1.0 - self.front_load_share) / self.cornering_stiffness_rear_n_per_rad
    }

    /// The understeer gradient K_us at small lateral acceleration, rad of
    /// road-wheel angle per m/s²: δ ≈ L·κ + K_us·a_y, K_us = m·(l_r/L)/C_f −
    /// m·(l_f/L)/C_r (positive: understeer).
    pub fn understeer_gradient_rad_per_mps2(&self, vehicle: &Vehicle) -> f64 {
        self.mass_kg * self.front_load_share / self.cornering_stiffness_front_n_per_rad
            - self.rear_slip_gradient_rad_per_mps2(vehicle)
    }

    /// The rear side slip β_r and front slip angle α_f, rad, at speed `v_mps`
    /// (signed), longitudinal acceleration `a_x_mps2` and lateral
    /// acceleration `a_y_mps2` (left positive), with load transfer.
    pub fn slip_rad(
        &self,
        vehicle: &Vehicle,
        v_mps: f64,
        a_x_mps2: f64,
        a_y_mps2: f64,
    ) -> (f64, f64) {
        Model::new(self, vehicle).slip(v_mps, a_x_mps2, a_y_mps2)
    }

    /// `(key, message)` of the first invalid value.
    pub(crate) fn check(&self) -> Result<(), (String, String)> {
        let key = |k: &str| format!("dynamics.{k}");
        for (k, v) in [
            ("mass_kg", self.mass_kg),
            ("cg_height_m", self.cg_height_m),
            (
                "cornering_stiffness_front_n_per_rad",
                self.cornering_stiffness_front_n_per_rad,
            ),
            (
                "cornering_stiffness_rear_n_per_rad",
                self.cornering_stiffness_rear_n_per_rad,
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err((key(k), format!("{v} must be positive")));
            }
        }
        for (k, v) in [
            ("front_load_share", self.front_load_share),
            (
                "roll_stiffness_front_share",
                self.roll_stiffness_front_share,
            ),
        ] {
            if !(v.is_finite() && v > 0.0 && v < 1.0) {
                return Err((key(k), format!("{v} must be strictly between 0 and 1")));
            }
        }
        if !(self.load_sensitivity.is_finite() && (0.0..=1.0).contains(&self.load_sensitivity)) {
            return Err((
                key("load_sensitivity"),
                format!("{} must be within 0..=1", self.load_sensitivity),
            ));
        }
        Ok(())
    }
}

/// The dynamics with the vehicle's geometry, ready to evaluate.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Model {
    mass: f64,
    /// Static share of the weight on the front axle (l_r / L).
    front_share: f64,
    h_over_l: f64,
    h: f64,
    roll_front: f64,
    track_front: f64,
    track_rear: f64,
    c_front: f64,
    c_rear: f64,
    eps: f64,
}

impl Model {
    pub(crate) fn new(spec: &DynamicsSpec, vehicle: &Vehicle) -> Self {
        Model {
            mass: spec.mass_kg,
            front_share: spec.front_load_share,
            h_over_l: spec.cg_height_m / vehicle.wheelbase_m,
            h: spec.cg_height_m,
            roll_front: spec.roll_stiffness_front_share,
            track_front: vehicle.track_front_m,
            track_rear: vehicle.track_rear_m,
            c_front: spec.cornering_stiffness_front_n_per_rad,
            c_rear: spec.cornering_stiffness_rear_n_per_rad,
            eps: spec.load_sensitivity,
        }
    }

    /// An axle's stiffness, N/rad: `c0` at static axle load `fz0` (both
    /// tyres alike), now carrying `fz` with `dfz` moved from the inner tyre
    /// to the outer one.
    fn axle_stiffness(&self, c0: f64, fz0: f64, fz: f64, dfz: f64) -> f64 {
        let tyre = |load: f64| {
            let x = (load / (0.5 * fz0)).max(0.0);
            0.5 * c0 * x * (1.0 - self.eps * (x - 1.0))
        };
        (tyre(0.5 * fz + dfz) + tyre(0.5 * fz - dfz)).max(1e-3 * c0)
    }

    /// The rear side slip β_r and the front slip angle α_f, rad.
    pub(crate) fn slip(&self, v: f64, a_x: f64, a_y: f64) -> (f64, f64) {
        if a_y == 0.0 || v == 0.0 {
            return (0.0, 0.0);
        }
        let w = self.mass * G_MPS2;
        let (fz0_f, fz0_r) = (w * self.front_share, w * (1.0 - self.front_share));
        let shift = self.mass * a_x * self.h_over_l;
        let (fz_f, fz_r) = (fz0_f - shift, fz0_r + shift);
        let roll = self.mass * a_y.abs() * self.h;
        let d_f = self.roll_front * roll / self.track_front;
        let d_r = (1.0 - self.roll_front) * roll / self.track_rear;
        let c_f = self.axle_stiffness(self.c_front, fz0_f, fz_f, d_f);
        let c_r = self.axle_stiffness(self.c_rear, fz0_r, fz_r, d_r);
        // Quasi-steady lateral forces: F_yr = m (l_f/L) a_y, F_yf = m (l_r/L) a_y.
        let f_r = self.mass * (1.0 - self.front_share) * a_y;
        let f_f = self.mass * self.front_share * a_y;
        (-v.signum() * f_r / c_r, f_f / c_f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slip_follows_the_gradient_at_small_lateral_acceleration() {
        let spec = DynamicsSpec::default();
        let car = Vehicle::paper_car();
        let g = spec.rear_slip_gradient_rad_per_mps2(&car);
        // 1500 · 0.42 / 130000.
        assert!((g - 0.004_846).abs() < 1e-6, "{g}");
        let (b, a) = spec.slip_rad(&car, 10.0, 0.0, 0.1);
        assert!((b + g * 0.1).abs() < 1e-3 * g * 0.1, "{b}");
        let k = spec.understeer_gradient_rad_per_mps2(&car);
        assert!(
            (a - b.abs() - k * 0.1).abs() < 1e-3 * k * 0.1,
            "{a} {b} {k}"
        );
        // Reversing turns the slip's sign round, a right turn too.
        assert_eq!(spec.slip_rad(&car, -2.0, 0.0, 0.1).0, -b);
        assert_eq!(spec.slip_rad(&car, 10.0, 0.0, -0.1).0, -b);
        // Load transfer makes the slip grow faster than a_y: at 0.38 g it is
        // above the linear value (about 1.0°).
        let ay = 0.38 * G_MPS2;
        let (b, _) = spec.slip_rad(&car, 15.0, 0.0, ay);
        assert!(-b > g * ay && -b < 1.1 * g * ay, "{} vs {}", -b, g * ay);
    }
}
