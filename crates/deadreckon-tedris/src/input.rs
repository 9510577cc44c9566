//! From a [`Drive`] to the machine's event stream: rear wheel distances, the
//! reference heading (GNSS course, course from successive fixes, or integrated
//! gyro) and GNSS antenna positions, in time order, with GNSS (or gyro) blanked
//! in the requested outage windows.

use serde::{Deserialize, Serialize};

use deadreckon_core::drive::{Drive, Wheels};

use crate::machine::{Geometry, HeadingSample, PositionFix, WheelSample};
use crate::Error;

/// Where the reference heading comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ReferenceSource {
    /// The receiver's course over ground (`course_deg`).
    GnssCourse,
    /// The direction of the chord between successive fixes, at their mid-time
    /// (for receivers that give no course).
    GnssTrack,
    /// The gyro yaw rate integrated (trapezoidal rule) into a heading: the robot variant.
    Gyro,
}

impl std::fmt::Display for ReferenceSource {
    /// Words for people: where the heading comes from.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ReferenceSource::GnssCourse => "the GNSS receiver's course over ground",
            ReferenceSource::GnssTrack => "the direction between successive GNSS fixes",
            ReferenceSource::Gyro => "the integrated gyro",
        })
    }
}

impl ReferenceSource {
    /// The source a drive supports: the GNSS course first, then the gyro, then the
    /// chords between fixes. Without a course, the integrated gyro is the better
    /// reference: chords of fixes with a metre of noise give no usable heading
    /// increments at robot speeds (the Husky bag: cross-correlation 0.06 against
    /// 0.94 for the gyro).
    pub fn auto(drive: &Drive) -> Result<Self, Error> {
        if drive.gnss.iter().any(|g| g.course_deg.is_some()) {
            Ok(ReferenceSource::GnssCourse)
        } else if drive.yaw_rate.len() >= 2 {
            Ok(ReferenceSource::Gyro)
        } else if drive.gnss.len() >= 2 {
            Ok(ReferenceSource::GnssTrack)
        } else {
            Err(Error::Insufficient(
                "the drive has neither GNSS nor gyro for a reference heading".into(),
            ))
        }
    }
}

/// One input of the machine.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Event {
    /// A wheel sample.
    Wheel(WheelSample),
    /// A reference heading.
    Heading(HeadingSample),
    /// A GNSS antenna position.
    Fix(PositionFix),
}

impl Event {
    /// Timestamp, s.
    pub fn t_s(&self) -> f64 {
        match self {
            Event::Wheel(w) => w.t_s,
            Event::Heading(h) => h.t_s,
            Event::Fix(f) => f.t_s,
        }
    }
    fn rank(&self) -> u8 {
        match self {
            Event::Wheel(_) => 0,
            Event::Heading(_) => 1,
            Event::Fix(_) => 2,
        }
    }
}

/// The machine's view of a drive.
#[derive(Debug, Clone, PartialEq)]
pub struct DriveInput {
    /// Events in time order (wheel before heading before fix at equal times).
    pub events: Vec<Event>,
    /// Geometry for the machine.
    pub geometry: Geometry,
    /// The reference used.
    pub source: ReferenceSource,
    /// Start pose (east, north, yaw) when no GNSS position is used (no fixes, or
    /// the gyro reference): the first truth pose (the robot's frame is defined by
    /// its start), if any.
    pub initial_pose: Option<(f64, f64, f64)>,
}

/// Builds the event stream, dropping the reference and the fixes inside `blank` windows `[start, end)`.
pub fn drive_input(
    drive: &Drive,
    source: Option<ReferenceSource>,
    blank: &[(f64, f64)],
) -> Result<DriveInput, Error> {
    drive_input_with(drive, source, blank, None)
}

