//! The tricycle shape: a steered, driven front wheel with a steering encoder
//! and a traction encoder, and an external tracker seeing a point mounted on
//! the base (as the real `tricycle-tracker` log).
//!
//! The truth is integrated at 1 kHz from a seeded random sequence of
//! manoeuvres: each holds a wheel speed (forward or reverse) and a wheel angle
//! (anywhere in ±90°, full lock included) for a few seconds, reached by
//! half-cosine transitions, so the speed changes sign through zero and the
//! wheel turns smoothly. The base moves `u·cos φ` along its heading and turns
//! at `u·sin φ / L` (`u` the wheel speed). Sensors sample the truth at
//! [`TricycleSimSpec::rate_hz`]:
//!
//! | stream | model |
//! |---|---|
//! | traction ticks | cumulative true wheel travel / (true Ktraction / ticks per revolution), floored (fractions carry over), signed |
//! | steering encoder | (φ − true offset) / true Ksteer as encoder counts, rounded, plus white noise in counts |
//! | tracker | base ∘ true mounting, plus white noise on x, y and heading |

use deadreckon_core::kinematics::tricycle::{
    TricycleDrive, TricycleGeometry, TricycleParams, TricycleSample,
};
use deadreckon_core::kinematics::Pose2;
use rand::{RngExt, SeedableRng};
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64;

use crate::SimError;

/// What to simulate.
#[derive(Debug, Clone, PartialEq)]
pub struct TricycleSimSpec {
    /// Encoder geometry.
    pub geometry: TricycleGeometry,
    /// The true parameters (what calibration should find).
    pub truth: TricycleParams,
    /// The nominal parameters written into the drive (the description's guesses).
    pub nominal: TricycleParams,
    /// Duration, s.
    pub duration_s: f64,
    /// Sample rate of encoders and tracker, Hz.
    pub rate_hz: f64,
    /// Largest wheel speed of a manoeuvre, m/s.
    pub max_speed_mps: f64,
    /// Largest wheel angle of a manoeuvre, rad (π/2: full lock, turning on the spot).
    pub max_wheel_angle_rad: f64,
    /// Tracker position noise (1σ), m.
    pub tracker_noise_m: f64,
    /// Tracker heading noise (1σ), rad.
    pub tracker_noise_rad: f64,
    /// Steering encoder noise (1σ), counts.
    pub steer_noise_counts: f64,
}

impl Default for TricycleSimSpec {
    /// The real log's robot: header values as nominal, the values calibrated
    /// on the log as truth, 25 Hz, up to 0.5 m/s, full lock.
    fn default() -> Self {
        TricycleSimSpec {
            geometry: TricycleGeometry {
                ticks_per_rev: 5000,
                steer_counts_per_rev: 8192,
            },
            truth: TricycleParams {
                ktraction_m: 0.0107,
                ksteer: 0.56,
                steer_offset_rad: -0.05,
                axle_length_m: 1.53,
                mount: Pose2::new(1.8, -0.03, 0.01),
            },
            nominal: TricycleParams {
                ktraction_m: 0.0106141,
                ksteer: 0.1,
                steer_offset_rad: 0.0,
                axle_length_m: 1.4,
                mount: Pose2::new(1.5, 0.0, 0.0),
            },
            duration_s: 300.0,
            rate_hz: 25.0,
            max_speed_mps: 0.5,
            max_wheel_angle_rad: std::f64::consts::FRAC_PI_2,
            tracker_noise_m: 0.005,
            tracker_noise_rad: 0.002,
            steer_noise_counts: 1.0,
        }
    }
}

/// A simulated tricycle drive with its truth.
#[derive(Debug, Clone, PartialEq)]
pub struct TricycleSim {
    /// The drive as sensors and tracker give it (nominal parameters from the spec).
    pub drive: TricycleDrive,
    /// The true base pose at each sample.
    pub base: Vec<Pose2>,
    /// The true wheel angle at each sample, rad.
    pub wheel_angle_rad: Vec<f64>,
    /// The true wheel speed at each sample, m/s.
    pub wheel_speed_mps: Vec<f64>,
}

/// Step of the truth integration, s.
const TRUTH_DT_S: f64 = 1e-3;
/// Transition time between manoeuvres, s.
const TRANSITION_S: f64 = 1.0;

/// One manoeuvre: hold `(u, φ)` until `end_s`.
#[derive(Debug, Clone, Copy)]
struct Manoeuvre {
    end_s: f64,
    speed_mps: f64,
    angle_rad: f64,
}

fn plan(spec: &TricycleSimSpec, r: &mut Pcg64) -> Vec<Manoeuvre> {
    let mut out = Vec::new();
    let mut t = 0.0;
    let mut k = 0;
    while t < spec.duration_s + 10.0 {
        t += r.random_range(3.0..8.0);
        // Every fourth manoeuvre is at full lock (one way or the other);
        // every third reverses; speeds never stay at zero.
        let angle = if k % 4 == 3 {
            if r.random_bool(0.5) {
                spec.max_wheel_angle_rad
            } else {
                -spec.max_wheel_angle_rad
            }
        } else {
            r.random_range(-spec.max_wheel_angle_rad.abs()..=spec.max_wheel_angle_rad.abs())
        };
        let speed = r.random_range(0.3 * spec.max_speed_mps..spec.max_speed_mps);
        out.push(Manoeuvre {
            end_s: t,
            speed_mps: if k % 3 == 2 { -speed } else { speed },
            angle_rad: angle,
        });
        k += 1;
    }
    out
}

