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
//!
//! Longitudinal effects (each off unless its key is set) change what a
//! wheel's rotation measures: the driven axle's **longitudinal slip**
//! F_x/C_x under the traction force F_x = m·a_x + m·g·sin θ + rolling
//! resistance + drag (braking shared by the axles by their static loads);
//! the **rolling circumference**, growing as 1 + k_v·v² and shrinking with
//! the wheel's load (the same load transfer as above); the **grade** and
//! **bumps**, sinusoidal elevations along the path whose slope lengthens the
//! distance rolled by √(1 + z′²) and whose pitch θ tips gravity into the
//! accelerometer's x axis. The truth stays the horizontal path of M.
//! `side_slip = false` keeps only these.

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
    /// Whether the tyres slip sideways (default true); false keeps the body
    /// along the path and only the longitudinal effects below.
    #[serde(default = "yes", skip_serializing_if = "is_true")]
    pub side_slip: bool,
    /// The driven axle (default front).
    #[serde(default, skip_serializing_if = "is_front")]
    pub driven_axle: DrivenAxle,
    /// Longitudinal slip stiffness of an axle (both tyres), N per unit
    /// slip (default 0: no longitudinal slip). The driven axle's wheels turn
    /// 1 + F_x/this times the ground distance under a traction force F_x
    /// (m·a_x + m·g·sin θ + rolling resistance + drag); braking is shared
    /// by the axles in proportion to their static loads.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub longitudinal_stiffness_n: f64,
    /// Rolling-resistance coefficient, unitless (default 0.012; with
    /// longitudinal slip only).
    #[serde(
        default = "default_rolling",
        skip_serializing_if = "is_default_rolling"
    )]
    pub rolling_resistance: f64,
    /// Aerodynamic drag: force over speed squared, N per (m/s)² (default 0.4:
    /// ½·ρ·c_d·A for 0.3 × 2.2 m²; with longitudinal slip only).
    #[serde(default = "default_drag", skip_serializing_if = "is_default_drag")]
    pub drag_n_per_mps2: f64,
    /// Growth of the rolling circumference with speed: the circumference is
    /// 1 + this·v² times the static one, per (m/s)² (default 0; 2e-6 gives
    /// +0.18 % at 30 m/s).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub radius_growth_per_mps2: f64,
    /// Change of a wheel's rolling circumference with its load: 1 − this·(F_z
    /// / F_z0 − 1) times the static one (default 0; 0.01–0.02 from a tyre's
    /// deflection).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub radius_load_sensitivity: f64,
    /// Road elevation: a sinusoid of this amplitude along the path, m
    /// (default 0: flat). The wheels roll the distance along the slope; an
    /// accelerometer reads the pitch.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub grade_amplitude_m: f64,
    /// Wavelength of the elevation sinusoid, m (default 500).
    #[serde(
        default = "default_grade_wavelength",
        skip_serializing_if = "is_default_grade_wavelength"
    )]
    pub grade_wavelength_m: f64,
    /// Bumps: a short sinusoid in the elevation, amplitude m (default 0),
    /// which adds wheel distance but no mean slope.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub bump_amplitude_m: f64,
    /// Wavelength of the bumps, m (default 3).
    #[serde(
        default = "default_bump_wavelength",
        skip_serializing_if = "is_default_bump_wavelength"
    )]
    pub bump_wavelength_m: f64,
}

/// The driven axle.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DrivenAxle {
    /// Front-wheel drive.
    #[default]
    Front,
    /// Rear-wheel drive.
    Rear,
}