/// [`drive_input`] with a prior gyro bias `(rad/s, samples)` (from the standstills
/// of the training drive, see [`crate::TedrisModel::gyro_bias`]), pooled with this
/// drive's standstill estimate weighted by their sample counts.
pub fn drive_input_with(
    drive: &Drive,
    source: Option<ReferenceSource>,
    blank: &[(f64, f64)],
    gyro_prior: Option<(f64, usize)>,
) -> Result<DriveInput, Error> {
    drive.validate()?;
    let source = match source {
        Some(s) => s,
        None => ReferenceSource::auto(drive)?,
    };
    let v = &drive.vehicle;
    let mut events = Vec::with_capacity(drive.wheels.len() + 2 * drive.gnss.len());
    match &drive.wheels {
        Wheels::Ticks(ticks) => {
            let m_per_tick = v.wheel_circumference_m / f64::from(v.ticks_per_rev);
            for w in ticks {
                events.push(Event::Wheel(WheelSample {
                    t_s: w.t_s,
                    left_m: w.rl as f64 * m_per_tick,
                    right_m: w.rr as f64 * m_per_tick,
                }));
            }
        }
        Wheels::Speeds(sp) => {
            let dts: Vec<f64> = sp.windows(2).map(|p| p[1].t_s - p[0].t_s).collect();
            let dt0 = crate::stats::median(&dts);
            for (i, w) in sp.iter().enumerate() {
                // An ABS ECU reports the mean speed over the period that ends at t_s.
                let dt = if i == 0 { dt0 } else { w.t_s - sp[i - 1].t_s };
                let (l, r) = (w.rl_mps * dt, w.rr_mps * dt);
                events.push(Event::Wheel(WheelSample {
                    t_s: w.t_s,
                    left_m: l,
                    right_m: r,
                }));
            }
        }
    }
    let fixes: Vec<_> = drive
        .gnss
        .iter()
        .filter(|g| !deadreckon_core::drive::in_windows(g.t_s, blank))
        .collect();
    // The robot variant (gyro reference) dead-reckons between its own odometry, as
    // in the paper: GNSS positions, if any, are not used, when the truth defines
    // the frame. Without truth (a real robot with GNSS), the fixes anchor the
    // position and the gyro heading is turned into their frame (see below).
    if source != ReferenceSource::Gyro || drive.truth.is_empty() {
        for g in &fixes {
            events.push(Event::Fix(PositionFix {
                t_s: g.t_s,
                east_m: g.east_m,
                north_m: g.north_m,
            }));
        }
    }
    let first_truth = drive
        .truth
        .first()
        .map(|p| (p.east_m, p.north_m, p.yaw_rad));
    match source {
        ReferenceSource::GnssCourse => {
            for g in &fixes {
                if let Some(yaw) = g.course_yaw_rad() {
                    events.push(Event::Heading(HeadingSample {
                        t_s: g.t_s,
                        yaw_rad: yaw,
                    }));
                }
            }
        }
        ReferenceSource::GnssTrack => {
            for (t_s, yaw_rad) in chords(&fixes) {
                events.push(Event::Heading(HeadingSample { t_s, yaw_rad }));
            }
        }
        ReferenceSource::Gyro => {
            let (b, n) = standstill_gyro_stats(drive);
            let (pb, pn) = gyro_prior.unwrap_or((0.0, 0));
            let bias = if n + pn > 0 {
                (b * n as f64 + pb * pn as f64) / (n + pn) as f64
            } else {
                0.0
            };
            let mut yaw = 0.0;
            let mut series = Vec::with_capacity(drive.yaw_rate.len());
            for (i, s) in drive.yaw_rate.iter().enumerate() {
                if i > 0 {
                    let p = &drive.yaw_rate[i - 1];
                    yaw += (0.5 * (s.value + p.value) - bias) * (s.t_s - p.t_s);
                }
                series.push((s.t_s, yaw));
            }
            // The start yaw: the truth's, else the circular mean of the fix chords'
            // directions minus the gyro heading (GNSS outside the outages), else 0.
            let yaw0 = match first_truth {
                Some(p) => p.2,
                None => chord_offset(&chords(&fixes), &series),
            };
            for (s, (t, y)) in drive.yaw_rate.iter().zip(series) {
                if !deadreckon_core::drive::in_windows(s.t_s, blank) {
                    events.push(Event::Heading(HeadingSample {
                        t_s: t,
                        yaw_rad: yaw0 + y,
                    }));
                }
            }
        }
    }
    events.sort_by(|a, b| a.t_s().total_cmp(&b.t_s()).then(a.rank().cmp(&b.rank())));
    let geometry = Geometry {
        track_rear_m: v.track_rear_m,
        lever_arm_m: v.gnss_lever_arm_m,
        heading_is_course: source != ReferenceSource::Gyro,
    };
    let initial_pose = if drive.gnss.is_empty() || source == ReferenceSource::Gyro {
        first_truth
    } else {
        None
    };
    Ok(DriveInput {
        events,
        geometry,
        source,
        initial_pose,
    })
}

