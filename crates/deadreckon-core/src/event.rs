//! Measurements as time-ordered events: the unit the filter consumes online
//! ([`crate::ekf::Feeder`], [`crate::online::Online`]) and the JSON-lines schema
//! of `deadreckon events` / `deadreckon stream` (`docs/events.md`), and
//! [`DriveEvents`], a recorded drive's streams merged lazily in time order.

use serde::{Deserialize, Serialize};

use crate::drive::{Drive, GnssFix, WheelSpeeds, Wheels};

/// One measurement, as a drive or a live stream delivers it. The serde form is
/// the JSON-lines event schema of `deadreckon events` (see `docs/events.md`):
/// a `sensor` tag and the drive format's column names.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "sensor", rename_all = "snake_case", deny_unknown_fields)]
pub enum Measurement {
    /// Ticks of each wheel since the previous wheel row.
    WheelTicks {
        /// Front left.
        fl: i64,
        /// Front right.
        fr: i64,
        /// Rear left.
        rl: i64,
        /// Rear right.
        rr: i64,
    },
    /// Wheel speeds, m/s.
    WheelSpeeds {
        /// Front left, m/s.
        fl_mps: f64,
        /// Front right, m/s.
        fr_mps: f64,
        /// Rear left, m/s.
        rl_mps: f64,
        /// Rear right, m/s.
        rr_mps: f64,
    },
    /// Raw gyro yaw rate, rad/s.
    YawRate {
        /// rad/s, counter-clockwise positive.
        yaw_rate_rps: f64,
    },
    /// CAN vehicle speed, m/s.
    Speed {
        /// m/s.
        speed_mps: f64,
    },
    /// Steering wheel angle, rad.
    Steering {
        /// rad, left positive.
        steering_wheel_rad: f64,
    },
    /// A three-axis gyro reading, rad/s, about the sensor's own axes (x
    /// forward, y left, z up as mounted): the drive format's three-axis
    /// `yaw_rate.csv`. The filter does not take it; [`crate::online::Online`]
    /// projects it on a stored IMU vertical ([`crate::live_corrections`]).
    Gyro {
        /// About x, rad/s.
        x_rps: f64,
        /// About y, rad/s.
        y_rps: f64,
        /// About z, rad/s.
        z_rps: f64,
    },
    /// An accelerometer reading, m/s², specific force in the gyro's axes
    /// (`accel.csv`). The filter does not take it; [`crate::online::Online`]
    /// uses its x for a stored driven-axle slip correction
    /// ([`crate::live_corrections`]).
    Accel {
        /// Forward, m/s².
        x_mps2: f64,
        /// Left, m/s².
        y_mps2: f64,
        /// Up, m/s².
        z_mps2: f64,
    },
    /// A GNSS fix of the antenna.
    Gnss {
        /// m east of the origin.
        east_m: f64,
        /// m north of the origin.
        north_m: f64,
        /// Horizontal standard deviation, m.
        std_m: f64,
        /// Course, degrees clockwise from north.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        course_deg: Option<f64>,
        /// Ground speed, m/s.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        speed_mps: Option<f64>,
    },
}

impl Measurement {
    /// The measurement of a wheel-speed row (its time left out).
    #[inline(always)]
    pub fn wheel_speeds(w: &WheelSpeeds) -> Self {
        Measurement::WheelSpeeds {
            fl_mps: w.fl_mps,
            fr_mps: w.fr_mps,
            rl_mps: w.rl_mps,
            rr_mps: w.rr_mps,
        }
    }

    /// The measurement of a GNSS fix (its time left out).
    #[inline(always)]
    pub fn gnss(g: &GnssFix) -> Self {
        Measurement::Gnss {
            east_m: g.east_m,
            north_m: g.north_m,
            std_m: g.std_m,
            course_deg: g.course_deg,
            speed_mps: g.speed_mps,
        }
    }
}

/// A measurement with its timestamp.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Event {
    /// Timestamp, s (the drive's clock).
    pub t_s: f64,
    /// The measurement.
    #[serde(flatten)]
    pub measurement: Measurement,
}

impl Event {
    /// Order of events with equal timestamps: wheels, gyro, speed, steering,
    /// GNSS (the per-measurement scheme processes them in this order).
    pub(crate) fn rank(&self) -> u8 {
        match self.measurement {
            Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => 0,
            Measurement::YawRate { .. } => 1,
            Measurement::Speed { .. } => 2,
            Measurement::Steering { .. } => 3,
            Measurement::Gnss { .. } => 4,
            // Never fed to the filter: Online turns a three-axis reading
            // into a yaw rate and consumes the accelerometer.
            Measurement::Gyro { .. } => 1,
            Measurement::Accel { .. } => 5,
        }
    }

