//! Corrections chosen by evidence: `--corrections auto` (issue 29).
//!
//! [`crate::timing::prepare_with`] estimates the driven axle's slip, the IMU
//! tilt, every stream's delay and the gyro scale error. Each estimate comes
//! with a standard error, but a correction applied at one or two standard
//! errors moves the results either way: on the simulator's calibration drive,
//! which has no delay and an exact gyro, the GNSS delay and the gyro scale
//! came out at 1.6 and 1.8 standard errors, were applied, and took the
//! evaluation drive's 30 s outages from 0.41 to 0.71 m (median).
//!
//! Here a correction is applied only when the drive's own GNSS says it
//! helps, through fixes the calibration did not see:
//!
//! 1. Every correction is estimated on the whole drive
//!    ([`crate::timing::prepare_with`] with [`Which::All`]). One that is not
//!    estimated, or within [`MIN_Z`] standard errors of none, is not a
//!    candidate (reported as measured, not applied).
//! 2. Windows of [`WINDOW_S`] (shorter on a short drive) start every
//!    [`PERIOD_WINDOWS`] window lengths once the vehicle has moved as long;
//!    alternate windows form two folds. For each
//!    fold the car is calibrated (RTS) with the fold's fixes hidden, and the
//!    filter dead-reckons through the fold's windows: the error at each
//!    window's end against the hidden fix is the held-back error.
//! 3. Forward selection through the same windows (paired: the fixes' own
//!    noise is the same for every candidate): the drive without the judged
//!    corrections is the start; each round tries every candidate left added
//!    to those chosen so far and adds the one that lowers the mean held-back
//!    error most, if its paired t statistic over the windows is at most
//!    −[`MIN_T`] (the gyro scale: below
//!    −[`crate::gyro_scale::HELD_BACK_MIN_T`]; the receiver's wander, judged
//!    last: [`wander_wins`], the held-back error or the hidden fixes' likelihood); the
//!    selection stops when no candidate does. Corrections
//!    interact (a gyro's delay and its scale error both turn the heading in
//!    turns): judged one by one from none, a gyro 0.12 s late and 1.5 % off
//!    scale showed the delay as a loss until the scale was applied.
//!
//! The GNSS delay is the exception: it is chosen on its significance alone
//! (at least [`MIN_Z`] standard errors), and the others are judged with it
//! applied. A receiver's delay shifts every fix by the same time, the
//! held-back ones too: a filter that follows late fixes dead-reckons to
//! where the late fix at the window's end shows the car, so the held-back
//! error cannot tell a late receiver from a corrected one (only a change of
//! velocity inside a window shows it, which is what the delay's own
//! estimate measures). On the comma2k19 segment the held-back fixes
//! preferred the uncorrected receiver (0.433 against 0.395 m over three
//! 10 s windows) while the reference trajectory, which has no such delay,
//! says the correction takes 20 s outages from 1.48 to 0.59 m.
//!
//! The additions to the paper's model ([`crate::model_options`]: the rear
//! side slip, the steering model, a walking gyro bias, a GNSS recovery that
//! waits) are candidates in the same selection: the estimated ones at
//! [`MIN_Z`] standard errors from the vehicle's values, the two settings
//! without an estimate on the held-back fixes alone (never on a drive too
//! short to judge; the recovery only where the held-back filter recovered).
//! The receiver's wander is judged last: fitted
//! ([`crate::model_options::wander_candidate`]) on the drive with the
//! options chosen by then and their calibration (which also serves as the
//! returned drive's calibration: the calibration keeps white fixes, so the
//! wander does not change it), a candidate when the fit is not white fixes,
//! applied when the held-back fixes say so; the hidden fixes carry the
//! wander, so each is compared with the dead-reckoned antenna plus the
//! wander the filter still expects there
//! ([`crate::outage::through_windows_against_fixes`]), the prediction a
//! white-fix filter makes implicitly by keeping the offset it followed.
//! What is chosen is [`crate::timing::Corrections::model`].
//!
//! A drive too short for [`MIN_WINDOWS`] windows cannot judge: there each
//! candidate is applied on its significance, and the output says so.
//!
//! Every candidate's two figures and the decision are returned
//! ([`HeldBack`]) for the JSON, the text and params.toml.
//!
//! **Warm starts** (issue 30). Each candidate's fold calibration starts
//! from the same fold's calibration without it (the baseline folds from
//! the baseline's parameters), and the GNSS delay's steps each from the
//! step before ([`crate::timing::gnss_delay`]): a calibration stops when a
//! pass moves no parameter by a tolerance unit, wherever it started, so
//! the choice is the same and the judged figures move within the
//! tolerance (docs/performance.md). The baseline's calibration and the
//! chosen drive's start from the request's start: they are the calibration
//! the caller gets, `calibrate`'s of the returned drive bit for bit.
//!
//! What the judgement does not hold back: the correction's value is the
//! whole drive's estimate, which saw every fix (each correction is one or a
//! few numbers fitted on hundreds of fixes; re-estimating it per fold would
//! multiply the cost of the corrections' estimation by three). The
//! calibration each candidate is judged with, and the dead reckoning, never
//! see the fixes they are judged on.

