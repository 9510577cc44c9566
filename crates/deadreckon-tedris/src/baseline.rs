//! The plain baseline TedriS is compared with: what a user writes in an
//! afternoon. Heading increments between consecutive GNSS courses (taken only
//! above a speed, wrapped, never unwrapped) are regressed without intercept on
//! the rear wheels' increments over the same interval:
//!
//! `Δθ = g·Δω + b·Δd`
//!
//! (ω = right − left wheel distance, m; d = mean distance, m), so `g` is the
//! inverse effective track (rad/m) and `b` the heading per metre of a rear
//! radius mismatch. Through an outage the heading starts from the courses of
//! the last `anchor_s` seconds (each carried to the outage start by the wheels,
//! averaged on the circle) and the position from the last fix (lever arm
//! removed), and both are integrated from the wheels alone.

use serde::{Deserialize, Serialize};

use deadreckon_core::angle::wrap;
use deadreckon_core::Drive;

use crate::input::{drive_input, Event, ReferenceSource};
use crate::machine::WheelSample;
use crate::outage::{Outage, OutageError};
use crate::Error;

/// Smallest wheel speed at which a course is used, m/s.
pub const MIN_SPEED_MPS: f64 = 2.0;
/// Courses before the outage start that anchor the heading, s.
pub const ANCHOR_S: f64 = 5.0;

/// The fitted baseline.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Baseline {
    /// Heading per metre of right − left wheel distance, rad/m.
    pub gain_rad_per_m: f64,
    /// Heading per metre travelled, rad/m.
    pub per_metre_rad: f64,
    /// Course increments used.
    pub pairs: usize,
}

/// What the baseline reads of a drive.
struct Streams {
    wheels: Vec<WheelSample>,
    /// (t, yaw of the course), every course.
    courses: Vec<(f64, f64)>,
    /// (t, east, north) of the antenna.
    fixes: Vec<(f64, f64, f64)>,
}

/// The streams of a drive, GNSS hidden in `blank`.
fn streams(drive: &Drive, blank: &[(f64, f64)]) -> Result<Streams, Error> {
    let input = drive_input(drive, Some(ReferenceSource::GnssCourse), blank)?;
    let mut s = Streams {
        wheels: Vec::new(),
        courses: Vec::new(),
        fixes: Vec::new(),
    };
    for e in &input.events {
        match e {
            Event::Wheel(w) => s.wheels.push(*w),
            Event::Heading(h) => s.courses.push((h.t_s, h.yaw_rad)),
            Event::Fix(f) => s.fixes.push((f.t_s, f.east_m, f.north_m)),
        }
    }
    Ok(s)
}

/// Wheel increments (Σω, Σd) over the samples with `a < t ≤ b`; `None` when
/// none, or the mean speed is below [`MIN_SPEED_MPS`].
fn increments(wheels: &[WheelSample], a: f64, b: f64) -> Option<(f64, f64)> {
    let i = wheels.partition_point(|w| w.t_s <= a);
    let j = wheels.partition_point(|w| w.t_s <= b);
    if j <= i {
        return None;
    }
    let (mut w, mut d) = (0.0, 0.0);
    for s in &wheels[i..j] {
        w += s.right_m - s.left_m;
        d += 0.5 * (s.left_m + s.right_m);
    }
    (d / (b - a) >= MIN_SPEED_MPS).then_some((w, d))
}

impl Baseline {
    /// The heading change of one wheel sample, rad.
    fn heading_step(&self, s: &WheelSample) -> f64 {
        self.gain_rad_per_m * (s.right_m - s.left_m)
            + self.per_metre_rad * 0.5 * (s.left_m + s.right_m)
    }

    /// Fits the baseline on a drive with GNSS courses: increments between
    /// consecutive courses.
    pub fn fit(drive: &Drive) -> Result<Baseline, Error> {
        let Streams {
            wheels, courses, ..
        } = streams(drive, &[])?;
        let pairs: Vec<(f64, f64, f64)> = courses
            .windows(2)
            .filter(|c| c[1].0 - c[0].0 <= 1.0)
            .map(|c| (c[0].0, c[1].0, wrap(c[1].1 - c[0].1)))
            .collect();
        Self::fit_pairs(&wheels, &pairs)
    }

    /// The block baseline: [`Baseline::fit`] on increments over blocks of
    /// at least `block_s` seconds (consecutive, not overlapping; a block
    /// ends at a gap of more than 1 s between courses), the course change
    /// summed over the block's consecutive courses. Over a block the wheel
    /// ticks' quantisation does not accumulate (one tick per wheel at each
    /// end), while between consecutive courses at 10 Hz it is as large as
    /// the turn (issue 35: 2 s blocks, k = 0.96–0.98 of 1/track on 48-tooth
    /// ticks at 100 Hz).
    pub fn fit_blocks(drive: &Drive, block_s: f64) -> Result<Baseline, Error> {
        let Streams {
            wheels, courses, ..
        } = streams(drive, &[])?;
        let mut pairs = Vec::new();
        let mut i = 0;
        while i + 1 < courses.len() {
            let (ta, ya) = courses[i];
            let mut y = ya;
            let mut j = i;
            while j + 1 < courses.len()
                && courses[j + 1].0 - courses[j].0 <= 1.0
                && courses[j].0 - ta < block_s
            {
                y += wrap(courses[j + 1].1 - courses[j].1);
                j += 1;
            }
            if j > i && courses[j].0 - ta >= block_s {
                pairs.push((ta, courses[j].0, y - ya));
            }
            i = j.max(i + 1);
        }
        Self::fit_pairs(&wheels, &pairs)
    }

