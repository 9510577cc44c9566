//! Plausibility checks across the streams of a drive: the mistakes of units
//! and clocks that no single file shows (each file is valid on its own) but
//! that make a calibration converge to a confident wrong answer.
//!
//! Each check compares two things that must agree on a real vehicle and says
//! what disagrees and by how much:
//!
//! | check | compares | catches |
//! |---|---|---|
//! | `vehicle_lengths` | geometry with what vehicles measure | lengths in millimetres |
//! | `time_overlap` | each stream's time span with the wheels' | milliseconds, another clock |
//! | `wheel_speed_range` | the speed the wheel rows imply with 90 m/s | cumulative counters, wrong `ticks_per_rev` |
//! | `can_vs_wheel_speed` | CAN speed with the wheel speed | km/h, mph |
//! | `gnss_vs_wheel_distance` | GNSS displacement with the wheels' distance | wrong circumference or ticks, km/h wheel speeds, swapped lat/lon |
//! | `gnss_turns_vs_wheel_turns` | the GNSS track's turns with the wheels' | latitude and longitude swapped, east and north swapped |
//! | `gyro_vs_wheel_yaw_rate` | gyro with the rear wheels' yaw rate | a flipped sign, deg/s (skid steering turns less than the wheels say: only a gyro below 0.1 times them is suspicious) |
//! | `course_vs_track` | GNSS course with the direction of the GNSS track | radians, counter-clockwise from east |
//! | `stuck_gnss` | GNSS position with wheel motion | a receiver repeating its last fix |
//! | `gnss_jump` | consecutive fixes with the fastest a vehicle goes ([`crate::gnss_jumps`]) | a jump of the position that stays (refused) or outlier fixes (a warning: the gate rejects them) |
//! | `time_unit` | speeds as read (GNSS `speed_mps`, CAN, wheel speeds) with the speed between fixes over their times; the wheel rows' interval | every file's times in milliseconds at once (all spans agree, so `time_overlap` cannot see it) |
//!
//! A finding is an [`Severity::Error`] when the data cannot be right (the
//! commands refuse the drive), a [`Severity::Warning`] when it is suspicious.
//! The checks need motion (speed, turns) to say anything: a drive that
//! never moves passes them all.

use crate::drive::{Drive, Wheels};

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// The data cannot be right: refuse it.
    Error,
    /// Suspicious: say so and go on.
    Warning,
}

/// One failed check.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Finding {
    /// The check's name (see the module table).
    pub check: &'static str,
    /// Error or warning.
    pub severity: Severity,
    /// What disagrees and by how much.
    pub message: String,
}

/// Speeds below this do not enter the ratios, m/s.
const MIN_SPEED_MPS: f64 = 2.0;
/// A ratio of two speeds (or distances) outside [1/RATIO_TOLERANCE, RATIO_TOLERANCE]
/// is a units mistake (scale errors of real sensors are a few per cent).
const RATIO_TOLERANCE: f64 = 1.25;
/// The fastest a wheel of any vehicle here turns, m/s.
const MAX_WHEEL_SPEED_MPS: f64 = 90.0;

/// Runs every check on `drive`.
pub fn check(drive: &Drive) -> Vec<Finding> {
    let mut out = Vec::new();
    vehicle_lengths(drive, &mut out);
    time_overlap(drive, &mut out);
    let rows = wheel_rows(drive);
    let speed = wheel_speed(drive, &rows);
    wheel_speed_range(&speed, &mut out);
    // The ratios mean nothing when the wheel speed itself is impossible.
    if !out.iter().any(|f| f.check == "wheel_speed_range") {
        can_vs_wheel_speed(drive, &speed, &mut out);
        gnss_vs_wheel_distance(drive, &speed, &mut out);
        gyro_vs_wheel_yaw_rate(drive, &rows, &mut out);
        gnss_turns_vs_wheel_turns(drive, &rows, &speed, &mut out);
    }
    course_vs_track(drive, &mut out);
    stuck_gnss(drive, &speed, &mut out);
    time_unit(drive, &speed, &mut out);
    gnss_jump(drive, &mut out);
    out
}

