//! The core library's error: what failed, with the values a program can
//! match on (which stream or key, the value, the rule or limit it broke),
//! and a `Display` that says it to a person.
//!
//! No message names a command-line flag: the library has C, Python and
//! ROS 2 users. A front end adds its own hint from the fields (the CLI's is
//! in `src/main.rs`, e.g. [`Need::InitialPose`] → `--init-pose`).

use std::borrow::Cow;
use std::fmt;

/// Errors of the core library.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The drive breaks an invariant (unsorted time, non-finite value, too short).
    #[error("invalid drive: {stream}: {fault}")]
    InvalidDrive {
        /// The stream (its file name without `.csv`: `wheel_speeds`,
        /// `gnss`, …; `events` for a live stream).
        stream: Cow<'static, str>,
        /// What is wrong with it.
        fault: DriveFault,
    },
    /// An event earlier than the one before it: a stream's events must be
    /// in time order (equal times are fine).
    #[error(
        "invalid drive: event at t={t_s} s comes after one at t={previous_t_s} s: events must be in time order"
    )]
    OutOfOrder {
        /// The event's time, s.
        t_s: f64,
        /// The time of the event before it, s.
        previous_t_s: f64,
    },
    /// A key of the vehicle description breaks its rule.
    #[error("invalid vehicle: {0}")]
    InvalidVehicle(Box<Invalid>),
    /// A calibration parameter or an option breaks its rule.
    #[error("invalid parameters: {0}")]
    InvalidParams(Box<Invalid>),
    /// Learning the parameters (RTS calibration, online learning) refused
    /// under per-reading timing with process noise above its limits: single
    /// readings would set the speed and yaw rate between wheel rows, and the
    /// calibration would read the GNSS fixes as speed.
    #[error(
        "invalid vehicle: the parameters cannot be learnt with per-reading timing and {}: \
         the readings between wheel rows would set the speed and yaw rate, and the \
         calibration would read the GNSS fixes as speed (circumferences millimetres to \
         metres off on simulated cars). Calibrate with timing at the wheel epochs, or lower \
         these values in vehicle.toml's [noise]",
        Limits(over)
    )]
    NoiseTooHighForPerReadingTiming {
        /// The process noises over their limits.
        over: Vec<Limit>,
    },
    /// A covariance lost positive definiteness or a matrix could not be inverted.
    #[error("numerical failure at t={t_s} s: {what}")]
    Numerical {
        /// Timestamp of the failing step.
        t_s: f64,
        /// What failed.
        what: String,
    },
    /// The data cannot support the requested computation (e.g. no GNSS for RTS calibration).
    #[error("insufficient data: {need}")]
    Insufficient {
        /// What the computation needed and did not find.
        need: Need,
    },
    /// A calibrated distance scale the GNSS chords disagree with, refused
    /// rather than kept: the smoothing filter did not follow the fixes.
    #[error("estimate rejected: {0}")]
    Rejected(Box<ScaleRejection>),
}

/// A calibrated distance scale the GNSS chords disagree with: the numbers
/// of [`Error::Rejected`].
#[derive(Debug, Clone, PartialEq)]
pub struct ScaleRejection {
    /// The mean relative disagreement of the scale with the chords
    /// (0.01: the wheels say 1 % more distance).
    pub scale_error: f64,
    /// Its standard error.
    pub scale_error_std: f64,
    /// The disagreement in standard errors.
    pub standard_errors: f64,
    /// The blocks of chords it is measured over.
    pub blocks: usize,
    /// The length of a block, s.
    pub block_s: f64,
    /// The two-sided p-value of the disagreement.
    pub p_value: f64,
    /// GNSS fixes the smoothing filter's gate rejected.
    pub gnss_rejected: usize,
    /// GNSS fixes offered to it.
    pub gnss_fixes: usize,
    /// Its recoveries after runs of rejected fixes.
    pub gnss_recoveries: usize,
    /// The smallest and largest calibrated circumference, m.
    pub circumference_m: (f64, f64),
    /// The calibration passes run.
    pub passes: usize,
}