fn yes() -> bool {
    true
}
fn is_true(b: &bool) -> bool {
    *b
}
fn is_front(a: &DrivenAxle) -> bool {
    *a == DrivenAxle::Front
}
fn is_zero(x: &f64) -> bool {
    *x == 0.0
}
fn default_rolling() -> f64 {
    0.012
}
fn is_default_rolling(x: &f64) -> bool {
    *x == default_rolling()
}
fn default_drag() -> f64 {
    0.4
}
fn is_default_drag(x: &f64) -> bool {
    *x == default_drag()
}
fn default_grade_wavelength() -> f64 {
    500.0
}
fn is_default_grade_wavelength(x: &f64) -> bool {
    *x == default_grade_wavelength()
}
fn default_bump_wavelength() -> f64 {
    3.0
}
fn is_default_bump_wavelength(x: &f64) -> bool {
    *x == default_bump_wavelength()
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
            side_slip: true,
            driven_axle: DrivenAxle::Front,
            longitudinal_stiffness_n: 0.0,
            rolling_resistance: default_rolling(),
            drag_n_per_mps2: default_drag(),
            radius_growth_per_mps2: 0.0,
            radius_load_sensitivity: 0.0,
            grade_amplitude_m: 0.0,
            grade_wavelength_m: default_grade_wavelength(),
            bump_amplitude_m: 0.0,
            bump_wavelength_m: default_bump_wavelength(),
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
        for (k, v) in [
            ("longitudinal_stiffness_n", self.longitudinal_stiffness_n),
            ("rolling_resistance", self.rolling_resistance),
            ("drag_n_per_mps2", self.drag_n_per_mps2),
            ("radius_growth_per_mps2", self.radius_growth_per_mps2),
            ("radius_load_sensitivity", self.radius_load_sensitivity),
            ("grade_amplitude_m", self.grade_amplitude_m),
            ("bump_amplitude_m", self.bump_amplitude_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((key(k), format!("{v} must be a non-negative number")));
            }
        }
        for (k, v) in [
            ("grade_wavelength_m", self.grade_wavelength_m),
            ("bump_wavelength_m", self.bump_wavelength_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err((key(k), format!("{v} must be positive")));
            }
        }
        for (k, a, l) in [
            (
                "grade_amplitude_m",
                self.grade_amplitude_m,
                self.grade_wavelength_m,
            ),
            (
                "bump_amplitude_m",
                self.bump_amplitude_m,
                self.bump_wavelength_m,
            ),
        ] {
            if std::f64::consts::TAU * a / l > 0.3 {
                return Err((
                    key(k),
                    format!("{a} m over a wavelength of {l} m is a slope steeper than 30 %"),
                ));
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
    side_slip: bool,
    rear_driven: bool,
    c_long: f64,
    rolling: f64,
    drag: f64,
    growth: f64,
    load_radius: f64,
    /// Elevation sinusoids: (amplitude m, wavenumber rad/m), grade and bumps.
    waves: [(f64, f64); 2],
}

/// What the longitudinal effects make of one instant.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rolling {
    /// Per wheel FL, FR, RL, RR: distance counted in units of the static
    /// circumference per metre of ground along the wheel's axis in the plane.
    pub factors: [f64; 4],
    /// Road pitch, rad (nose up positive).
    pub pitch_rad: f64,
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
            side_slip: spec.side_slip,
            rear_driven: spec.driven_axle == DrivenAxle::Rear,
            c_long: spec.longitudinal_stiffness_n,
            rolling: spec.rolling_resistance,
            drag: spec.drag_n_per_mps2,
            growth: spec.radius_growth_per_mps2,
            load_radius: spec.radius_load_sensitivity,
            waves: [
                (
                    spec.grade_amplitude_m,
                    std::f64::consts::TAU / spec.grade_wavelength_m,
                ),
                (
                    spec.bump_amplitude_m,
                    std::f64::consts::TAU / spec.bump_wavelength_m,
                ),
            ],
        }
    }

    /// Whether anything longitudinal is on (else every factor is 1).
    pub(crate) fn rolls(&self) -> bool {
        self.c_long > 0.0
            || self.growth > 0.0
            || self.load_radius > 0.0
            || self.waves.iter().any(|w| w.0 > 0.0)
    }

    /// dz/ds of the road at path distance `s`, and of its grade part alone.
    fn slopes(&self, s: f64) -> (f64, f64) {
        let d = |(a, k): (f64, f64)| a * k * (k * s).cos();
        let grade = d(self.waves[0]);
        (grade + d(self.waves[1]), grade)
    }

    /// The longitudinal effects at path distance `s`, speed `v`, and
    /// accelerations `a_x`, `a_y`.
    pub(crate) fn rolling(&self, s: f64, v: f64, a_x: f64, a_y: f64) -> Rolling {
        let (dz, grade) = self.slopes(s);
        let pitch_rad = grade.atan();
        // Distance along the road per metre in the plane (bumps included).
        let along = dz.hypot(1.0);
        let w = self.mass * G_MPS2;
        let (fz0_f, fz0_r) = (w * self.front_share, w * (1.0 - self.front_share));
        let shift = self.mass * a_x * self.h_over_l;
        let (fz_f, fz_r) = (fz0_f - shift, fz0_r + shift);
        let roll = self.mass * a_y * self.h;
        // a_y > 0 (left turn): load moves to the right wheels.
        let d_f = self.roll_front * roll / self.track_front;
        let d_r = (1.0 - self.roll_front) * roll / self.track_rear;
        let loads = [
            0.5 * fz_f - d_f,
            0.5 * fz_f + d_f,
            0.5 * fz_r - d_r,
            0.5 * fz_r + d_r,
        ];
        let static_loads = [0.5 * fz0_f, 0.5 * fz0_f, 0.5 * fz0_r, 0.5 * fz0_r];
        // Longitudinal slip per axle (front, rear).
        let mut slip = [0.0, 0.0];
        if self.c_long > 0.0 && v != 0.0 {
            let resist = v.signum() * (self.rolling * w + self.drag * v * v);
            let f_x = self.mass * (a_x + G_MPS2 * pitch_rad.sin()) + resist;
            // Slip as a wheel's extra turning relative to the ground, signed
            // by the force along the direction of travel.
            let f = f_x * v.signum();
            if f > 0.0 {
                slip[usize::from(self.rear_driven)] = f / self.c_long;
            } else {
                slip = [
                    f * self.front_share / self.c_long,
                    f * (1.0 - self.front_share) / self.c_long,
                ];
            }
        }
        let growth = 1.0 + self.growth * v * v;
        let factors = [0, 1, 2, 3].map(|i| {
            let load = 1.0 - self.load_radius * (loads[i] / static_loads[i] - 1.0);
            along * (1.0 + slip[i / 2]) / (growth * load)
        });
        Rolling { factors, pitch_rad }
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
        if !self.side_slip || a_y == 0.0 || v == 0.0 {
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
