//! Scenarios: the vehicle, the route, the speed policy, the sensors and the true
//! errors of one simulation, read from TOML. The built-in scenarios are TOML
//! files shipped with the crate (`crates/deadreckon-sim/scenarios/`), so they
//! double as examples of the format:
//!
//! ```toml
//! name = "my-car"
//! vehicle = "paper-car"          # a preset, or a [vehicle] table (vehicle.toml keys)
//! laps = 2
//! # duration_s = 600             # cut (or extend at standstill) the drive
//!
//! [errors]                       # the true parameters (default: nominal)
//! gyro_bias_rps = -0.003
//! speed_scale = 0.99
//! circumference_fl_m = 1.913
//! circumference_fr_m = 1.913
//! circumference_rl_m = 1.916
//! circumference_rr_m = 1.916
//!
//! [route]
//! closed = true
//! segments = [
//!   { kind = "straight", length_m = 300 },
//!   { kind = "stop", duration_s = 5 },
//!   { kind = "turn", angle_deg = 90, radius_m = 12 },
//!   { kind = "roundabout", circle_deg = 300, radius_m = 15 },
//! ]
//!
//! [speed]                        # every key optional
//! default_limit_kmh = 50
//!
//! [sensors.wheels]
//! kind = "ticks"
//! rate_hz = 50
//! offset_s = 0.004
//!
//! [sensors.gnss]
//! rate_hz = 2
//! std_m = 0.5
//! ```

use std::path::Path;

use deadreckon_core::{Params, Vehicle};
use serde::de::{self, Deserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize};

use crate::dynamics::DynamicsSpec;
use crate::profile::SpeedSpec;
use crate::route::RouteSpec;
use crate::sensors::{GnssSpec, SensorsSpec};
use crate::SimError;

/// A simulation scenario.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
#[non_exhaustive]
pub struct Scenario {
    /// Name, used in messages.
    pub name: String,
    /// What the scenario is for.
    #[serde(default)]
    pub description: String,
    /// The vehicle: a preset name (see [`Scenario::vehicle_presets`]) or a table
    /// with the `vehicle.toml` keys. Its nominal values go into the drive.
    #[serde(deserialize_with = "vehicle_or_preset")]
    pub vehicle: Vehicle,
    /// The true parameters (default: the vehicle's nominal ones, no errors).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub errors: Option<Params>,
    /// How many times the route is driven (default 1).
    #[serde(default = "one")]
    pub laps: u32,
    /// Length of the recording, s: cuts the drive, or keeps the vehicle at
    /// standstill after the route ends (default: end of the route).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duration_s: Option<f64>,
    /// Rate of the truth integration, Hz (default 1000).
    #[serde(default = "default_integration_rate")]
    pub integration_rate_hz: f64,
    /// The route.
    pub route: RouteSpec,
    /// The speed policy.
    #[serde(default)]
    pub speed: SpeedSpec,
    /// The sensors.
    pub sensors: SensorsSpec,
    /// Vehicle dynamics: tyre side slip and understeer (default none: the
    /// exact kinematic bicycle model). See [`crate::dynamics`].
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<DynamicsSpec>,
}

/// Longest drive simulated, s (about 11.6 days).
pub const MAX_DURATION_S: f64 = 1e6;
/// Most laps.
pub const MAX_LAPS: u32 = 10_000;

fn one() -> u32 {
    1
}
fn default_integration_rate() -> f64 {
    1000.0
}

const BUILTINS: [(&str, &str); 4] = [
    ("calibration", include_str!("../scenarios/calibration.toml")),
    ("evaluation", include_str!("../scenarios/evaluation.toml")),
    ("tedris-car", include_str!("../scenarios/tedris-car.toml")),
    (
        "tedris-robot",
        include_str!("../scenarios/tedris-robot.toml"),
    ),
];

/// A vehicle preset by name.
fn preset(name: &str) -> Option<Vehicle> {
    match name {
        "paper-car" => Some(Vehicle::paper_car()),
        "campus-car" => Some(campus_car()),
        "turtlebot2" => Some(turtlebot2()),
        _ => None,
    }
}

/// The TedriS car: a compact front-wheel-drive car; rear track 1.57 m (the
/// paper's robot/car track ratio 0.25/1.57), other values typical.
fn campus_car() -> Vehicle {
    Vehicle {
        wheelbase_m: 2.6,
        track_front_m: 1.58,
        track_rear_m: 1.57,
        gnss_lever_arm_m: 1.0,
        ticks_per_rev: 48,
        wheel_circumference_m: 1.95,
        steering_ratio: 16.0,
        ..Vehicle::paper_car()
    }
}

