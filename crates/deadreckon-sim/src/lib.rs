//! # deadreckon-sim
//!
//! A sensor simulator with known truth, for the command line (`deadreckon
//! simulate`), the tests and the demos. A [`Scenario`] (built in, or read from a
//! TOML file) describes a vehicle, a route, a speed policy, the sensors and their
//! true errors; [`simulate`] turns it into a [`deadreckon_core::Drive`] whose
//! `truth` is exact, together with the true calibration parameters.
//!
//! The truth comes from a finer model than the estimators': the route is made of
//! straights and circular arcs joined by clothoids (curvature varies linearly with
//! distance, so it never steps), the speed follows half-cosine transitions
//! (continuous acceleration, bounded jerk), and the rear-axle centre M is
//! integrated at 1 kHz (Simpson's rule) with the exact kinematic bicycle model:
//! yaw rate = speed × curvature. Sensors sample that truth at their own rates and
//! time offsets:
//!
//! | stream | model |
//! |---|---|
//! | wheel ticks | each wheel's ground distance (eq. 6 of Welte et al., 2019) divided by its **true** circumference, times ticks per revolution; the emitted count is the floor of the cumulative count minus what was already emitted, so fractions carry over. Each wheel's tone ring starts at its own phase between two edges (uniform, seeded), as a parked wheel stops anywhere: a counter is as often ahead of the true distance as behind it (starting every ring at an edge, the counts trailed by half a tooth on average, which the GNSS delay read as −5.7, −5.7 and −1.7 ms on the evaluation scenario with 0.05 m fixes and ticks at 25, 50 and 100 Hz) |
//! | wheel speeds | the rotation over the last period times the **nominal** circumference (what an ECU reports), plus noise, quantised |
//! | gyro | yaw rate + bias + white noise (eq. 4) |
//! | CAN speed | scale × speed + white noise (eq. 5, literally: at standstill it reads the noise, sign included) |
//! | steering wheel | r_s · atan(l_RF · κ + β), β white: the noise of eq. 7 on tan(δ/r_s) |
//! | wheel faults (optional) | spin bursts under traction on one wheel, one wheel smaller from some time on ([`faults`]) |
//! | GNSS | antenna position (lever arm forward of M) + white noise; course and speed from the antenna velocity + white noise |
//! | vehicle dynamics (optional `[dynamics]`) | a quasi-steady single-track model with load-sensitive tyre cornering stiffness and load transfer ([`dynamics`]): the body yaw is M's course less the rear side slip β_r ≈ −g·a_y; gyro, wheels (each along its own axis), antenna and truth yaw follow the body; the steering reads the understeer δ ≈ L·κ + K_us·a_y. Optional longitudinal effects on what the wheels count: the driven axle's slip under the traction force, rolling circumferences growing with speed and shrinking with load, grade and bumps (sinusoidal elevations; the accelerometer reads the pitch) |
//! | stream clocks (optional `clock = {…}` in any stream) | the sample describes the true time, its stamp is the stream's clock: offset + drift (ppm) + white jitter ([`imperfections`]); wheel ticks are counted over the true intervals |
//! | tone-ring tooth error (optional `sensors.wheels.tooth_error_std`) | each tooth of each wheel's ring misplaced by a fixed fraction of the pitch: ticks count the misplaced edges, speeds are the rotation inferred from them |
//! | gyro bias drift (optional `sensors.gyro.bias_drift_std_rps`) | a Gauss–Markov bias on top of the constant one |
//! | GNSS multipath (optional `[sensors.gnss.multipath]`) | Poisson bursts of a few seconds, each with one position offset of a few metres, on top of the wander (`markov_std_m`), the white noise and the latency |
//!
//! Every optional effect is off by default: a scenario without them
//! simulates exactly as before they existed. The dynamic family
//! ([`family::DynamicCar`], [`family::Effects`]) draws each at random per
//! car and switches each on or off.
//!
//! Other vehicle shapes: [`tricycle`] simulates a steered, driven front
//! wheel with steering and traction encoders and an external tracker, through
//! full-lock turns and reversals.
//!
//! Conventions are those of `deadreckon-core`: metres east and north, yaw
//! counter-clockwise from east, yaw rate counter-clockwise positive, course in
//! degrees clockwise from north. The route starts at the origin.
//!
//! ```
//! use deadreckon_sim::{simulate, Scenario};
//! let scenario = Scenario::builtin("evaluation")?.with_laps(1);
//! let out = simulate(&scenario, 7)?;
//! assert!(out.drive.validate().is_ok());
//! assert!((out.stats.distance_m - 1700.0).abs() < 200.0);
//! # Ok::<(), deadreckon_sim::SimError>(())
//! ```
#![deny(missing_docs)]

