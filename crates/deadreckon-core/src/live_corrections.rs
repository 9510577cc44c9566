//! The corrections a params.toml stores ([`KnownCorrections`]: each
//! stream's delay, the IMU's vertical, the gyro scale error, the driven
//! axle's slip) applied to a live stream one event at a time, with the
//! arithmetic [`KnownCorrections::apply`] applies to a whole drive, so that
//! [`crate::online::Online`] fed a drive's events equals the batch filter on
//! the corrected drive (`deadreckon run --params`) to the bit.
//!
//! Per event, as [`KnownCorrections::apply`] does per stream:
//!
//! - **Slip** ([`crate::traction::apply_at`]): a wheel-speed row at `t` has
//!   its driven axle divided by `1 + |κ|·(f − f̄)`, `f` the mean of the
//!   accelerometer's x over `[t − 0.5, t + 0.5)` s (from running sums over
//!   every `accel` event since the stream's start, as the batch code sums
//!   from the drive's start), `f̄` the stored mean of the calibration drive.
//!   A file without that mean (written before it) cannot be applied live:
//!   the slip is left out and [`LiveCorrections::slip_left_out`] says so.
//! - **Tilt** ([`crate::imu::level_with`]): with a stored vertical `up`, the
//!   yaw rate is `x·up₀ + y·up₁ + z·up₂` of each three-axis `gyro` event;
//!   from the first such event on, one-axis `yaw_rate` events are dropped
//!   (a drive with a three-axis gyro has its yaw rate replaced whole).
//!   Without a stored vertical, `gyro` events are dropped and `yaw_rate`
//!   events are the yaw rate, as in the drive.
//! - **Delays** ([`crate::timing::shift`]): an event of a stream late by `d`
//!   is re-stamped `t − d` (wheels and the accelerometer are never shifted).
//! - **Gyro scale** ([`crate::gyro_scale::apply`]): the yaw rate divided by
//!   `1 + e`.
//!
//! **Order.** Re-stamped events are held in a reorder buffer keyed on
//! (corrected time, the rank of [`crate::event::DriveEvents`]' ties: wheels,
//! gyro, speed, steering, GNSS, arrival) and released once no later input
//! can precede them: input times do not decrease, so an event arriving at
//! `t` has a corrected time of at least `t − D`, `D` the largest delay (and
//! 0, the wheels'). A wheel row also waits for the accelerometer's samples
//! up to 0.5 s after it when the slip is applied. Everything is therefore
//! held back by [`LiveCorrections::hold_s`] = `max(0, delays…, 0.5 with the
//! slip)` seconds of stream time: the latency the corrections add.
//!
//! **The end.** The batch filter never uses a reading after the drive's last
//! wheel row. A released reading later than the last released wheel row
//! waits (in the tail) for the next wheel row; at the end of the stream
//! ([`LiveCorrections::end`]) the tail is dropped. [`LiveCorrections::pause`]
//! releases only what a resumed stream cannot precede and keeps the rest
//! (the reorder buffer and the tail are part of the serialised state), so a
//! stream cut between two input timestamps and resumed from its state gives
//! what the uncut stream gives, bit for bit.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::event::{Event, Measurement};
use crate::timing::KnownCorrections;
use crate::Error;

/// Half-width of the accelerometer window of the slip correction, s
/// ([`crate::traction::apply_at`]'s ±0.5 s).
pub const SLIP_WINDOW_S: f64 = 0.5;

/// One event held back: its corrected time and tie rank, and its arrival.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Held {
    rank: u8,
    seq: u64,
    ev: Event,
}

/// The stored corrections on a live stream, with its reorder buffer; see
/// the module documentation. [`Default`]: nothing to apply (events pass
/// through in time order, the tail rule still applying).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct LiveCorrections {
    known: KnownCorrections,
    /// The slip is applied (a slip and its mean stored).
    slip: bool,
    hold_s: f64,
    /// The newest input time.
    last_input_s: Option<f64>,
    /// Corrected events not yet released, in release order.
    pending: VecDeque<Held>,
    seq: u64,
    /// A three-axis gyro event has arrived (with a stored vertical, the
    /// one-axis yaw rate is dropped from then on).
    three_axis: bool,
    /// Accelerometer samples still inside a future wheel row's window:
    /// `(t, the sum of every earlier sample's x)`.
    accel: VecDeque<(f64, f64)>,
    /// The sum of every accelerometer sample's x so far.
    accel_sum: f64,
    /// The time of the last wheel row released.
    last_wheel_s: Option<f64>,
    /// Released readings later than the last wheel row.
    tail: Vec<Event>,
    /// Readings dropped at the end (after the last wheel row).
    dropped_after_last_wheel: u64,
}

