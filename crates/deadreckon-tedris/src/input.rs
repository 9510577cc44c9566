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

impl ReferenceSource {
    /// The source a drive supports, GNSS course first, then fixes, then gyro.
    pub fn auto(drive: &Drive) -> Result<Self, Error> {
        if drive.gnss.iter().any(|g| g.course_deg.is_some()) {
            Ok(ReferenceSource::GnssCourse)
        } else if drive.gnss.len() >= 2 {
            Ok(ReferenceSource::GnssTrack)
        } else if drive.yaw_rate.len() >= 2 {
            Ok(ReferenceSource::Gyro)
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

fn blanked(t: f64, windows: &[(f64, f64)]) -> bool {
    windows.iter().any(|&(a, b)| t >= a && t < b)
}

/// Builds the event stream, dropping the reference and the fixes inside `blank` windows `[start, end)`.
pub fn drive_input(
    drive: &Drive,
    source: Option<ReferenceSource>,
    blank: &[(f64, f64)],
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
        .filter(|g| !blanked(g.t_s, blank))
        .collect();
    // The robot variant (gyro reference) dead-reckons between its own odometry, as
    // in the paper: GNSS positions, if any, are not used.
    if source != ReferenceSource::Gyro {
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
            for p in fixes.windows(2) {
                let (de, dn) = (p[1].east_m - p[0].east_m, p[1].north_m - p[0].north_m);
                if de.hypot(dn) >= 0.3 && p[1].t_s - p[0].t_s < 2.0 {
                    events.push(Event::Heading(HeadingSample {
                        t_s: 0.5 * (p[0].t_s + p[1].t_s),
                        yaw_rad: dn.atan2(de),
                    }));
                }
            }
        }
        ReferenceSource::Gyro => {
            let mut yaw = first_truth.map_or(0.0, |p| p.2);
            let bias = standstill_gyro_bias(drive);
            for (i, s) in drive.yaw_rate.iter().enumerate() {
                if i > 0 {
                    let p = &drive.yaw_rate[i - 1];
                    yaw += (0.5 * (s.value + p.value) - bias) * (s.t_s - p.t_s);
                }
                if !blanked(s.t_s, blank) {
                    events.push(Event::Heading(HeadingSample {
                        t_s: s.t_s,
                        yaw_rad: yaw,
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

/// The gyro bias as the mean yaw rate while the rear wheels do not turn (at least
/// 20 gyro samples at standstill; 0 otherwise), rad/s. A gyro heading is only a
/// reference once its bias is removed.
pub fn standstill_gyro_bias(drive: &Drive) -> f64 {
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
        crate::stats::mean(&vals)
    } else {
        0.0
    }
}
