//! Every stream's delay and the corrections of a drive: [`estimate`],
//! [`prepare`] and the corrections known in advance ([`KnownCorrections`]).

use super::gnss::gnss_delay_of;
use super::scalar::{gyro_delay, speed_delay, steering_delay};
use super::{shift_in_place, Delay, DelayOptions, Delays, Status, Stream, MEASURED_NOT_APPLIED};
use crate::calibrate::{self, CalibrationOptions};
use crate::drive::Drive;
use crate::lend::{Change, Changes};
use crate::{Error, Params};

/// Every stream's delay: the scalar streams on `drive` as given, then the
/// GNSS on the drive with the scalar delays applied.
pub fn estimate(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<Delays, Error> {
    estimate_with_params(drive, copts, o).map(|(d, _)| d)
}

/// [`estimate`], also returning the calibration at the final GNSS delay
/// (with the scalar delays applied on the receiver's clock,
/// [`on_true_time`]), when the GNSS delay was estimated.
pub fn estimate_with_params(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delays, Option<Params>), Error> {
    estimate_with_params_owned(drive.clone(), copts, o)
}

/// [`estimate_with_params`] on a drive handed over: the GNSS delay's steps
/// run on it, moved in place to the scalar streams' true time, instead of
/// on a copy (one copy of the drive less through the GNSS delay's
/// calibrations, the default `calibrate`'s peak: docs/performance.md,
/// "Fifth round").
pub fn estimate_with_params_owned(
    mut drive: Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delays, Option<Params>), Error> {
    estimate_with_params_in(&mut drive, copts, o)
}

/// [`estimate_with_params_owned`] on a drive it may change: moved in place
/// to the scalar streams' true time, its fixes to the GNSS delay's last
/// step (only timestamps and the vehicle change: a drive lent its streams,
/// [`crate::lend`], gives them back as they were).
fn estimate_with_params_in(
    drive: &mut Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Delays, Option<Params>), Error> {
    // One after the other on the calling thread: run in parallel (rayon)
    // they saved 0.1 s of wall time on the bench's 10-minute drive but
    // their temporaries went to a worker thread's malloc arena, which the
    // calling thread's later allocations do not reuse: the hour's peak RSS
    // with `--corrections gnss` rose from 113.6 to 138.0 MB with one
    // thread (issue 30; the same with MALLOC_ARENA_MAX=1: 111 MB).
    let mut delays = Delays {
        gyro: gyro_delay(drive, o),
        speed: speed_delay(drive, o),
        steering: steering_delay(drive, o),
        gnss: Delay::not_estimated("not estimated"),
    };
    let true_time = on_true_time(&delays, drive);
    let intervals = drive.vehicle.noise.wheel_rows_over_interval;
    if intervals {
        // A filter over the wheel intervals takes the streams on true time.
        delays = delays.for_wheel_intervals(drive);
    }
    true_time.apply_in_place(drive);
    // The filter's streams are moved by the delays as estimated (on true
    // time over the intervals: as the reference's, exactly).
    let view = if intervals {
        [0.0; 3]
    } else {
        [Stream::Gyro, Stream::Speed, Stream::Steering]
            .map(|s| delays.get(s).applied_s() - true_time.get(s).applied_s())
    };
    let (g, params) = gnss_delay_of(drive, copts, o, view)?;
    delays.gnss = g;
    Ok((delays, params))
}

/// The scalar streams' delays as the GNSS delay's reference needs them:
/// each estimated one plus half the drive's wheel period
/// ([`wheel_half_period_s`]), the GNSS delay left out.
///
/// A scalar delay is measured against a signal from the wheel rows at their
/// stamps, while each row describes the period that ended there: the
/// reference is half a period late, and a stream on time reads half a period
/// early (the evaluation drive, seed 25, 50 Hz ticks, no delays: gyro
/// −14.3 ± 4.2 ms, CAN speed −9.6 ± 0.8 ms). Those readings stay the
/// delays `all` applies and `auto` judges (they align the streams with the
/// paper's wheel step). The GNSS delay's reference takes each wheel row over
/// its own interval ([`super::REFERENCE_WHEEL_ROWS`]), on true time, and the
/// streams moved by the readings as they are lag it: the dynamic family's
/// car 1003 (50 Hz ticks, no delays), its CAN speed moved by −13 ms, read
/// the receiver's delay as −44.4 ± 10.2 ms (applied by `auto` on its
/// significance) against −28.3 ± 10.2 ms with the half period added and
/// −26.9 ± 10.3 ms with no stream moved.
pub fn on_true_time(delays: &Delays, drive: &Drive) -> Delays {
    let half = wheel_half_period_s(drive);
    let mut out = delays.clone();
    for s in [Stream::Gyro, Stream::Speed, Stream::Steering] {
        let d = out.get_mut(s);
        if d.status.is_estimated() {
            d.delay_s += half;
        }
        // The estimate's own offset (`Delays::for_wheel_intervals`) is in
        // the half period already.
        d.step_offset_s = 0.0;
    }
    out.gnss = Delay::not_estimated("not estimated");
    out
}

/// Half the median interval between the drive's wheel rows, s (0 with fewer
/// than two rows).
pub fn wheel_half_period_s(drive: &Drive) -> f64 {
    let mut t: Vec<f64> = match &drive.wheels {
        crate::drive::Wheels::Ticks(v) => v.windows(2).map(|w| w[1].t_s - w[0].t_s).collect(),
        crate::drive::Wheels::Speeds(v) => v.windows(2).map(|w| w[1].t_s - w[0].t_s).collect(),
    };
    if t.is_empty() {
        return 0.0;
    }
    let mid = t.len() / 2;
    0.5 * *t.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

/// Which corrections [`crate::held_back::prepare`] estimates and applies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Which {
    /// Every correction estimated; each applied only when it lowers the
    /// dead-reckoning error through GNSS the calibration did not see
    /// ([`crate::held_back`]): the commands' default.
    #[default]
    Auto,
    /// The driven axle's slip, the IMU tilt, every stream's delay and the
    /// gyro scale.
    All,
    /// The driven axle's slip, the IMU tilt, the GNSS delay and the gyro
    /// scale (the other streams' delays estimated and reported, not
    /// applied).
    Gnss,
    /// Nothing estimated or applied.
    None,
}

impl Which {
    /// The word the command line takes: `auto`, `all`, `gnss`, `none`.
    pub fn name(self) -> &'static str {
        match self {
            Which::Auto => "auto",
            Which::All => "all",
            Which::Gnss => "gnss",
            Which::None => "none",
        }
    }
}

