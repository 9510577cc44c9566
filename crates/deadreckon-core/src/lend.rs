//! Working drives that borrow the streams they do not change (issue 30).
//!
//! The default `calibrate` judges its corrections on working drives: the
//! drive with the GNSS delay's trial shifts, with a candidate's delay, with
//! the IMU levelled. Each used to be a copy of the whole drive (136 B per
//! wheel epoch on the bench's drives, the largest owner at the default's
//! peak: docs/performance.md, "Eighth round"), though a correction changes
//! one or two streams, most often only their timestamps.
//!
//! [`lend`] moves the streams out of the drive as given into the working
//! drive instead, and [`give_back`] moves them back afterwards:
//!
//! - a stream the corrections leave alone ([`Change::None`]) is moved, not
//!   copied;
//! - a stream whose timestamps they shift ([`Change::Times`]: a delay) is
//!   moved and its timestamps kept aside (8 bytes a sample instead of a
//!   copy of the sample), and written back when it is given back: bit for
//!   bit the stream as it was, whatever the shift did;
//! - a stream whose values they change or replace ([`Change::Values`]: the
//!   levelled yaw rate, the gyro's scale, the GNSS delay's steps) is
//!   copied, as before.
//!
//! The truth is lent only when the working drive's calibration reads it
//! ([`crate::calibrate::CalibrationOptions::reads_truth`]): otherwise the
//! working drive has none, as [`Drive::clone_without_truth`] gave it.

use crate::drive::{Drive, Wheels};
use crate::timing::KnownCorrections;

/// What the working drive's corrections do to one stream.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Default)]
pub enum Change {
    /// Nothing: the stream is moved into the working drive and back.
    #[default]
    None,
    /// Its timestamps only (a delay): moved, its timestamps kept aside.
    Times,
    /// Its values, or the whole stream replaced: copied.
    Values,
}

/// What the working drive's corrections do to each stream (the
/// accelerometer is never corrected: always moved).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Changes {
    /// The wheels (the driven axle's slip: [`Change::Values`]; they have
    /// no delay).
    pub wheels: Change,
    /// The yaw rate.
    pub yaw_rate: Change,
    /// The three-axis gyro.
    pub imu_gyro: Change,
    /// The CAN speed.
    pub speed: Change,
    /// The steering wheel angle.
    pub steering: Change,
    /// The GNSS fixes.
    pub gnss: Change,
}

impl Changes {
    /// What shifting the streams by `delays_s` ([`crate::timing::shift_in_place`],
    /// in [`crate::timing::Stream::ALL`] order) changes: the timestamps of
    /// each stream whose delay is not +0.0 (`t − 0.0` is `t` bit for bit,
    /// `−0.0 − (−0.0)` is not).
    pub fn of_delays(delays_s: [f64; 4]) -> Changes {
        let shifted = |d: f64| {
            if d.to_bits() == 0 {
                Change::None
            } else {
                Change::Times
            }
        };
        let [g, s, st, gn] = delays_s;
        Changes {
            wheels: Change::None,
            yaw_rate: shifted(g),
            imu_gyro: shifted(g),
            speed: shifted(s),
            steering: shifted(st),
            gnss: shifted(gn),
        }
    }

    /// Both `self`'s and `other`'s changes (the larger of each stream's).
    pub fn and(self, other: Changes) -> Changes {
        Changes {
            wheels: self.wheels.max(other.wheels),
            yaw_rate: self.yaw_rate.max(other.yaw_rate),
            imu_gyro: self.imu_gyro.max(other.imu_gyro),
            speed: self.speed.max(other.speed),
            steering: self.steering.max(other.steering),
            gnss: self.gnss.max(other.gnss),
        }
    }

    /// Every stream's timestamps (the GNSS delay's steps move the scalar
    /// streams to their true time and the fixes by each step).
    pub const ALL_TIMES: Changes = Changes {
        wheels: Change::None,
        yaw_rate: Change::Times,
        imu_gyro: Change::Times,
        speed: Change::Times,
        steering: Change::Times,
        gnss: Change::Times,
    };

    /// [`Changes::and`] with the yaw rate's values changed (levelled or
    /// rescaled) when `yes`.
    pub fn yaw_values(self, yes: bool) -> Changes {
        let mut c = self;
        if yes {
            c.yaw_rate = Change::Values;
        }
        c
    }
}

/// How one stream was lent: what [`give_back`] needs to restore it.
#[derive(Debug, Default)]
enum Lent {
    /// Moved: moved back.
    #[default]
    Moved,
    /// Moved with its timestamps: moved back and the timestamps restored.
    Times(Vec<f64>),
    /// Copied: the working drive's copy is dropped.
    Copied,
}

/// What [`lend`] took from a drive, for [`give_back`].
#[derive(Debug)]
#[must_use = "the lent streams are lost unless given back"]
pub struct Loan {
    wheels_copied: bool,
    yaw_rate: Lent,
    imu_gyro: Lent,
    speed: Lent,
    steering: Lent,
    gnss: Lent,
    truth: bool,
}

