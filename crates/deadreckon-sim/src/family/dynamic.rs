//! The dynamic family: the family's cars with a real car's physics and
//! sensors, each effect drawn at random per car and switchable
//! ([`Effects`]), to measure what each costs an estimator by ablation.
//!
//! A [`DynamicCar`] is a [`CarFamily`] car (geometry, tyres, receiver) plus
//! every effect's magnitude, each drawn from its own seeded generator
//! ([`rng`] with its own purpose), so switching one effect off or on leaves
//! the others' draws, the route and every stream's noise unchanged:
//!
//! | effect ([`Effects`] field) | what is drawn per car |
//! |---|---|
//! | `side_slip` | a [`DynamicsSpec`]: mass 1200–2000 kg, front weight share 0.52–0.64, centre of gravity 0.45–0.65 m high, the rear stiffness from a side-slip gradient of 0.003–0.007 rad per m/s², the front one from an understeer gradient of 0.001–0.004 rad per m/s², load sensitivity 0.2–0.4, front roll share 0.5–0.7 |
//! | `longitudinal` | the driven axle (front 70 % of cars) slipping by the traction force over a stiffness of 15–25 times its static load, rolling resistance 0.008–0.015, drag 0.3–0.5 N/(m/s)²; rolling circumference +0.1–0.3 % at 30 m/s and −(0.01–0.02) per unit of relative load change |
//! | `terrain` | a sinusoidal elevation of 300–1000 m wavelength and 2–6 % largest grade, bumps of 5–15 mm amplitude and 2–5 m wavelength |
//! | `clocks` | each stream's own clock ([`ClockSpec`]): wheels, gyro, CAN speed and steering offset 0–10 ms (late), drift ±100 ppm, jitter 0.2–1 ms (wheels at 50 Hz up to 2 ms); the receiver's stamps jitter 0–5 ms |
//! | `tooth_error` | tone-ring tooth position error 0.2–1 % of the pitch (48 teeth, fixed per wheel and tooth) |
//! | `gyro_drift` | a Gauss–Markov gyro bias of 0.00005–0.0002 rad/s (10–40 °/h, an automotive MEMS gyro's in-run instability), correlation time 100–600 s, on top of the constant bias |
//! | `gyro_scale` | a gyro scale error of ±1 % |
//! | `multipath` | GNSS multipath bursts: 0.2–1 per minute, 2–6 s long, offsets of 1–4 m per axis (std) |
//! | `wander` | the receiver's slow Gauss–Markov error: the family car's `gnss_markov` (0–1.5 m, 20–120 s) |
//! | `latency` | the receiver's latency (the family car's, 0–0.15 s), CAN speed and steering latencies 0–0.1 s |
//! | `steering_offset` | a steering-wheel offset of 1–3°, either sign |
//!
//! Every drive has wheel ticks or wheel speeds (drawn per car, ticks half of
//! the time) at 50 or 100 Hz, a gyro at 100 Hz, CAN speed and steering at
//! 50 Hz, and the family car's receiver. With [`Effects::none`] the drive is
//! kinematic: white GNSS, true time stamps, no latency, no offsets.

use rand::RngExt;
use serde::{Deserialize, Serialize};

use super::{between, rng, CarFamily};
use crate::dynamics::{DrivenAxle, DynamicsSpec};
use crate::imperfections::{ClockSpec, MultipathSpec};
use crate::scenario::Scenario;
use crate::sensors::{ScalarSpec, SteeringSpec, WheelKind};

/// Which effects a dynamic drive has (each drawn per car in [`DynamicCar`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Effects {
    /// Tyre side slip and understeer ([`crate::dynamics`]).
    pub side_slip: bool,
    /// The driven axle's longitudinal slip, rolling radii growing with
    /// speed and shrinking with load.
    pub longitudinal: bool,
    /// Grade (a sinusoidal elevation) and bumps.
    pub terrain: bool,
    /// Each stream on its own clock: offset, drift, jitter.
    pub clocks: bool,
    /// Tone-ring tooth-spacing error.
    pub tooth_error: bool,
    /// Drifting gyro bias.
    pub gyro_drift: bool,
    /// Gyro scale error.
    pub gyro_scale: bool,
    /// GNSS multipath bursts.
    pub multipath: bool,
    /// The receiver's slowly wandering position error.
    pub wander: bool,
    /// Latencies of the receiver, CAN speed and steering.
    pub latency: bool,
    /// Steering-wheel offset.
    pub steering_offset: bool,
}