/// A TurtleBot2-like differential-drive robot: track 0.25 m (the TedriS
/// paper), Kobuki wheels (circumference 0.2199 m, 2578 ticks per revolution).
/// A differential drive has no front axle: the wheelbase is a token 1 mm and
/// the "front" wheels roll like the rear ones.
fn turtlebot2() -> Vehicle {
    Vehicle {
        wheelbase_m: 0.001,
        track_front_m: 0.25,
        track_rear_m: 0.25,
        gnss_lever_arm_m: 0.0,
        ticks_per_rev: 2578,
        wheel_circumference_m: 0.2199,
        steering_ratio: 1.0,
        ..Vehicle::paper_car()
    }
}

fn vehicle_or_preset<'de, D: Deserializer<'de>>(d: D) -> Result<Vehicle, D::Error> {
    struct V;
    impl<'de> Visitor<'de> for V {
        type Value = Vehicle;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str(
                "a vehicle preset name (paper-car, campus-car, turtlebot2) or a vehicle table",
            )
        }
        fn visit_str<E: de::Error>(self, s: &str) -> Result<Vehicle, E> {
            preset(s).ok_or_else(|| {
                E::custom(format!(
                    "unknown vehicle preset `{s}` (known: paper-car, campus-car, turtlebot2)"
                ))
            })
        }
        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Vehicle, A::Error> {
            Vehicle::deserialize(de::value::MapAccessDeserializer::new(map))
        }
    }
    d.deserialize_any(V)
}

