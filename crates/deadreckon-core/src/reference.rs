//! A state trajectory sampled at known times, interpolated at any time: used for
//! the truth (with speed and yaw rate derived by finite differences where the
//! file does not give them) and for smoothed estimates.

use std::sync::atomic::{AtomicUsize, Ordering};

use crate::drive::TruthPose;
use crate::model::{State, X, Y};

/// States at increasing times, linearly interpolated between samples.
///
/// [`Reference::state_at`] searches from where its last call ended (a
/// pass over a drive asks for increasing times: a step or two instead of a
/// binary search; any order gives the same answers).
#[derive(Debug, Default)]
pub struct Reference {
    /// Sample times, s, strictly increasing.
    pub t: Vec<f64>,
    /// States (yaw continuous, not wrapped).
    pub x: Vec<State>,
    /// Where the last search ended (a hint only, shared by threads).
    hint: AtomicUsize,
}

impl Clone for Reference {
    fn clone(&self) -> Self {
        Reference::from_states(self.t.clone(), self.x.clone())
    }
}

impl Reference {
    /// Builds the reference from `truth.csv` poses: yaw is unwrapped, speed is
    /// `speed_mps` when every pose has it, else the central difference of position
    /// projected on the heading; the yaw rate is the central difference of yaw.
    /// Returns `None` with fewer than 3 poses.
    pub fn from_truth(truth: &[TruthPose]) -> Option<Reference> {
        let n = truth.len();
        if n < 3 {
            return None;
        }
        let yaw = crate::angle::unwrap(&truth.iter().map(|p| p.yaw_rad).collect::<Vec<_>>());
        let have_speed = truth.iter().all(|p| p.speed_mps.is_some());
        let mut x = Vec::with_capacity(n);
        for i in 0..n {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            let dt = truth[b].t_s - truth[a].t_s;
            let v = if have_speed {
                truth[i].speed_mps.unwrap_or(0.0)
            } else {
                let (de, dn) = (
                    truth[b].east_m - truth[a].east_m,
                    truth[b].north_m - truth[a].north_m,
                );
                (de * yaw[i].cos() + dn * yaw[i].sin()) / dt
            };
            let w = (yaw[b] - yaw[a]) / dt;
            x.push(State::from([
                truth[i].east_m,
                truth[i].north_m,
                yaw[i],
                v,
                w,
            ]));
        }
        Some(Reference::from_states(
            truth.iter().map(|p| p.t_s).collect(),
            x,
        ))
    }

    /// Builds a reference from states at times (e.g. smoothed epochs).
    pub fn from_states(t: Vec<f64>, x: Vec<State>) -> Reference {
        Reference {
            t,
            x,
            hint: AtomicUsize::new(0),
        }
    }

    /// The interpolated state at `t`, or `None` outside the covered time span.
    pub fn state_at(&self, t: f64) -> Option<State> {
        Some(match bracket(&self.t, |k| self.t[k], t, &self.hint)? {
            Bracket::Last => self.x[self.t.len() - 1],
            Bracket::Between(i, a) => self.x[i - 1] * (1.0 - a) + self.x[i] * a,
        })
    }

    /// Cumulative travelled distance (m) at each sample, from the positions.
    pub fn distance(&self) -> Vec<f64> {
        let mut d = Vec::with_capacity(self.x.len());
        let mut acc = 0.0;
        for i in 0..self.x.len() {
            if i > 0 {
                acc += (self.x[i][X] - self.x[i - 1][X]).hypot(self.x[i][Y] - self.x[i - 1][Y]);
            }
            d.push(acc);
        }
        d
    }

    /// Time span covered.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((*self.t.first()?, *self.t.last()?))
    }
}

/// The truth's positions borrowed from the drive's poses, interpolated at
/// any time: [`Reference::from_truth`]'s east and north, bit for bit,
/// without its copy of every pose as a state (48 B a pose: 17.3 MB on the
/// bench's hour of 100 Hz truth, held by `evaluate --outage` beside the
/// drive; docs/performance.md, "Sixth round"). For what reads only the
/// positions (the outage windows' errors against the truth).
#[derive(Debug)]
pub struct TruthPositions<'a> {
    poses: &'a [TruthPose],
    /// Where the last search ended (a hint only, as [`Reference`]'s).
    hint: AtomicUsize,
}

impl<'a> TruthPositions<'a> {
    /// The positions of `truth`; `None` with fewer than 3 poses, as
    /// [`Reference::from_truth`].
    pub fn new(truth: &'a [TruthPose]) -> Option<Self> {
        (truth.len() >= 3).then(|| TruthPositions {
            poses: truth,
            hint: AtomicUsize::new(0),
        })
    }