impl Effects {
    /// The names of the effects, in the order of [`Effects::only`].
    pub const NAMES: [&'static str; 11] = [
        "side_slip",
        "longitudinal",
        "terrain",
        "clocks",
        "tooth_error",
        "gyro_drift",
        "gyro_scale",
        "multipath",
        "wander",
        "latency",
        "steering_offset",
    ];

    /// No effect: a kinematic car with white GNSS and true stamps.
    pub fn none() -> Self {
        Effects::default()
    }

    /// Every effect.
    pub fn all() -> Self {
        let mut e = Effects::none();
        for name in Effects::NAMES {
            *e.flag(name).expect("a known name") = true;
        }
        e
    }

    /// Only the effect `name` (one of [`Effects::NAMES`]); `None` for other names.
    pub fn only(name: &str) -> Option<Self> {
        let mut e = Effects::none();
        *e.flag(name)? = true;
        Some(e)
    }

    /// Every effect but `name`; `None` for other names.
    pub fn all_but(name: &str) -> Option<Self> {
        let mut e = Effects::all();
        *e.flag(name)? = false;
        Some(e)
    }

    /// The switch of the effect `name` (one of [`Effects::NAMES`]).
    pub fn flag(&mut self, name: &str) -> Option<&mut bool> {
        Some(match name {
            "side_slip" => &mut self.side_slip,
            "longitudinal" => &mut self.longitudinal,
            "terrain" => &mut self.terrain,
            "clocks" => &mut self.clocks,
            "tooth_error" => &mut self.tooth_error,
            "gyro_drift" => &mut self.gyro_drift,
            "gyro_scale" => &mut self.gyro_scale,
            "multipath" => &mut self.multipath,
            "wander" => &mut self.wander,
            "latency" => &mut self.latency,
            "steering_offset" => &mut self.steering_offset,
            _ => return None,
        })
    }
}

/// The clocks of one car's streams (used when [`Effects::clocks`] is on).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Clocks {
    /// The wheel ECU's.
    pub wheels: ClockSpec,
    /// The gyro's.
    pub gyro: ClockSpec,
    /// The CAN speed's.
    pub speed: ClockSpec,
    /// The steering's.
    pub steering: ClockSpec,
    /// The receiver's stamps (jitter only).
    pub gnss: ClockSpec,
}

impl Clocks {
    /// Every stream's clock, wheels first, to switch a part of them off
    /// (an ablation of offsets, drifts or jitter).
    pub fn each_mut(&mut self) -> [&mut ClockSpec; 5] {
        [
            &mut self.wheels,
            &mut self.gyro,
            &mut self.speed,
            &mut self.steering,
            &mut self.gnss,
        ]
    }
}

/// One car of the dynamic family: a [`CarFamily`] car and the magnitude of
/// every effect, drawn from `seed`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DynamicCar {
    /// The family car (geometry, tyres, receiver, wander, GNSS latency).
    pub base: CarFamily,
    /// Ticks or speeds.
    pub wheel_kind: WheelKind,
    /// Wheel rate, Hz (50 or 100).
    pub wheel_rate_hz: f64,
    /// Tyre side slip and understeer, longitudinal slip, rolling radii,
    /// grade and bumps (each part used when its effect is on).
    pub dynamics: DynamicsSpec,
    /// The streams' clocks.
    pub clocks: Clocks,
    /// Tone-ring tooth position error, pitches.
    pub tooth_error_std: f64,
    /// Drifting gyro bias: std, rad/s, and correlation time, s.
    pub gyro_drift: (f64, f64),
    /// Gyro scale error (relative).
    pub gyro_scale_error: f64,
    /// Multipath bursts.
    pub multipath: MultipathSpec,
    /// CAN speed and steering latencies, s.
    pub can_latency_s: (f64, f64),
    /// Steering-wheel offset, rad.
    pub steering_offset_rad: f64,
}

/// Purposes of the per-effect generators (after the family's 1–3).
const SLIP: u64 = 101;
const CLOCKS: u64 = 102;
const TOOTH: u64 = 103;
const GYRO: u64 = 104;
const MULTIPATH: u64 = 105;
const LATENCY: u64 = 106;
const STEERING: u64 = 107;
const STREAMS: u64 = 108;
const PHASES: u64 = 109;
const LONGITUDINAL: u64 = 110;
const TERRAIN: u64 = 111;
const TICK_COUNTER: u64 = 112;

/// The tone rings' tooth counts of [`DynamicCar::draw_tick_counter`]: 40–100 teeth.
pub const TICK_COUNTER_TEETH: (u32, u32) = (40, 100);
/// The counters' rates of [`DynamicCar::draw_tick_counter`], Hz.
pub const TICK_COUNTER_RATES_HZ: [f64; 3] = [25.0, 50.0, 100.0];