impl Scenario {
    /// The names of the built-in scenarios.
    pub fn names() -> Vec<&'static str> {
        BUILTINS.iter().map(|(n, _)| *n).collect()
    }

    /// The names of the vehicle presets usable as `vehicle = "NAME"`.
    pub fn vehicle_presets() -> Vec<&'static str> {
        vec!["paper-car", "campus-car", "turtlebot2"]
    }

    /// A vehicle preset by name.
    pub fn vehicle_preset(name: &str) -> Option<Vehicle> {
        preset(name)
    }

    /// A built-in scenario:
    ///
    /// - `calibration`: a 4 km urban loop driven twice, paper car, the paper's
    ///   true errors (table III, GT row) and noise (table II).
    /// - `evaluation`: a different 1.7 km loop driven three times, same car.
    /// - `tedris-car`: a campus loop with light and sharp curves and a
    ///   roundabout, rear wheel speeds at 25 Hz, GNSS with course at 4 Hz.
    /// - `tedris-robot`: a TurtleBot2 at 0.3 m/s on curves of decreasing
    ///   radius, gyro and encoders at 10 Hz.
    ///
    /// # Errors
    /// [`SimError::UnknownScenario`] for other names.
    pub fn builtin(name: &str) -> Result<Scenario, SimError> {
        let Some((_, text)) = BUILTINS.iter().find(|(n, _)| *n == name) else {
            return Err(SimError::UnknownScenario {
                name: name.into(),
                known: Scenario::names().join(", "),
            });
        };
        Scenario::parse(text, &format!("builtin {name}"))
    }

    /// Parses a scenario from TOML text.
    ///
    /// # Errors
    /// [`SimError::Parse`] with the line and column of the problem.
    pub fn from_toml_str(text: &str) -> Result<Scenario, SimError> {
        Scenario::parse(text, "string")
    }

    /// Reads a scenario file.
    ///
    /// # Errors
    /// [`SimError::Io`] or [`SimError::Parse`], naming the file.
    pub fn load(path: &Path) -> Result<Scenario, SimError> {
        let text = std::fs::read_to_string(path).map_err(|source| SimError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Scenario::parse(&text, &path.display().to_string())
    }

    fn parse(text: &str, origin: &str) -> Result<Scenario, SimError> {
        toml::from_str(text).map_err(|e| SimError::Parse {
            origin: origin.into(),
            message: e.to_string(),
        })
    }

    /// The scenario as TOML (for writing next to a simulated drive).
    ///
    /// # Errors
    /// [`SimError::Parse`] if a value cannot be represented in TOML.
    pub fn to_toml_string(&self) -> Result<String, SimError> {
        toml::to_string(self).map_err(|e| SimError::Parse {
            origin: self.name.clone(),
            message: e.to_string(),
        })
    }

    /// Replaces the true errors (gyro bias, speed scale, circumferences).
    pub fn with_errors(mut self, errors: Params) -> Self {
        self.errors = Some(errors);
        self
    }

    /// Replaces the vehicle (the true errors are kept; see [`Scenario::with_errors`]).
    pub fn with_vehicle(mut self, vehicle: Vehicle) -> Self {
        self.vehicle = vehicle;
        self
    }

    /// Sets the number of laps.
    pub fn with_laps(mut self, laps: u32) -> Self {
        self.laps = laps;
        self
    }

    /// Sets the recording length, s.
    pub fn with_duration_s(mut self, duration_s: f64) -> Self {
        self.duration_s = Some(duration_s);
        self
    }

    /// Sets the GNSS position noise, m (adds a 1 Hz receiver if there is none).
    pub fn with_gnss_std_m(mut self, std_m: f64) -> Self {
        match &mut self.sensors.gnss {
            Some(g) => g.std_m = std_m,
            None => self.sensors.gnss = Some(GnssSpec::white(1.0, std_m)),
        }
        self
    }

    /// Removes the GNSS receiver.
    pub fn without_gnss(mut self) -> Self {
        self.sensors.gnss = None;
        self
    }

    /// Replaces the speed policy.
    pub fn with_speed(mut self, speed: SpeedSpec) -> Self {
        self.speed = speed;
        self
    }

    /// Adds wheel faults (spin bursts, a smaller wheel from mid-drive).
    pub fn with_wheel_faults(mut self, faults: crate::faults::WheelFaultsSpec) -> Self {
        self.sensors.wheel_faults = Some(faults);
        self
    }

    /// Sets (or, with `None`, removes) the vehicle dynamics.
    pub fn with_dynamics(mut self, dynamics: Option<DynamicsSpec>) -> Self {
        self.dynamics = dynamics;
        self
    }

    /// Replaces the sensors.
    pub fn with_sensors(mut self, sensors: SensorsSpec) -> Self {
        self.sensors = sensors;
        self
    }

    /// How long `laps` laps of the route last as planned (the speed policy's
    /// profile), s: what the drive lasts without `duration_s`.
    ///
    /// # Errors
    /// [`SimError::Invalid`] naming the key when the route or the speed
    /// policy cannot be planned.
    pub fn planned_duration_s(&self, laps: u32) -> Result<f64, SimError> {
        let invalid = |key: &str, message: String| SimError::Invalid {
            scenario: self.name.clone(),
            key: key.into(),
            message,
        };
        let route = crate::route::Route::build(&self.route, laps)
            .map_err(|(key, message)| invalid(&key, message))?;
        let profile = crate::profile::SpeedProfile::plan(&route, &self.speed)
            .map_err(|message| invalid("speed", message))?;
        Ok(profile.duration_s())
    }

    /// The fewest laps (at least `laps`) whose planned drive lasts
    /// `duration_s`: a drive longer than the route repeats it rather than
    /// standing still after it.
    ///
    /// # Errors
    /// As [`Scenario::planned_duration_s`].
    pub fn laps_lasting(&self, duration_s: f64) -> Result<u32, SimError> {
        let one = self.planned_duration_s(1)?;
        if one <= 0.0 {
            return Ok(self.laps);
        }
        let mut laps = ((duration_s / one).ceil() as u32).clamp(self.laps.max(1), MAX_LAPS);
        // Consecutive laps join without their stops at the start and end: a
        // lap more may be needed.
        while laps < MAX_LAPS && self.planned_duration_s(laps)? < duration_s {
            laps += 1;
        }
        Ok(laps)
    }

    /// The true parameters: `errors`, or the vehicle's nominal values.
    pub fn true_params(&self) -> Params {
        self.errors
            .unwrap_or_else(|| Params::nominal(&self.vehicle))
    }

    /// Checks the scenario: vehicle, true parameters, laps, rates, offsets,
    /// noise and speed policy (the route is checked when it is built).
    ///
    /// # Errors
    /// [`SimError::Core`] for the vehicle and parameters, [`SimError::Invalid`]
    /// naming the key otherwise.
    pub fn validate(&self) -> Result<(), SimError> {
        let invalid = |key: &str, message: String| SimError::Invalid {
            scenario: self.name.clone(),
            key: key.into(),
            message,
        };
        self.vehicle.validate()?;
        self.true_params().validate()?;
        if !(1..=MAX_LAPS).contains(&self.laps) {
            return Err(invalid(
                "laps",
                format!("must be within 1..={MAX_LAPS}, got {}", self.laps),
            ));
        }
        if let Some(d) = self.duration_s {
            if !(d.is_finite() && d > 0.0 && d <= MAX_DURATION_S) {
                return Err(invalid(
                    "duration_s",
                    format!("must be a positive number of seconds, got {d}"),
                ));
            }
        }
        let rate = self.integration_rate_hz;
        if !(rate.is_finite() && (100.0..=1e5).contains(&rate)) {
            return Err(invalid(
                "integration_rate_hz",
                format!("must be within 100..=100000 Hz, got {rate}"),
            ));
        }
        for (key, r, offset) in self.sensors.clocks() {
            if !(r.is_finite() && r > 0.0 && r <= rate) {
                return Err(invalid(
                    &format!("{key}.rate_hz"),
                    format!(
                        "must be positive and at most the integration rate ({rate} Hz), got {r}"
                    ),
                ));
            }
            if !(offset.is_finite() && offset >= 0.0) {
                return Err(invalid(
                    &format!("{key}.offset_s"),
                    format!("must be a non-negative number, got {offset}"),
                ));
            }
        }
        for (key, r, clock) in self.sensors.ecu_clocks() {
            if let Some(c) = clock {
                c.check(key, r).map_err(|(k, m)| invalid(&k, m))?;
            }
        }
        let tooth = self.sensors.wheels.tooth_error_std;
        if !(tooth.is_finite() && (0.0..=0.1).contains(&tooth)) {
            return Err(invalid(
                "sensors.wheels.tooth_error_std",
                format!("must be within 0..=0.1 tooth pitches, got {tooth}"),
            ));
        }
        if let Some(g) = &self.sensors.gyro {
            let tau = g.bias_drift_tau_s;
            if !(tau.is_finite() && tau > 0.0) {
                return Err(invalid(
                    "sensors.gyro.bias_drift_tau_s",
                    format!("must be a positive number of seconds, got {tau}"),
                ));
            }
        }
        if let Some(m) = self
            .sensors
            .gnss
            .as_ref()
            .and_then(|g| g.multipath.as_ref())
        {
            m.check().map_err(|(k, m)| invalid(&k, m))?;
        }
        for (key, v) in self.sensors.noises() {
            if !(v.is_finite() && v >= 0.0) {
                return Err(invalid(
                    key,
                    format!("must be a non-negative number, got {v}"),
                ));
            }
        }
        if let Some(g) = &self.sensors.steering {
            if let Some(r) = g.true_ratio {
                if !(r.is_finite() && r > 0.0) {
                    return Err(invalid(
                        "sensors.steering.true_ratio",
                        format!("must be a positive number, got {r}"),
                    ));
                }
            }
            if !g.wheel_offset_rad.is_finite() {
                return Err(invalid(
                    "sensors.steering.wheel_offset_rad",
                    "must be finite".into(),
                ));
            }
        }
        if let Some(g) = &self.sensors.gnss {
            if g.std_m.is_nan() || g.std_m <= 0.0 {
                return Err(invalid(
                    "sensors.gnss.std_m",
                    "must be positive (it is written as the fix's std_m)".into(),
                ));
            }
        }
        if let Some(f) = &self.sensors.wheel_faults {
            f.check().map_err(|(k, m)| invalid(&k, m))?;
        }
        self.speed.check().map_err(|(k, m)| invalid(&k, m))?;
        if let Some(d) = &self.dynamics {
            d.check().map_err(|(k, m)| invalid(&k, m))?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn builtins_parse_and_validate() {
        for name in Scenario::names() {
            let s = Scenario::builtin(name).unwrap();
            s.validate().unwrap();
            let again = Scenario::from_toml_str(&s.to_toml_string().unwrap()).unwrap();
            assert_eq!(s, again, "{name} does not round-trip through TOML");
        }
        assert!(matches!(
            Scenario::builtin("nope"),
            Err(SimError::UnknownScenario { .. })
        ));
    }

    #[test]
    fn unknown_keys_and_presets_are_reported() {
        let base = Scenario::builtin("evaluation")
            .unwrap()
            .to_toml_string()
            .unwrap();
        let typo = base.replacen("laps =", "lapz =", 1);
        assert!(matches!(
            Scenario::from_toml_str(&typo),
            Err(SimError::Parse { .. })
        ));
        let seg = base.replacen(
            "kind = \"straight\"",
            "kind = \"straight\", lenght_m = 3",
            1,
        );
        assert!(Scenario::from_toml_str(&seg).is_err());
        let text = "name = \"x\"\nvehicle = \"tank\"\n[route]\nsegments = []\n[sensors.wheels]\nkind = \"ticks\"\nrate_hz = 50\n";
        let e = Scenario::from_toml_str(text).unwrap_err().to_string();
        assert!(e.contains("tank"), "{e}");
    }
}