/// One stream of samples with a timestamp.
trait Stamped: Clone {
    fn t_s(&mut self) -> &mut f64;
}

macro_rules! stamped {
    ($($t:ty),*) => {$(
        impl Stamped for $t {
            fn t_s(&mut self) -> &mut f64 {
                &mut self.t_s
            }
        }
    )*};
}
stamped!(
    crate::drive::Scalar,
    crate::drive::Axes,
    crate::drive::GnssFix
);

fn lend_stream<T: Stamped>(source: &mut Vec<T>, change: Change) -> (Vec<T>, Lent) {
    match change {
        Change::None => (std::mem::take(source), Lent::Moved),
        Change::Times => {
            let times = source.iter_mut().map(|s| *s.t_s()).collect();
            (std::mem::take(source), Lent::Times(times))
        }
        Change::Values => (source.clone(), Lent::Copied),
    }
}

fn give_back_stream<T: Stamped>(source: &mut Vec<T>, working: Vec<T>, lent: Lent) {
    match lent {
        Lent::Moved => *source = working,
        Lent::Times(times) => {
            *source = working;
            for (s, t) in source.iter_mut().zip(times) {
                *s.t_s() = t;
            }
        }
        Lent::Copied => {}
    }
}

/// A working drive made from `source` for corrections that make `changes`:
/// the vehicle copied, the streams moved or copied as the module docs say,
/// the truth moved when `with_truth` (else none). `source` is left with the
/// copied streams only until [`give_back`].
pub fn lend(source: &mut Drive, changes: Changes, with_truth: bool) -> (Drive, Loan) {
    let (yaw_rate, l_yaw) = lend_stream(&mut source.yaw_rate, changes.yaw_rate);
    let (gyro, l_gyro) = lend_stream(&mut source.imu.gyro, changes.imu_gyro);
    let (speed, l_speed) = lend_stream(&mut source.speed, changes.speed);
    let (steering, l_steering) = lend_stream(&mut source.steering, changes.steering);
    let (gnss, l_gnss) = lend_stream(&mut source.gnss, changes.gnss);
    let working = Drive {
        vehicle: source.vehicle.clone(),
        wheels: if changes.wheels == Change::None {
            std::mem::replace(&mut source.wheels, Wheels::Ticks(Vec::new()))
        } else {
            source.wheels.clone()
        },
        yaw_rate,
        speed,
        steering,
        gnss,
        truth: if with_truth {
            std::mem::take(&mut source.truth)
        } else {
            Vec::new()
        },
        imu: crate::drive::Imu {
            gyro,
            accel: std::mem::take(&mut source.imu.accel),
        },
    };
    let loan = Loan {
        wheels_copied: changes.wheels != Change::None,
        yaw_rate: l_yaw,
        imu_gyro: l_gyro,
        speed: l_speed,
        steering: l_steering,
        gnss: l_gnss,
        truth: with_truth,
    };
    (working, loan)
}

/// Gives the streams [`lend`] took back to `source`: bit for bit the drive
/// it was before, whatever the corrections did to `working` (the shifted
/// timestamps are restored; what was copied is dropped).
pub fn give_back(source: &mut Drive, working: Drive, loan: Loan) {
    let Drive {
        wheels,
        yaw_rate,
        speed,
        steering,
        gnss,
        truth,
        imu,
        ..
    } = working;
    if !loan.wheels_copied {
        source.wheels = wheels;
    }
    give_back_stream(&mut source.yaw_rate, yaw_rate, loan.yaw_rate);
    give_back_stream(&mut source.imu.gyro, imu.gyro, loan.imu_gyro);
    give_back_stream(&mut source.speed, speed, loan.speed);
    give_back_stream(&mut source.steering, steering, loan.steering);
    give_back_stream(&mut source.gnss, gnss, loan.gnss);
    source.imu.accel = imu.accel;
    if loan.truth {
        source.truth = truth;
    }
}

/// `source` with the corrections `k` applied
/// ([`KnownCorrections::apply_to`]), lent the streams they leave alone or
/// only move in time ([`KnownCorrections::changes`]): bit for bit `k`
/// applied to a copy of `source` (without its truth unless `with_truth`).
/// [`give_back`] returns the streams.
pub fn corrected(k: &KnownCorrections, source: &mut Drive, with_truth: bool) -> (Drive, Loan) {
    let (d, loan) = lend(source, k.changes(), with_truth);
    (k.apply_to(d), loan)
}

/// `f` of [`corrected`]'s drive, the streams given back afterwards.
pub fn with_corrected<R>(
    k: &KnownCorrections,
    source: &mut Drive,
    with_truth: bool,
    f: impl FnOnce(&Drive) -> R,
) -> R {
    let (d, loan) = corrected(k, source, with_truth);
    let r = f(&d);
    give_back(source, d, loan);
    r
}

#[cfg(test)]
#[path = "lend_tests.rs"]
mod tests;