/// `(u, φ)` at time `t`: the current manoeuvre's values, reached from the
/// previous one's by a half-cosine over [`TRANSITION_S`].
fn command(plan: &[Manoeuvre], t: f64) -> (f64, f64) {
    let i = plan.partition_point(|m| m.end_s <= t).min(plan.len() - 1);
    let cur = plan[i];
    let (start, prev) = if i == 0 {
        (0.0, (0.0, 0.0))
    } else {
        (
            plan[i - 1].end_s,
            (plan[i - 1].speed_mps, plan[i - 1].angle_rad),
        )
    };
    let s = ((t - start) / TRANSITION_S).clamp(0.0, 1.0);
    let w = 0.5 - 0.5 * (std::f64::consts::PI * s).cos();
    (
        prev.0 + w * (cur.speed_mps - prev.0),
        prev.1 + w * (cur.angle_rad - prev.1),
    )
}

/// Simulates a tricycle drive from `seed` (a PCG generator: the same seed
/// gives the same drive).
pub fn simulate_tricycle(spec: &TricycleSimSpec, seed: u64) -> Result<TricycleSim, SimError> {
    let bad = |m: String| SimError::Invalid {
        scenario: "tricycle".into(),
        key: "spec".into(),
        message: m,
    };
    spec.truth
        .validate()
        .map_err(|e| bad(format!("true tricycle parameters: {e}")))?;
    spec.nominal
        .validate()
        .map_err(|e| bad(format!("nominal tricycle parameters: {e}")))?;
    if !(spec.duration_s > 0.0 && spec.rate_hz > 0.0 && spec.rate_hz <= 500.0) {
        return Err(bad(
            "duration must be positive and the rate in (0, 500] Hz".into()
        ));
    }
    if !(spec.max_speed_mps > 0.0 && spec.max_wheel_angle_rad.abs() <= std::f64::consts::FRAC_PI_2)
    {
        return Err(bad(
            "max speed must be positive and the wheel angle within ±π/2".into(),
        ));
    }
    if spec.truth.ksteer == 0.0 || spec.truth.ktraction_m <= 0.0 {
        return Err(bad(
            "true Ksteer must be non-zero and Ktraction positive".into()
        ));
    }
    let noise = |s: f64| {
        if !(s.is_finite() && s >= 0.0) {
            return Err(bad(format!(
                "noise must be finite and non-negative, got {s}"
            )));
        }
        Normal::new(0.0, s).map_err(|e| bad(e.to_string()))
    };
    let (n_xy, n_yaw, n_steer) = (
        noise(spec.tracker_noise_m)?,
        noise(spec.tracker_noise_rad)?,
        noise(spec.steer_noise_counts)?,
    );
    let mut r = Pcg64::seed_from_u64(seed ^ 0x7452_4943_5943_4c45);
    let manoeuvres = plan(spec, &mut r);
    let tp = spec.truth;
    let m_per_tick = tp.ktraction_m / f64::from(spec.geometry.ticks_per_rev);
    let counts_per_rad = f64::from(spec.geometry.steer_counts_per_rev) / std::f64::consts::TAU;
    let sample_dt = 1.0 / spec.rate_hz;
    let n_samples = (spec.duration_s * spec.rate_hz).floor() as usize + 1;
    let mut out = TricycleSim {
        drive: TricycleDrive {
            geometry: spec.geometry,
            nominal: spec.nominal,
            samples: Vec::with_capacity(n_samples),
        },
        base: Vec::with_capacity(n_samples),
        wheel_angle_rad: Vec::with_capacity(n_samples),
        wheel_speed_mps: Vec::with_capacity(n_samples),
    };
    let mut pose = Pose2::default();
    let mut travel = 0.0;
    let mut t = 0.0;
    for k in 0..n_samples {
        let t_k = k as f64 * sample_dt;
        while t < t_k - 0.5 * TRUTH_DT_S {
            let dt = TRUTH_DT_S.min(t_k - t);
            let (u, phi) = command(&manoeuvres, t + 0.5 * dt);
            let ds = u * dt;
            let dpsi = ds * phi.sin() / tp.axle_length_m;
            let mid = pose.yaw_rad + 0.5 * dpsi;
            pose.x_m += ds * phi.cos() * mid.cos();
            pose.y_m += ds * phi.cos() * mid.sin();
            pose.yaw_rad += dpsi;
            travel += ds;
            t += dt;
        }
        let (u, phi) = command(&manoeuvres, t_k);
        let counts =
            (phi - tp.steer_offset_rad) / tp.ksteer * counts_per_rad + n_steer.sample(&mut r);
        let tracked = pose.compose(&tp.mount);
        out.drive.samples.push(TricycleSample {
            t_s: t_k,
            ticks: (travel / m_per_tick).floor() as i64,
            steer_counts: counts.round() as i64,
            reference: Some(Pose2::new(
                tracked.x_m + n_xy.sample(&mut r),
                tracked.y_m + n_xy.sample(&mut r),
                deadreckon_core::angle::wrap(tracked.yaw_rad + n_yaw.sample(&mut r)),
            )),
        });
        out.base.push(pose);
        out.wheel_angle_rad.push(phi);
        out.wheel_speed_mps.push(u);
    }
    Ok(out)
}