use crate::calibrate::{self, CalibrationOptions};
use crate::drive::Drive;
use crate::lend;
use crate::model_options::{self, ModelOption, ModelOptions};
use crate::timing::{self, Corrections, DelayOptions, KnownCorrections, Status, Stream, Which};
use crate::Error;

mod folds;
pub(crate) use folds::paired;
pub use folds::windows;
use folds::{held_back_errors, mean, HeldBackRun};

/// Longest held-back window, s: 20 s, the length of the outages `evaluate`
/// reports on comma2k19 (long enough for a delay or a scale error to show
/// in the dead-reckoned position, short enough for a 10-minute drive to
/// give about twenty windows).
pub const WINDOW_S: f64 = 20.0;

/// Shortest held-back window, s: 8 s. A drive too short for
/// [`MIN_WINDOWS`] windows of [`WINDOW_S`] gets shorter ones (a sixth of
/// its moving span), down to this.
pub const MIN_WINDOW_S: f64 = 8.0;

/// Start-to-start spacing of the windows, in window lengths: 1.5 (10 s of
/// fixes between two 20 s windows let the aided filter take its position
/// back). The first window starts as long after the vehicle first moves
/// (30 s for 20 s windows: the heading is known by then on every drive of
/// the simulator's families; outage windows before it are the pull-away,
/// see [`crate::outage`]).
pub const PERIOD_WINDOWS: f64 = 1.5;

/// Fewest windows (both folds) for a judgement: 6 (about three and a half
/// minutes of moving). On a shorter drive every candidate (at least
/// [`SHORT_MIN_Z`] standard errors) is applied on its significance, and the
/// output says so: a paired t over three windows is too weak to overrule a
/// significant estimate. On the comma2k19 segment (60 s, three windows of
/// 9.8 s) the held-back judgement dropped the front axle's slip (13.6
/// standard errors; t = −0.6) and took 20 s outages from 0.613 to 0.644 m
/// (median, against the reference); calibrated on either 30 s half, with
/// too few windows to judge, applying nothing but the GNSS delay gave
/// 1.223 / 0.640 m on the other half against 0.807 / 0.511 m with every
/// significant correction.
pub const MIN_WINDOWS: usize = 6;

/// A candidate must be this many standard errors from none: 3.
pub const MIN_Z: f64 = 3.0;

/// On a drive too short to judge ([`MIN_WINDOWS`]), a correction is
/// applied when its estimate is at least √2 standard errors from none: then
/// applying it is expected to leave a smaller squared error than leaving it
/// out (with an unbiased estimate x̂ of standard error σ, applying leaves σ²,
/// leaving it out x², estimated by x̂² − σ²). With [`MIN_Z`] there, the
/// comma2k19 phone's tilt, 2.64° ± 0.97° on the second 30 s half, was left
/// out and that half's calibration took the first half's 20 s outages from
/// 0.513 to 0.599 m (median).
pub const SHORT_MIN_Z: f64 = std::f64::consts::SQRT_2;

/// A candidate is applied when it lowers the held-back error with a paired
/// t statistic of at most minus this: 1 (the mean difference at least its
/// own standard error; about 16 % one-sided for a correction that does
/// nothing). Chosen on the two drives of `deadreckon-sim/tests/held_back.rs`:
/// the simulated CAN speed's half-period delay, real but harmless, gave
/// t = −0.18 (0.6716 against 0.6745 m over 30 windows); a gyro 0.12 s late
/// gave t = −1.13 (0.812 against 0.938 m), the end errors of 20 s windows
/// varying by about 0.6 m from window to window. Checked on the dynamic
/// family (`deadreckon-api/tests/dynamic_family_defaults.rs`), held out on
/// cars 101–110.
pub const MIN_T: f64 = 1.0;

