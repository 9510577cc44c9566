//! Route geometry: straights, turns and roundabouts joined by clothoids, and stops.
//!
//! A route is a list of [`Segment`]s. Each turn of radius R and angle θ is
//! expanded into a clothoid entry (curvature rising linearly from 0 to ±1/R over
//! `transition_m`), a circular arc, and a clothoid exit; the clothoids are taken
//! out of the arc, so the turn still changes the heading by exactly θ and the
//! straights keep their lengths. Curvature is therefore continuous along the
//! whole route (piecewise linear in distance), and so is the yaw rate v·κ.
//!
//! A closed route (`closed = true`) must turn by a multiple of 360°; the
//! remaining position gap is closed by lengthening or shortening the two
//! straights whose directions are the most perpendicular, so that every lap
//! starts where the previous one ended.

use serde::{Deserialize, Serialize};

/// One element of a route. In TOML, an inline table with a `kind`:
/// `{ kind = "straight", length_m = 300, speed_limit_kmh = 50 }`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
#[non_exhaustive]
pub enum Segment {
    /// A straight line.
    Straight {
        /// Length, m.
        length_m: f64,
        /// Speed limit, km/h (default: `speed.default_limit_kmh`).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        speed_limit_kmh: Option<f64>,
    },
    /// A turn: clothoid, circular arc, clothoid.
    Turn {
        /// Heading change, degrees, positive to the left (counter-clockwise).
        angle_deg: f64,
        /// Radius of the circular part, m.
        radius_m: f64,
        /// Speed limit, km/h (the lateral-acceleration limit applies too).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        speed_limit_kmh: Option<f64>,
        /// Length of each clothoid, m (default: `route.transition_m`); shortened
        /// to the turn's arc length when the turn is too short.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        transition_m: Option<f64>,
    },
    /// A roundabout driven counter-clockwise (right-hand traffic; a negative
    /// `circle_deg` drives it clockwise): a right deflection of
    /// `deflection_deg` into the ring, `circle_deg` around it, and the same
    /// deflection out. Net heading change: `circle_deg − 2·deflection_deg`.
    Roundabout {
        /// Angle driven on the ring, degrees (positive: counter-clockwise).
        circle_deg: f64,
        /// Radius of the ring, m.
        radius_m: f64,
        /// Entry and exit deflection, degrees (default 45).
        #[serde(default = "default_deflection_deg")]
        deflection_deg: f64,
        /// Radius of the entry and exit deflections, m (default 12).
        #[serde(default = "default_deflection_radius_m")]
        deflection_radius_m: f64,
        /// Speed limit, km/h.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        speed_limit_kmh: Option<f64>,
    },
    /// A standstill (traffic light, stop sign) of the given duration; with
    /// `reverse_m`, a shunt within it: the car backs up that far along the
    /// path it just drove and drives forward to where it stopped (the stop
    /// is lengthened to fit both moves).
    Stop {
        /// Standstill duration, s.
        duration_s: f64,
        /// Distance backed up during the stop, m (default: none).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        reverse_m: Option<f64>,
    },
}

fn default_deflection_deg() -> f64 {
    45.0
}
fn default_deflection_radius_m() -> f64 {
    12.0
}
fn default_transition_m() -> f64 {
    10.0
}

/// The route of a scenario (the `[route]` table).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RouteSpec {
    /// Close the loop (heading and position) so that laps can be repeated.
    #[serde(default)]
    pub closed: bool,
    /// Initial yaw, degrees counter-clockwise from east (default 0).
    #[serde(default)]
    pub start_yaw_deg: f64,
    /// Default clothoid length of turns, m (default 10).
    #[serde(default = "default_transition_m")]
    pub transition_m: f64,
    /// The segments, in driving order.
    pub segments: Vec<Segment>,
}

/// A piece of constant or linearly varying curvature.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    /// Distance from the start of the lap to the start of the piece, m.
    pub s0: f64,
    /// Length, m.
    pub len: f64,
    /// Curvature at the start, 1/m.
    pub k0: f64,
    /// Curvature at the end, 1/m.
    pub k1: f64,
    /// Yaw at the start, rad (unwrapped, relative to the lap start).
    pub psi0: f64,
}

