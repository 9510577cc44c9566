//! Vehicle truth: the exact kinematic bicycle model of the rear-axle centre M,
//! integrated at a fixed rate (1 kHz by default) with Simpson's rule.
//!
//! Speed v(t) and distance s(t) come from the speed profile, curvature κ(s) and
//! yaw ψ(s) from the route, both in closed form; the yaw rate is ψ̇ = v·κ. What
//! needs integration is the position, ẋ = v cos ψ, ẏ = v sin ψ, and the ground
//! distance rolled by each wheel. Wheel ground speeds are those of a rigid body
//! rolling without slip (eq. 6 of Welte et al., 2019):
//!
//! - rear left / right: v ∓ (l_R/2)·ψ̇
//! - front left / right: √((l_RF·ψ̇)² + (v ∓ (l_F/2)·ψ̇)²)
//!
//! Between grid points, [`Kinematics::between`] evaluates v, ψ, ψ̇ exactly and
//! interpolates the integrated quantities linearly (error below 1e-5 m at 1 kHz).
//!
//! With a `[dynamics]` table ([`crate::dynamics`]) the route is still the path
//! of M (its course integrates the position), but the body yaw is the course
//! less the rear side slip β_r, the yaw rate is the course rate less β̇_r
//! (a central difference of the closed-form β_r over ±[`SLIP_RATE_STEP_S`]),
//! and each wheel rolls its ground velocity's component along its own axis.

use deadreckon_core::Vehicle;

use crate::dynamics::Model;
use crate::profile::SpeedProfile;
use crate::route::Route;

/// The true state at one instant.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct State {
    /// Time, s.
    pub t: f64,
    /// Distance travelled by M, m.
    pub s: f64,
    /// Speed of M, m/s.
    pub v: f64,
    /// Longitudinal acceleration, m/s².
    pub a: f64,
    /// Path curvature, 1/m.
    pub kappa: f64,
    /// Body yaw, rad, counter-clockwise from east, unwrapped (the path's
    /// course less `beta`).
    pub psi: f64,
    /// Body yaw rate, rad/s.
    pub yaw_rate: f64,
    /// Course of M along the path, rad, unwrapped (`psi` without dynamics).
    pub course: f64,
    /// Rear side slip β_r: the angle of M's velocity from the body x axis, rad
    /// (0 without dynamics).
    pub beta: f64,
    /// Road-wheel angle of the single-track model, rad: atan(L·κ) without
    /// dynamics, the front axle's velocity direction plus its slip angle with.
    pub road_wheel_rad: f64,
    /// Road pitch, rad, nose up (0 without a grade).
    pub pitch_rad: f64,
    /// East of the origin, m.
    pub x: f64,
    /// North of the origin, m.
    pub y: f64,
    /// Ground distance rolled by each wheel, FL, FR, RL, RR, m; with the
    /// longitudinal effects of `[dynamics]` (slip, radii, slopes) the
    /// distance its rotation measures in static circumferences.
    pub wheel_m: [f64; 4],
}

/// The closed-form part of the truth: motion along the route.
#[derive(Debug, Clone)]
pub struct Kinematics<'a> {
    route: &'a Route,
    profile: &'a SpeedProfile,
    half_front: f64,
    half_rear: f64,
    wheelbase: f64,
    dynamics: Option<Model>,
}

/// Step of the central difference that gives β̇_r, s.
pub const SLIP_RATE_STEP_S: f64 = 1e-3;

/// Speed, curvature, yaw and yaw rate at one time, without the integrated part.
#[derive(Debug, Clone, Copy)]
struct Exact {
    s: f64,
    v: f64,
    a: f64,
    kappa: f64,
    psi: f64,
    yaw_rate: f64,
    course: f64,
    beta: f64,
    alpha_front: f64,
    road_wheel_rad: f64,
    /// Per wheel: distance counted per metre rolled in the plane (1
    /// without longitudinal effects).
    roll_factors: [f64; 4],
    pitch_rad: f64,
}

impl<'a> Kinematics<'a> {
    pub(crate) fn new(
        route: &'a Route,
        profile: &'a SpeedProfile,
        vehicle: &Vehicle,
        dynamics: Option<Model>,
    ) -> Self {
        Kinematics {
            route,
            profile,
            half_front: 0.5 * vehicle.track_front_m,
            half_rear: 0.5 * vehicle.track_rear_m,
            wheelbase: vehicle.wheelbase_m,
            dynamics,
        }
    }