/// The receiver's wander ([`ModelOption::GnssWander`], judged last) is
/// applied when it lowers the held-back error at all: paired t below
/// minus this, 0 (issue 36). At [`MIN_T`] it was left out of receivers
/// whose fixes wander, at t between −1 and 0, and their pose covariance
/// stayed the white-fix filter's: over-confident by ×16–×24 on choice cars
/// 74, 75 and 81, where the wander filter's is within ×2–×3. Chosen among 1, 0.5 and 0 on issue 36's choice
/// cars 65–88 (`deadreckon-api/tests/pose_nees_family.rs`: mean final
/// error of 30 s outages 0.967 / 0.945 / 0.937 m, pose NEES merged over
/// the cars ×6.6 / ×5.4 / ×3.9 over-confident) and the dynamic family's
/// development cars 1–6 (`dynamic_family_defaults.rs`, effects none /
/// wander / all / all but the wander: 0.375 / 1.744 / 3.042 / 1.275 m,
/// 0.377 / 1.602 / 2.873 / 1.275 m, 0.377 / 1.534 / 2.873 / 1.306 m);
/// checked on check cars 89–112 and held-out cars 101–110 (docs/gnss-wander.md).
pub const WANDER_MIN_T: f64 = 0.0;

/// Whether candidate `c` judged at paired t `t` is applied: at most −[`MIN_T`],
/// below −[`crate::gyro_scale::HELD_BACK_MIN_T`] for the gyro scale (the
/// receiver's wander: [`wander_wins`]).
fn wins(c: Correction, t: f64) -> bool {
    match c {
        Correction::GyroScale => t < -crate::gyro_scale::HELD_BACK_MIN_T,
        Correction::Model(ModelOption::GnssWander) => wander_wins(t, f64::NAN),
        _ => t <= -MIN_T,
    }
}

/// Whether the receiver's wander is applied, judged at paired t `t` of the
/// held-back error and `score_t` of the hidden fixes' log-likelihood: when
/// it lowers the error (t below −[`WANDER_MIN_T`]), or when the fixes are
/// more likely with it (`score_t` above 0) and the error is not higher by
/// [`WANDER_MAX_ERROR_T`] standard errors or more.
///
/// The wander is a model of the fixes' noise: what it changes most is the
/// covariance the filter reports through an outage, which the error at a
/// window's end does not see and the fix's likelihood under the dead
/// reckoning's prediction (a proper score of that prediction) does. On
/// issue 36's choice car 70 the error rule left it out at t +0.16 (score t
/// +1.12) and the evaluation drive's pose NEES was ×45.6 over-confident,
/// ×1.7 with it, with 30 s outages ending 0.69 m off instead of 0.92 m.
pub fn wander_wins(t: f64, score_t: f64) -> bool {
    t < -WANDER_MIN_T || (score_t > 0.0 && t < WANDER_MAX_ERROR_T)
}

/// The held-back error's paired t at or above which a wander that makes
/// the hidden fixes more likely is still left out, 1: one standard error,
/// as [`MIN_T`] for the other corrections. Not tuned: set before the
/// measurement, kept on issue 36's choice cars 65–88 and the dynamic
/// family's development cars 1–6; checked on check cars 89–112 and
/// held-out cars 101–110 (docs/gnss-wander.md).
pub const WANDER_MAX_ERROR_T: f64 = 1.0;

/// The corrections a drive can be judged with.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Correction {
    /// The driven axle's slip ([`crate::traction`]).
    Traction,
    /// The IMU tilt ([`crate::imu`]).
    Tilt,
    /// A stream's delay.
    Delay(Stream),
    /// The gyro scale error ([`crate::gyro_scale`]).
    GyroScale,
    /// An addition to the paper's model ([`crate::model_options`]).
    Model(ModelOption),
}

impl Correction {
    /// Words for people: "driven axle's slip", "IMU tilt", "gnss delay",
    /// "gyro scale".
    pub fn name(self) -> String {
        match self {
            Correction::Traction => "driven axle's slip".into(),
            Correction::Tilt => "IMU tilt".into(),
            Correction::Delay(s) => format!("{} delay", s.name()),
            Correction::GyroScale => "gyro scale".into(),
            Correction::Model(m) => m.name().into(),
        }
    }

