//! Randomized scenario families: many different cars, receivers and drives
//! drawn from seeds, so that a method is tested on members it was never tuned
//! on instead of on one built-in scenario.
//!
//! A member is a **car** (drawn from a car seed: geometry, tyre radii, wheel
//! speed noise kind and level, wheel rate, the GNSS receiver's rate, noise,
//! slowly wandering position error, course convention and what it reports at
//! low speed, latency) driving a **drive** (drawn from a drive seed: a random open route
//! of straights, turns, roundabouts and stops, its length, the streams' clock
//! phases). Training on one drive of a car and predicting on another drive of
//! the same car is the use the TedriS tests make of it.
//!
//! ```
//! use deadreckon_sim::{family::CarFamily, simulate};
//! let car = CarFamily::draw(3);
//! let scenario = car.drive(11, 300.0);
//! let out = simulate(&scenario, 11)?;
//! assert!(out.stats.duration_s > 250.0);
//! # Ok::<(), deadreckon_sim::SimError>(())
//! ```
//!
//! Reversing: at a share of the stops ([`SHUNT_SHARE`]) the car backs up
//! 3–15 m along the path it just drove and drives forward again (signed
//! wheel speeds; an antenna-velocity course turns round, a body-yaw course
//! does not). What the family does not cover: other reversing manoeuvres
//! (three-point turns, parking), unsigned wheel speeds, wheel ticks (wheel
//! speeds only), slopes and slip.
//!
//! The **dynamic family** ([`DynamicCar`], [`Effects`]) adds a real car's
//! physics and sensors to these cars: tyre side slip and understeer, each
//! stream on its own clock, tone-ring tooth errors, gyro bias drift and
//! scale error, GNSS multipath, wander and latency, a steering offset —
//! each drawn per car and switchable, wheel ticks among the wheel kinds.
//! [`DynamicCar::draw_tick_counter`] gives the same cars with tick-counting
//! wheels on tone rings of 40–100 teeth at 25, 50 or 100 Hz.

mod dynamic;

pub use dynamic::{Clocks, DynamicCar, Effects, TICK_COUNTER_RATES_HZ, TICK_COUNTER_TEETH};

use deadreckon_core::{Params, Vehicle};
use rand::{RngExt, SeedableRng};
use rand_pcg::Pcg64;
use serde::{Deserialize, Serialize};

use crate::profile::SpeedSpec;
use crate::route::{RouteSpec, Segment};
use crate::scenario::Scenario;
use crate::sensors::{
    CourseConvention, GnssSpec, LowSpeedCourse, ScalarSpec, SensorsSpec, WheelKind, WheelsSpec,
};

/// One car of the family: everything that stays the same from drive to drive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CarFamily {
    /// The seed it was drawn from.
    pub seed: u64,
    /// Nominal vehicle (what the user writes in `vehicle.toml`).
    pub vehicle: Vehicle,
    /// True parameters (rear radii apart, all four off the nominal).
    pub errors: Params,
    /// Wheel speed rate, Hz.
    pub wheel_rate_hz: f64,
    /// White wheel speed noise, m/s (0 when the noise is tone-ring jitter).
    pub wheel_noise_mps: f64,
    /// Tone-ring edge jitter, m (0 when the noise is white).
    pub edge_jitter_m: f64,
    /// GNSS rate, Hz.
    pub gnss_rate_hz: f64,
    /// White GNSS position noise, m.
    pub gnss_std_m: f64,
    /// Gauss–Markov GNSS position error, m, and its correlation time, s.
    pub gnss_markov: (f64, f64),
    /// GNSS latency (the fixes describe the car this long before their time
    /// stamps), s.
    pub gnss_latency_s: f64,
    /// GNSS velocity noise, m/s.
    pub velocity_std_mps: f64,
    /// Speed below which the receiver has no course, m/s.
    pub min_course_speed_mps: f64,
    /// What it reports then.
    pub low_speed_course: LowSpeedCourse,
    /// What its course is the direction of.
    pub course_convention: CourseConvention,
}

/// A generator seeded from `seed` and a purpose, so drawing one more value for
/// one purpose does not change the others.
fn rng(seed: u64, purpose: u64) -> Pcg64 {
    Pcg64::seed_from_u64(
        seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ purpose.wrapping_mul(0xD1B5_4A32_D192_ED03),
    )
}

/// The share of a drive's stops at which the car shunts (backs up and
/// drives forward again).
pub const SHUNT_SHARE: f64 = 0.4;

fn between(r: &mut Pcg64, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * r.random::<f64>()
}