impl Piece {
    fn kappa(&self, u: f64) -> f64 {
        if self.len > 0.0 {
            self.k0 + (self.k1 - self.k0) * u / self.len
        } else {
            self.k0
        }
    }
    fn psi(&self, u: f64) -> f64 {
        let dk = if self.len > 0.0 {
            (self.k1 - self.k0) / self.len
        } else {
            0.0
        };
        self.psi0 + self.k0 * u + 0.5 * dk * u * u
    }
}

/// A speed zone: one segment of one lap.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Zone {
    /// Distance from the start of the route, m.
    pub s0: f64,
    /// Length, m (0 for a stop).
    pub len: f64,
    /// Speed limit of the segment, m/s, if it gives one.
    pub limit_mps: Option<f64>,
    /// Largest absolute curvature in the zone, 1/m.
    pub max_abs_kappa: f64,
    /// Standstill duration, s, for a stop.
    pub stop_s: Option<f64>,
    /// Distance backed up and driven again during the stop, m (0: none).
    pub reverse_m: f64,
}

/// A route expanded into pieces, repeated over laps.
#[derive(Debug, Clone)]
pub(crate) struct Route {
    pieces: Vec<Piece>,
    /// Speed zones over all laps.
    pub zones: Vec<Zone>,
    /// Length of one lap, m.
    pub lap_length_m: f64,
    /// Heading change of one lap, rad.
    pub lap_turn_rad: f64,
    /// Number of laps.
    pub laps: u32,
    /// Initial yaw, rad.
    pub start_yaw_rad: f64,
}

/// Where a route error is (key) and what it is.
pub(crate) type RouteError = (String, String);

struct Expanded {
    pieces: Vec<Piece>,
    /// Per zone: index range into `pieces` and the zone without `s0`.
    zones: Vec<(std::ops::Range<usize>, Zone)>,
    /// Indices of the pieces that are straights (for closing the loop).
    straights: Vec<usize>,
}

impl Route {
    /// Expands `spec` and repeats it `laps` times.
    pub fn build(spec: &RouteSpec, laps: u32) -> Result<Route, RouteError> {
        let mut ex = expand(spec)?;
        let total: f64 = ex.pieces.iter().map(|p| p.len).sum();
        if total.is_nan() || total <= 0.0 {
            return Err(("route.segments".into(), "the route has no length".into()));
        }
        let start_yaw_rad = spec.start_yaw_deg.to_radians();
        if spec.closed {
            close_loop(&mut ex, start_yaw_rad)?;
        }
        // Cumulative distance and heading.
        let mut s = 0.0;
        let mut psi = 0.0;
        for p in &mut ex.pieces {
            p.s0 = s;
            p.psi0 = psi;
            s += p.len;
            psi += 0.5 * (p.k0 + p.k1) * p.len;
        }
        let lap_length_m = s;
        let lap_turn_rad = psi;
        let mut zones = Vec::with_capacity(ex.zones.len() * laps as usize);
        for lap in 0..laps {
            let offset = f64::from(lap) * lap_length_m;
            for (range, z) in &ex.zones {
                let (s0, len) = if range.is_empty() {
                    // A stop: at the start of the next piece.
                    let s0 = ex.pieces.get(range.start).map_or(lap_length_m, |p| p.s0);
                    (s0, 0.0)
                } else {
                    let s0 = ex.pieces[range.start].s0;
                    (s0, ex.pieces[range.clone()].iter().map(|p| p.len).sum())
                };
                zones.push(Zone {
                    s0: s0 + offset,
                    len,
                    ..*z
                });
            }
        }
        Ok(Route {
            pieces: ex.pieces,
            zones,
            lap_length_m,
            lap_turn_rad,
            laps,
            start_yaw_rad,
        })
    }