    /// A key for JSON and params.toml: `traction`, `imu`, `delay_gnss`,
    /// `gyro_scale`, or the model option's ([`ModelOption::key`]).
    pub fn key(self) -> String {
        match self {
            Correction::Traction => "traction".into(),
            Correction::Tilt => "imu".into(),
            Correction::Delay(s) => format!("delay_{}", s.name()),
            Correction::GyroScale => "gyro_scale".into(),
            Correction::Model(m) => m.key().into(),
        }
    }
}

impl std::fmt::Display for Correction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

/// One candidate's judgement.
#[derive(Debug, Clone, PartialEq)]
pub struct Judged {
    /// Which correction.
    pub correction: Correction,
    /// Its estimate over the whole drive divided by its standard error.
    pub z: f64,
    /// Mean held-back error with it added to the corrections chosen before
    /// it (the last round it was tried in), m.
    pub with_m: f64,
    /// Mean held-back error of those corrections without it, m.
    pub against_m: f64,
    /// The paired t statistic of the difference (negative: it helps).
    pub t: f64,
    /// The receiver's wander only: the paired t statistic of the hidden
    /// fixes' log-likelihood under the dead reckoning's prediction, with it
    /// against without (positive: the fixes are more likely with it; NaN
    /// for the others).
    pub score_t: f64,
    /// Applied.
    pub applied: bool,
    /// Chosen on its significance alone, not on the held-back fixes (the
    /// GNSS delay: the held-back fixes keep the receiver's clock).
    pub by_significance: bool,
}

/// What the held-back GNSS said.
#[derive(Debug, Clone, PartialEq)]
pub struct HeldBack {
    /// Held-back windows (both folds).
    pub windows: usize,
    /// Window length, s.
    pub window_s: f64,
    /// Mean held-back error without the judged corrections, m (the GNSS
    /// delay applied where it was chosen on its significance; NaN when not
    /// judged).
    pub without_m: f64,
    /// Every candidate (estimated, at least [`MIN_Z`] standard errors).
    pub judged: Vec<Judged>,
    /// Mean held-back error with the chosen candidates together, m (when
    /// more than one was chosen).
    pub together_m: Option<f64>,
    /// Why nothing was judged (a drive too short), if so.
    pub not_judged: Option<String>,
    /// The standard errors a correction needed to be a candidate:
    /// [`MIN_Z`], or [`SHORT_MIN_Z`] on a drive too short to judge.
    pub min_z: f64,
}

impl HeldBack {
    /// The decision on `c`, if it was a candidate.
    pub fn decision(&self, c: Correction) -> Option<&Judged> {
        self.judged.iter().find(|j| j.correction == c)
    }
}

/// The corrections `which` asks for, estimated and applied; with
/// [`Which::Auto`] each one chosen on held-back GNSS (module docs). The one
/// entry the commands, Python and `batch` call.
pub fn prepare(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections), Error> {
    prepare_calibrated(drive, copts, o, which).map(|(d, c, _)| (d, c))
}

/// [`prepare`], also returning `calibrate::calibrate(&drive, copts)` of the
/// drive it returns when the choice ran it already (with `auto`, the
/// baseline's calibration when nothing but the GNSS delay was chosen): the
/// caller need not calibrate the same drive twice. `None` when it did not.
pub fn prepare_calibrated(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections, Option<crate::calibrate::Calibration>), Error> {
    if which != Which::Auto {
        return timing::prepare_with(drive, copts, o, which).map(|(d, c)| (d, c, None));
    }
    // A copy without the truth (unless the calibration reads it), which
    // the working drives borrow from; the truth joins the drive returned
    // (no correction changes it).
    let (mut out, c, cal) = prepare_calibrated_owned(copts.working_copy(drive), copts, o, which)?;
    if out.truth.is_empty() {
        out.truth = drive.truth.clone();
    }
    Ok((out, c, cal))
}