impl CarFamily {
    /// The car of `seed`.
    pub fn draw(seed: u64) -> Self {
        let r = &mut rng(seed, 1);
        let track = between(r, 1.45, 1.75);
        let circ = between(r, 1.85, 2.05);
        let vehicle = Vehicle {
            wheelbase_m: between(r, 2.4, 3.0),
            track_front_m: track + between(r, -0.03, 0.03),
            track_rear_m: track,
            gnss_lever_arm_m: between(r, 0.2, 1.8),
            ticks_per_rev: 48,
            wheel_circumference_m: circ,
            steering_ratio: 16.0,
            ..Vehicle::paper_car()
        };
        // Tyres: a common error of up to ±1 %, the two rear ones up to 0.4 % apart.
        let common = between(r, -0.01, 0.01);
        let apart = between(r, -0.004, 0.004);
        let errors = Params {
            gyro_bias_rps: between(r, -0.003, 0.003),
            speed_scale: 1.0 + between(r, -0.01, 0.01),
            circumference_fl_m: circ * (1.0 + common + between(r, -0.002, 0.002)),
            circumference_fr_m: circ * (1.0 + common + between(r, -0.002, 0.002)),
            circumference_rl_m: circ * (1.0 + common - 0.5 * apart),
            circumference_rr_m: circ * (1.0 + common + 0.5 * apart),
        };
        let white = r.random::<bool>();
        let (wheel_noise_mps, edge_jitter_m) = if white {
            (between(r, 0.003, 0.015), 0.0)
        } else {
            (0.0, between(r, 0.0005, 0.0015))
        };
        let low_speed_course = match r.random_range(0..3) {
            0 => LowSpeedCourse::Dropped,
            1 => LowSpeedCourse::Random,
            _ => LowSpeedCourse::Frozen,
        };
        let course_convention = if r.random::<bool>() {
            CourseConvention::AntennaVelocity
        } else {
            CourseConvention::BodyYaw
        };
        CarFamily {
            seed,
            vehicle,
            errors,
            wheel_rate_hz: [25.0, 50.0][r.random_range(0..2)],
            wheel_noise_mps,
            edge_jitter_m,
            gnss_rate_hz: [4.0, 5.0, 10.0][r.random_range(0..3)],
            gnss_std_m: between(r, 0.3, 1.5),
            gnss_markov: (between(r, 0.0, 1.5), between(r, 20.0, 120.0)),
            velocity_std_mps: between(r, 0.03, 0.12),
            min_course_speed_mps: between(r, 0.3, 1.5),
            low_speed_course,
            course_convention,
            // Drawn last: the values above are those of the family before
            // latencies were added.
            gnss_latency_s: between(r, 0.0, 0.15),
        }
    }

    /// A drive of this car drawn from `seed`, at least `min_duration_s` long
    /// (stops included): a random open route of straights, turns,
    /// roundabouts and stops, with shunts (backing up) at a share
    /// [`SHUNT_SHARE`] of the stops.
    pub fn drive(&self, seed: u64, min_duration_s: f64) -> Scenario {
        self.drive_with(seed, min_duration_s, SHUNT_SHARE)
    }

    /// [`CarFamily::drive`] without shunts: the car only drives forward (the
    /// same route and stops).
    pub fn drive_forward(&self, seed: u64, min_duration_s: f64) -> Scenario {
        self.drive_with(seed, min_duration_s, 0.0)
    }