impl LiveCorrections {
    /// The corrections `known` on a live stream (checked:
    /// [`KnownCorrections::validate`]).
    pub fn new(known: &KnownCorrections) -> Result<Self, Error> {
        known.validate().map_err(|m| {
            Error::param("corrections", crate::Value::Unstated, crate::Rule::Said(m))
        })?;
        let slip = known.traction_slip_per_mps2 != 0.0 && known.traction_mean_force_mps2.is_some();
        let mut hold_s = known.delays_s.iter().fold(0.0_f64, |m, d| m.max(*d));
        if slip {
            hold_s = hold_s.max(SLIP_WINDOW_S);
        }
        Ok(LiveCorrections {
            known: *known,
            slip,
            hold_s,
            ..Default::default()
        })
    }

    /// The corrections applied.
    pub fn known(&self) -> &KnownCorrections {
        &self.known
    }

    /// How long events are held back, s of stream time: the largest stored
    /// delay (0 when none is positive), at least [`SLIP_WINDOW_S`] when the
    /// slip is applied. A pose comes out this much later than without the
    /// corrections.
    pub fn hold_s(&self) -> f64 {
        self.hold_s
    }

    /// True when a driven-axle slip is stored without the mean forward
    /// specific force it is applied at (a file written before it): the
    /// slip is not applied here, while `run` applies it at each drive's own
    /// mean.
    pub fn slip_left_out(&self) -> bool {
        self.known.traction_slip_per_mps2 != 0.0 && !self.slip
    }

    /// Events held: in the reorder buffer and in the tail.
    pub fn held(&self) -> usize {
        self.pending.len() + self.tail.len()
    }

    /// Readings dropped at the end for coming after the last wheel row.
    pub fn dropped_after_last_wheel(&self) -> u64 {
        self.dropped_after_last_wheel
    }

    /// Takes one input event (times must not decrease) and releases, through
    /// `release`, the corrected events no later input can precede, in order.
    pub fn push(
        &mut self,
        ev: Event,
        release: &mut dyn FnMut(Event) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let t = ev.t_s;
        if !t.is_finite() {
            return Err(Error::drive(
                "events",
                crate::DriveFault::NonFiniteTime {
                    index: None,
                    t_s: t,
                },
            ));
        }
        if let Some(last) = self.last_input_s {
            if t < last {
                return Err(Error::OutOfOrder {
                    t_s: t,
                    previous_t_s: last,
                });
            }
        }
        self.last_input_s = Some(t);
        if let Some(c) = self.corrected(ev) {
            self.hold(c);
        }
        let w = t - self.hold_s;
        self.release_while(|h| h.ev.t_s < w, release)
    }

    /// Releases what a stream resumed with later input times cannot
    /// precede (corrected times up to the newest input's less
    /// [`Self::hold_s`]); keeps the rest for the resumed stream.
    pub fn pause(
        &mut self,
        release: &mut dyn FnMut(Event) -> Result<(), Error>,
    ) -> Result<(), Error> {
        let Some(last) = self.last_input_s else {
            return Ok(());
        };
        let w = last - self.hold_s;
        self.release_while(|h| h.ev.t_s <= w, release)
    }

    /// The end of the stream: releases everything held and drops the
    /// readings after the last wheel row (which the batch filter never
    /// uses).
    pub fn end(
        &mut self,
        release: &mut dyn FnMut(Event) -> Result<(), Error>,
    ) -> Result<(), Error> {
        self.release_while(|_| true, release)?;
        self.dropped_after_last_wheel += self.tail.len() as u64;
        self.tail.clear();
        Ok(())
    }

    /// The event with the corrections applied, `None` when it is consumed
    /// (an accelerometer sample) or dropped (a gyro reading the drive's
    /// correction would not use).
    fn corrected(&mut self, ev: Event) -> Option<Event> {
        let [d_gyro, d_speed, d_steering, d_gnss] = self.known.delays_s;
        let t = ev.t_s;
        let scaled = |v: f64| {
            let e = self.known.gyro_scale_error;
            if e != 0.0 {
                v / (1.0 + e)
            } else {
                v
            }
        };
        let yaw = |v: f64| Event {
            t_s: t - d_gyro,
            measurement: Measurement::YawRate {
                yaw_rate_rps: scaled(v),
            },
        };
        match ev.measurement {
            Measurement::Accel { x_mps2, .. } => {
                if self.slip {
                    self.accel.push_back((t, self.accel_sum));
                    self.accel_sum += x_mps2;
                }
                None
            }
            Measurement::Gyro {
                x_rps,
                y_rps,
                z_rps,
            } => {
                let up = self.known.up?;
                self.three_axis = true;
                Some(yaw(x_rps * up[0] + y_rps * up[1] + z_rps * up[2]))
            }
            Measurement::YawRate { yaw_rate_rps } => {
                if self.known.up.is_some() && self.three_axis {
                    return None;
                }
                Some(yaw(yaw_rate_rps))
            }
            Measurement::Speed { .. } => Some(Event {
                t_s: t - d_speed,
                ..ev
            }),
            Measurement::Steering { .. } => Some(Event {
                t_s: t - d_steering,
                ..ev
            }),
            Measurement::Gnss { .. } => Some(Event {
                t_s: t - d_gnss,
                ..ev
            }),
            Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => Some(ev),
        }
    }