/// [`prepare_calibrated`] of a drive handed over: its streams are lent to
/// the judgement's working drives ([`crate::lend`]) instead of copied, and
/// the chosen corrections are applied to it in place (the default
/// `calibrate`'s peak: docs/performance.md, "Eighth round"). The same
/// drive, corrections and calibration bit for bit.
pub fn prepare_calibrated_owned(
    mut source: Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections, Option<crate::calibrate::Calibration>), Error> {
    if which != Which::Auto {
        return timing::prepare_owned(source, copts, o, which).map(|(d, c)| (d, c, None));
    }
    let mut corrections = timing::estimate_lent(&mut source, copts, o, Which::All)?;
    let interval_delays = corrections.delays.for_wheel_intervals(&source);
    let drive = &mut source;
    let windows = windows(drive);
    let short = windows[0].len() + windows[1].len() < MIN_WINDOWS;
    let min_z = if short { SHORT_MIN_Z } else { MIN_Z };
    let mut candidates = candidates(&corrections, min_z);
    let mut held = HeldBack {
        min_z,
        windows: windows[0].len() + windows[1].len(),
        window_s: windows[0].first().map_or(WINDOW_S, |w| w.1 - w.0),
        without_m: f64::NAN,
        judged: Vec::new(),
        together_m: None,
        not_judged: None,
    };
    // The GNSS delay is chosen on its significance alone (module docs):
    // the held-back fixes keep the receiver's clock, so they cannot judge it.
    let gnss = Correction::Delay(Stream::Gnss);
    // The calibration of the chosen drive, where the wander's fit ran it
    // (the wander does not change it: the calibration keeps white fixes).
    let mut chosen_calibration = None;
    let mut chosen: Vec<Correction> = candidates
        .iter()
        .filter(|(c, _)| *c == gnss)
        .map(|(c, _)| *c)
        .collect();
    let base = chosen.clone();
    // The drive with the GNSS delay (if chosen) and the paper's model, and
    // its calibration: the start of every fold's passes, and the estimates
    // of the model's additions (side slip, steering) that are candidates.
    let (base_drive, base_loan) = lend::corrected(
        &known(
            &corrections,
            &interval_delays,
            &base,
            &ModelOptions::default(),
        ),
        drive,
        copts.reads_truth(),
    );
    let base_calibration = calibrate::calibrate(&base_drive, copts).ok();
    let initial = base_calibration.as_ref().map(|c| c.estimate.params);
    let mut model_values = match &base_calibration {
        Some(c) => {
            let (m, values) = model_options::candidates(&base_drive, c, min_z);
            // The settings without an estimate (walk, recovery) need the
            // held-back fixes: on a drive too short to judge they stay off.
            candidates.extend(
                m.into_iter()
                    .filter(|(_, z)| !short || z.is_finite())
                    .map(|(o, z)| (Correction::Model(o), z)),
            );
            values
        }
        None => ModelOptions::default(),
    };
    let judged: Vec<(Correction, f64)> = candidates
        .iter()
        .copied()
        .filter(|(c, _)| *c != gnss)
        .collect();
    held.judged = chosen
        .iter()
        .map(|&c| Judged {
            correction: c,
            z: candidates
                .iter()
                .find(|x| x.0 == c)
                .map_or(f64::NAN, |x| x.1),
            with_m: f64::NAN,
            against_m: f64::NAN,
            t: f64::NAN,
            score_t: f64::NAN,
            applied: true,
            by_significance: true,
        })
        .collect();
    if judged.is_empty() {
        // Nothing to judge: no filter runs.
        lend::give_back(drive, base_drive, base_loan);
    } else if short {
        lend::give_back(drive, base_drive, base_loan);
        held.not_judged = Some(format!(
            "{} held-back windows of {:.0} s, at least {MIN_WINDOWS} needed: the drive is too short to judge a correction on its own GNSS, so each is applied on its significance",
            held.windows, held.window_s
        ));
        held.judged.extend(judged.iter().map(|&(c, z)| Judged {
            correction: c,
            z,
            with_m: f64::NAN,
            against_m: f64::NAN,
            t: f64::NAN,
            score_t: f64::NAN,
            applied: true,
            by_significance: true,
        }));
        chosen.extend(judged.iter().map(|j| j.0));
    } else {
        let mut won: Vec<Correction> = Vec::new();
        // Forward selection: each round adds the candidate that lowers the
        // held-back error most, if it does so significantly (paired t at
        // most -MIN_T over the same windows); the others are tried again
        // with it in the next round.
        let mut current = held_back_errors(&base_drive, copts, [initial; 2], &windows, None)?;
        // The baseline's drive is not read again (each candidate's drive is
        // made from `drive`): its streams go back for the candidates'.
        lend::give_back(drive, base_drive, base_loan);
        held.without_m = mean(&current.errors);
        // A recovery that waits can change nothing where the filter never
        // recovered: then it is no candidate (and costs no run).
        let recovery = Correction::Model(ModelOption::GnssRecovery);
        let mut left: Vec<(Correction, f64)> = judged
            .iter()
            .copied()
            .filter(|(c, _)| *c != recovery || current.recoveries > 0)
            .collect();
        let mut set = base.clone();
        let mut tried: Vec<Judged> = Vec::new();
        loop {
            let mut best: Option<(usize, HeldBackRun, f64)> = None;
            for (i, &(c, z)) in left.iter().enumerate() {
                let with: Vec<Correction> = set.iter().copied().chain([c]).collect();
                let k = known(&corrections, &interval_delays, &with, &model_values);
                // The calibration holds the gyro bias constant: with a
                // walking bias the folds calibrate as without it.
                let same_calibration =
                    (c == Correction::Model(ModelOption::GyroWalk)).then_some(&current.params);
                // Each fold's calibration starts from the same fold's
                // calibration without the candidate (module docs, "Warm
                // starts").
                let start = current.params.map(|p| p.or(initial));
                let run = lend::with_corrected(&k, drive, copts.reads_truth(), |d| {
                    held_back_errors(d, copts, start, &windows, same_calibration)
                })?;
                let (diff_m, t) = paired(&run.errors, &current.errors);
                let j = Judged {
                    correction: c,
                    z,
                    with_m: mean(&run.errors),
                    against_m: mean(&current.errors),
                    t,
                    score_t: f64::NAN,
                    applied: false,
                    by_significance: false,
                };
                match tried.iter_mut().find(|x| x.correction == c) {
                    Some(x) => *x = j,
                    None => tried.push(j),
                }
                if wins(c, t) && best.as_ref().is_none_or(|b| diff_m < b.2) {
                    best = Some((i, run, diff_m));
                }
            }
            match best {
                Some((i, run, _)) => {
                    let (c, _) = left.remove(i);
                    set.push(c);
                    won.push(c);
                    if let Some(x) = tried.iter_mut().find(|x| x.correction == c) {
                        x.applied = true;
                    }
                    current = run;
                }
                None => break,
            }
        }
        // The receiver's wander: fitted after the others were chosen, on
        // the drive with them and its calibration (model_options' docs),
        // judged last. The calibration keeps white fixes, so the folds
        // calibrate as without it.
        let fitted = wander_may_be_fitted(drive).then(|| {
            let k = known(&corrections, &interval_delays, &set, &model_values);
            lend::with_corrected(&k, drive, copts.reads_truth(), |d| {
                let cal = if set == base {
                    base_calibration.clone()
                } else {
                    calibrate::calibrate(d, copts).ok()
                }?;
                let w = model_options::wander_candidate(d, &cal.estimate.params, &copts.filter);
                Some((cal, w))
            })
        });
        if let Some((cal, wander)) = fitted.flatten() {
            if let Some(w) = wander {
                model_values.gnss_wander = Some(w);
                let c = Correction::Model(ModelOption::GnssWander);
                let with: Vec<Correction> = set.iter().copied().chain([c]).collect();
                let k = known(&corrections, &interval_delays, &with, &model_values);
                let run = lend::with_corrected(&k, drive, copts.reads_truth(), |d| {
                    held_back_errors(d, copts, [initial; 2], &windows, Some(&current.params))
                })?;
                let (_, t) = paired(&run.errors, &current.errors);
                let (_, score_t) = paired(&run.scores, &current.scores);
                let applied = wander_wins(t, score_t);
                tried.push(Judged {
                    correction: c,
                    z: f64::NAN,
                    with_m: mean(&run.errors),
                    against_m: mean(&current.errors),
                    t,
                    score_t,
                    applied,
                    by_significance: false,
                });
                if applied {
                    set.push(c);
                    won.push(c);
                    current = run;
                }
            }
            chosen_calibration = Some(cal);
        }
        if !won.is_empty() {
            held.together_m = Some(mean(&current.errors));
        }
        held.judged.extend(tried);
        chosen.extend(won);
    }
    if chosen.contains(&Correction::Model(ModelOption::WheelIntervals)) {
        // What params.toml and the JSON report as applied.
        corrections.delays = interval_delays.clone();
    }
    mark(&mut corrections, &held, &chosen);
    let applied = known(&corrections, &interval_delays, &chosen, &model_values);
    let out = applied.apply_to(source);
    corrections.model = applied.model;
    corrections.held_back = Some(held);
    // Nothing chosen beyond the baseline: `out` is the baseline's drive
    // (the same known corrections), whose calibration is at hand.
    let calibration = chosen_calibration.or(base_calibration.filter(|_| chosen == base));
    Ok((out, corrections, calibration))
}