    /// The interpolated `(east, north)` at `t`, m, or `None` outside the
    /// covered time span: [`Reference::state_at`]'s `X` and `Y`.
    pub fn position_at(&self, t: f64) -> Option<(f64, f64)> {
        let p = self.poses;
        Some(match bracket(p, |k| p[k].t_s, t, &self.hint)? {
            Bracket::Last => (p[p.len() - 1].east_m, p[p.len() - 1].north_m),
            // Term by term as `State * f64 + State * f64` is, so the same bits.
            Bracket::Between(i, a) => (
                p[i - 1].east_m * (1.0 - a) + p[i].east_m * a,
                p[i - 1].north_m * (1.0 - a) + p[i].north_m * a,
            ),
        })
    }

    /// Time span covered.
    pub fn span(&self) -> Option<(f64, f64)> {
        Some((self.poses.first()?.t_s, self.poses.last()?.t_s))
    }
}

/// Where `t` falls among `n = samples.len()` increasing sample times
/// (`time_at(k)`): past the last sample, or between samples `i − 1` and
/// `i` at fraction `a`; `None` outside the span. The search starts from
/// `hint` and leaves it where it ended ([`crate::cursor::partition_from`]).
enum Bracket {
    Last,
    Between(usize, f64),
}

fn bracket<T>(
    samples: &[T],
    time_at: impl Fn(usize) -> f64,
    t: f64,
    hint: &AtomicUsize,
) -> Option<Bracket> {
    let n = samples.len();
    if n == 0 || !(t >= time_at(0) && t <= time_at(n - 1)) {
        return None;
    }
    let i = crate::cursor::partition_from(n, &time_at, t, hint.load(Ordering::Relaxed));
    hint.store(i, Ordering::Relaxed);
    if i >= n {
        return Some(Bracket::Last);
    }
    let i = i.max(1);
    let (t0, t1) = (time_at(i - 1), time_at(i));
    let a = if t1 > t0 { (t - t0) / (t1 - t0) } else { 0.0 };
    Some(Bracket::Between(i, a))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{V, YAW_RATE};
    #[test]
    fn derives_speed_and_yaw_rate_on_a_circle() {
        let r = 20.0;
        let v = 5.0;
        let w = v / r;
        let truth: Vec<TruthPose> = (0..2000)
            .map(|i| {
                let t = i as f64 * 0.01;
                let a = w * t;
                TruthPose {
                    t_s: t,
                    east_m: r * a.sin(),
                    north_m: r * (1.0 - a.cos()),
                    yaw_rad: crate::angle::wrap(a),
                    speed_mps: None,
                }
            })
            .collect();
        let rf = Reference::from_truth(&truth).unwrap();
        let s = rf.state_at(12.345).unwrap();
        assert!((s[V] - v).abs() < 1e-3, "{}", s[V]);
        assert!((s[YAW_RATE] - w).abs() < 1e-6);
        assert!(rf.state_at(-1.0).is_none());
    }

    #[test]
    fn truth_positions_are_the_references_east_and_north_bit_for_bit() {
        // Uneven times, a repeated time, positions far from the origin.
        let truth: Vec<TruthPose> = (0..500)
            .map(|i| {
                let t = i as f64 * 0.01 + if i % 7 == 0 { 0.003 } else { 0.0 };
                TruthPose {
                    t_s: if i == 250 { 249.0 * 0.01 } else { t },
                    east_m: 4.0e5 + (i as f64 * 0.37).sin() * 30.0,
                    north_m: -2.0e5 + i as f64 * 0.11,
                    yaw_rad: 0.1 * i as f64,
                    speed_mps: None,
                }
            })
            .collect();
        let rf = Reference::from_truth(&truth).unwrap();
        let tp = TruthPositions::new(&truth).unwrap();
        assert_eq!(tp.span(), rf.span());
        // Times in a scrambled order (the hint must not matter), inside
        // and outside the span, on samples and between them.
        let mut k: u64 = 0x9e37_79b9_7f4a_7c15;
        for j in 0..3000 {
            k = k
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let t = if j % 3 == 0 {
                truth[(k >> 33) as usize % truth.len()].t_s
            } else {
                (k >> 11) as f64 / (1u64 << 53) as f64 * 5.2 - 0.1
            };
            let want = rf.state_at(t).map(|x| (x[X].to_bits(), x[Y].to_bits()));
            let got = tp.position_at(t).map(|(e, n)| (e.to_bits(), n.to_bits()));
            assert_eq!(got, want, "at t = {t}");
        }
        assert!(TruthPositions::new(&truth[..2]).is_none());
    }
}
