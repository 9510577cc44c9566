//! Speed profile: a smooth speed along the route, with stops.
//!
//! Every segment is a zone with a cruise speed: the segment's speed limit (or the
//! default), lowered in turns so that the lateral acceleration v²·|κ| stays below
//! `max_lateral_accel_mps2` over the turn's largest curvature. Speed changes are
//! half-cosine transitions, v(τ) = v₀ + (v₁ − v₀)(1 − cos(πτ/T))/2: the
//! acceleration is a half sine, zero at both ends, so it is continuous, and T is
//! chosen so that its peak stays below `max_accel_mps2` (or `max_decel_mps2`) and
//! the jerk below `max_jerk_mps3`. A transition belongs to the faster of the two
//! zones: braking ends where a slower zone begins, acceleration starts where it
//! ends, so the limits hold everywhere. Zones too short for their transitions get
//! their cruise speed lowered until everything fits.

use serde::{Deserialize, Serialize};

use crate::route::Route;

/// The speed policy of a scenario (the `[speed]` table). Every key has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpeedSpec {
    /// Speed limit of segments that give none, km/h (default 50).
    pub default_limit_kmh: f64,
    /// Largest lateral acceleration in turns, m/s² (default 2.0).
    pub max_lateral_accel_mps2: f64,
    /// Peak acceleration, m/s² (default 1.2).
    pub max_accel_mps2: f64,
    /// Peak deceleration, m/s² (default 1.5).
    pub max_decel_mps2: f64,
    /// Peak jerk, m/s³ (default 1.0).
    pub max_jerk_mps3: f64,
    /// Standstill before driving off, s (default 5).
    pub start_stop_s: f64,
    /// Standstill after arriving, s (default 5).
    pub end_stop_s: f64,
}

impl Default for SpeedSpec {
    fn default() -> Self {
        SpeedSpec {
            default_limit_kmh: 50.0,
            max_lateral_accel_mps2: 2.0,
            max_accel_mps2: 1.2,
            max_decel_mps2: 1.5,
            max_jerk_mps3: 1.0,
            start_stop_s: 5.0,
            end_stop_s: 5.0,
        }
    }
}

impl SpeedSpec {
    /// Checks every value is finite and positive (stops: non-negative).
    pub(crate) fn check(&self) -> Result<(), (String, String)> {
        for (k, v) in [
            ("speed.default_limit_kmh", self.default_limit_kmh),
            ("speed.max_lateral_accel_mps2", self.max_lateral_accel_mps2),
            ("speed.max_accel_mps2", self.max_accel_mps2),
            ("speed.max_decel_mps2", self.max_decel_mps2),
            ("speed.max_jerk_mps3", self.max_jerk_mps3),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err((k.into(), format!("must be a positive number, got {v}")));
            }
        }
        for (k, v) in [
            ("speed.start_stop_s", self.start_stop_s),
            ("speed.end_stop_s", self.end_stop_s),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((k.into(), format!("must be a non-negative number, got {v}")));
            }
        }
        Ok(())
    }
}

/// One phase of the profile.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    /// Standstill.
    Hold,
    /// Constant speed.
    Cruise(f64),
    /// Half-cosine transition from the first speed to the second.
    Ramp(f64, f64),
    /// A shunt during a stop: this distance (negative: backwards) from rest
    /// to rest, s(τ) = s₀ + Δ·(τ/T − sin(2πτ/T)/(2π)): speed and
    /// acceleration are zero at both ends.
    Shunt(f64),
}

#[derive(Debug, Clone, Copy, PartialEq)]
struct Phase {
    t0: f64,
    s0: f64,
    dur: f64,
    kind: Kind,
}

/// Distance, speed and acceleration at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Motion {
    /// Distance along the route, m.
    pub s: f64,
    /// Speed, m/s.
    pub v: f64,
    /// Acceleration, m/s².
    pub a: f64,
}

/// The planned speed over time.
#[derive(Debug, Clone)]
pub(crate) struct SpeedProfile {
    phases: Vec<Phase>,
    end_t: f64,
    end_s: f64,
}

/// Peak speed of a shunt, m/s.
const SHUNT_SPEED_MPS: f64 = 1.5;
/// Shortest rest before, between and after the moves of a shunt, s.
const SHUNT_REST_S: f64 = 1.0;