/// Whether the receiver's wander can be a candidate: the drive has fixes
/// and its vehicle carries no wander already.
fn wander_may_be_fitted(drive: &Drive) -> bool {
    drive.gnss.len() >= 2 && drive.vehicle.noise.gnss_wander_std_m == 0.0
}

/// The estimated corrections at least `min_z` standard errors from none,
/// with their z.
fn candidates(c: &Corrections, min_z: f64) -> Vec<(Correction, f64)> {
    let mut out = Vec::new();
    let mut push = |what: Correction, estimated: bool, value: f64, std: f64| {
        let z = value / std;
        if estimated && z.is_finite() && z.abs() >= min_z {
            out.push((what, z));
        }
    };
    if let Some(t) = &c.traction {
        push(
            Correction::Traction,
            t.is_estimated(),
            t.slip_per_mps2,
            t.std,
        );
    }
    if let Some(t) = &c.tilt {
        push(Correction::Tilt, t.is_estimated(), t.tilt_rad, t.std_rad);
    }
    for s in Stream::ALL {
        let d = c.delays.get(s);
        push(
            Correction::Delay(s),
            d.status.is_estimated(),
            d.delay_s,
            d.std_s,
        );
    }
    if let Some(g) = &c.gyro_scale {
        push(
            Correction::GyroScale,
            g.is_estimated(),
            g.scale_error,
            g.std,
        );
    }
    out
}