fn signed(r: &mut rand_pcg::Pcg64, lo: f64, hi: f64) -> f64 {
    let m = between(r, lo, hi);
    if r.random::<bool>() {
        m
    } else {
        -m
    }
}

impl DynamicCar {
    /// The car of `seed` (its base is [`CarFamily::draw`]`(seed)`).
    pub fn draw(seed: u64) -> Self {
        let base = CarFamily::draw(seed);
        let r = &mut rng(seed, SLIP);
        let mass_kg = between(r, 1200.0, 2000.0);
        let front_load_share = between(r, 0.52, 0.64);
        let cg_height_m = between(r, 0.45, 0.65);
        let slip_gradient = between(r, 0.003, 0.007);
        let understeer = between(r, 0.001, 0.004);
        let dynamics = DynamicsSpec {
            mass_kg,
            front_load_share,
            cg_height_m,
            cornering_stiffness_rear_n_per_rad: mass_kg * (1.0 - front_load_share) / slip_gradient,
            cornering_stiffness_front_n_per_rad: mass_kg * front_load_share
                / (understeer + slip_gradient),
            load_sensitivity: between(r, 0.2, 0.4),
            roll_stiffness_front_share: between(r, 0.5, 0.7),
            ..DynamicsSpec::default()
        };
        // Drawn after the side slip's values, from their own generators.
        let r = &mut rng(seed, LONGITUDINAL);
        let rear_driven = r.random::<f64>() < 0.3;
        let driven_share = if rear_driven {
            1.0 - front_load_share
        } else {
            front_load_share
        };
        let dynamics = DynamicsSpec {
            driven_axle: if rear_driven {
                DrivenAxle::Rear
            } else {
                DrivenAxle::Front
            },
            longitudinal_stiffness_n: between(r, 15.0, 25.0) * mass_kg * 9.81 * driven_share,
            rolling_resistance: between(r, 0.008, 0.015),
            drag_n_per_mps2: between(r, 0.3, 0.5),
            radius_growth_per_mps2: between(r, 0.001, 0.003) / 900.0,
            radius_load_sensitivity: between(r, 0.01, 0.02),
            ..dynamics
        };
        let r = &mut rng(seed, TERRAIN);
        let grade_wavelength_m = between(r, 300.0, 1000.0);
        let grade_amplitude_m = between(r, 0.02, 0.06) * grade_wavelength_m / std::f64::consts::TAU;
        let dynamics = DynamicsSpec {
            grade_amplitude_m,
            grade_wavelength_m,
            bump_amplitude_m: between(r, 0.005, 0.015),
            bump_wavelength_m: between(r, 2.0, 5.0),
            ..dynamics
        };
        let s = &mut rng(seed, STREAMS);
        let wheel_kind = if s.random::<bool>() {
            WheelKind::Ticks
        } else {
            WheelKind::Speeds
        };
        let wheel_rate_hz = [50.0, 100.0][s.random_range(0..2)];
        let r = &mut rng(seed, CLOCKS);
        let mut ecu = |max_jitter_s: f64| ClockSpec {
            offset_s: between(r, 0.0, 0.01),
            drift_ppm: between(r, -100.0, 100.0),
            jitter_std_s: between(r, 0.0002, max_jitter_s),
        };
        let clocks = Clocks {
            wheels: ecu(0.1 / wheel_rate_hz),
            gyro: ecu(0.001),
            speed: ecu(0.001),
            steering: ecu(0.001),
            gnss: ClockSpec {
                jitter_std_s: between(r, 0.0, 0.005),
                ..ClockSpec::default()
            },
        };
        let tooth_error_std = between(&mut rng(seed, TOOTH), 0.002, 0.01);
        let r = &mut rng(seed, GYRO);
        let gyro_drift = (between(r, 0.00005, 0.0002), between(r, 100.0, 600.0));
        let gyro_scale_error = between(r, -0.01, 0.01);
        let r = &mut rng(seed, MULTIPATH);
        let multipath = MultipathSpec {
            bursts_per_min: between(r, 0.2, 1.0),
            mean_duration_s: between(r, 2.0, 6.0),
            offset_std_m: between(r, 1.0, 4.0),
        };
        let r = &mut rng(seed, LATENCY);
        let can_latency_s = (between(r, 0.0, 0.1), between(r, 0.0, 0.1));
        let steering_offset_rad = signed(&mut rng(seed, STEERING), 1.0, 3.0).to_radians();
        DynamicCar {
            base,
            wheel_kind,
            wheel_rate_hz,
            dynamics,
            clocks,
            tooth_error_std,
            gyro_drift,
            gyro_scale_error,
            multipath,
            can_latency_s,
            steering_offset_rad,
        }
    }