fn gnss_jump(d: &Drive, out: &mut Vec<Finding>) {
    use crate::gnss_jumps::{jumps, MAX_SPEED_MPS, RETURN_WITHIN_S};
    let all = jumps(&d.gnss);
    for j in all.iter().filter(|j| !j.returns) {
        out.push(error(
            "gnss_jump",
            format!(
                "the GNSS position jumps {:.0} m between the fixes at {:.3} and {:.3} s \
                 (faster than {MAX_SPEED_MPS} m/s) and does not come back within {RETURN_WITHIN_S} s: \
                 a change of datum or base station, or a receiver restarting elsewhere? \
                 The fixes before and after cannot be fused; use the drive before or after it",
                j.distance_m, j.from_t_s, j.to_t_s
            ),
        ));
    }
    let outliers: Vec<_> = all.iter().filter(|j| j.returns).collect();
    if let Some(worst) = outliers
        .iter()
        .max_by(|a, b| a.distance_m.total_cmp(&b.distance_m))
    {
        out.push(Finding {
            check: "gnss_jump",
            severity: Severity::Warning,
            message: format!(
                "{} GNSS outlier stretch{} (fixes farther than a vehicle can go, back within \
                 {RETURN_WITHIN_S} s; the largest {:.0} m at {:.3} s): the filter's gate rejects \
                 and counts them",
                outliers.len(),
                if outliers.len() == 1 { "" } else { "es" },
                worst.distance_m,
                worst.to_t_s
            ),
        });
    }
}

/// A ratio of a speed as read to the same speed over the timestamps near
/// this factor (within [`TIME_UNIT_TOLERANCE`]) is a time unit mistake.
const TIME_UNIT_FACTORS: [(f64, &str); 2] = [
    (1000.0, "every file's times in milliseconds?"),
    (1e6, "every file's times in microseconds?"),
];
/// How far (as a factor) from a [`TIME_UNIT_FACTORS`] entry a ratio may be.
const TIME_UNIT_TOLERANCE: f64 = 2.0;
/// A median interval of wheel rows above this is slower than any wheel
/// odometry logs (they run at 10–100 Hz), s.
const MAX_WHEEL_INTERVAL_S: f64 = 1.0;

/// Speeds read as m/s do not depend on the timestamps; speeds derived from
/// positions over time do. With every file's times multiplied by 1000 the
/// spans agree with each other, and the wheel speeds are all below the
/// thresholds of the other checks, so those see nothing; but a speed read
/// (the receiver's `speed_mps`, the CAN speed, wheel speeds in m/s) is then
/// 1000 times the speed between the fixes.
fn time_unit(d: &Drive, wheel_speed: &[(f64, f64)], out: &mut Vec<Finding>) {
    let read_speed = |t: f64, fix: &crate::drive::GnssFix| -> Option<(f64, &'static str)> {
        if let Some(v) = fix.speed_mps {
            return Some((v.abs(), "the receiver's speed_mps"));
        }
        if !d.speed.is_empty() {
            let i = d.speed.partition_point(|c| c.t_s < t);
            if i > 0 && i < d.speed.len() {
                return Some((d.speed[i].value.abs(), "the CAN speed"));
            }
        }
        if matches!(d.wheels, Wheels::Speeds(_)) {
            return interpolate(wheel_speed, t).map(|v| (v.abs(), "the wheel speeds"));
        }
        None
    };
    let mut ratios = Vec::new();
    let mut what = "";
    for p in d.gnss.windows(2) {
        let dt = p[1].t_s - p[0].t_s;
        if dt <= 0.0 {
            continue;
        }
        let chord = (p[1].east_m - p[0].east_m).hypot(p[1].north_m - p[0].north_m);
        let Some((v, w)) = read_speed(0.5 * (p[0].t_s + p[1].t_s), &p[1]) else {
            continue;
        };
        // Moving, and far enough for the fixes' noise not to decide.
        if v > MIN_SPEED_MPS && chord > 2.0 * p[1].std_m {
            ratios.push(v / (chord / dt));
            what = w;
        }
    }
    if ratios.len() >= 10 {
        let ratio = quantile_of(&ratios, 0.5);
        if let Some((k, hint)) = TIME_UNIT_FACTORS
            .iter()
            .find(|(k, _)| (ratio / k).max(k / ratio) < TIME_UNIT_TOLERANCE)
        {
            out.push(error(
                "time_unit",
                format!(
                    "{what} is {ratio:.0} times the speed between the GNSS fixes over their \
                     timestamps (median of {} pairs): the timestamps run {k:.0} times too fast; {hint} \
                     (the drive would last {:.1} h instead of {:.0} s)",
                    ratios.len(),
                    d.wheels.t_s(d.wheels.len() - 1) / 3600.0 - d.wheels.t_s(0) / 3600.0,
                    (d.wheels.t_s(d.wheels.len() - 1) - d.wheels.t_s(0)) / k,
                ),
            ));
            return;
        }
    }
    let n = d.wheels.len();
    if n >= 10 {
        let dts: Vec<f64> = (1..n)
            .map(|i| d.wheels.t_s(i) - d.wheels.t_s(i - 1))
            .collect();
        let median = quantile_of(&dts, 0.5);
        if median > MAX_WHEEL_INTERVAL_S {
            out.push(Finding {
                check: "time_unit",
                severity: Severity::Warning,
                message: format!(
                    "the wheel rows come every {median:.3} s (median): wheel odometry is logged at \
                     10–100 Hz; are the times in milliseconds ({:.4} s)?",
                    median / 1000.0
                ),
            });
        }
    }
}