/// What [`prepare`] found and applied.
#[derive(Debug, Clone, PartialEq)]
pub struct Corrections {
    /// The driven axle's slip (`None`: no accelerometer in the drive, or
    /// not attempted).
    pub traction: Option<crate::traction::TractionSlip>,
    /// The IMU's tilt (`None`: no three-axis IMU in the drive).
    pub tilt: Option<crate::imu::Tilt>,
    /// The streams' delays.
    pub delays: Delays,
    /// The gyro's scale error (`None` when not attempted: no GNSS delay, so
    /// no calibration to take the bias from).
    pub gyro_scale: Option<crate::gyro_scale::GyroScale>,
    /// With [`Which::Auto`]: what the held-back GNSS said of each
    /// correction ([`crate::held_back`]).
    pub held_back: Option<crate::held_back::HeldBack>,
    /// With [`Which::Auto`]: the additions to the paper's model the
    /// held-back GNSS chose ([`crate::model_options`]; empty otherwise).
    pub model: crate::model_options::ModelOptions,
}

impl Corrections {
    /// Nothing estimated or applied: what [`prepare_with`] returns with
    /// [`Which::None`] (the drive then unchanged).
    pub fn none() -> Corrections {
        Corrections {
            traction: None,
            tilt: None,
            delays: Delays::none(),
            gyro_scale: None,
            held_back: None,
            model: Default::default(),
        }
    }
}