    /// Total length over all laps, m.
    pub fn length_m(&self) -> f64 {
        self.lap_length_m * f64::from(self.laps)
    }

    /// Curvature (1/m) and unwrapped yaw (rad) at distance `s` from the start.
    /// `s` is clamped to the route.
    pub fn eval(&self, s: f64) -> (f64, f64) {
        let s = s.clamp(0.0, self.length_m());
        let lap = ((s / self.lap_length_m).floor() as u32).min(self.laps.saturating_sub(1));
        let u = s - f64::from(lap) * self.lap_length_m;
        let i = self.pieces.partition_point(|p| p.s0 <= u).saturating_sub(1);
        let p = &self.pieces[i];
        let du = (u - p.s0).clamp(0.0, p.len);
        let psi = self.start_yaw_rad + f64::from(lap) * self.lap_turn_rad + p.psi(du);
        (p.kappa(du), psi)
    }
}

/// Largest length, radius or speed limit accepted in a segment.
const MAX_LENGTH_M: f64 = 1e6;

fn kmh(v: Option<f64>) -> Option<f64> {
    v.map(|v| v / 3.6)
}

/// Adds a turn's pieces (clothoid, arc, clothoid) and returns its largest |κ|.
fn push_turn(pieces: &mut Vec<Piece>, angle_rad: f64, radius_m: f64, transition_m: f64) -> f64 {
    let k = angle_rad.signum() / radius_m;
    let arc = radius_m * angle_rad.abs();
    let lt = transition_m.min(arc);
    let piece = |len, k0, k1| Piece {
        s0: 0.0,
        len,
        k0,
        k1,
        psi0: 0.0,
    };
    if lt > 0.0 {
        pieces.push(piece(lt, 0.0, k));
    }
    if arc - lt > 0.0 {
        pieces.push(piece(arc - lt, k, k));
    }
    if lt > 0.0 {
        pieces.push(piece(lt, k, 0.0));
    }
    k.abs()
}