impl fmt::Display for ScaleRejection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "the calibrated distance scale disagrees with the GNSS chords by {:+.2}% ± {:.2}% \
             ({:+.1} standard errors over {} blocks of {} s, p = {:.1e}): the smoothing \
             filter did not follow the fixes ({} of {} rejected by its gate, {} recoveries; \
             circumferences {:.4}–{:.4} m after {} passes)",
            100.0 * self.scale_error,
            100.0 * self.scale_error_std,
            self.standard_errors,
            self.blocks,
            self.block_s,
            self.p_value,
            self.gnss_rejected,
            self.gnss_fixes,
            self.gnss_recoveries,
            self.circumference_m.0,
            self.circumference_m.1,
            self.passes,
        )
    }
}

/// A key (of vehicle.toml, of the parameters, of an option) whose value
/// breaks its rule: the content of [`Error::InvalidVehicle`] and
/// [`Error::InvalidParams`].
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid {
    /// The key, as its file spells it (`noise.gnss_std_m`,
    /// `origin.lat_deg`, `wheel_circumference_m`) or the option's name.
    pub key: Cow<'static, str>,
    /// The value given.
    pub value: Value,
    /// The rule it breaks.
    pub rule: Rule,
}

impl fmt::Display for Invalid {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        Setting(&self.key, &self.value, &self.rule).fmt(f)
    }
}

/// What is wrong with a stream of a drive.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum DriveFault {
    /// Fewer samples than the computation needs.
    TooFewSamples {
        /// The fewest it needs.
        min: usize,
        /// The samples it has.
        have: usize,
    },
    /// A sample whose time is not a finite number.
    NonFiniteTime {
        /// Its index in the stream, if the stream is stored.
        index: Option<usize>,
        /// The time read.
        t_s: f64,
    },
    /// A sample not after the one before it.
    NotIncreasing {
        /// Its index in the stream.
        index: usize,
        /// Its time, s.
        t_s: f64,
        /// The time of the one before it, s.
        previous_t_s: f64,
    },
    /// A value that is not a finite number.
    NonFinite {
        /// Which value (`speed`, `value`, `position`).
        what: &'static str,
    },
    /// A value that must be positive and is not.
    NotPositive {
        /// Which value (`std_m`).
        what: &'static str,
    },
    /// Wheel ticks where a differential drive needs wheel speeds (odometry).
    TicksNotSpeeds,
    /// A fault said in words (the rare ones: a log reader's line-level
    /// findings, which name the line).
    Said(String),
}

impl fmt::Display for DriveFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::TooFewSamples { min, have } => {
                write!(f, "needs at least {min} epochs, has {have}")
            }
            Self::NonFiniteTime { index: Some(i), .. } => {
                write!(f, "sample {i} has a non-finite time")
            }
            Self::NonFiniteTime { index: None, t_s } => write!(f, "event time {t_s} is not finite"),
            Self::NotIncreasing {
                index,
                t_s,
                previous_t_s,
            } => write!(
                f,
                "sample {index} at t={t_s} s is not after the previous one (t={previous_t_s} s)"
            ),
            Self::NonFinite { what } => write!(f, "non-finite {what}"),
            Self::NotPositive { what } => write!(f, "{what} must be positive"),
            Self::TicksNotSpeeds => {
                write!(
                    f,
                    "a differential drive needs wheel speeds (odometry), not ticks"
                )
            }
            Self::Said(s) => f.write_str(s),
        }
    }
}

/// A value given for a key, as read.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Value {
    /// A number.
    Number(f64),
    /// Several numbers (a vector, or the values of related keys).
    Numbers(Vec<f64>),
    /// A count (of parameters, samples).
    Count(usize),
    /// Text (a name, a date).
    Text(String),
    /// Not repeated in the message (the rule says it all, or there is none).
    Unstated,
}

impl From<f64> for Value {
    fn from(v: f64) -> Self {
        Value::Number(v)
    }
}