    /// The car of `seed` ([`DynamicCar::draw`], every draw the same) with
    /// tick-counting wheels: a tone ring of 40–100 teeth
    /// ([`TICK_COUNTER_TEETH`], the nominal and the true ring alike) counted
    /// at 25, 50 or 100 Hz ([`TICK_COUNTER_RATES_HZ`]), both drawn from a
    /// generator of their own. With [`Effects::tooth_error`] the teeth are
    /// misplaced by the car's `tooth_error_std`. The TedriS tick-counter
    /// tests (`deadreckon-tedris/tests/tick_family.rs`) train and test on
    /// these cars.
    pub fn draw_tick_counter(seed: u64) -> Self {
        let mut car = DynamicCar::draw(seed);
        let r = &mut rng(seed, TICK_COUNTER);
        let (lo, hi) = TICK_COUNTER_TEETH;
        car.base.vehicle.ticks_per_rev = r.random_range(lo..=hi);
        car.wheel_kind = WheelKind::Ticks;
        let rate = TICK_COUNTER_RATES_HZ[r.random_range(0..TICK_COUNTER_RATES_HZ.len())];
        // The wheel clock's jitter was drawn as a share of the drawn rate's
        // period: the same share of this one's.
        car.clocks.wheels.jitter_std_s *= car.wheel_rate_hz / rate;
        car.wheel_rate_hz = rate;
        car
    }