fn expand(spec: &RouteSpec) -> Result<Expanded, RouteError> {
    let bad =
        |i: usize, key: &str, msg: &str| (format!("route.segments[{i}].{key}"), msg.to_string());
    // Bounded so that every derived quantity stays finite and step counts fit.
    let positive = |i: usize, key: &str, v: f64| {
        if v.is_finite() && (0.01..=MAX_LENGTH_M).contains(&v) {
            Ok(())
        } else {
            Err(bad(
                i,
                key,
                &format!("must be a number within 0.01..={MAX_LENGTH_M}, got {v}"),
            ))
        }
    };
    let limit = |i: usize, v: Option<f64>| v.map_or(Ok(()), |v| positive(i, "speed_limit_kmh", v));
    if !(spec.transition_m.is_finite() && spec.transition_m >= 0.0) {
        return Err((
            "route.transition_m".into(),
            "must be a non-negative number".into(),
        ));
    }
    if !spec.start_yaw_deg.is_finite() {
        return Err(("route.start_yaw_deg".into(), "must be finite".into()));
    }
    let mut pieces = Vec::new();
    let mut zones = Vec::new();
    let mut straights = Vec::new();
    let zone = |limit_mps, max_abs_kappa, stop_s| Zone {
        s0: 0.0,
        len: 0.0,
        limit_mps,
        max_abs_kappa,
        stop_s,
        reverse_m: 0.0,
    };
    for (i, seg) in spec.segments.iter().enumerate() {
        let start = pieces.len();
        match *seg {
            Segment::Straight {
                length_m,
                speed_limit_kmh,
            } => {
                positive(i, "length_m", length_m)?;
                limit(i, speed_limit_kmh)?;
                straights.push(pieces.len());
                pieces.push(Piece {
                    s0: 0.0,
                    len: length_m,
                    k0: 0.0,
                    k1: 0.0,
                    psi0: 0.0,
                });
                zones.push((start..pieces.len(), zone(kmh(speed_limit_kmh), 0.0, None)));
            }
            Segment::Turn {
                angle_deg,
                radius_m,
                speed_limit_kmh,
                transition_m,
            } => {
                positive(i, "radius_m", radius_m)?;
                if !(angle_deg.is_finite() && angle_deg != 0.0) {
                    return Err(bad(i, "angle_deg", "must be a non-zero number"));
                }
                limit(i, speed_limit_kmh)?;
                let lt = transition_m.unwrap_or(spec.transition_m);
                if !(lt.is_finite() && lt >= 0.0) {
                    return Err(bad(i, "transition_m", "must be a non-negative number"));
                }
                let k = push_turn(&mut pieces, angle_deg.to_radians(), radius_m, lt);
                zones.push((start..pieces.len(), zone(kmh(speed_limit_kmh), k, None)));
            }
            Segment::Roundabout {
                circle_deg,
                radius_m,
                deflection_deg,
                deflection_radius_m,
                speed_limit_kmh,
            } => {
                positive(i, "radius_m", radius_m)?;
                positive(i, "deflection_radius_m", deflection_radius_m)?;
                if !(circle_deg.is_finite() && circle_deg != 0.0) {
                    return Err(bad(i, "circle_deg", "must be a non-zero number"));
                }
                if !(deflection_deg.is_finite() && deflection_deg >= 0.0) {
                    return Err(bad(i, "deflection_deg", "must be a non-negative number"));
                }
                limit(i, speed_limit_kmh)?;
                let dir = circle_deg.signum();
                let lt = spec.transition_m;
                let lim = kmh(speed_limit_kmh);
                for (angle, radius) in [
                    (-dir * deflection_deg, deflection_radius_m),
                    (circle_deg, radius_m),
                    (-dir * deflection_deg, deflection_radius_m),
                ] {
                    if angle != 0.0 {
                        let first = pieces.len();
                        let k = push_turn(&mut pieces, angle.to_radians(), radius, lt);
                        zones.push((first..pieces.len(), zone(lim, k, None)));
                    }
                }
            }
            Segment::Stop {
                duration_s,
                reverse_m,
            } => {
                if !(duration_s.is_finite() && duration_s >= 0.0) {
                    return Err(bad(i, "duration_s", "must be a non-negative number"));
                }
                let reverse_m = reverse_m.unwrap_or(0.0);
                if !(reverse_m.is_finite() && reverse_m >= 0.0) {
                    return Err(bad(i, "reverse_m", "must be a non-negative number"));
                }
                let back: f64 = pieces.iter().map(|p| p.len).sum();
                if reverse_m > back {
                    return Err(bad(
                        i,
                        "reverse_m",
                        "is longer than the path driven before the stop",
                    ));
                }
                zones.push((
                    start..start,
                    Zone {
                        reverse_m,
                        ..zone(None, 0.0, Some(duration_s))
                    },
                ));
            }
        }
    }
    Ok(Expanded {
        pieces,
        zones,
        straights,
    })
}

/// Position of the end of the pieces relative to their start (yaw `yaw0`),
/// by Simpson's rule on sub-steps of at most 0.25 m.
fn end_offset(pieces: &[Piece], yaw0: f64) -> (f64, f64) {
    let (mut x, mut y, mut psi) = (0.0, 0.0, yaw0);
    for p in pieces {
        let q = Piece { psi0: psi, ..*p };
        let n = 2 * ((p.len / 0.5).ceil() as usize).max(1);
        let h = p.len / n as f64;
        for j in 0..=n {
            let w = if j == 0 || j == n {
                1.0
            } else if j % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let a = q.psi(j as f64 * h);
            x += w * h / 3.0 * a.cos();
            y += w * h / 3.0 * a.sin();
        }
        psi = q.psi(p.len);
    }
    (x, y)
}