/// The `q` quantile of unsorted values.
fn quantile_of(v: &[f64], q: f64) -> f64 {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    crate::metrics::quantile(&s, q)
}

fn error(check: &'static str, message: String) -> Finding {
    Finding {
        check,
        severity: Severity::Error,
        message,
    }
}

fn vehicle_lengths(d: &Drive, out: &mut Vec<Finding>) {
    let v = &d.vehicle;
    for (key, value, max) in [
        ("wheelbase_m", v.wheelbase_m, 20.0),
        ("track_front_m", v.track_front_m, 5.0),
        ("track_rear_m", v.track_rear_m, 5.0),
        ("wheel_circumference_m", v.wheel_circumference_m, 10.0),
    ] {
        if value > max {
            out.push(error(
                "vehicle_lengths",
                format!(
                    "vehicle.toml: {key} = {value} m is more than {max} m \
                     (millimetres? {} m)",
                    value / 1000.0
                ),
            ));
        }
    }
}

fn time_overlap(d: &Drive, out: &mut Vec<Finding>) {
    let (Some(a), Some(b)) = (
        d.wheels.len().checked_sub(1).map(|_| d.wheels.t_s(0)),
        d.wheels.len().checked_sub(1).map(|i| d.wheels.t_s(i)),
    ) else {
        return;
    };
    let spans = [
        (
            "yaw_rate",
            d.yaw_rate
                .first()
                .zip(d.yaw_rate.last())
                .map(|(x, y)| (x.t_s, y.t_s)),
        ),
        (
            "speed",
            d.speed
                .first()
                .zip(d.speed.last())
                .map(|(x, y)| (x.t_s, y.t_s)),
        ),
        (
            "steering",
            d.steering
                .first()
                .zip(d.steering.last())
                .map(|(x, y)| (x.t_s, y.t_s)),
        ),
        (
            "gnss",
            d.gnss
                .first()
                .zip(d.gnss.last())
                .map(|(x, y)| (x.t_s, y.t_s)),
        ),
    ];
    for (name, span) in spans {
        let Some((c, e)) = span else { continue };
        let overlap = (b.min(e) - a.max(c)).max(0.0);
        let shorter = (b - a).min(e - c).max(1e-9);
        let ratio = (e - c) / (b - a).max(1e-9);
        if !(1.0 / 20.0..=20.0).contains(&ratio) {
            let unit = if (ratio / 1000.0 - 1.0).abs() < 0.2 {
                " (milliseconds?)"
            } else if (ratio * 1000.0 - 1.0).abs() < 0.2 {
                " (the wheels in milliseconds?)"
            } else {
                ""
            };
            out.push(error(
                "time_overlap",
                format!(
                    "{name} spans {:.3} s ({c:.3}..{e:.3}) and the wheels {:.3} s ({a:.3}..{b:.3}): \
                     {ratio:.1} times as long — another time unit{unit}",
                    e - c,
                    b - a
                ),
            ));
        } else if overlap < 0.5 * shorter {
            out.push(error(
                "time_overlap",
                format!(
                    "{name} spans {c:.3}..{e:.3} s and the wheels {a:.3}..{b:.3} s: they overlap \
                     for {:.0}% of the shorter — another clock?",
                    100.0 * overlap / shorter
                ),
            ));
        }
    }
}