    /// A drive of this car from `seed` with `effects`: the family car's
    /// route and receiver ([`CarFamily::drive`], shunts included), this
    /// car's wheels, a gyro at 100 Hz, CAN speed and steering at 50 Hz, and
    /// the effects asked for at this car's magnitudes.
    pub fn drive(&self, seed: u64, min_duration_s: f64, effects: &Effects) -> Scenario {
        let mut base = self.base.clone();
        base.wheel_rate_hz = self.wheel_rate_hz;
        let mut sc = base.drive(seed, min_duration_s);
        sc.name = format!("dynamic-car-{}-drive-{seed}", self.base.seed);
        sc.description =
            "a member of the dynamic car family (deadreckon_sim::family::DynamicCar)".into();
        let phases = &mut rng(seed, PHASES + self.base.seed.wrapping_mul(31));
        let s = &mut sc.sensors;
        s.wheels.kind = self.wheel_kind;
        if effects.tooth_error {
            s.wheels.tooth_error_std = self.tooth_error_std;
        }
        let gyro = s.gyro.as_mut().expect("the family has a gyro");
        if effects.gyro_drift {
            gyro.bias_drift_std_rps = self.gyro_drift.0;
            gyro.bias_drift_tau_s = self.gyro_drift.1;
        }
        if effects.gyro_scale {
            gyro.scale_error = self.gyro_scale_error;
        }
        let lat = if effects.latency {
            self.can_latency_s
        } else {
            (0.0, 0.0)
        };
        s.speed = Some(ScalarSpec {
            rate_hz: 50.0,
            offset_s: between(phases, 0.0, 0.02),
            noise_std: 0.1,
            latency_s: lat.0,
            scale_error: 0.0,
            tilt_deg: None,
            bias_drift_std_rps: 0.0,
            bias_drift_tau_s: 300.0,
            clock: None,
        });
        s.steering = Some(SteeringSpec {
            rate_hz: 50.0,
            offset_s: between(phases, 0.0, 0.02),
            noise_std: 0.02,
            latency_s: lat.1,
            true_ratio: None,
            wheel_offset_rad: if effects.steering_offset {
                self.steering_offset_rad
            } else {
                0.0
            },
            clock: None,
        });
        if effects.clocks {
            s.wheels.clock = Some(self.clocks.wheels);
            s.gyro.as_mut().expect("gyro").clock = Some(self.clocks.gyro);
            s.speed.as_mut().expect("speed").clock = Some(self.clocks.speed);
            s.steering.as_mut().expect("steering").clock = Some(self.clocks.steering);
        }
        let g = s.gnss.as_mut().expect("the family has a receiver");
        if effects.clocks {
            g.clock = Some(self.clocks.gnss);
        }
        if !effects.wander {
            g.markov_std_m = 0.0;
        }
        if !effects.latency {
            g.latency_s = 0.0;
        }
        if effects.multipath {
            g.multipath = Some(self.multipath.clone());
        }
        if effects.side_slip || effects.longitudinal || effects.terrain {
            let mut d = self.dynamics.clone();
            let flat = DynamicsSpec::default();
            d.side_slip = effects.side_slip;
            if !effects.longitudinal {
                d.longitudinal_stiffness_n = 0.0;
                d.radius_growth_per_mps2 = 0.0;
                d.radius_load_sensitivity = 0.0;
            }
            if !effects.terrain {
                d.grade_amplitude_m = flat.grade_amplitude_m;
                d.bump_amplitude_m = flat.bump_amplitude_m;
            }
            sc.dynamics = Some(d);
        }
        sc
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn switching_one_effect_changes_only_its_part_of_the_scenario() {
        let car = DynamicCar::draw(3);
        assert_eq!(car, DynamicCar::draw(3));
        let none = car.drive(5, 200.0, &Effects::none());
        assert!(none.dynamics.is_none());
        assert_eq!(none.sensors.gnss.as_ref().unwrap().markov_std_m, 0.0);
        for name in Effects::NAMES {
            let with = car.drive(5, 200.0, &Effects::only(name).unwrap());
            assert_ne!(with, none, "{name} changed nothing");
            assert_eq!(with.route, none.route, "{name}");
            assert_eq!(with.speed, none.speed, "{name}");
            assert_eq!(with.sensors.wheels.offset_s, none.sensors.wheels.offset_s);
        }
        // All on is each on; unknown names are refused.
        let all = Effects::all();
        for name in Effects::NAMES {
            assert_eq!(Effects::all_but(name).unwrap(), {
                let mut e = all;
                *e.flag(name).unwrap() = false;
                e
            });
        }
        assert!(Effects::only("tyre_pressure").is_none());
        // The side slip's draws are the same whether the longitudinal ones
        // exist or not: each effect has its own generator.
        let g = car
            .dynamics
            .rear_slip_gradient_rad_per_mps2(&car.base.vehicle);
        assert!((0.003..=0.007).contains(&g), "{g}");
    }

    #[test]
    fn tick_counters_span_their_teeth_and_rates_and_keep_the_cars_other_draws() {
        let cars: Vec<DynamicCar> = (1..=40).map(DynamicCar::draw_tick_counter).collect();
        let teeth: Vec<u32> = cars.iter().map(|c| c.base.vehicle.ticks_per_rev).collect();
        assert!(teeth.iter().all(|t| (40..=100).contains(t)), "{teeth:?}");
        assert!(teeth.iter().any(|&t| t < 55) && teeth.iter().any(|&t| t > 85));
        for rate in TICK_COUNTER_RATES_HZ {
            assert!(cars.iter().any(|c| c.wheel_rate_hz == rate), "{rate} Hz");
        }
        for (i, c) in cars.iter().enumerate() {
            assert_eq!(c.wheel_kind, WheelKind::Ticks);
            let plain = DynamicCar::draw(i as u64 + 1);
            assert_eq!(c.dynamics, plain.dynamics);
            assert_eq!(c.tooth_error_std, plain.tooth_error_std);
            assert_eq!(c.base.errors, plain.base.errors);
        }
        // Every car's drive is valid with every effect (the wheel clock's
        // jitter within a tenth of the counter's period: car 4 at 100 Hz
        // was not, with the jitter drawn for 50 Hz).
        for c in &cars {
            let sc = c.drive(1, 100.0, &Effects::all());
            assert_eq!(sc.sensors.wheels.kind, WheelKind::Ticks);
            assert_eq!(sc.sensors.wheels.rate_hz, c.wheel_rate_hz);
            sc.validate().unwrap();
        }
    }

    #[test]
    fn wheel_ticks_are_among_the_drawn_kinds_at_50_or_100_hz() {
        let cars: Vec<DynamicCar> = (1..=20).map(DynamicCar::draw).collect();
        assert!(cars.iter().any(|c| c.wheel_kind == WheelKind::Ticks));
        assert!(cars.iter().any(|c| c.wheel_kind == WheelKind::Speeds));
        assert!(cars
            .iter()
            .all(|c| [50.0, 100.0].contains(&c.wheel_rate_hz)));
        let sc = cars[0].drive(1, 100.0, &Effects::all());
        assert_eq!(sc.sensors.gyro.as_ref().unwrap().rate_hz, 100.0);
        assert!(sc.sensors.gyro.as_ref().unwrap().clock.is_some());
        sc.validate().unwrap();
        // Every effect is written to, and read back from, the scenario file.
        let text = sc.to_toml_string().unwrap();
        assert_eq!(Scenario::from_toml_str(&text).unwrap(), sc, "{text}");
    }
}