    /// Whether the truth has side slip (a `[dynamics]` table).
    pub fn is_dynamic(&self) -> bool {
        self.dynamics.is_some()
    }

    /// β_r and α_f at `t` (zero without dynamics).
    fn slip_at(&self, model: &Model, t: f64) -> (f64, f64) {
        let m = self.profile.eval(t);
        let (kappa, _) = self.route.eval(m.s);
        model.slip(m.v, m.a, m.v * m.v * kappa)
    }

    fn exact(&self, t: f64) -> Exact {
        let m = self.profile.eval(t);
        let (kappa, psi) = self.route.eval(m.s);
        let Some(model) = &self.dynamics else {
            return Exact {
                s: m.s,
                v: m.v,
                a: m.a,
                kappa,
                psi,
                yaw_rate: m.v * kappa,
                course: psi,
                beta: 0.0,
                alpha_front: 0.0,
                road_wheel_rad: (self.wheelbase * kappa).atan(),
                roll_factors: [1.0; 4],
                pitch_rad: 0.0,
            };
        };
        let (roll_factors, pitch_rad) = if model.rolls() {
            let r = model.rolling(m.s, m.v, m.a, m.v * m.v * kappa);
            (r.factors, r.pitch_rad)
        } else {
            ([1.0; 4], 0.0)
        };
        let (beta, alpha_front) = model.slip(m.v, m.a, m.v * m.v * kappa);
        let h = SLIP_RATE_STEP_S;
        let beta_rate = (self.slip_at(model, t + h).0 - self.slip_at(model, t - h).0) / (2.0 * h);
        let yaw_rate = m.v * kappa - beta_rate;
        // The front axle's velocity in the body frame, its direction (as a
        // line: reversing keeps the wheel angle), plus the slip angle.
        let road_wheel_rad = if m.v == 0.0 {
            (self.wheelbase * kappa).atan()
        } else {
            let (sb, cb) = beta.sin_cos();
            ((m.v * sb + self.wheelbase * yaw_rate) / (m.v * cb)).atan()
                + m.v.signum() * alpha_front
        };
        Exact {
            s: m.s,
            v: m.v,
            a: m.a,
            kappa,
            psi: psi - beta,
            yaw_rate,
            course: psi,
            beta,
            alpha_front,
            road_wheel_rad,
            roll_factors,
            pitch_rad,
        }
    }

    /// Ground speeds of the wheels FL, FR, RL, RR at `e`: along their own
    /// axes, negative when reversing.
    fn wheel_speeds_at(&self, e: &Exact) -> [f64; 4] {
        if self.dynamics.is_none() {
            return self.wheel_speeds(e.v, e.yaw_rate);
        }
        let w = e.yaw_rate;
        let (sb, cb) = e.beta.sin_cos();
        let (vx, vy) = (e.v * cb, e.v * sb + self.wheelbase * w);
        let sign = if e.v < 0.0 { -1.0 } else { 1.0 };
        let front = e.alpha_front.cos();
        let f = e.roll_factors;
        [
            f[0] * sign * front * vy.hypot(vx - self.half_front * w),
            f[1] * sign * front * vy.hypot(vx + self.half_front * w),
            f[2] * (vx - self.half_rear * w),
            f[3] * (vx + self.half_rear * w),
        ]
    }

    /// Ground speeds of the wheels FL, FR, RL, RR for speed `v` and yaw rate
    /// `w` of the kinematic model, negative when reversing (the front
    /// wheels' speed takes the sign of `v`).
    pub fn wheel_speeds(&self, v: f64, w: f64) -> [f64; 4] {
        let lat = self.wheelbase * w;
        let sign = if v < 0.0 { -1.0 } else { 1.0 };
        [
            sign * (lat * lat + (v - self.half_front * w).powi(2)).sqrt(),
            sign * (lat * lat + (v + self.half_front * w).powi(2)).sqrt(),
            v - self.half_rear * w,
            v + self.half_rear * w,
        ]
    }