/// Each wheel row as the four wheels' speeds, `(t, [FL, FR, RL, RR] m/s)`
/// (ticks over the row interval with the nominal circumference).
pub(crate) fn wheel_rows(d: &Drive) -> Vec<(f64, [f64; 4])> {
    let v = &d.vehicle;
    match &d.wheels {
        Wheels::Ticks(rows) => {
            let per_tick = v.wheel_circumference_m / v.ticks_per_rev as f64;
            // At most a row per interval: reserved once, not doubled as
            // it grows (issue 30: 10.5 MB for 7.2 on the bench's hour).
            let mut out = Vec::with_capacity(rows.len().saturating_sub(1));
            out.extend(rows.windows(2).filter_map(|p| {
                let dt = p[1].t_s - p[0].t_s;
                let r = &p[1];
                (dt > 0.0).then(|| {
                    (
                        r.t_s,
                        [r.fl, r.fr, r.rl, r.rr].map(|k| k as f64 * per_tick / dt),
                    )
                })
            }));
            out
        }
        Wheels::Speeds(rows) => rows
            .iter()
            .map(|r| (r.t_s, [r.fl_mps, r.fr_mps, r.rl_mps, r.rr_mps]))
            .collect(),
    }
}

/// The vehicle speed the wheel rows imply, `(t, m/s)`: the mean of the present wheels.
fn wheel_speed(d: &Drive, rows: &[(f64, [f64; 4])]) -> Vec<(f64, f64)> {
    let present: Vec<usize> = (0..4).filter(|&i| d.vehicle.wheels_present[i]).collect();
    if present.is_empty() {
        return Vec::new();
    }
    rows.iter()
        .map(|(t, w)| {
            (
                *t,
                present.iter().map(|&i| w[i]).sum::<f64>() / present.len() as f64,
            )
        })
        .collect()
}

fn wheel_speed_range(speed: &[(f64, f64)], out: &mut Vec<Finding>) {
    let v: Vec<f64> = speed.iter().map(|s| s.1.abs()).collect();
    if v.len() < 10 {
        return;
    }
    // The 99th percentile, so that one bad row does not decide.
    let p99 = quantile_of(&v, 0.99);
    if p99 > MAX_WHEEL_SPEED_MPS {
        out.push(error(
            "wheel_speed_range",
            format!(
                "the wheel rows imply {p99:.0} m/s (99th percentile; no wheel turns faster \
                 than {MAX_WHEEL_SPEED_MPS} m/s): cumulative tick counters written as counts \
                 per row, a wrong ticks_per_rev, or speeds in the wrong unit?"
            ),
        ));
    }
}

/// Linear interpolation of `(t, v)` samples at `t` (`None` outside).
fn interpolate(s: &[(f64, f64)], t: f64) -> Option<f64> {
    let i = s.partition_point(|p| p.0 < t);
    if i == 0 || i >= s.len() {
        return None;
    }
    let (a, b) = (s[i - 1], s[i]);
    let f = (t - a.0) / (b.0 - a.0);
    Some(a.1 + f * (b.1 - a.1))
}

/// An error when `ratio` (of `what` to the wheels') is not near 1, with the
/// likely mistake when it is near one of `hints`' factors.
fn ratio_finding(
    check: &'static str,
    what: &str,
    ratio: f64,
    hints: &[(f64, &str)],
    otherwise: &str,
) -> Option<Finding> {
    if (1.0 / RATIO_TOLERANCE..=RATIO_TOLERANCE).contains(&ratio) {
        return None;
    }
    let hint = hints
        .iter()
        .find(|(k, _)| (ratio / k - 1.0).abs() < 0.1)
        .map_or(otherwise, |(_, h)| h);
    Some(error(
        check,
        format!("{what} is {ratio:.3} times the wheels' ({hint})"),
    ))
}