/// The rule a key's value breaks.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Rule {
    /// A finite number above zero.
    Positive,
    /// A finite number, zero or more; `zero_means` says what 0 does.
    NonNegative {
        /// What 0 means, if it means something.
        zero_means: Option<&'static str>,
    },
    /// A finite number (or numbers).
    Finite,
    /// A number within ±`max`.
    WithinAbs(f64),
    /// A number from `min` to `max`, in `unit`.
    Between {
        /// The least.
        min: f64,
        /// The most.
        max: f64,
        /// Their meaning and unit, said after them.
        unit: &'static str,
    },
    /// At least `min`; `why` says why.
    AtLeast {
        /// The least.
        min: f64,
        /// Why, if not obvious.
        why: Option<&'static str>,
    },
    /// A positive number, or infinity, which means `inf_means`.
    PositiveOrInf {
        /// What infinity means.
        inf_means: &'static str,
    },
    /// Exactly `count` finite numbers.
    FiniteCount(usize),
    /// One of these names.
    OneOf(&'static [&'static str]),
    /// A UTC date or date-time.
    DateTime,
    /// A non-empty name without control characters.
    Name,
    /// At least one element.
    NonEmpty,
    /// A range of time (from, until) with from before until.
    TimeRange,
    /// A range of time inside the drive's wheel time span.
    InsideDrive {
        /// The drive's first wheel time, s.
        from_s: f64,
        /// Its last, s.
        until_s: f64,
    },
    /// A rule said in words (the rare ones; the text names the key).
    Said(String),
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Positive => write!(f, "must be a positive number"),
            Self::NonNegative { zero_means: None } => write!(f, "must be a non-negative number"),
            Self::NonNegative {
                zero_means: Some(z),
            } => write!(f, "must be a non-negative number (0: {z})"),
            Self::Finite => write!(f, "must be finite"),
            Self::WithinAbs(max) => write!(f, "must be a number within ±{max}"),
            Self::Between { min, max, unit } => {
                write!(f, "must be {unit}, {min} to {max}")
            }
            Self::AtLeast { min, why: None } => write!(f, "must be at least {min}"),
            Self::AtLeast { min, why: Some(w) } => write!(f, "must be at least {min} ({w})"),
            Self::PositiveOrInf { inf_means } => {
                write!(f, "must be positive (or inf {inf_means})")
            }
            Self::FiniteCount(n) => write!(f, "must be {n} finite numbers"),
            Self::OneOf(names) => write!(f, "must be one of {}", names.join(", ")),
            Self::DateTime => write!(
                f,
                "must be a UTC date or date-time, YYYY-MM-DD or YYYY-MM-DDTHH:MM:SS[.fff][Z]"
            ),
            Self::Name => write!(f, "must be a non-empty name without control characters"),
            Self::NonEmpty => write!(f, "must name at least one"),
            Self::TimeRange => write!(f, "must be a time range from:until s, from before until"),
            Self::InsideDrive { from_s, until_s } => write!(
                f,
                "must lie inside the drive, which runs {from_s:.3}–{until_s:.3} s \
                 (drive times, e.g. UNIX time for bags)"
            ),
            Self::Said(s) => write!(f, "{s}"),
        }
    }
}

/// `key rule, got value`, the words of a key that breaks its rule.
struct Setting<'a>(&'a Cow<'static, str>, &'a Value, &'a Rule);

impl fmt::Display for Setting<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Setting(key, value, rule) = self;
        match (rule, value) {
            (Rule::OneOf(names), Value::Text(t)) => {
                return write!(f, "unknown {key} `{t}` ({})", names.join(", "));
            }
            (Rule::Said(s), _) if key.is_empty() => write!(f, "{s}")?,
            (Rule::Said(s), _) => write!(f, "{key}: {s}")?,
            _ => write!(f, "{key} {rule}")?,
        }
        match value {
            Value::Number(v) => write!(f, ", got {v}"),
            Value::Numbers(v) => write!(f, ", got {v:?}"),
            Value::Count(n) => write!(f, ", got {n}"),
            Value::Text(t) => write!(f, ", got {t:?}"),
            Value::Unstated => Ok(()),
        }
    }
}

/// A value over its limit.
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// The key, as in vehicle.toml (`noise.process_speed_mps`).
    pub key: &'static str,
    /// Its value.
    pub value: f64,
    /// The most it may be.
    pub max: f64,
}

struct Limits<'a>(&'a [Limit]);