/// Estimates the driven axle's slip ([`crate::traction`], correcting its
/// wheel speeds when estimated), the IMU tilt (projecting the gyro on the
/// vertical when estimated), every stream's delay and the gyro scale error
/// ([`crate::gyro_scale`], with the bias of a calibration at the final
/// delays), and returns the drive with them applied.
pub fn prepare(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
) -> Result<(Drive, Corrections), Error> {
    prepare_with(drive, copts, o, Which::All)
}

/// [`prepare`] with a choice of what is applied (see [`Which`]); an
/// unapplied delay is marked not estimated with the reason.
/// [`Which::Auto`] is decided by [`crate::held_back::prepare`], which calls
/// this with [`Which::All`]; asked here, it is refused.
pub fn prepare_with(
    drive: &Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections), Error> {
    prepare_owned(drive.clone(), copts, o, which)
}

/// [`prepare_with`] on a drive handed over: the corrections estimated on
/// working drives lent its streams ([`estimate_lent`]), then applied to it
/// in place. The same drive and corrections bit for bit.
pub fn prepare_owned(
    mut drive: Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<(Drive, Corrections), Error> {
    if which == Which::None {
        return Ok((drive, Corrections::none()));
    }
    let c = estimate_lent(&mut drive, copts, o, which)?;
    if let Some(t) = c.traction.as_ref().filter(|t| t.is_estimated()) {
        crate::traction::apply_at_in_place(&mut drive, t.slip_per_mps2, None);
    }
    levelled_and_delayed(&mut drive, &c.tilt, &c.delays);
    if let Some(g) = c.gyro_scale.as_ref().filter(|g| g.is_estimated()) {
        crate::gyro_scale::apply_in_place(&mut drive, g.scale_error);
    }
    Ok((drive, c))
}

/// The drive levelled by `tilt` and moved by the applied `delays`, in place.
fn levelled_and_delayed(d: &mut Drive, tilt: &Option<crate::imu::Tilt>, delays: &Delays) {
    crate::imu::level_in_place(d, tilt.as_ref());
    delays.apply_in_place(d);
}

/// What [`levelled_and_delayed`] changes.
fn level_and_delay_changes(tilt: &Option<crate::imu::Tilt>, delays: &Delays) -> Changes {
    Changes::of_delays(Stream::ALL.map(|s| delays.get(s).applied_s()))
        .yaw_values(tilt.as_ref().is_some_and(|t| t.is_estimated()))
}

/// The corrections [`prepare_with`] estimates (`which`: not [`Which::None`]
/// or [`Which::Auto`]), on working drives lent `source`'s streams
/// ([`crate::lend`]: moved, with their timestamps kept where a delay moves
/// them, copied where a correction changes their values) and given back:
/// `source` is as it was. The same corrections bit for bit as on copies
/// of the drive (the default `calibrate`'s peak: docs/performance.md,
/// "Eighth round").
pub fn estimate_lent(
    source: &mut Drive,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<Corrections, Error> {
    if which == Which::Auto {
        return Err(Error::param(
            "corrections",
            crate::Value::Text("auto".into()),
            crate::Rule::Said(
                "the automatic choice of corrections is made by held_back::prepare".into(),
            ),
        ));
    }
    // The driven axle's slip first: the wheels are the clock and the scale
    // every other correction is measured against.
    let traction = crate::traction::estimate(source);
    match traction.as_ref().filter(|t| t.is_estimated()) {
        Some(t) => {
            let changes = Changes {
                wheels: Change::Values,
                ..Changes::default()
            };
            let (mut slipped, loan) = crate::lend::lend(source, changes, true);
            crate::traction::apply_at_in_place(&mut slipped, t.slip_per_mps2, None);
            let c = estimate_slipped(&mut slipped, traction.clone(), copts, o, which);
            crate::lend::give_back(source, slipped, loan);
            c
        }
        None => estimate_slipped(source, traction, copts, o, which),
    }
}

/// [`estimate_lent`] after the slip (`d`: the drive with it applied).
fn estimate_slipped(
    d: &mut Drive,
    traction: Option<crate::traction::TractionSlip>,
    copts: &CalibrationOptions,
    o: &DelayOptions,
    which: Which,
) -> Result<Corrections, Error> {
    // The GNSS delay's steps on the levelled drive moved in place (as
    // `imu::level`), without the truth unless the calibration reads it.
    let tilt = crate::imu::estimate_tilt(d);
    let levels = tilt.as_ref().is_some_and(|t| t.is_estimated());
    let (mut levelled, loan) = crate::lend::lend(
        d,
        Changes::ALL_TIMES.yaw_values(levels),
        copts.reads_truth(),
    );
    crate::imu::level_in_place(&mut levelled, tilt.as_ref());
    let steps = estimate_with_params_in(&mut levelled, copts, o);
    crate::lend::give_back(d, levelled, loan);
    let (mut delays, params) = steps?;
    if which == Which::Gnss {
        for d in [&mut delays.gyro, &mut delays.speed, &mut delays.steering] {
            if d.status.is_estimated() {
                // The measured delay and its std stay in `d` for the reports.
                d.status = Status::NotEstimated(MEASURED_NOT_APPLIED.to_string());
            }
        }
    }
    // The gyro scale on the drive levelled and delayed (the drive
    // `prepare_with` returns before the scale), truth as the steps'.
    let (mut out, loan) = crate::lend::lend(
        d,
        level_and_delay_changes(&tilt, &delays),
        copts.reads_truth(),
    );
    levelled_and_delayed(&mut out, &tilt, &delays);
    // The bias of the calibration at the final GNSS delay (a time shift of
    // the gyro does not change its bias), else of a calibration here.
    let params = match params {
        Some(p) => Some(p),
        None => calibrate::calibrate_parameters(&out, copts)
            .ok()
            .map(|c| c.estimate.params),
    };
    let gyro_scale = params.map(|p| crate::gyro_scale::estimate(&out, p.gyro_bias_rps));
    crate::lend::give_back(d, out, loan);
    Ok(Corrections {
        traction,
        tilt,
        delays,
        gyro_scale,
        held_back: None,
        model: Default::default(),
    })
}

/// Applies known corrections (e.g. from a params.toml): the yaw rate
/// projected on `up` (sensor axes) when given and the drive has a three-axis
/// gyro, then the delays, s, in [`Stream::ALL`] order, then the gyro scale
/// error.
pub fn apply_known(
    drive: &Drive,
    delays_s: [f64; 4],
    up: Option<[f64; 3]>,
    gyro_scale_error: f64,
) -> Drive {
    // One copy of the drive, corrected in place (a copy per step held up to
    // three copies at once).
    let mut d = drive.clone();
    apply_known_in_place(&mut d, delays_s, up, gyro_scale_error);
    d
}

/// [`apply_known`] to a drive in place (no copy): the yaw rate about `up`
/// (as [`crate::imu::level_with`]), the delays, the gyro's scale.
pub fn apply_known_in_place(
    d: &mut Drive,
    delays_s: [f64; 4],
    up: Option<[f64; 3]>,
    gyro_scale_error: f64,
) {
    if let Some(u) = up {
        crate::imu::level_with_in_place(d, u);
    }
    shift_in_place(d, delays_s);
    if gyro_scale_error != 0.0 {
        crate::gyro_scale::apply_in_place(d, gyro_scale_error);
    }
}

/// Corrections known beforehand and applied as they are: those a
/// params.toml stores (`[delays]`, `[traction]`, `[imu]`, `[gyro_scale]`), or those a
/// TedriS model was trained with.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct KnownCorrections {
    /// Delays, s, in [`Stream::ALL`] order (0: none).
    pub delays_s: [f64; 4],
    /// The IMU's vertical in its own axes (`None`: the gyro as it is).
    pub up: Option<[f64; 3]>,
    /// The gyro's relative scale error (0: none).
    pub gyro_scale_error: f64,
    /// The driven axle's slip per m/s² of forward specific force
    /// ([`crate::traction`]; 0: none; the sign names the axle). Absent from
    /// models and files written before it: 0.
    #[serde(default)]
    pub traction_slip_per_mps2: f64,
    /// The mean forward specific force, m/s², of the drive the slip was
    /// estimated on ([`crate::traction::TractionSlip::mean_force_mps2`]),
    /// the level the wheel speeds are corrected to. `None` (files written
    /// before it): each drive's own mean, which a live stream cannot know
    /// ([`crate::live_corrections`] then leaves the slip out).
    #[serde(default)]
    pub traction_mean_force_mps2: Option<f64>,
    /// Additions to the paper's model set on the vehicle
    /// ([`crate::model_options`]; empty: the vehicle's own). Absent from
    /// models and files written before them: none.
    #[serde(default)]
    pub model: crate::model_options::ModelOptions,
}

impl KnownCorrections {
    /// Applies them to `drive`: the slip first ([`crate::traction::apply`]),
    /// then [`apply_known`], in [`prepare_with`]'s order.
    pub fn apply(&self, drive: &Drive) -> Drive {
        self.apply_to(drive.clone())
    }

    /// [`KnownCorrections::apply`] to a drive handed over: corrected in
    /// place (a copy only for the traction slip's wheel speeds), e.g. a copy
    /// made without the truth ([`Drive::clone_without_truth`]).
    pub fn apply_to(&self, drive: Drive) -> Drive {
        let mut out = drive;
        if self.traction_slip_per_mps2 != 0.0 {
            crate::traction::apply_at_in_place(
                &mut out,
                self.traction_slip_per_mps2,
                self.traction_mean_force_mps2,
            );
        }
        apply_known_in_place(&mut out, self.delays_s, self.up, self.gyro_scale_error);
        self.model.apply_to(&mut out.vehicle);
        out
    }

    /// What [`KnownCorrections::apply_to`] changes in each stream, for a
    /// working drive lent the others ([`crate::lend`]): the wheel speeds
    /// with the slip, the yaw rate's values levelled or rescaled, the
    /// three-axis gyro rescaled, each delayed stream's timestamps.
    pub fn changes(&self) -> Changes {
        let mut c = Changes::of_delays(self.delays_s)
            .yaw_values(self.up.is_some() || self.gyro_scale_error != 0.0);
        if self.gyro_scale_error != 0.0 {
            c.imu_gyro = Change::Values;
        }
        if self.traction_slip_per_mps2 != 0.0 {
            c.wheels = Change::Values;
        }
        c
    }

    /// Whether there is nothing to apply.
    pub fn is_empty(&self) -> bool {
        *self == KnownCorrections::default()
    }

    /// Checks the values are plausible: delays finite and under 10 s, `up`
    /// a unit vector, the scale error within
    /// [`crate::gyro_scale::MAX_SCALE_ERROR`]. The error names the key.
    pub fn validate(&self) -> Result<(), String> {
        for (s, v) in Stream::ALL.iter().zip(self.delays_s) {
            if !(v.is_finite() && v.abs() < 10.0) {
                return Err(format!(
                    "`delays.{}.delay_s` = {v} is not a plausible delay (|d| < 10 s)",
                    s.name()
                ));
            }
        }
        if let Some(u) = self.up {
            let n = u.iter().map(|x| x * x).sum::<f64>().sqrt();
            if (n - 1.0).abs().is_nan() || (n - 1.0).abs() >= 1e-3 {
                return Err("`imu.up` must be a unit vector of 3 numbers".into());
            }
        }
        let g = self.gyro_scale_error;
        if !(g.is_finite() && g.abs() <= crate::gyro_scale::MAX_SCALE_ERROR) {
            return Err(format!(
                "`gyro_scale.scale_error` = {g} is not a plausible gyro scale error"
            ));
        }
        let k = self.traction_slip_per_mps2;
        if !(k.is_finite() && k.abs() <= crate::traction::MAX_SLIP_PER_MPS2) {
            return Err(format!(
                "`traction.slip_per_mps2` = {k} is not a plausible tyre slip (|κ| ≤ {} per m/s²)",
                crate::traction::MAX_SLIP_PER_MPS2
            ));
        }
        self.model.validate()?;
        if let Some(m) = self.traction_mean_force_mps2 {
            if !(m.is_finite() && m.abs() < 100.0) {
                return Err(format!(
                    "`traction.mean_force_mps2` = {m} is not a plausible mean forward specific force (|f| < 100 m/s²)"
                ));
            }
        }
        Ok(())
    }
}