fn can_vs_wheel_speed(d: &Drive, speed: &[(f64, f64)], out: &mut Vec<Finding>) {
    let r: Vec<f64> = d
        .speed
        .iter()
        .filter_map(|c| {
            let w = interpolate(speed, c.t_s)?;
            (w.abs() > MIN_SPEED_MPS).then(|| c.value / w)
        })
        .collect();
    if r.len() < 20 {
        return;
    }
    let ratio = quantile_of(&r, 0.5);
    out.extend(ratio_finding(
        "can_vs_wheel_speed",
        "the CAN speed",
        ratio,
        &[
            (3.6, "CAN speed in km/h?"),
            (2.237, "CAN speed in mph?"),
            (1.0 / 3.6, "wheel speeds in km/h?"),
        ],
        "a wrong wheel_circumference_m or ticks_per_rev?",
    ));
}

fn gnss_vs_wheel_distance(d: &Drive, speed: &[(f64, f64)], out: &mut Vec<Finding>) {
    // Chords between fixes far enough apart for the position noise not to
    // lengthen them (the wheels travel 20 standard deviations), compared with
    // the wheels' distance over the same time; the median ratio (curves make
    // a few chords shorter than the path).
    let distance = |a: f64, b: f64| -> Option<f64> {
        let i = speed.partition_point(|p| p.0 <= a);
        let j = speed.partition_point(|p| p.0 <= b);
        if i == 0 || j >= speed.len() {
            return None;
        }
        let moving = speed[i..j].iter().all(|p| p.1.abs() > MIN_SPEED_MPS);
        moving.then(|| {
            speed[i..=j]
                .windows(2)
                .map(|p| p[1].1.abs() * (p[1].0 - p[0].0))
                .sum()
        })
    };
    let mut ratios = Vec::new();
    let mut k = 0;
    while k < d.gnss.len() {
        let a = &d.gnss[k];
        let need = 20.0 * a.std_m;
        let mut next = k + 1;
        for j in k + 1..d.gnss.len() {
            let b = &d.gnss[j];
            next = j + 1;
            if b.t_s - a.t_s > 10.0 {
                break;
            }
            let Some(w) = distance(a.t_s, b.t_s) else {
                break;
            };
            if w >= need {
                ratios.push((b.east_m - a.east_m).hypot(b.north_m - a.north_m) / w);
                break;
            }
        }
        k = next.max(k + 1);
    }
    if ratios.len() < 10 {
        return;
    }
    out.extend(ratio_finding(
        "gnss_vs_wheel_distance",
        "the GNSS displacement",
        quantile_of(&ratios, 0.5),
        &[
            (1.0 / 3.6, "wheel speeds in km/h?"),
            (0.001, "wheel_circumference_m in millimetres?"),
            (1000.0, "GNSS positions in millimetres?"),
        ],
        "a wrong wheel_circumference_m or ticks_per_rev, or latitude and longitude swapped?",
    ));
}

/// The yaw rate of an axle whose two wheels carry sensors, `(t, rad/s)`:
/// (right − left) / track (rear axle first).
fn wheel_yaw_rate(d: &Drive, rows: &[(f64, [f64; 4])]) -> Option<Vec<(f64, f64)>> {
    let v = &d.vehicle;
    let (l, r, track) = if v.wheels_present[2] && v.wheels_present[3] {
        (2, 3, v.track_rear_m)
    } else if v.wheels_present[0] && v.wheels_present[1] {
        (0, 1, v.track_front_m)
    } else {
        return None;
    };
    Some(
        rows.iter()
            .map(|(t, w)| (*t, (w[r] - w[l]) / track))
            .collect(),
    )
}

