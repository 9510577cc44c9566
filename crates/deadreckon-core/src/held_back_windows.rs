//! The held-back windows of [`super`]: where the judgement hides fixes.

use super::{MIN_WINDOW_S, PERIOD_WINDOWS, WINDOW_S};
use crate::drive::Drive;
use crate::outage;

/// The two folds of held-back windows (module docs): alternate windows
/// every [`PERIOD_WINDOWS`] window lengths, the first as long after the
/// vehicle first moves, each ending a second before the last fix and the
/// last wheel row; the windows [`WINDOW_S`] long, or a sixth of the moving
/// span where that is shorter (not under [`MIN_WINDOW_S`]).
pub fn windows(drive: &Drive) -> [Vec<(f64, f64)>; 2] {
    let mut folds = [Vec::new(), Vec::new()];
    let n = drive.wheels.len();
    let (Some(first), Some(last)) = (drive.gnss.first(), drive.gnss.last()) else {
        return folds;
    };
    if n == 0 {
        return folds;
    }
    let (w0, w1) = (drive.wheels.t_s(0), drive.wheels.t_s(n - 1));
    // The first fix moving faster than a walk.
    let moving = drive
        .gnss
        .windows(2)
        .find(|p| {
            let dt = p[1].t_s - p[0].t_s;
            dt > 0.0
                && ((p[1].east_m - p[0].east_m).hypot(p[1].north_m - p[0].north_m) / dt)
                    > outage::MOVING_MPS
        })
        .map(|p| p[0].t_s)
        .unwrap_or(first.t_s)
        .max(w0);
    let end = last.t_s.min(w1) - 1.0;
    let window_s = ((end - moving) / 6.0).clamp(MIN_WINDOW_S, WINDOW_S);
    let period_s = PERIOD_WINDOWS * window_s;
    let mut a = moving + period_s;
    let mut k = 0;
    while a + window_s <= end {
        folds[k % 2].push((a, a + window_s));
        a += period_s;
        k += 1;
    }
    folds
}