    fn drive_with(&self, seed: u64, min_duration_s: f64, shunt_share: f64) -> Scenario {
        let r = &mut rng(seed, 2 + self.seed.wrapping_mul(31));
        // The shunts from their own generator: the routes are those drawn
        // before reversing was added.
        let shunts = &mut rng(seed, 3 + self.seed.wrapping_mul(31));
        let mut segments = vec![Segment::Straight {
            length_m: between(r, 80.0, 200.0),
            speed_limit_kmh: Some(between(r, 30.0, 50.0)),
        }];
        let speed = SpeedSpec {
            default_limit_kmh: 40.0,
            max_lateral_accel_mps2: between(r, 1.5, 2.5),
            start_stop_s: between(r, 5.0, 20.0),
            end_stop_s: 5.0,
            ..SpeedSpec::default()
        };
        let start_yaw_deg = between(r, -180.0, 180.0);
        let route_of = |segments: &[Segment]| RouteSpec {
            closed: false,
            start_yaw_deg,
            transition_m: 8.0,
            segments: segments.to_vec(),
        };
        // Segments are drawn in batches until the planned drive is long enough.
        loop {
            for _ in 0..8 {
                segments.push(random_segment(r, shunts, shunt_share));
            }
            let spec = route_of(&segments);
            let planned = crate::route::Route::build(&spec, 1)
                .ok()
                .and_then(|route| crate::profile::SpeedProfile::plan(&route, &speed).ok())
                .map_or(0.0, |p| p.duration_s());
            if planned >= min_duration_s || segments.len() > 2000 {
                break;
            }
        }
        let wheels = WheelsSpec {
            kind: WheelKind::Speeds,
            rate_hz: self.wheel_rate_hz,
            offset_s: between(r, 0.0, 1.0 / self.wheel_rate_hz),
            noise_std_mps: self.wheel_noise_mps,
            resolution_mps: 0.01,
            edge_jitter_m: self.edge_jitter_m,
            tooth_error_std: 0.0,
            clock: None,
        };
        let gnss = GnssSpec {
            rate_hz: self.gnss_rate_hz,
            offset_s: between(r, 0.0, 1.0 / self.gnss_rate_hz),
            std_m: self.gnss_std_m,
            velocity_std_mps: Some(self.velocity_std_mps),
            min_course_speed_mps: self.min_course_speed_mps,
            low_speed_course: self.low_speed_course,
            course_convention: self.course_convention,
            markov_std_m: self.gnss_markov.0,
            markov_tau_s: self.gnss_markov.1,
            latency_s: self.gnss_latency_s,
            multipath: None,
            clock: None,
        };
        Scenario {
            name: format!("car-family-{}-drive-{seed}", self.seed),
            description: "a member of the randomized car family (deadreckon_sim::family)".into(),
            vehicle: self.vehicle.clone(),
            errors: Some(self.errors),
            laps: 1,
            duration_s: None,
            integration_rate_hz: 1000.0,
            route: route_of(&segments),
            speed,
            sensors: SensorsSpec {
                wheels,
                gyro: Some(ScalarSpec {
                    offset_s: between(r, 0.0, 0.01),
                    ..ScalarSpec::plain(100.0, 0.003)
                }),
                speed: None,
                steering: None,
                gnss: Some(gnss),
                truth_rate_hz: 50.0,
                wheel_faults: None,
            },
            dynamics: None,
        }
    }
}

/// One random segment: a straight, a turn, a roundabout or a stop (with a
/// shunt drawn from `shunts`).
fn random_segment(r: &mut Pcg64, shunts: &mut Pcg64, shunt_share: f64) -> Segment {
    let pick = r.random::<f64>();
    if pick < 0.42 {
        Segment::Straight {
            length_m: between(r, 50.0, 400.0),
            speed_limit_kmh: Some(between(r, 20.0, 50.0)),
        }
    } else if pick < 0.77 {
        let sign = if r.random::<bool>() { 1.0 } else { -1.0 };
        Segment::Turn {
            angle_deg: sign * between(r, 15.0, 120.0),
            radius_m: between(r, 8.0, 90.0),
            speed_limit_kmh: None,
            transition_m: None,
        }
    } else if pick < 0.85 {
        Segment::Roundabout {
            circle_deg: between(r, 120.0, 300.0),
            radius_m: between(r, 10.0, 20.0),
            deflection_deg: 45.0,
            deflection_radius_m: 12.0,
            speed_limit_kmh: Some(25.0),
        }
    } else {
        Segment::Stop {
            duration_s: between(r, 5.0, 40.0),
            reverse_m: (shunts.random::<f64>() < shunt_share).then(|| between(shunts, 3.0, 15.0)),
        }
    }
}