/// Turns the GNSS track makes against those of the wheels: a mirrored track
/// (latitude and longitude swapped, or east and north) turns the other way,
/// while its distances may stay within the distance check's tolerance.
fn gnss_turns_vs_wheel_turns(
    d: &Drive,
    rows: &[(f64, [f64; 4])],
    speed: &[(f64, f64)],
    out: &mut Vec<Finding>,
) {
    let Some(rate) = wheel_yaw_rate(d, rows) else {
        return;
    };
    // The wheels' heading, integrated (trapezoids).
    let mut heading = Vec::with_capacity(rate.len());
    let mut h = 0.0;
    for (i, &(t, w)) in rate.iter().enumerate() {
        if i > 0 {
            let (t0, w0) = rate[i - 1];
            h += 0.5 * (w + w0) * (t - t0);
        }
        heading.push((t, h));
    }
    let moving = |a: f64, b: f64| {
        let i = speed.partition_point(|p| p.0 < a);
        let j = speed.partition_point(|p| p.0 <= b);
        i > 0 && j < speed.len() && speed[i..j].iter().all(|p| p.1 > MIN_SPEED_MPS)
    };
    // Chords of the GNSS track long against the fixes' noise (ten standard
    // deviations: direction to about 0.1 rad) and at most 5 s long, one
    // after the other, while moving forward: (middle time, direction).
    let mut chords: Vec<(f64, f64, f64)> = Vec::new();
    let mut k = 0;
    while k < d.gnss.len() {
        let a = &d.gnss[k];
        let mut next = k + 1;
        for j in k + 1..d.gnss.len() {
            let b = &d.gnss[j];
            if b.t_s - a.t_s > 5.0 {
                break;
            }
            let (de, dn) = (b.east_m - a.east_m, b.north_m - a.north_m);
            if de.hypot(dn) >= 10.0 * a.std_m.max(b.std_m) {
                if moving(a.t_s, b.t_s) {
                    chords.push((a.t_s, b.t_s, dn.atan2(de)));
                }
                next = j;
                break;
            }
        }
        k = next;
    }
    // Turns of more than 0.3 rad between neighbouring chords.
    let (mut turns, mut against) = (0usize, 0usize);
    for w in chords.windows(2) {
        let ((a0, b0, d0), (a1, b1, d1)) = (w[0], w[1]);
        if a1 - b0 > 5.0 {
            continue;
        }
        let (m0, m1) = (0.5 * (a0 + b0), 0.5 * (a1 + b1));
        let (Some(h0), Some(h1)) = (interpolate(&heading, m0), interpolate(&heading, m1)) else {
            continue;
        };
        let wheels = h1 - h0;
        let gnss = (d1 - d0 + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        if wheels.abs() > 0.3 {
            turns += 1;
            if gnss * wheels < 0.0 {
                against += 1;
            }
        }
    }
    if turns >= 5 && against as f64 > 0.8 * turns as f64 {
        out.push(error(
            "gnss_turns_vs_wheel_turns",
            format!(
                "the GNSS track turns the other way from the wheels in {against} of {turns} \
                 turns: latitude and longitude swapped (or east and north)?"
            ),
        ));
    }
}

fn gyro_vs_wheel_yaw_rate(d: &Drive, rows: &[(f64, [f64; 4])], out: &mut Vec<Finding>) {
    let Some(rate) = wheel_yaw_rate(d, rows) else {
        return;
    };
    // Smooth the wheel rate over about 0.5 s (ticks are coarse), then regress
    // the gyro on it through the origin after removing both means (the bias).
    let smooth: Vec<(f64, f64)> = rate
        .iter()
        .map(|&(t, _)| {
            let i = rate.partition_point(|p| p.0 < t - 0.25);
            let j = rate.partition_point(|p| p.0 <= t + 0.25);
            let s = &rate[i..j];
            (
                t,
                s.iter().map(|p| p.1).sum::<f64>() / s.len().max(1) as f64,
            )
        })
        .collect();
    let pairs: Vec<(f64, f64)> = d
        .yaw_rate
        .iter()
        .filter_map(|g| Some((interpolate(&smooth, g.t_s)?, g.value)))
        .collect();
    if pairs.len() < 50 {
        return;
    }
    let n = pairs.len() as f64;
    let (mx, my) = pairs
        .iter()
        .fold((0.0, 0.0), |(a, b), p| (a + p.0 / n, b + p.1 / n));
    let (mut sxx, mut sxy) = (0.0, 0.0);
    for p in &pairs {
        sxx += (p.0 - mx) * (p.0 - mx);
        sxy += (p.0 - mx) * (p.1 - my);
    }
    // Enough turning to tell: a standard deviation of 0.03 rad/s.
    if sxx / n < 0.03f64.powi(2) {
        return;
    }
    let slope = sxy / sxx;
    if slope < -0.5 {
        out.push(error(
            "gyro_vs_wheel_yaw_rate",
            format!(
                "the gyro turns the other way from the wheels (slope {slope:.2} against the \
                 rear wheels' yaw rate): yaw_rate_rps must be counter-clockwise positive"
            ),
        ));
    } else if slope > 2.0 {
        let hint = if (slope / 57.2958 - 1.0).abs() < 0.15 {
            " (degrees per second?)"
        } else {
            ""
        };
        out.push(error(
            "gyro_vs_wheel_yaw_rate",
            format!("the gyro is {slope:.3} times the rear wheels' yaw rate{hint}"),
        ));
    } else if slope < 0.1 {
        // Skid-steered robots turn far less than their wheels say (the Jackal:
        // 0.2), so only a gyro that hardly follows at all is suspicious.
        out.push(Finding {
            check: "gyro_vs_wheel_yaw_rate",
            severity: Severity::Warning,
            message: format!(
                "the gyro follows the wheels' yaw rate only {slope:.3} times: another axis, \
                 or a rate in another unit?"
            ),
        });
    }
}

/// Smallest absolute difference of two angles, degrees.
fn angle_diff_deg(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(360.0);
    d.min(360.0 - d)
}

fn course_vs_track(d: &Drive, out: &mut Vec<Finding>) {
    let mut given = Vec::new();
    let mut radians = Vec::new();
    let mut ccw_east = Vec::new();
    // Chords between fixes at least 20 standard deviations apart (within
    // 10 s), against the course of the fix in the middle.
    let g = &d.gnss;
    let mut k = 0;
    while k < g.len() {
        let need = 20.0 * g[k].std_m;
        let mut next = k + 1;
        for j in k + 1..g.len() {
            next = j + 1;
            if g[j].t_s - g[k].t_s > 10.0 {
                break;
            }
            let (de, dn) = (g[j].east_m - g[k].east_m, g[j].north_m - g[k].north_m);
            if de.hypot(dn) < need {
                continue;
            }
            let mid = &g[(k + j) / 2];
            if let (Some(c), Some(v)) = (mid.course_deg, mid.speed_mps) {
                if v >= 3.0 {
                    let track = de.atan2(dn).to_degrees(); // clockwise from north
                    given.push(angle_diff_deg(c, track));
                    radians.push(angle_diff_deg(c.to_degrees(), track));
                    ccw_east.push(angle_diff_deg(90.0 - c, track));
                }
            }
            break;
        }
        k = next.max(k + 1);
    }
    if given.len() < 20 {
        return;
    }
    let m = quantile_of(&given, 0.5);
    if m < 30.0 {
        return;
    }
    let hint = if quantile_of(&radians, 0.5) < 15.0 {
        " (radians? course_deg is degrees)"
    } else if quantile_of(&ccw_east, 0.5) < 15.0 {
        " (counter-clockwise from east? course_deg is clockwise from north)"
    } else {
        ""
    };
    out.push(error(
        "course_vs_track",
        format!(
            "the GNSS course differs from the direction of the GNSS track by {m:.0}° \
             (median){hint}"
        ),
    ));
}

fn stuck_gnss(d: &Drive, speed: &[(f64, f64)], out: &mut Vec<Finding>) {
    // The longest run of fixes at one position while the wheels travel.
    let mut worst: Option<(f64, f64, f64)> = None;
    let mut start = 0;
    for k in 1..=d.gnss.len() {
        let same = k < d.gnss.len()
            && d.gnss[k].east_m == d.gnss[start].east_m
            && d.gnss[k].north_m == d.gnss[start].north_m;
        if same {
            continue;
        }
        let (a, b) = (d.gnss[start].t_s, d.gnss[k - 1].t_s);
        if b - a > 30.0 {
            let i = speed.partition_point(|p| p.0 < a);
            let j = speed.partition_point(|p| p.0 <= b);
            let travelled: f64 = speed[i..j]
                .windows(2)
                .map(|p| p[1].1.abs() * (p[1].0 - p[0].0))
                .sum();
            if travelled > 50.0 && worst.is_none_or(|w| b - a > w.1 - w.0) {
                worst = Some((a, b, travelled));
            }
        }
        start = k;
    }
    if let Some((a, b, m)) = worst {
        out.push(error(
            "stuck_gnss",
            format!(
                "the GNSS position stays the same from {a:.1} to {b:.1} s while the wheels \
                 travel {m:.0} m: a receiver repeating its last fix?"
            ),
        ));
    }
}
