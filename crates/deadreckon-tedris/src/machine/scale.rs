//! The rear wheels' distance scale: how far the car really goes per metre the
//! rear wheels report (their mean circumference against the nominal one),
//! from GNSS chords. The heading model needs no scale (it is fitted on the
//! wheels' own distances), but the position does: a tyre 1 % larger than
//! nominal puts the dead-reckoned car 8 m short after 800 m.
//!
//! While the GNSS is good, each fix (lever arm removed) is kept beside the
//! unscaled dead-reckoned rear-axle position at its time. Chords of
//! [`CHORD_S`] between fixes of one continuous run (no gap, no outage) compare
//! the two: the scale is the least-squares ratio Σ Δg·Δr / Σ Δr·Δr. Like the
//! heading calibration, a scale is fitted on the first [`FIT_SHARE`] of the
//! window, refused when it reaches `max_distance_scale_error`, and accepted
//! only when it explains the held-back chords at least as well as the
//! current scale.

use super::*;
use crate::tuning::*;

/// One fix beside the unscaled dead-reckoned position at its time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub(super) struct ChordPoint {
    /// Time of the fix, s.
    pub t_s: f64,
    /// The fix moved to the rear-axle centre, east and north, m.
    pub fix: (f64, f64),
    /// The dead-reckoned rear-axle centre with unscaled wheel distances, m.
    pub raw: (f64, f64),
    /// The continuous run of fixes it belongs to.
    pub run: u32,
}

/// The chords of a window: (GNSS chord, unscaled DR chord), east and north, m.
type Chord = ((f64, f64), (f64, f64));

impl Tedris {
    /// Keeps a fix for the scale calibration (see the module documentation).
    pub(super) fn keep_chord_point(&mut self, t_s: f64, fix: (f64, f64), raw: (f64, f64)) {
        let run = match self.chord_points.back() {
            Some(p) if t_s - p.t_s <= CHORD_GAP_S => p.run,
            Some(p) => p.run + 1,
            None => 0,
        };
        self.chord_points
            .push_back(ChordPoint { t_s, fix, raw, run });
        let win = self.config.calibration_window_s;
        while self.chord_points.front().is_some_and(|p| t_s - p.t_s > win) {
            self.chord_points.pop_front();
        }
    }

    /// Non-overlapping chords of [`CHORD_S`] within runs, at least
    /// [`MIN_CHORD_M`] long, with their end times.
    fn chords(&self) -> Vec<(f64, Chord)> {
        let pts: Vec<&ChordPoint> = self.chord_points.iter().collect();
        let mut out = Vec::new();
        let mut i = 0;
        while i < pts.len() {
            let a = pts[i];
            let Some(j) = (i + 1..pts.len()).find(|&j| pts[j].t_s - a.t_s >= CHORD_S) else {
                break;
            };
            let b = pts[j];
            if b.run == a.run {
                let g = (b.fix.0 - a.fix.0, b.fix.1 - a.fix.1);
                let r = (b.raw.0 - a.raw.0, b.raw.1 - a.raw.1);
                if r.0.hypot(r.1) >= MIN_CHORD_M {
                    out.push((b.t_s, (g, r)));
                }
            }
            i = j;
        }
        out
    }

    /// Re-estimates the distance scale on the chords of the calibration
    /// window (the extended variant; see the module documentation).
    pub(super) fn calibrate_scale(&mut self) {
        let Some(model) = self.model.as_ref() else {
            return;
        };
        if !model.config.distance_scale() {
            return;
        }
        let chords = self.chords();
        let (Some(first), Some(last)) = (chords.first(), chords.last()) else {
            return;
        };
        let split = chords.partition_point(|c| c.0 < first.0 + FIT_SHARE * (last.0 - first.0));
        let (fit, held) = chords.split_at(split);
        if fit.len() < MIN_SCALE_CHORDS || held.len() < MIN_SCALE_CHORDS / 3 {
            return;
        }
        let (sgr, srr) = fit.iter().fold((0.0, 0.0), |(a, b), (_, (g, r))| {
            (a + g.0 * r.0 + g.1 * r.1, b + r.0 * r.0 + r.1 * r.1)
        });
        if srr <= 0.0 {
            return;
        }
        let k = sgr / srr;
        if !k.is_finite() || (k - 1.0).abs() >= model.config.max_distance_scale_error {
            // At or beyond the physical bound: refused, not clamped.
            self.refused_calibrations += 1;
            return;
        }
        let residual = |k: f64| -> f64 {
            held.iter()
                .map(|(_, (g, r))| (g.0 - k * r.0).powi(2) + (g.1 - k * r.1).powi(2))
                .sum()
        };
        if residual(k) > residual(model.distance_scale.value) {
            self.refused_calibrations += 1;
            return;
        }
        if let Some(m) = self.model.as_mut() {
            m.distance_scale = crate::model::DistanceScale {
                value: k,
                chords: fit.len(),
            };
        }
    }
}