/// Closes a loop: checks the total turn, then adjusts two straights.
fn close_loop(ex: &mut Expanded, yaw0: f64) -> Result<(), RouteError> {
    let turn: f64 = ex.pieces.iter().map(|p| 0.5 * (p.k0 + p.k1) * p.len).sum();
    let turns = (turn / std::f64::consts::TAU).round();
    if (turn - turns * std::f64::consts::TAU).abs() > 1e-6 || turns == 0.0 {
        return Err((
            "route.closed".into(),
            format!(
                "a closed route must turn by a non-zero multiple of 360°, this one turns by {:.4}°",
                turn.to_degrees()
            ),
        ));
    }
    // Yaw along each straight.
    let mut psi = yaw0;
    let mut yaw = vec![0.0; ex.pieces.len()];
    for (i, p) in ex.pieces.iter().enumerate() {
        yaw[i] = psi;
        psi += 0.5 * (p.k0 + p.k1) * p.len;
    }
    // Of all pairs of straights at an angle, the one that closes the gap with the
    // smallest relative change of its lengths: solve da·ua + db·ub = −gap.
    let (gx, gy) = end_offset(&ex.pieces, yaw0);
    let mut best: Option<(usize, f64, usize, f64, f64)> = None;
    for (ia, &a) in ex.straights.iter().enumerate() {
        for &b in &ex.straights[ia + 1..] {
            let (ua, ub) = ((yaw[a].cos(), yaw[a].sin()), (yaw[b].cos(), yaw[b].sin()));
            let det = ua.0 * ub.1 - ua.1 * ub.0;
            if det.abs() < 0.3 {
                continue;
            }
            let da = (-gx * ub.1 + gy * ub.0) / det;
            let db = (-ua.0 * gy + ua.1 * gx) / det;
            let (la, lb) = (ex.pieces[a].len, ex.pieces[b].len);
            if la + da < 1.0 || lb + db < 1.0 {
                continue;
            }
            let change = (da / la).abs().max((db / lb).abs());
            if best.is_none_or(|(.., c)| change < c) {
                best = Some((a, da, b, db, change));
            }
        }
    }
    let Some((a, da, b, db, _)) = best else {
        return Err((
            "route.closed".into(),
            format!(
                "cannot close the loop (gap {:.1} m east, {:.1} m north) by changing the length of two \
                 straights at an angle; adjust the segments",
                gx, gy
            ),
        ));
    };
    ex.pieces[a].len += da;
    ex.pieces[b].len += db;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square(closed: bool) -> RouteSpec {
        let mut segments = Vec::new();
        for (i, len) in [100.0, 80.0, 110.0, 70.0].into_iter().enumerate() {
            segments.push(Segment::Straight {
                length_m: len + i as f64,
                speed_limit_kmh: None,
            });
            segments.push(Segment::Turn {
                angle_deg: 90.0,
                radius_m: 10.0,
                speed_limit_kmh: None,
                transition_m: None,
            });
        }
        RouteSpec {
            closed,
            start_yaw_deg: 30.0,
            transition_m: 10.0,
            segments,
        }
    }

    #[test]
    fn closed_loop_returns_to_start() {
        let r = Route::build(&square(true), 2).unwrap();
        let (gx, gy) = end_offset(&r.pieces, r.start_yaw_rad);
        assert!(gx.hypot(gy) < 1e-6, "gap {gx} {gy}");
        assert!((r.lap_turn_rad - std::f64::consts::TAU).abs() < 1e-12);
        let (k, psi) = r.eval(r.lap_length_m * 1.5);
        assert!(k.is_finite() && psi > r.lap_turn_rad);
    }

    #[test]
    fn curvature_is_continuous() {
        let r = Route::build(&square(false), 1).unwrap();
        let mut prev = r.eval(0.0).0;
        let mut s = 0.0;
        while s < r.length_m() {
            s += 0.01;
            let k = r.eval(s).0;
            assert!(
                (k - prev).abs() < 0.1 / 10.0 * 0.011 + 1e-12,
                "curvature step at {s}"
            );
            prev = k;
        }
    }

    #[test]
    fn open_loop_turn_of_wrong_total_is_rejected() {
        let mut spec = square(true);
        spec.segments.pop();
        assert!(Route::build(&spec, 1).is_err());
    }
}