pub mod dynamics;
pub mod family;
pub mod faults;
pub mod imperfections;
pub mod profile;
pub mod route;
pub mod scenario;
pub mod sensors;
pub mod tricycle;
mod truth;

use deadreckon_core::{Drive, Params};

pub use dynamics::DynamicsSpec;
pub use faults::{ShrinkSpec, SpinSpec, WheelFaultsSpec};
pub use imperfections::{ClockSpec, MultipathSpec};
pub use profile::SpeedSpec;
pub use route::{RouteSpec, Segment};
pub use scenario::Scenario;
pub use sensors::{
    CourseConvention, GnssSpec, LowSpeedCourse, ScalarSpec, SensorsSpec, SteeringSpec, WheelKind,
    WheelsSpec,
};

/// Errors of the simulator. Every variant says where the problem is.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SimError {
    /// The name is not one of [`Scenario::names`].
    #[error("unknown scenario `{name}` (built-in scenarios: {known})")]
    UnknownScenario {
        /// The name asked for.
        name: String,
        /// The built-in names, comma-separated.
        known: String,
    },
    /// A scenario file could not be read.
    #[error("cannot read scenario file {path}: {source}")]
    Io {
        /// The file.
        path: std::path::PathBuf,
        /// The underlying error.
        #[source]
        source: std::io::Error,
    },
    /// A scenario text is not valid TOML or does not match the scenario schema.
    #[error("cannot parse scenario {origin}: {message}")]
    Parse {
        /// File name, or `builtin NAME`, or `string`.
        origin: String,
        /// The parser's message (with line and column).
        message: String,
    },
    /// A scenario value is out of range or inconsistent.
    #[error("invalid scenario `{scenario}`: {key}: {message}")]
    Invalid {
        /// The scenario's name.
        scenario: String,
        /// The offending key, e.g. `route.segments[3].radius_m`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// The vehicle or the true parameters are rejected by the core library.
    #[error(transparent)]
    Core(#[from] deadreckon_core::Error),
}

/// What the simulator returns.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOutput {
    /// The simulated drive: nominal vehicle, sensor streams and exact truth.
    pub drive: Drive,
    /// The true parameters the sensors were simulated with: gyro bias, CAN
    /// speed scale and the four true circumferences.
    pub truth_params: Params,
    /// Summary of the true motion.
    pub stats: SimStats,
}

/// Summary of the true motion of a simulated drive.
#[derive(Debug, Clone, PartialEq)]
pub struct SimStats {
    /// Distance driven by the rear-axle centre, m.
    pub distance_m: f64,
    /// Duration of the drive, s.
    pub duration_s: f64,
    /// Distance over duration (stops included), m/s.
    pub mean_speed_mps: f64,
    /// Highest speed, m/s.
    pub max_speed_mps: f64,
    /// Highest absolute yaw rate, rad/s.
    pub max_abs_yaw_rate_rps: f64,
    /// Highest absolute lateral acceleration (speed × yaw rate), m/s².
    pub max_abs_lateral_accel_mps2: f64,
    /// Standstill intervals as (start, duration), s.
    pub stops: Vec<(f64, f64)>,
    /// Ground distance rolled by each wheel, FL, FR, RL, RR, m (signed: a
    /// wheel rolling backwards subtracts).
    pub wheel_distance_m: [f64; 4],
    /// Heading change from start to end, rad, unwrapped.
    pub heading_change_rad: f64,
    /// Wheel-spin bursts simulated (`[sensors.wheel_faults.spin]`), `(start, end)` in s.
    pub spin_bursts: Vec<(f64, f64)>,
    /// GNSS multipath bursts simulated (`[sensors.gnss.multipath]`), `(start,
    /// end, east offset, north offset)` in s (true time) and m.
    pub multipath_bursts: Vec<(f64, f64, f64, f64)>,
    /// The tone rings' tooth position errors per wheel FL, FR, RL, RR, in
    /// tooth pitches (`sensors.wheels.tooth_error_std`; `None` without).
    pub tooth_errors: Option<[Vec<f64>; 4]>,
}