impl fmt::Display for Limits<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, l) in self.0.iter().enumerate() {
            if i > 0 {
                write!(f, " and ")?;
            }
            write!(f, "{} = {} (at most {})", l.key, l.value, l.max)?;
        }
        Ok(())
    }
}

/// A computation that needs data.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum Task {
    /// The RTS calibration (eq. 23–26).
    RtsCalibration,
    /// The calibration against the truth.
    TruthCalibration,
    /// The ZUPT calibration of the gyro bias.
    ZuptCalibration,
    /// Drift and distance metrics against the truth.
    Evaluation,
    /// Dead reckoning through sliding GNSS outages.
    OutageEvaluation,
    /// The NEES of the pose on dead-reckoning windows.
    Nees,
    /// The filter's initial state from the truth.
    InitFromTruth,
    /// The filter's initial state from GNSS.
    InitFromGnss,
    /// Fitting the GNSS receiver's wander.
    WanderFit,
    /// A differential drive's yaw from the gyro.
    GyroYaw,
    /// Dead reckoning a kinematic shape (differential drive, tricycle).
    DeadReckoning,
    /// The four-wheel filter.
    Filter,
}

impl fmt::Display for Task {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::RtsCalibration => "RTS calibration",
            Self::TruthCalibration => "truth calibration",
            Self::ZuptCalibration => "ZUPT",
            Self::Evaluation => "evaluation",
            Self::OutageEvaluation => "outage evaluation",
            Self::Nees => "NEES",
            Self::InitFromTruth => "initialisation from the truth",
            Self::InitFromGnss => "initialisation from GNSS",
            Self::WanderFit => "fitting the receiver's wander",
            Self::GyroYaw => "yaw from the gyro",
            Self::DeadReckoning => "dead reckoning",
            Self::Filter => "the filter",
        })
    }
}

/// An input a computation reads.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Input {
    /// GNSS fixes (gnss.csv).
    Gnss,
    /// At least one GNSS fix.
    GnssFix,
    /// A GNSS fix after the filter's start.
    GnssFixAfterStart,
    /// truth.csv with at least `min_poses` poses.
    Truth {
        /// The fewest poses (0: any).
        min_poses: usize,
    },
    /// truth.csv covering the drive.
    TruthCovering,
    /// truth.csv or GNSS fixes.
    TruthOrGnss,
    /// A gyro stream (yaw_rate.csv or the IMU's gyro).
    Gyro,
    /// Wheel rows.
    WheelRows,
    /// Wheel epochs after the initial time.
    WheelEpochsAfterStart,
    /// Odometry samples (a kinematic shape's wheel stream).
    Odometry,
    /// The vehicle moving `distance_m`.
    Travel {
        /// How far, m.
        distance_m: f64,
    },
    /// A standstill of at least `min_s` with gyro readings.
    Standstill {
        /// How long, s.
        min_s: f64,
    },
    /// At least one window.
    Window,
}

impl fmt::Display for Input {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Gnss => write!(f, "GNSS fixes (gnss.csv)"),
            Self::GnssFix => write!(f, "at least one fix"),
            Self::GnssFixAfterStart => write!(f, "a GNSS fix after the filter's start"),
            Self::Truth { min_poses: 0 } => write!(f, "truth.csv"),
            Self::Truth { min_poses } => write!(f, "truth.csv with at least {min_poses} poses"),
            Self::TruthCovering => write!(f, "truth.csv covering the drive"),
            Self::TruthOrGnss => write!(f, "truth.csv or GNSS fixes"),
            Self::Gyro => write!(f, "a gyro stream (yaw_rate.csv or the IMU's gyro)"),
            Self::WheelRows => write!(f, "wheel rows"),
            Self::WheelEpochsAfterStart => write!(f, "wheel epochs after the initial time"),
            Self::Odometry => write!(f, "odometry samples"),
            Self::Travel { distance_m } => write!(f, "the vehicle to move {distance_m} m"),
            Self::Standstill { min_s } => {
                write!(f, "a standstill of at least {min_s} s with gyro readings")
            }
            Self::Window => write!(f, "at least one window"),
        }
    }
}