    fn hold(&mut self, ev: Event) {
        let rank = ev.rank();
        let t = ev.t_s;
        // After every held event of an earlier time, or of the same time
        // and a rank not above: ties keep their arrival order.
        let i = self
            .pending
            .partition_point(|h| h.ev.t_s < t || (h.ev.t_s == t && h.rank <= rank));
        self.pending.insert(
            i,
            Held {
                rank,
                seq: self.seq,
                ev,
            },
        );
        self.seq += 1;
    }

    fn release_while(
        &mut self,
        ready: impl Fn(&Held) -> bool,
        release: &mut dyn FnMut(Event) -> Result<(), Error>,
    ) -> Result<(), Error> {
        while let Some(h) = self.pending.front() {
            if !ready(h) {
                break;
            }
            let Some(h) = self.pending.pop_front() else {
                break;
            };
            let ev = h.ev;
            if ev.is_wheel() {
                let ev = self.slip_corrected(ev);
                for e in std::mem::take(&mut self.tail) {
                    release(e)?;
                }
                self.last_wheel_s = Some(ev.t_s);
                release(ev)?;
            } else if self.last_wheel_s.is_some_and(|w| ev.t_s <= w) {
                release(ev)?;
            } else {
                self.tail.push(ev);
            }
        }
        Ok(())
    }

    /// A wheel row with the driven axle's slip removed
    /// ([`crate::traction::apply_at`]'s arithmetic).
    fn slip_corrected(&mut self, mut ev: Event) -> Event {
        if !self.slip {
            return ev;
        }
        let t = ev.t_s;
        let (lo, hi) = (t - SLIP_WINDOW_S, t + SLIP_WINDOW_S);
        let a = self.accel.partition_point(|s| s.0 < lo);
        let b = self.accel.partition_point(|s| s.0 < hi);
        let local = (b > a).then(|| {
            let cum_b = self.accel.get(b).map_or(self.accel_sum, |s| s.1);
            (cum_b - self.accel[a].1) / (b - a) as f64
        });
        // No later wheel row (time ≥ t) looks before t − 0.5.
        self.accel.drain(..a);
        let (Some(fw), Some(mean)) = (local, self.known.traction_mean_force_mps2) else {
            return ev;
        };
        let slip = self.known.traction_slip_per_mps2;
        let scale = 1.0 + slip.abs() * (fw - mean);
        if let Measurement::WheelSpeeds {
            fl_mps,
            fr_mps,
            rl_mps,
            rr_mps,
        } = ev.measurement
        {
            let (mut fl, mut fr, mut rl, mut rr) = (fl_mps, fr_mps, rl_mps, rr_mps);
            if slip > 0.0 {
                fl /= scale;
                fr /= scale;
            } else {
                rl /= scale;
                rr /= scale;
            }
            ev.measurement = Measurement::WheelSpeeds {
                fl_mps: fl,
                fr_mps: fr,
                rl_mps: rl,
                rr_mps: rr,
            };
        }
        ev
    }
}

/// Every reading of `drive` as input events, in time order (ties: wheels,
/// three-axis gyro, yaw rate, speed, steering, GNSS, accelerometer), with
/// the three-axis gyro and the accelerometer when the drive has them and
/// the readings after the last wheel row (a delayed stream's reading may
/// fall before it once corrected): what `deadreckon events` prints, so that
/// a live filter with stored corrections has every reading the batch
/// filter uses.
pub fn input_events(drive: &crate::Drive) -> Vec<Event> {
    let mut out: Vec<(u8, Event)> = crate::event::DriveEvents::new_uncut(drive)
        .map(|e| {
            let key = match e.measurement {
                Measurement::WheelTicks { .. } | Measurement::WheelSpeeds { .. } => 0,
                Measurement::YawRate { .. } => 2,
                Measurement::Speed { .. } => 3,
                Measurement::Steering { .. } => 4,
                _ => 5,
            };
            (key, e)
        })
        .collect();
    out.extend(drive.imu.gyro.iter().map(|g| {
        (
            1,
            Event {
                t_s: g.t_s,
                measurement: Measurement::Gyro {
                    x_rps: g.x,
                    y_rps: g.y,
                    z_rps: g.z,
                },
            },
        )
    }));
    out.extend(drive.imu.accel.iter().map(|a| {
        (
            6,
            Event {
                t_s: a.t_s,
                measurement: Measurement::Accel {
                    x_mps2: a.x,
                    y_mps2: a.y,
                    z_mps2: a.z,
                },
            },
        )
    }));
    // Stable: each stream keeps its order.
    out.sort_by(|a, b| a.1.t_s.total_cmp(&b.1.t_s).then(a.0.cmp(&b.0)));
    out.into_iter().map(|(_, e)| e).collect()
}