    /// Least squares over course increments `(t_a, t_b, Δθ)`.
    fn fit_pairs(wheels: &[WheelSample], pairs: &[(f64, f64, f64)]) -> Result<Baseline, Error> {
        let (mut sww, mut swd, mut sdd, mut swy, mut sdy, mut n) = (0.0, 0.0, 0.0, 0.0, 0.0, 0);
        for &(ta, tb, y) in pairs {
            // Speeds at both courses above the gate, and over the interval.
            let around = |t: f64| increments(wheels, t - 0.5, t + 0.5).is_some();
            let Some((w, d)) = increments(wheels, ta, tb) else {
                continue;
            };
            if !(around(ta) && around(tb)) {
                continue;
            }
            sww += w * w;
            swd += w * d;
            sdd += d * d;
            swy += w * y;
            sdy += d * y;
            n += 1;
        }
        let det = sww * sdd - swd * swd;
        if n < 50 || det.abs() <= f64::EPSILON * sww * sdd {
            return Err(Error::Insufficient(format!(
                "the baseline needs at least 50 course increments above {MIN_SPEED_MPS} m/s with turns; found {n}"
            )));
        }
        Ok(Baseline {
            gain_rad_per_m: (swy * sdd - sdy * swd) / det,
            per_metre_rad: (sdy * sww - swy * swd) / det,
            pairs: n,
        })
    }

    /// Dead reckoning through `outage` of `drive`, its error against the truth
    /// (rear-axle centre) at every wheel sample.
    pub fn run_outage(&self, drive: &Drive, outage: &Outage) -> Result<OutageError, Error> {
        let Streams {
            wheels,
            courses,
            fixes,
        } = streams(drive, &[(outage.start_s, outage.end_s)])?;
        let t0 = outage.start_s;
        let turn = |a: f64, b: f64| -> f64 {
            let i = wheels.partition_point(|w| w.t_s <= a);
            let j = wheels.partition_point(|w| w.t_s <= b);
            wheels[i..j].iter().map(|s| self.heading_step(s)).sum()
        };
        // Heading: the courses of the last ANCHOR_S seconds at speed, carried to t0.
        let (mut sx, mut sy) = (0.0, 0.0);
        for &(t, y) in courses.iter().filter(|c| c.0 < t0 && c.0 >= t0 - ANCHOR_S) {
            if increments(&wheels, t - 0.5, t + 0.5).is_some() {
                let h = y + turn(t, t0);
                sx += h.cos();
                sy += h.sin();
            }
        }
        let last_course = courses
            .iter()
            .rev()
            .find(|c| c.0 < t0 && increments(&wheels, c.0 - 0.5, c.0 + 0.5).is_some());
        let yaw = if sx != 0.0 || sy != 0.0 {
            sy.atan2(sx)
        } else if let Some(&(t, y)) = last_course {
            y + turn(t, t0)
        } else {
            return Err(Error::Insufficient(format!(
                "no course before the outage at {t0} s"
            )));
        };
        // Position: the last fix, lever arm removed, carried to t0 by the wheels.
        let Some(&(tf, e, n)) = fixes.iter().rev().find(|f| f.0 < t0) else {
            return Err(Error::Insufficient(format!(
                "no fix before the outage at {t0} s"
            )));
        };
        let l = drive.vehicle.gnss_lever_arm_m;
        let back = turn(tf, t0);
        let yaw_f = yaw - back;
        let (mut x, mut y) = (e - l * yaw_f.cos(), n - l * yaw_f.sin());
        let mut h = yaw_f;
        let mut errs = Vec::new();
        let i = wheels.partition_point(|w| w.t_s <= tf);
        for s in &wheels[i..] {
            if s.t_s >= outage.end_s {
                break;
            }
            let dh = self.heading_step(s);
            let d = 0.5 * (s.left_m + s.right_m);
            let mid = h + 0.5 * dh;
            x += d * mid.cos();
            y += d * mid.sin();
            h += dh;
            if s.t_s > t0 {
                if let Some((te, tn)) = crate::outage::truth_at(drive, s.t_s) {
                    errs.push((s.t_s, (x - te).hypot(y - tn)));
                }
            }
        }
        let n = errs.len();
        Ok(crate::outage::summarise_errors(
            outage,
            deadreckon_core::compared::Against::Truth,
            &errs,
            n,
            n,
            1.0,
        ))
    }
}