/// The corrections of `set`, with the values of `c` and of `model` for
/// the model's additions.
///
/// With the wheel intervals in `set`, the delays are applied as such a
/// filter needs them (`interval`: [`timing::Delays::for_wheel_intervals`]).
fn known(
    c: &Corrections,
    interval: &timing::Delays,
    set: &[Correction],
    model: &ModelOptions,
) -> KnownCorrections {
    let delays = if set.contains(&Correction::Model(ModelOption::WheelIntervals)) {
        interval
    } else {
        &c.delays
    };
    let mut k = KnownCorrections::default();
    for &what in set {
        match what {
            Correction::Traction => {
                if let Some(t) = &c.traction {
                    k.traction_slip_per_mps2 = t.slip_per_mps2;
                }
            }
            Correction::Tilt => k.up = c.tilt.as_ref().map(|t| t.up),
            Correction::Delay(s) => {
                let i = Stream::ALL.iter().position(|&x| x == s).unwrap_or(0);
                // As `Delays::apply`: the GNSS delay with the filter's step
                // offset.
                k.delays_s[i] = delays.get(s).applied_s();
            }
            Correction::GyroScale => {
                if let Some(g) = &c.gyro_scale {
                    k.gyro_scale_error = g.scale_error;
                }
            }
            Correction::Model(m) => k.model = k.model.with(m, model),
        }
    }
    k
}

/// Marks every estimated correction that is not in `chosen` as measured,
/// not applied, with the held-back figures as the reason.
fn mark(c: &mut Corrections, held: &HeldBack, chosen: &[Correction]) {
    let why = |what: Correction| -> String {
        match held.decision(what) {
            None => format!(
                "measured, not applied: within {:.1} standard errors of none",
                held.min_z
            ),
            Some(_) if held.not_judged.is_some() => format!(
                "measured, not applied: {}",
                held.not_judged.as_deref().unwrap_or_default()
            ),
            Some(j) => format!(
                "measured, not applied: held-back GNSS {:.3} m with it, {:.3} m without (paired t {:+.1}, {} windows of {:.0} s)",
                j.with_m, j.against_m, j.t, held.windows, held.window_s
            ),
        }
    };
    let unapply = |what: Correction, status: &mut Status| {
        if status.is_estimated() && !chosen.contains(&what) {
            *status = Status::NotEstimated(why(what));
        }
    };
    if let Some(t) = &mut c.traction {
        unapply(Correction::Traction, &mut t.status);
    }
    if let Some(t) = &mut c.tilt {
        unapply(Correction::Tilt, &mut t.status);
    }
    for s in Stream::ALL {
        unapply(Correction::Delay(s), &mut c.delays.get_mut(s).status);
    }
    if let Some(g) = &mut c.gyro_scale {
        unapply(Correction::GyroScale, &mut g.status);
    }
}
