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

use deadreckon_core::Vehicle;

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
    /// Yaw, rad, counter-clockwise from east, unwrapped.
    pub psi: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate: f64,
    /// East of the origin, m.
    pub x: f64,
    /// North of the origin, m.
    pub y: f64,
    /// Ground distance rolled by each wheel, FL, FR, RL, RR, m.
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
}

/// Speed, curvature, yaw and yaw rate at one time, without the integrated part.
#[derive(Debug, Clone, Copy)]
struct Exact {
    s: f64,
    v: f64,
    a: f64,
    kappa: f64,
    psi: f64,
    yaw_rate: f64,
}

impl<'a> Kinematics<'a> {
    pub(crate) fn new(route: &'a Route, profile: &'a SpeedProfile, vehicle: &Vehicle) -> Self {
        Kinematics {
            route,
            profile,
            half_front: 0.5 * vehicle.track_front_m,
            half_rear: 0.5 * vehicle.track_rear_m,
            wheelbase: vehicle.wheelbase_m,
        }
    }

    fn exact(&self, t: f64) -> Exact {
        let m = self.profile.eval(t);
        let (kappa, psi) = self.route.eval(m.s);
        Exact {
            s: m.s,
            v: m.v,
            a: m.a,
            kappa,
            psi,
            yaw_rate: m.v * kappa,
        }
    }

    /// Ground speeds of the wheels FL, FR, RL, RR for speed `v` and yaw rate
    /// `w`, negative when reversing (the front wheels' speed takes the sign
    /// of `v`).
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
        // Simpson's rule on ẋ = v cos ψ, ẏ = v sin ψ and on the wheel speeds.
        let (sin0, cos0) = s0.psi.sin_cos();
        let (sinm, cosm) = m.psi.sin_cos();
        let (sin1, cos1) = e.psi.sin_cos();
        let w = h / 6.0;
        let x = s0.x + w * (s0.v * cos0 + 4.0 * m.v * cosm + e.v * cos1);
        let y = s0.y + w * (s0.v * sin0 + 4.0 * m.v * sinm + e.v * sin1);
        let (w0, wm, w1) = (
            kin.wheel_speeds(s0.v, s0.yaw_rate),
            kin.wheel_speeds(m.v, m.yaw_rate),
            kin.wheel_speeds(e.v, e.yaw_rate),
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
            x,
            y,
            wheel_m,
        };
        Some(&self.state)
    }
}