/// Simulates `scenario` with the noise drawn from `seed` (a PCG-64 generator
/// per stream, so the same seed always gives the same drive).
///
/// # Errors
/// [`SimError::Invalid`] when the scenario is inconsistent (see
/// [`Scenario::validate`]), [`SimError::Core`] when the result fails
/// [`Drive::validate`].
pub fn simulate(scenario: &Scenario, seed: u64) -> Result<SimOutput, SimError> {
    scenario.validate()?;
    let invalid = |key: &str, message: String| SimError::Invalid {
        scenario: scenario.name.clone(),
        key: key.into(),
        message,
    };
    let route = route::Route::build(&scenario.route, scenario.laps)
        .map_err(|(key, message)| invalid(&key, message))?;
    let profile = profile::SpeedProfile::plan(&route, &scenario.speed)
        .map_err(|message| invalid("speed", message))?;
    let t_end = scenario.duration_s.unwrap_or(profile.duration_s());
    if t_end > scenario::MAX_DURATION_S {
        return Err(invalid(
            "duration_s",
            format!(
                "the drive would last {t_end:.0} s, more than {} s",
                scenario::MAX_DURATION_S
            ),
        ));
    }
    let params = scenario.true_params();
    let model = scenario
        .dynamics
        .as_ref()
        .map(|d| dynamics::Model::new(d, &scenario.vehicle));
    let kin = truth::Kinematics::new(&route, &profile, &scenario.vehicle, model);
    let mut integrator = truth::Integrator::new(&kin, scenario.integration_rate_hz, t_end);
    let mut suite = sensors::Suite::new(
        &scenario.sensors,
        &scenario.vehicle,
        &params,
        seed,
        t_end,
        kin.is_dynamic(),
    );

    let first = *integrator.state();
    suite.sample(&kin, &first, &first);
    let mut prev = first;
    let mut max_speed: f64 = 0.0;
    let mut max_yaw_rate: f64 = 0.0;
    let mut max_lat: f64 = 0.0;
    while let Some(cur) = integrator.step() {
        suite.sample(&kin, &prev, cur);
        max_speed = max_speed.max(cur.v);
        max_yaw_rate = max_yaw_rate.max(cur.yaw_rate.abs());
        max_lat = max_lat.max((cur.v * cur.yaw_rate).abs());
        prev = *cur;
    }
    let duration_s = prev.t;
    let distance_m = prev.s;
    let stats = SimStats {
        distance_m,
        duration_s,
        mean_speed_mps: if duration_s > 0.0 {
            distance_m / duration_s
        } else {
            0.0
        },
        max_speed_mps: max_speed,
        max_abs_yaw_rate_rps: max_yaw_rate,
        max_abs_lateral_accel_mps2: max_lat,
        stops: profile.stops_until(t_end),
        wheel_distance_m: prev.wheel_m,
        heading_change_rad: prev.psi - first.psi,
        spin_bursts: suite.spin_bursts(),
        multipath_bursts: suite.multipath_bursts(),
        tooth_errors: suite.tooth_errors(),
    };
    let drive = suite.finish(scenario.vehicle.clone());
    drive.validate()?;
    Ok(SimOutput {
        drive,
        truth_params: params,
        stats,
    })
}
