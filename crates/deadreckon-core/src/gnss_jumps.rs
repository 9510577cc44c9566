//! Jumps of the GNSS position that no vehicle can make: consecutive fixes
//! farther apart than [`MAX_SPEED_MPS`] allows over their time difference.
//!
//! A jump that comes back (an outlier fix, or a few) is what the filter's χ²
//! gate rejects and counts: the plausibility checks warn about it. A jump that
//! stays (every later fix displaced, a datum or base-station change, a
//! receiver restarting far away) is not an outlier the gate can hold: after
//! `gnss_max_rejections` the filter recovers onto the displaced fixes and the
//! calibration fits the jump into its parameters (measured with
//! `--skip-checks` on `simulate --scenario calibration --duration 300` with
//! every fix from the 299th on, 149 s, moved 1 km east: the steering ratio
//! 11.51 instead of 15.73, the circumferences' standard errors 0.038 m
//! instead of 0.0015 m). Such a drive is refused, with the time and size of
//! the jump.

use crate::drive::GnssFix;

/// A speed no vehicle here reaches, m/s (the fastest wheel of the plausibility
/// checks).
pub const MAX_SPEED_MPS: f64 = 90.0;
/// A jump back within this time makes the displaced fixes an outlier, s.
pub const RETURN_WITHIN_S: f64 = 10.0;

/// One impossible jump between consecutive fixes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    /// The time of the last fix before the jump, s.
    pub from_t_s: f64,
    /// The time of the first fix after it, s.
    pub to_t_s: f64,
    /// The distance between the two fixes, m.
    pub distance_m: f64,
    /// The index in the fixes of the first fix after the jump.
    pub index: usize,
    /// True when a later fix within [`RETURN_WITHIN_S`] is back where the
    /// vehicle could be: the displaced fixes are outliers.
    pub returns: bool,
}

/// Whether a vehicle can go from `a` to `b`: the distance within what
/// [`MAX_SPEED_MPS`] covers over their time difference plus ten times the
/// fixes' standard deviations.
fn reachable(a: &GnssFix, b: &GnssFix) -> bool {
    let d = (b.east_m - a.east_m).hypot(b.north_m - a.north_m);
    d <= MAX_SPEED_MPS * (b.t_s - a.t_s).abs() + 10.0 * (a.std_m + b.std_m)
}

/// The impossible jumps between consecutive `fixes` (in time order).
pub fn jumps(fixes: &[GnssFix]) -> Vec<Jump> {
    let mut out = Vec::new();
    let mut k = 1;
    while k < fixes.len() {
        let (a, b) = (&fixes[k - 1], &fixes[k]);
        if reachable(a, b) {
            k += 1;
            continue;
        }
        // Back within RETURN_WITHIN_S: the first later fix a vehicle could
        // reach from the last good one.
        let back = (k + 1..fixes.len())
            .take_while(|&j| fixes[j].t_s - b.t_s <= RETURN_WITHIN_S)
            .find(|&j| reachable(a, &fixes[j]));
        out.push(Jump {
            from_t_s: a.t_s,
            to_t_s: b.t_s,
            distance_m: (b.east_m - a.east_m).hypot(b.north_m - a.north_m),
            index: k,
            returns: back.is_some(),
        });
        // An outlier stretch counts once; after a jump that stays, the
        // displaced fixes are the new normal.
        k = back.map_or(k + 1, |j| j + 1);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn fix(t_s: f64, east_m: f64) -> GnssFix {
        GnssFix {
            t_s,
            east_m,
            north_m: 0.0,
            std_m: 0.5,
            course_deg: None,
            speed_mps: None,
        }
    }

    /// Fixes at 2 Hz along a straight at 10 m/s, with `shift` added to some.
    fn track(shift: impl Fn(usize) -> f64) -> Vec<GnssFix> {
        (0..100)
            .map(|i| fix(0.5 * i as f64, 5.0 * i as f64 + shift(i)))
            .collect()
    }

    #[test]
    fn a_straight_drive_has_no_jump() {
        assert!(jumps(&track(|_| 0.0)).is_empty());
    }

    #[test]
    fn one_outlier_fix_is_a_jump_that_returns() {
        let j = jumps(&track(|i| if i == 50 { 1000.0 } else { 0.0 }));
        assert_eq!(j.len(), 1, "{j:?}");
        assert!(j[0].returns);
        assert_eq!(j[0].index, 50);
        assert!((j[0].distance_m - 1005.0).abs() < 1e-9);
    }

    #[test]
    fn a_step_of_a_kilometre_is_a_jump_that_stays() {
        let j = jumps(&track(|i| if i >= 50 { 1000.0 } else { 0.0 }));
        assert_eq!(j.len(), 1, "{j:?}");
        assert!(!j[0].returns);
        assert_eq!((j[0].from_t_s, j[0].to_t_s), (24.5, 25.0));
    }

    #[test]
    fn a_jump_back_after_more_than_ten_seconds_stays() {
        // 30 fixes (15 s) displaced by 5 km (1 km is within what 90 m/s
        // covers in the 10 s after the jump back): two jumps, neither
        // returning in time.
        let j = jumps(&track(|i| if (50..80).contains(&i) { 5000.0 } else { 0.0 }));
        assert_eq!(j.len(), 2, "{j:?}");
        assert!(j.iter().all(|j| !j.returns));
    }
}