/// Issue 36's family (`calibration_noise_family.rs`, deadreckon-api's
/// `pose_nees_family.rs`): car `seed` of [`CarFamily`] with a gyro drawn
/// between 0.0003 and 0.003 rad/s per reading (log-uniform; vehicle.toml
/// declares it), a gyro bias within ±0.005 rad/s and a 50 Hz CAN speed
/// stream (so the speed scale is calibrated too): the 600 s scenario of
/// drive `drive_seed`, and the gyro's noise.
pub fn good_gyro_car(seed: u64, drive_seed: u64) -> (Scenario, f64) {
    let mut car = CarFamily::draw(seed);
    let r = &mut Pcg64::seed_from_u64(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 36);
    let gyro_rps = 0.0003 * 10f64.powf(r.random::<f64>());
    car.errors.gyro_bias_rps = -0.005 + 0.01 * r.random::<f64>();
    car.vehicle.noise.gyro_rps = gyro_rps;
    let mut s = car.drive(drive_seed, 600.0);
    if let Some(g) = s.sensors.gyro.as_mut() {
        g.noise_std = gyro_rps;
    }
    s.sensors.speed = Some(ScalarSpec::plain(50.0, 0.1));
    (s, gyro_rps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate;

    #[test]
    fn members_differ_and_repeat() {
        assert_eq!(CarFamily::draw(5), CarFamily::draw(5));
        assert_ne!(
            CarFamily::draw(5).vehicle.track_rear_m,
            CarFamily::draw(6).vehicle.track_rear_m
        );
        let car = CarFamily::draw(5);
        assert_eq!(car.drive(1, 200.0), car.drive(1, 200.0));
        assert_ne!(car.drive(1, 200.0).route, car.drive(2, 200.0).route);
    }

    #[test]
    fn random_low_speed_course_reports_courses_at_standstill() {
        // Find a car whose receiver reports random courses, simulate, and check
        // that at standstill courses are reported and spread over the circle.
        let car = (0..100)
            .map(CarFamily::draw)
            .find(|c| c.low_speed_course == LowSpeedCourse::Random)
            .expect("a random-course car in 100 seeds");
        let out = simulate(&car.drive(4, 300.0), 4).expect("simulated");
        let slow: Vec<f64> = out
            .drive
            .gnss
            .iter()
            .filter(|g| {
                g.speed_mps
                    .is_some_and(|s| s < 0.5 * car.min_course_speed_mps)
            })
            .filter_map(|g| g.course_deg)
            .collect();
        assert!(slow.len() > 20, "{} slow courses", slow.len());
        let (lo, hi) = slow
            .iter()
            .fold((f64::MAX, f64::MIN), |(a, b), c| (a.min(*c), b.max(*c)));
        assert!(lo < 60.0 && hi > 300.0, "{lo}..{hi}");
    }

    #[test]
    fn drives_last_at_least_the_asked_duration_and_stop() {
        for seed in 1..=5 {
            let car = CarFamily::draw(seed);
            let out = simulate(&car.drive(seed, 400.0), seed).expect("simulated");
            assert!(out.stats.duration_s >= 400.0, "{}", out.stats.duration_s);
            assert!(out.drive.validate().is_ok());
            assert!(!out.stats.stops.is_empty());
        }
    }

    /// The bug: a wheel at rest read its edge jitter and white noise as
    /// speeds of up to 0.3 m/s (no edge passes a sensor at rest: it reads 0),
    /// which turned a parked car's dead-reckoned heading.
    #[test]
    fn wheel_speeds_at_rest_carried_jitter_and_noise() {
        for seed in [2, 3] {
            let car = CarFamily::draw(seed);
            let out = simulate(&car.drive_forward(7, 300.0), 7).expect("simulated");
            let deadreckon_core::drive::Wheels::Speeds(ws) = &out.drive.wheels else {
                panic!("speeds");
            };
            let mut at_rest = 0;
            for &(t, d) in &out.stats.stops {
                for w in ws.iter().filter(|w| w.t_s > t + 0.5 && w.t_s < t + d - 0.5) {
                    assert_eq!([w.fl_mps, w.fr_mps, w.rl_mps, w.rr_mps], [0.0; 4], "{w:?}");
                    at_rest += 1;
                }
            }
            assert!(at_rest > 100, "{at_rest} samples at rest");
        }
    }

    /// Shunts: the rear wheels read negative speeds while the car backs up;
    /// an antenna-velocity course turns round with the motion, a body-yaw
    /// course does not.
    #[test]
    fn shunts_reverse_the_wheels_and_only_the_antenna_course() {
        let mut car = CarFamily::draw(2);
        car.min_course_speed_mps = 0.3;
        car.gnss_markov = (0.0, 60.0);
        for convention in [CourseConvention::AntennaVelocity, CourseConvention::BodyYaw] {
            car.course_convention = convention;
            let out = simulate(&car.drive(5, 600.0), 5).expect("simulated");
            let d = &out.drive;
            let deadreckon_core::drive::Wheels::Speeds(ws) = &d.wheels else {
                panic!("speeds");
            };
            assert!(ws.iter().any(|w| w.rl_mps < -0.5 && w.rr_mps < -0.5));
            // Courses while backing up faster than 1 m/s, against the yaw.
            let yaw_at = |t: f64| {
                let i = d
                    .truth
                    .partition_point(|p| p.t_s < t)
                    .min(d.truth.len() - 1);
                (d.truth[i].yaw_rad, d.truth[i].speed_mps.unwrap_or(0.0))
            };
            let mut n = 0;
            for g in &d.gnss {
                let (yaw, v) = yaw_at(g.t_s - car.gnss_latency_s);
                let Some(c) = g.course_yaw_rad() else {
                    continue;
                };
                if v < -1.0 {
                    let off = deadreckon_core::angle::wrap(c - yaw).abs();
                    match convention {
                        CourseConvention::AntennaVelocity => assert!(off > 2.0, "{off}"),
                        CourseConvention::BodyYaw => assert!(off < 1.0, "{off}"),
                    }
                    n += 1;
                }
            }
            assert!(n > 5, "{n} courses while backing up");
        }
    }
}