/// What a computation needed and did not find in the data.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Need {
    /// An input the drive lacks, or has too little of.
    Input {
        /// The computation.
        task: Task,
        /// The input.
        input: Input,
    },
    /// A pose to start dead reckoning from: truth.csv, gnss.csv, or one
    /// given by the caller.
    InitialPose,
    /// Reference poses (a kinematic shape's tracker or GNSS) to start
    /// outages from and score them.
    ReferencePoses,
    /// A track the drive does not have.
    Track {
        /// The name asked for.
        name: String,
        /// The names the drive has.
        have: Vec<String>,
    },
    /// Motion above a speed.
    Motion {
        /// The speed never exceeded, m/s.
        min_speed_mps: f64,
    },
    /// A drive long enough for one outage window.
    OutageWindow {
        /// The outage, s.
        outage_s: f64,
        /// The warm-up (or fixes) needed before it, s.
        warmup_s: f64,
        /// The span the windows could use, s.
        span_s: (f64, f64),
        /// When the vehicle first moves, s (if the window must start moving).
        moving_from_s: Option<f64>,
    },
    /// An outage window that starts with the heading known.
    KnownHeading {
        /// The outage, s.
        outage_s: f64,
        /// The yaw standard deviation that counts as known, rad.
        yaw_std_rad: f64,
        /// When the aided filter's yaw standard deviation first falls to
        /// it, s (never: `None`).
        known_from_s: Option<f64>,
        /// The windows that start before that.
        windows: usize,
    },
    /// Travel with fixes before a kinematic filter can start.
    FilterStart {
        /// The path the odometry must travel, m.
        path_m: f64,
        /// The fixes it needs over it.
        fixes: usize,
    },
    /// A complete segment to measure drift on.
    DriftSegment {
        /// The segment, m.
        segment_m: f64,
    },
    /// Poses of two trajectories close enough in time to associate.
    Association {
        /// The reference's name.
        reference: String,
        /// The estimate's name.
        estimate: String,
        /// The largest time difference allowed, s.
        max_diff_s: f64,
    },
    /// A path longer than the RPE's delta.
    RpePath {
        /// Whose path (`estimate's`, `reference's`).
        whose: &'static str,
        /// The associated poses.
        poses: usize,
        /// Its length, m.
        path_m: f64,
        /// The RPE's delta, m.
        delta_m: f64,
    },
    /// Trajectory errors to summarise.
    TrajectoryErrors,
    /// Epochs out of the filter.
    FilterEpochs,
    /// A calibration pass that ran.
    CalibrationPass,
    /// Degrees of freedom for a χ² bound.
    DegreesOfFreedom {
        /// The degrees of freedom given.
        dof: f64,
    },
}

impl fmt::Display for Need {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Input { task, input } => write!(f, "{task} needs {input}"),
            Self::InitialPose => write!(
                f,
                "dead reckoning needs an initial pose: truth.csv, gnss.csv or one given"
            ),
            Self::ReferencePoses => {
                write!(f, "no reference poses to start and score outages from")
            }
            Self::Track { name, have } => write!(
                f,
                "no track named `{name}` (this drive has: {})",
                have.join(", ")
            ),
            Self::Motion { min_speed_mps } => write!(
                f,
                "the vehicle never moves faster than {min_speed_mps} m/s: no outage to evaluate"
            ),
            Self::OutageWindow {
                outage_s,
                warmup_s,
                span_s: (a, b),
                moving_from_s,
            } => {
                write!(f, "the drive ({a:.1}–{b:.1} s")?;
                if let Some(m) = moving_from_s {
                    write!(f, ", moving from {m:.1} s")?;
                }
                write!(f, ") is too short for a {outage_s} s outage")?;
                if *warmup_s > 0.0 {
                    write!(f, " after {warmup_s} s of warm-up")?;
                }
                Ok(())
            }
            Self::KnownHeading {
                outage_s,
                yaw_std_rad,
                known_from_s,
                windows,
            } => {
                let deg = yaw_std_rad.to_degrees();
                let known = match known_from_s {
                    Some(k) => format!("first falls to {deg:.1}° at {k:.1} s"),
                    None => format!("never falls to {deg:.1}°"),
                };
                write!(
                    f,
                    "no {outage_s} s outage window starts with the heading known: the aided \
                     filter's yaw standard deviation {known}, and every window ({windows}) \
                     starts before that (too few GNSS fixes while moving, or a drive too short)"
                )
            }
            Self::FilterStart { path_m, fixes } => write!(
                f,
                "the odometry never travels {path_m} m with {fixes} fixes: the filter cannot start"
            ),
            Self::DriftSegment { segment_m } => write!(
                f,
                "the drive has no complete segment of {segment_m} m to measure drift on"
            ),
            Self::Association {
                reference,
                estimate,
                max_diff_s,
            } => write!(
                f,
                "no poses of `{reference}` and `{estimate}` are within {max_diff_s} s of each other"
            ),
            Self::RpePath {
                whose,
                poses,
                path_m,
                delta_m,
            } => write!(
                f,
                "the {whose} path over the {poses} associated poses is {path_m:.1} m, \
                 shorter than the RPE's delta of {delta_m} m"
            ),
            Self::TrajectoryErrors => write!(f, "no trajectory errors to summarise"),
            Self::FilterEpochs => write!(f, "the filter produced no epochs"),
            Self::CalibrationPass => write!(f, "no calibration pass ran"),
            Self::DegreesOfFreedom { dof } => {
                write!(f, "a χ² bound needs positive degrees of freedom, got {dof}")
            }
        }
    }
}