/// Duration of a shunt of `d` metres: peak speed 2d/T at most
/// [`SHUNT_SPEED_MPS`], peak acceleration 2πd/T² at most `a`.
fn shunt_time(d: f64, a: f64) -> f64 {
    (2.0 * d / SHUNT_SPEED_MPS).max((2.0 * std::f64::consts::PI * d / a).sqrt())
}

/// Duration of a transition between `v0` and `v1` with peak acceleration `a`
/// and peak jerk `j`: a = πΔ/(2T), j = π²Δ/(2T²).
fn ramp_time(v0: f64, v1: f64, a: f64, j: f64) -> f64 {
    let dv = (v1 - v0).abs();
    (std::f64::consts::PI * dv / (2.0 * a)).max(std::f64::consts::PI * (dv / (2.0 * j)).sqrt())
}

impl SpeedProfile {
    /// Plans the profile over all laps of `route`.
    pub fn plan(route: &Route, spec: &SpeedSpec) -> Result<SpeedProfile, String> {
        // Zones: (length, cruise speed, stop duration); shunts by zone index.
        let mut zones: Vec<(f64, f64, Option<f64>)> = vec![(0.0, 0.0, Some(spec.start_stop_s))];
        let mut shunts = std::collections::HashMap::new();
        for z in &route.zones {
            if let Some(d) = z.stop_s {
                if z.reverse_m > 0.0 {
                    shunts.insert(zones.len(), z.reverse_m);
                }
                zones.push((0.0, 0.0, Some(d)));
            } else if z.len > 1e-9 {
                let mut v = z.limit_mps.unwrap_or(spec.default_limit_kmh / 3.6);
                if z.max_abs_kappa > 0.0 {
                    v = v.min((spec.max_lateral_accel_mps2 / z.max_abs_kappa).sqrt());
                }
                zones.push((z.len, v, None));
            }
        }
        zones.push((0.0, 0.0, Some(spec.end_stop_s)));
        let (acc, dec, jerk) = (spec.max_accel_mps2, spec.max_decel_mps2, spec.max_jerk_mps3);
        let dist = |v0: f64, v1: f64| {
            let a = if v1 > v0 { acc } else { dec };
            ramp_time(v0, v1, a, jerk) * 0.5 * (v0 + v1)
        };
        let n = zones.len();
        let speed = |zones: &[(f64, f64, Option<f64>)], i: usize| zones[i].1;
        // Lower the cruise speed of zones too short for their transitions.
        let mut rounds = 0;
        loop {
            let mut changed = false;
            for i in 1..n - 1 {
                if zones[i].2.is_some() {
                    continue;
                }
                let v = speed(&zones, i);
                let (vp, vn) = (speed(&zones, i - 1), speed(&zones, i + 1));
                let need =
                    if vp < v { dist(vp, v) } else { 0.0 } + if vn < v { dist(v, vn) } else { 0.0 };
                if need > zones[i].0 {
                    zones[i].1 *= 0.98;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
            rounds += 1;
            if rounds > 100_000 {
                return Err("cannot fit the speed transitions into the route".into());
            }
        }
        // Phases.
        let mut phases = Vec::new();
        let (mut t, mut s) = (0.0, 0.0);
        let mut push = |dur: f64, len: f64, kind: Kind, t: &mut f64, s: &mut f64| {
            if dur > 0.0 {
                phases.push(Phase {
                    t0: *t,
                    s0: *s,
                    dur,
                    kind,
                });
                *t += dur;
                *s += len;
            }
        };
        for i in 0..n {
            let (len, v, stop) = zones[i];
            if let Some(d) = stop {
                match shunts.get(&i) {
                    Some(&back) => {
                        // Rest, back up, rest, drive forward again, rest.
                        let move_t = shunt_time(back, spec.max_accel_mps2);
                        let rest = ((d - 2.0 * move_t) / 3.0).max(SHUNT_REST_S);
                        push(rest, 0.0, Kind::Hold, &mut t, &mut s);
                        push(move_t, -back, Kind::Shunt(-back), &mut t, &mut s);
                        push(rest, 0.0, Kind::Hold, &mut t, &mut s);
                        push(move_t, back, Kind::Shunt(back), &mut t, &mut s);
                        push(rest, 0.0, Kind::Hold, &mut t, &mut s);
                    }
                    None => push(d, 0.0, Kind::Hold, &mut t, &mut s),
                }
                continue;
            }
            let (vp, vn) = (zones[i - 1].1, zones[i + 1].1);
            let d_in = if vp < v { dist(vp, v) } else { 0.0 };
            let d_out = if vn < v { dist(v, vn) } else { 0.0 };
            if d_in > 0.0 {
                push(
                    ramp_time(vp, v, acc, jerk),
                    d_in,
                    Kind::Ramp(vp, v),
                    &mut t,
                    &mut s,
                );
            }
            let cruise = (len - d_in - d_out).max(0.0);
            push(cruise / v, cruise, Kind::Cruise(v), &mut t, &mut s);
            if d_out > 0.0 {
                push(
                    ramp_time(v, vn, dec, jerk),
                    d_out,
                    Kind::Ramp(v, vn),
                    &mut t,
                    &mut s,
                );
            }
        }
        Ok(SpeedProfile {
            phases,
            end_t: t,
            end_s: s,
        })
    }

    /// Duration of the whole profile, stops included, s.
    pub fn duration_s(&self) -> f64 {
        self.end_t
    }

    /// Distance, speed and acceleration at time `t` (standstill after the end).
    pub fn eval(&self, t: f64) -> Motion {
        let i = self.phases.partition_point(|p| p.t0 <= t);
        if i == 0 {
            return Motion {
                s: 0.0,
                v: 0.0,
                a: 0.0,
            };
        }
        let p = &self.phases[i - 1];
        let tau = t - p.t0;
        if tau >= p.dur && i == self.phases.len() {
            return Motion {
                s: self.end_s,
                v: 0.0,
                a: 0.0,
            };
        }
        let tau = tau.min(p.dur);
        match p.kind {
            Kind::Hold => Motion {
                s: p.s0,
                v: 0.0,
                a: 0.0,
            },
            Kind::Cruise(v) => Motion {
                s: p.s0 + v * tau,
                v,
                a: 0.0,
            },
            Kind::Shunt(d) => {
                let w = 2.0 * std::f64::consts::PI / p.dur;
                let (sin, cos) = (w * tau).sin_cos();
                Motion {
                    s: p.s0 + d * (tau / p.dur - sin / (w * p.dur)),
                    v: d / p.dur * (1.0 - cos),
                    a: d / p.dur * w * sin,
                }
            }
            Kind::Ramp(v0, v1) => {
                let dv = v1 - v0;
                let w = std::f64::consts::PI / p.dur;
                let (sin, cos) = (w * tau).sin_cos();
                Motion {
                    s: p.s0 + v0 * tau + 0.5 * dv * (tau - sin / w),
                    v: v0 + 0.5 * dv * (1.0 - cos),
                    a: 0.5 * dv * w * sin,
                }
            }
        }
    }

    /// Standstill intervals (start, duration) that begin before `t_end`,
    /// adjacent holds merged, cut at `t_end`.
    pub fn stops_until(&self, t_end: f64) -> Vec<(f64, f64)> {
        let mut out: Vec<(f64, f64)> = Vec::new();
        for p in self
            .phases
            .iter()
            .filter(|p| p.kind == Kind::Hold && p.t0 < t_end)
        {
            match out.last_mut() {
                Some(last) if (last.0 + last.1 - p.t0).abs() < 1e-9 => last.1 += p.dur,
                _ => out.push((p.t0, p.dur)),
            }
        }
        if t_end > self.end_t {
            match out.last_mut() {
                Some(last) if (last.0 + last.1 - self.end_t).abs() < 1e-9 => {
                    last.1 = t_end - last.0
                }
                _ => out.push((self.end_t, t_end - self.end_t)),
            }
        }
        for o in &mut out {
            o.1 = o.1.min(t_end - o.0);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::route::{RouteSpec, Segment};

    fn route() -> Route {
        let spec = RouteSpec {
            closed: false,
            start_yaw_deg: 0.0,
            transition_m: 10.0,
            segments: vec![
                Segment::Straight {
                    length_m: 200.0,
                    speed_limit_kmh: None,
                },
                Segment::Turn {
                    angle_deg: 90.0,
                    radius_m: 10.0,
                    speed_limit_kmh: None,
                    transition_m: None,
                },
                Segment::Straight {
                    length_m: 5.0,
                    speed_limit_kmh: Some(70.0),
                },
                Segment::Stop {
                    duration_s: 3.0,
                    reverse_m: None,
                },
                Segment::Straight {
                    length_m: 300.0,
                    speed_limit_kmh: Some(30.0),
                },
            ],
        };
        Route::build(&spec, 1).unwrap()
    }

    #[test]
    fn speed_is_smooth_and_reaches_the_end() {
        let r = route();
        let spec = SpeedSpec::default();
        let p = SpeedProfile::plan(&r, &spec).unwrap();
        let dt = 1e-3;
        let mut prev = p.eval(0.0);
        let mut t = dt;
        while t < p.duration_s() + 1.0 {
            let m = p.eval(t);
            assert!(m.v >= -1e-12 && m.v <= 50.0 / 3.6 + 1e-9);
            assert!(
                (m.a - prev.a).abs() <= spec.max_jerk_mps3 * dt * 1.01 + 1e-9,
                "jerk at {t}"
            );
            assert!(m.a <= spec.max_accel_mps2 + 1e-9 && m.a >= -spec.max_decel_mps2 - 1e-9);
            assert!(
                ((m.s - prev.s) - 0.5 * (m.v + prev.v) * dt).abs() < 1e-6,
                "s and v disagree at {t}"
            );
            prev = m;
            t += dt;
        }
        assert!((prev.s - r.length_m()).abs() < 1e-6);
        assert_eq!(p.stops_until(p.duration_s()).len(), 3);
    }

    #[test]
    fn a_shunt_backs_up_along_the_path_and_returns() {
        let spec = RouteSpec {
            closed: false,
            start_yaw_deg: 0.0,
            transition_m: 10.0,
            segments: vec![
                Segment::Straight {
                    length_m: 100.0,
                    speed_limit_kmh: None,
                },
                Segment::Stop {
                    duration_s: 10.0,
                    reverse_m: Some(8.0),
                },
                Segment::Straight {
                    length_m: 100.0,
                    speed_limit_kmh: None,
                },
            ],
        };
        let r = Route::build(&spec, 1).unwrap();
        let sp = SpeedSpec::default();
        let p = SpeedProfile::plan(&r, &sp).unwrap();
        let dt = 1e-3;
        let (mut prev, mut t) = (p.eval(0.0), dt);
        let (mut s_min, mut v_min) = (f64::MAX, 0.0f64);
        let (mut after_stop, mut reached) = (None, false);
        while t < p.duration_s() {
            let m = p.eval(t);
            assert!(
                ((m.s - prev.s) - 0.5 * (m.v + prev.v) * dt).abs() < 1e-6,
                "at {t}"
            );
            assert!(
                m.a <= sp.max_accel_mps2 + 1e-9 && m.a >= -sp.max_decel_mps2 - 1e-9,
                "at {t}"
            );
            if reached || m.s > 100.0 - 1e-9 {
                reached = true;
                s_min = s_min.min(m.s);
            }
            v_min = v_min.min(m.v);
            if prev.v < 0.0 && m.v >= 0.0 {
                after_stop = Some(m.s);
            }
            prev = m;
            t += dt;
        }
        // Backed up 8 m from the stop at 100 m, at up to 1.5 m/s.
        assert!((s_min - 92.0).abs() < 1e-6, "{s_min}");
        assert!((-SHUNT_SPEED_MPS - 1e-9..-1.0).contains(&v_min), "{v_min}");
        assert!(after_stop.is_some_and(|s| (s - 92.0).abs() < 1e-6));
        assert!((prev.s - r.length_m()).abs() < 1e-3);
        // Three rests: the stop is three stops.
        assert_eq!(p.stops_until(p.duration_s()).len(), 5);
        // Backing up further than the path driven is refused.
        let mut bad = spec.clone();
        bad.segments[1] = Segment::Stop {
            duration_s: 10.0,
            reverse_m: Some(150.0),
        };
        let e = Route::build(&bad, 1).unwrap_err();
        assert!(e.1.contains("longer than the path"), "{e:?}");
    }
}