    pub(crate) fn is_wheel(&self) -> bool {
        self.rank() == 0
    }

    /// The fix of a GNSS event.
    pub fn gnss_fix(&self) -> Option<GnssFix> {
        match self.measurement {
            Measurement::Gnss {
                east_m,
                north_m,
                std_m,
                course_deg,
                speed_mps,
            } => Some(GnssFix {
                t_s: self.t_s,
                east_m,
                north_m,
                std_m,
                course_deg,
                speed_mps,
            }),
            _ => None,
        }
    }
}

/// The streams of a drive merged into time order (ties in [`Event`] rank
/// order), lazily, from `after_s` (exclusive) to the last wheel row: readings
/// after the last wheel row are never used.
#[derive(Debug, Clone)]
pub struct DriveEvents<'a> {
    drive: &'a Drive,
    next: [usize; 5],
    /// The time of each stream's next reading (+∞ when it has none left).
    next_t: [f64; 5],
    t_end: f64,
}

impl<'a> DriveEvents<'a> {
    /// Events of `drive` with `t > after_s`.
    pub fn new(drive: &'a Drive, after_s: f64) -> Self {
        let w = &drive.wheels;
        let first_wheel = (0..w.len())
            .find(|&k| w.t_s(k) > after_s)
            .unwrap_or(w.len());
        let mut events = DriveEvents {
            drive,
            next: [
                first_wheel,
                drive.yaw_rate.partition_point(|s| s.t_s <= after_s),
                drive.speed.partition_point(|s| s.t_s <= after_s),
                drive.steering.partition_point(|s| s.t_s <= after_s),
                drive.gnss.partition_point(|s| s.t_s <= after_s),
            ],
            next_t: [f64::INFINITY; 5],
            t_end: if w.is_empty() {
                f64::NEG_INFINITY
            } else {
                w.t_s(w.len() - 1)
            },
        };
        for k in 0..5 {
            events.next_t[k] = events.time(k).unwrap_or(f64::INFINITY);
        }
        events
    }

    /// Every event of `drive`.
    pub fn all(drive: &'a Drive) -> Self {
        Self::new(drive, f64::NEG_INFINITY)
    }

    /// Every event of `drive`, the readings after the last wheel row
    /// included (what a live stream delivers:
    /// [`crate::live_corrections::input_events`]).
    pub fn new_uncut(drive: &'a Drive) -> Self {
        let mut e = Self::new(drive, f64::NEG_INFINITY);
        e.t_end = f64::INFINITY;
        for k in 0..5 {
            e.next_t[k] = e.time(k).unwrap_or(f64::INFINITY);
        }
        e
    }

    fn time(&self, stream: usize) -> Option<f64> {
        let d = self.drive;
        let i = self.next[stream];
        let t = match stream {
            0 => (i < d.wheels.len()).then(|| d.wheels.t_s(i)),
            1 => d.yaw_rate.get(i).map(|s| s.t_s),
            2 => d.speed.get(i).map(|s| s.t_s),
            3 => d.steering.get(i).map(|s| s.t_s),
            _ => d.gnss.get(i).map(|s| s.t_s),
        }?;
        (t <= self.t_end).then_some(t)
    }
}

impl Iterator for DriveEvents<'_> {
    type Item = Event;
    // Inlined into the consumer's loop: an event is returned by value, and
    // across a call it goes through memory (about 8% of the 11-state step).
    #[inline(always)]
    fn next(&mut self) -> Option<Event> {
        // The earliest next reading; ties go to the lower stream (rank order).
        let mut k = 0;
        for j in 1..5 {
            if self.next_t[j] < self.next_t[k] {
                k = j;
            }
        }
        let t_s = self.next_t[k];
        if t_s == f64::INFINITY {
            return None;
        }
        let i = self.next[k];
        self.next[k] += 1;
        self.next_t[k] = self.time(k).unwrap_or(f64::INFINITY);
        let d = self.drive;
        let measurement = match k {
            0 => match &d.wheels {
                Wheels::Ticks(v) => Measurement::WheelTicks {
                    fl: v[i].fl,
                    fr: v[i].fr,
                    rl: v[i].rl,
                    rr: v[i].rr,
                },
                Wheels::Speeds(v) => Measurement::wheel_speeds(&v[i]),
            },
            1 => Measurement::YawRate {
                yaw_rate_rps: d.yaw_rate[i].value,
            },
            2 => Measurement::Speed {
                speed_mps: d.speed[i].value,
            },
            3 => Measurement::Steering {
                steering_wheel_rad: d.steering[i].value,
            },
            _ => Measurement::gnss(&d.gnss[i]),
        };
        Some(Event { t_s, measurement })
    }
}
