//! The 95 % bound ([`crate::bound`]) on every pose a filter gives: `run`'s
//! tracks and the online filter's poses, by one rule so that `stream`
//! equals `run` on the same epochs.
//!
//! **The rule.** A pose of the four-wheel filter (rear axle, covariance
//! `P` of east/north) gets `r(k² P + σ² I)`, `k` the fitted factor
//! ([`BoundFit`]) and `σ` the declared accuracy of the last GNSS fix at
//! or before the pose's time that the filter was given (hidden fixes of
//! `gnss_outages` do not count): the receiver's offset that the filter
//! cannot see ([`crate::bound`]'s floor, which the factor does not
//! inflate). In an outage that fix is the
//! last one handed over, as `evaluate --outage` computes it; where GNSS
//! is present it is the latest fix, and the bound is the bound of the
//! filtered position. A pose before any fix gets the filter's covariance
//! alone (`σ = 0`), and so does every pose of a filter that carries the
//! receiver's wander ([`crate::gnss_error`]): its covariance holds the
//! receiver's offset then, which the floor would count a second time
//! ([`carries_wander`]).

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::bound::{BoundFit, Cov2};
use crate::drive::GnssFix;
use crate::track::{Track, TrackPoint};

/// A filter's pose with its 95 % horizontal bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The pose and its covariance.
    pub point: TrackPoint,
    /// The 95 % bound of its position, m.
    pub bound_95_m: f64,
}

/// The 95 % bound of the rear-axle position of `p` with the receiver's
/// declared accuracy `receiver_std_m` (the module's rule), m.
pub fn point_bound_m(fit: &BoundFit, p: &TrackPoint, receiver_std_m: f64) -> f64 {
    let cov = Cov2 {
        ee_m2: p.cov_pose[0],
        en_m2: 0.5 * (p.cov_pose[1] + p.cov_pose[3]),
        nn_m2: p.cov_pose[4],
    };
    fit.floored_bound_m(&cov, &Cov2::circular(receiver_std_m))
}

/// Whether the filter of a vehicle with `noise` carries the receiver's
/// wander as states: then the bound has no receiver's floor (the module's
/// rule).
pub fn carries_wander(noise: &crate::vehicle::Noise) -> bool {
    noise.gnss_wander_std_m > 0.0
}

/// The most fixes [`FixFloor`] keeps ahead of the poses (a stream's fixes
/// run at most a reorder window ahead of its epochs).
const KEPT_FIXES: usize = 256;

/// The declared accuracy of the last fix at or before a time, for poses
/// asked in time order: the fixes given (time order) and not yet passed
/// by a pose.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct FixFloor {
    /// `(t_s, declared std_m)`: the last fix at or before the last pose
    /// asked, then those after it.
    fixes: VecDeque<(f64, f64)>,
    /// The filter carries the receiver's wander: no floor
    /// ([`carries_wander`]).
    #[serde(default)]
    wander_carried: bool,
}

impl FixFloor {
    /// The floor of a filter that carries the receiver's wander or not
    /// ([`carries_wander`]): with it, every pose's floor is 0.
    pub fn new(wander_carried: bool) -> Self {
        FixFloor {
            fixes: VecDeque::new(),
            wander_carried,
        }
    }

    /// Takes a fix given to the filter; one not later than the last taken
    /// (the online filter replays its first events once started) is
    /// ignored.
    pub fn push(&mut self, fix: &GnssFix) {
        if self.fixes.back().is_some_and(|b| fix.t_s <= b.0) {
            return;
        }
        self.fixes
            .push_back((fix.t_s, crate::bound::receiver_std_m(fix)));
        if self.fixes.len() > KEPT_FIXES {
            self.fixes.pop_front();
        }
    }

    /// The declared accuracy of the last fix at or before `t_s`, m (0
    /// before any); forgets the fixes before that one (ask in time order).
    pub fn std_at(&mut self, t_s: f64) -> f64 {
        while self.fixes.get(1).is_some_and(|f| f.0 <= t_s) {
            self.fixes.pop_front();
        }
        match self.fixes.front() {
            _ if self.wander_carried => 0.0,
            Some(&(t, s)) if t <= t_s => s,
            _ => 0.0,
        }
    }
}