/// Directions of the chords between fixes, at their mid-times: from each fix to
/// the first later fix at least max(0.3 m, 2·std_m) away, within 5 s (successive
/// fixes of a slow robot are closer than their noise). Mid-times of chords of
/// different lengths can repeat: the machine rejects a heading not after the
/// previous one.
fn chords(fixes: &[&deadreckon_core::drive::GnssFix]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    for (i, a) in fixes.iter().enumerate() {
        let base = (2.0 * a.std_m).max(0.3);
        let b = fixes[i + 1..]
            .iter()
            .take_while(|b| b.t_s - a.t_s < 5.0)
            .find(|b| (b.east_m - a.east_m).hypot(b.north_m - a.north_m) >= base);
        if let Some(b) = b {
            let (de, dn) = (b.east_m - a.east_m, b.north_m - a.north_m);
            out.push((0.5 * (a.t_s + b.t_s), dn.atan2(de)));
        }
    }
    out
}

/// Circular mean of (chord direction − gyro heading at the chord's time), rad (0 without chords).
fn chord_offset(chords: &[(f64, f64)], gyro: &[(f64, f64)]) -> f64 {
    let (mut sx, mut sy) = (0.0, 0.0);
    for &(t, y) in chords {
        let k = gyro.partition_point(|g| g.0 < t);
        if k == 0 || k >= gyro.len() {
            continue;
        }
        let (a, b) = (gyro[k - 1], gyro[k]);
        let g = a.1 + (b.1 - a.1) * (t - a.0) / (b.0 - a.0).max(1e-9);
        let d = y - g;
        sx += d.cos();
        sy += d.sin();
    }
    if sx == 0.0 && sy == 0.0 {
        0.0
    } else {
        sy.atan2(sx)
    }
}

/// The gyro bias as the mean yaw rate while the rear wheels do not turn (at least
/// 20 gyro samples at standstill; 0 otherwise), rad/s. A gyro heading is only a
/// reference once its bias is removed.
pub fn standstill_gyro_bias(drive: &Drive) -> f64 {
    standstill_gyro_stats(drive).0
}

/// The standstill gyro bias (rad/s) and the number of gyro samples it averages
/// (0 samples and bias 0 when fewer than 20 are at standstill).
pub fn standstill_gyro_stats(drive: &Drive) -> (f64, usize) {
    let still: Vec<(f64, f64)> = match &drive.wheels {
        Wheels::Ticks(v) => v
            .windows(2)
            .filter(|w| w[1].rl == 0 && w[1].rr == 0)
            .map(|w| (w[0].t_s, w[1].t_s))
            .collect(),
        Wheels::Speeds(v) => v
            .windows(2)
            .filter(|w| w[1].rl_mps == 0.0 && w[1].rr_mps == 0.0)
            .map(|w| (w[0].t_s, w[1].t_s))
            .collect(),
    };
    let mut vals = Vec::new();
    let mut k = 0;
    for s in &drive.yaw_rate {
        while k < still.len() && still[k].1 < s.t_s {
            k += 1;
        }
        if k < still.len() && still[k].0 <= s.t_s && s.t_s <= still[k].1 {
            vals.push(s.value);
        }
    }
    if vals.len() >= 20 {
        (crate::stats::mean(&vals), vals.len())
    } else {
        (0.0, 0)
    }
}