impl Error {
    /// [`Error::Insufficient`] for `task` lacking `input`.
    pub fn needs(task: Task, input: Input) -> Self {
        Error::Insufficient {
            need: Need::Input { task, input },
        }
    }

    /// [`Error::InvalidParams`] for `key`, whose `value` breaks `rule`.
    pub fn param(key: impl Into<Cow<'static, str>>, value: impl Into<Value>, rule: Rule) -> Self {
        Error::InvalidParams(Box::new(Invalid {
            key: key.into(),
            value: value.into(),
            rule,
        }))
    }

    /// [`Error::InvalidVehicle`] for `key`, whose `value` breaks `rule`.
    pub fn vehicle(key: impl Into<Cow<'static, str>>, value: impl Into<Value>, rule: Rule) -> Self {
        Error::InvalidVehicle(Box::new(Invalid {
            key: key.into(),
            value: value.into(),
            rule,
        }))
    }

    /// [`Error::InvalidDrive`] for `stream`.
    pub fn drive(stream: impl Into<Cow<'static, str>>, fault: DriveFault) -> Self {
        Error::InvalidDrive {
            stream: stream.into(),
            fault,
        }
    }
}

impl From<Need> for Error {
    fn from(need: Need) -> Self {
        Error::Insufficient { need }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The error stays small enough to return by value: boxed payloads
    /// for the big variants (clippy's `result_large_err` fired on
    /// `deadreckon-io`'s errors, which hold it, at 104 bytes).
    #[test]
    fn the_error_is_at_most_64_bytes() {
        assert!(
            std::mem::size_of::<Error>() <= 64,
            "{}",
            std::mem::size_of::<Error>()
        );
    }

    #[test]
    fn messages_say_the_key_the_rule_and_the_value() {
        let e = Error::vehicle("noise.gnss_std_m", -1.0, Rule::Positive);
        assert_eq!(
            e.to_string(),
            "invalid vehicle: noise.gnss_std_m must be a positive number, got -1"
        );
        let e = Error::needs(Task::RtsCalibration, Input::Gnss);
        assert_eq!(
            e.to_string(),
            "insufficient data: RTS calibration needs GNSS fixes (gnss.csv)"
        );
        let e = Error::drive(
            "gnss",
            DriveFault::NotIncreasing {
                index: 3,
                t_s: 1.0,
                previous_t_s: 2.0,
            },
        );
        assert_eq!(
            e.to_string(),
            "invalid drive: gnss: sample 3 at t=1 s is not after the previous one (t=2 s)"
        );
        let e = Error::NoiseTooHighForPerReadingTiming {
            over: vec![Limit {
                key: "noise.process_speed_mps",
                value: 0.5,
                max: 0.1,
            }],
        };
        assert!(e
            .to_string()
            .contains("per-reading timing and noise.process_speed_mps = 0.5 (at most 0.1):"));
    }
}