    /// The state at `t`, between the grid states `a` and `b` (`a.t ≤ t ≤ b.t`).
    pub fn between(&self, t: f64, a: &State, b: &State) -> State {
        let e = self.exact(t);
        let span = b.t - a.t;
        let l = if span > 0.0 {
            ((t - a.t) / span).clamp(0.0, 1.0)
        } else {
            0.0
        };
        let lerp = |p: f64, q: f64| p + l * (q - p);
        let mut wheel_m = [0.0; 4];
        for (i, w) in wheel_m.iter_mut().enumerate() {
            *w = lerp(a.wheel_m[i], b.wheel_m[i]);
        }
        State {
            t,
            s: e.s,
            v: e.v,
            a: e.a,
            kappa: e.kappa,
            psi: e.psi,
            yaw_rate: e.yaw_rate,
            course: e.course,
            beta: e.beta,
            road_wheel_rad: e.road_wheel_rad,
            pitch_rad: e.pitch_rad,
            x: lerp(a.x, b.x),
            y: lerp(a.y, b.y),
            wheel_m,
        }
    }
}

/// Fixed-step integrator of the truth.
#[derive(Debug)]
pub struct Integrator<'a> {
    kin: &'a Kinematics<'a>,
    dt: f64,
    k: u64,
    n: u64,
    t_end: f64,
    state: State,
    /// The exact part of `state` (its wheel speeds without recomputation).
    exact: Exact,
}

impl<'a> Integrator<'a> {
    /// Starts at t = 0 at the origin; steps of 1/`rate_hz` up to `t_end`.
    pub(crate) fn new(kin: &'a Kinematics<'a>, rate_hz: f64, t_end: f64) -> Self {
        let e = kin.exact(0.0);
        let state = State {
            t: 0.0,
            s: e.s,
            v: e.v,
            a: e.a,
            kappa: e.kappa,
            psi: e.psi,
            yaw_rate: e.yaw_rate,
            course: e.course,
            beta: e.beta,
            road_wheel_rad: e.road_wheel_rad,
            pitch_rad: e.pitch_rad,
            x: 0.0,
            y: 0.0,
            wheel_m: [0.0; 4],
        };
        let n = (t_end * rate_hz).ceil().max(0.0) as u64;
        Integrator {
            kin,
            dt: 1.0 / rate_hz,
            k: 0,
            n,
            t_end,
            state,
            exact: e,
        }
    }

    /// The current state.
    pub fn state(&self) -> &State {
        &self.state
    }

    /// Advances one step (the last one ends exactly at `t_end`); `None` at the end.
    pub fn step(&mut self) -> Option<&State> {
        if self.k >= self.n {
            return None;
        }
        self.k += 1;
        let t0 = self.state.t;
        let t1 = if self.k == self.n {
            self.t_end
        } else {
            self.k as f64 * self.dt
        };
        let h = t1 - t0;
        let kin = self.kin;
        let m = kin.exact(t0 + 0.5 * h);
        let e = kin.exact(t1);
        let s0 = &self.state;
        // Simpson's rule on ẋ = v cos χ, ẏ = v sin χ (χ the course of M) and
        // on the wheel speeds.
        let (sin0, cos0) = s0.course.sin_cos();
        let (sinm, cosm) = m.course.sin_cos();
        let (sin1, cos1) = e.course.sin_cos();
        let w = h / 6.0;
        let x = s0.x + w * (s0.v * cos0 + 4.0 * m.v * cosm + e.v * cos1);
        let y = s0.y + w * (s0.v * sin0 + 4.0 * m.v * sinm + e.v * sin1);
        let (w0, wm, w1) = (
            kin.wheel_speeds_at(&self.exact),
            kin.wheel_speeds_at(&m),
            kin.wheel_speeds_at(&e),
        );
        let mut wheel_m = s0.wheel_m;
        for i in 0..4 {
            wheel_m[i] += w * (w0[i] + 4.0 * wm[i] + w1[i]);
        }
        self.state = State {
            t: t1,
            s: e.s,
            v: e.v,
            a: e.a,
            kappa: e.kappa,
            psi: e.psi,
            yaw_rate: e.yaw_rate,
            course: e.course,
            beta: e.beta,
            road_wheel_rad: e.road_wheel_rad,
            pitch_rad: e.pitch_rad,
            x,
            y,
            wheel_m,
        };
        self.exact = e;
        Some(&self.state)
    }
}