/// The bounds of a filter's track given the fixes of `gnss` (those in
/// `hidden` windows left out), pose by pose, m: what the online filter
/// gives its poses ([`crate::online::Online::push_poses`]). No floor when
/// the filter carried the receiver's wander (`wander_carried`).
pub fn filtered_bounds_m(
    track: &Track,
    gnss: &[GnssFix],
    hidden: &[(f64, f64)],
    fit: &BoundFit,
    wander_carried: bool,
) -> Vec<f64> {
    let mut floor = FixFloor::new(wander_carried);
    let mut next = 0;
    track
        .points
        .iter()
        .map(|p| {
            while let Some(g) = gnss.get(next).filter(|g| g.t_s <= p.t_s) {
                if !crate::drive::in_windows(g.t_s, hidden) {
                    floor.push(g);
                }
                next += 1;
            }
            point_bound_m(fit, p, floor.std_at(p.t_s))
        })
        .collect()
}

/// The bounds of a track dead-reckoned from one start, m: the receiver's
/// floor is `start_std_m` throughout (the declared accuracy of the fix the
/// start was taken from; 0 from the truth or a given pose).
pub fn dead_reckoned_bounds_m(track: &Track, start_std_m: f64, fit: &BoundFit) -> Vec<f64> {
    track
        .points
        .iter()
        .map(|p| point_bound_m(fit, p, start_std_m))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(t_s: f64, std_m: f64) -> GnssFix {
        GnssFix {
            t_s,
            east_m: 0.0,
            north_m: 0.0,
            std_m,
            course_deg: None,
            speed_mps: None,
        }
    }

    fn point(t_s: f64, var_m2: f64) -> TrackPoint {
        TrackPoint {
            t_s,
            east_m: 0.0,
            north_m: 0.0,
            yaw_rad: 0.0,
            speed_mps: 0.0,
            yaw_rate_rps: 0.0,
            cov_pose: [var_m2, 0.0, 0.0, 0.0, var_m2, 0.0, 0.0, 0.0, 1e-4],
        }
    }

    #[test]
    fn the_floor_is_the_last_fix_at_or_before_the_pose() {
        let mut f = FixFloor::default();
        assert_eq!(f.std_at(0.5), 0.0);
        f.push(&fix(1.0, 2.0));
        f.push(&fix(2.0, 3.0));
        f.push(&fix(2.0, 9.0)); // a replayed (not later) fix: ignored
        assert_eq!(f.std_at(0.9), 0.0);
        assert_eq!(f.std_at(1.0), 2.0);
        assert_eq!(f.std_at(1.99), 2.0);
        assert_eq!(f.std_at(2.0), 3.0);
        assert_eq!(f.std_at(7.0), 3.0);
    }

    #[test]
    fn the_factor_inflates_the_filter_and_not_the_receivers_floor() {
        // Var 3 m² from the filter inflated by k² = 1.5² to 6.75 m², plus
        // 1 m std from the receiver: a circle of 7.75 m², whose 95 % radius
        // is √7.75 · √(−2 ln 0.05) = 6.8143 m.
        let fit = BoundFit {
            k: 1.5,
            ..BoundFit::FILTER
        };
        let b = point_bound_m(&fit, &point(0.0, 3.0), 1.0);
        let want = 7.75f64.sqrt() * (-2.0 * 0.05f64.ln()).sqrt();
        assert!((b - want).abs() < 1e-5 * want, "{b} vs {want}");
    }

    #[test]
    fn a_hidden_fix_is_not_the_floor_of_a_filtered_track() {
        let t = Track {
            name: "filtered".into(),
            points: vec![point(0.5, 1.0), point(1.5, 1.0), point(2.5, 1.0)],
            origin: None,
        };
        let gnss = [fix(1.0, 2.0), fix(2.0, 5.0)];
        let fit = BoundFit::FILTER;
        let b = filtered_bounds_m(&t, &gnss, &[(1.8, 2.2)], &fit, false);
        assert_eq!(b[0], point_bound_m(&fit, &t.points[0], 0.0));
        assert_eq!(b[1], point_bound_m(&fit, &t.points[1], 2.0));
        assert_eq!(b[2], point_bound_m(&fit, &t.points[2], 2.0));
        let open = filtered_bounds_m(&t, &gnss, &[], &fit, false);
        assert_eq!(open[2], point_bound_m(&fit, &t.points[2], 5.0));
        // A filter that carries the receiver's wander: no floor.
        let carried = filtered_bounds_m(&t, &gnss, &[], &fit, true);
        for (b, p) in carried.iter().zip(&t.points) {
            assert_eq!(*b, point_bound_m(&fit, p, 0.0));
        }
    }
}
