//! Reading what a command is given: drives (a directory or any recording,
//! with the topic mapping, the wheel-file choice and the plausibility
//! checks), the car's parameters (`nominal` or a params.toml, with the
//! corrections it stores), simulated drives written to disk.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use deadreckon_core::plausibility::Finding;
use deadreckon_core::{Drive, Params, ParamsWithStd};
use deadreckon_io::{ReadOptions, WheelFile};
use deadreckon_sim::{Scenario, SimOutput};

use crate::binding;
use crate::checks::Checks;
use crate::error::{invalid, While};
use crate::params_file::ParamsFile;
use crate::Error;

/// How drives are read: the global options `--mapping`, `--skip-checks`
/// and `--wheels`, passed to each command explicitly (no global state).
#[derive(Debug, Default)]
pub struct Loader {
    /// The mapping file for ROS recordings (`None`: the built-in mapping).
    pub mapping: Option<PathBuf>,
    /// Read drives without the cross-stream plausibility checks.
    pub skip_checks: bool,
    /// The wheel file to read when a drive directory has both.
    pub wheels: Option<WheelFile>,
    /// Told of each warning of the checks as a drive is read (the command
    /// line prints them on standard error); `None`: kept in
    /// [`Loader::checks`] only.
    pub on_warning: Option<fn(&Path, &Finding)>,
    /// Apply a params.toml to a drive of another vehicle, or with values
    /// implausible for the drive's vehicle (`--params-for-other-vehicle`;
    /// [`crate::binding`]): a note instead of an error.
    pub params_for_other_vehicle: bool,
    /// What the checks said of the last drive read.
    checks: Mutex<Checks>,
}

impl Loader {
    /// A loader with these options.
    pub fn new(
        mapping: Option<PathBuf>,
        skip_checks: bool,
        wheels: Option<WheelFile>,
        on_warning: Option<fn(&Path, &Finding)>,
    ) -> Loader {
        Loader {
            mapping,
            skip_checks,
            wheels,
            on_warning,
            params_for_other_vehicle: false,
            checks: Default::default(),
        }
    }

    /// [`params_bound`] with this loader's `params_for_other_vehicle`.
    pub fn params(&self, spec: &str, drive: &Drive) -> Result<(Params, binding::Note), Error> {
        params_bound(spec, drive, self.params_for_other_vehicle)
    }

    /// Reads a drive from a drive directory or a recording a reader
    /// understands ([`crate::read_drive_with`]), checked.
    pub fn drive(&self, path: &Path) -> Result<Drive, Error> {
        self.drive_with(path, &ReadOptions::default())
    }

    /// [`Loader::drive`] with reading options for drive directories
    /// (recordings are read whole); `wheels` fills the wheel-file choice
    /// they leave open.
    pub fn drive_with(&self, path: &Path, options: &ReadOptions) -> Result<Drive, Error> {
        let mut options = options.clone();
        if options.prefer_wheels.is_none() {
            options.prefer_wheels = self.wheels;
        }
        let drive = crate::read_drive_with(path, &options, self.mapping.as_deref())?;
        let checks = crate::checks::check(path, &drive, self.skip_checks)?;
        if let Some(warn) = self.on_warning {
            for f in &checks.warnings {
                warn(path, f);
            }
        }
        // A poisoned lock holds a whole `Checks` still: take it.
        *self.checks.lock().unwrap_or_else(|p| p.into_inner()) = checks;
        Ok(drive)
    }

    /// The plausibility checks' verdict on the last drive read, and its
    /// time span.
    pub fn checks(&self) -> Checks {
        self.checks
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .clone()
    }
}

/// Reads a params.toml with its standard errors, validated
/// ([`ParamsFile::read`]: the file read and checked once).
pub fn params_file(spec: &str) -> Result<ParamsWithStd, Error> {
    Ok(ParamsFile::read(spec)?.estimate)
}

/// `nominal` (the vehicle's) or a params.toml's parameters, checked
/// against the drive's vehicle ([`params_bound`], refusing another
/// vehicle's).
pub fn params(spec: &str, drive: &Drive) -> Result<Params, Error> {
    params_bound(spec, drive, false).map(|(p, _)| p)
}

/// `nominal` (the vehicle's) or a params.toml's parameters bound to the
/// drive's vehicle ([`binding::check`]): another vehicle's file, or a
/// circumference implausible for this one, is refused unless
/// `allow_other`; the note says what was let through, or that the file
/// names no vehicle.
pub fn params_bound(
    spec: &str,
    drive: &Drive,
    allow_other: bool,
) -> Result<(Params, binding::Note), Error> {
    if spec == "nominal" {
        return Ok((Params::nominal(&drive.vehicle), None));
    }
    bind(spec, &ParamsFile::read(spec)?, drive, allow_other)
}

/// The parameters of the params.toml `file` (read from `spec`) bound to
/// the drive's vehicle ([`params_bound`]).
pub(crate) fn bind(
    spec: &str,
    file: &ParamsFile,
    drive: &Drive,
    allow_other: bool,
) -> Result<(Params, binding::Note), Error> {
    let p = file.estimate.params;
    let note = binding::check(spec, file.vehicle(), &p, &drive.vehicle, allow_other)?;
    Ok((p, note))
}

/// A calibrated circumference further than this factor from the vehicle's
/// nominal one is a unit mistake (the hint names millimetres or
/// centimetres); the bound a circumference must keep is the tighter
/// [`binding::MAX_CIRCUMFERENCE_DEVIATION`].
pub const MAX_CIRCUMFERENCE_FACTOR: f64 = 1.5;

/// Refuses parameters whose circumferences are further than
/// [`binding::MAX_CIRCUMFERENCE_DEVIATION`] from `vehicle`'s nominal
/// `wheel_circumference_m` (millimetres, or another vehicle's file), naming
/// the file, the key and both values.
pub fn check_against_vehicle(
    spec: &str,
    p: &Params,
    vehicle: &deadreckon_core::Vehicle,
) -> Result<(), Error> {
    binding::check_circumferences(spec, p, vehicle).map_err(Error::Invalid)
}

/// The drive with the corrections stored in the params.toml `spec`
/// applied (none for `nominal` or a file without them).
pub fn apply_stored(spec: &str, drive: Drive) -> Result<Drive, Error> {
    if spec == "nominal" {
        return Ok(drive);
    }
    Ok(ParamsFile::read(spec)?.corrections.apply(&drive))
}

/// `nominal` or a params.toml, and the drive with the corrections that
/// file stores applied (its delays, IMU tilt and gyro scale): the
/// parameters were calibrated on the corrected streams, and on the raw ones
/// they are wrong (a tilted, scaled gyro turns the track).
pub fn params_corrected(spec: &str, drive: Drive) -> Result<(Params, Drive), Error> {
    params_corrected_bound(spec, drive, false).map(|(p, d, _)| (p, d))
}

/// [`params_corrected`] with [`params_bound`]'s `allow_other` and note.
pub fn params_corrected_bound(
    spec: &str,
    drive: Drive,
    allow_other: bool,
) -> Result<(Params, Drive, binding::Note), Error> {
    params_file_corrected(spec, drive, allow_other).map(|(p, d, n, _)| (p, d, n))
}

/// [`params_corrected_bound`] with the file itself (`None` for
/// `nominal`): read once, for its parameters, its vehicle, its
/// corrections and its bound.
pub fn params_file_corrected(
    spec: &str,
    drive: Drive,
    allow_other: bool,
) -> Result<(Params, Drive, binding::Note, Option<ParamsFile>), Error> {
    if spec == "nominal" {
        return Ok((Params::nominal(&drive.vehicle), drive, None, None));
    }
    let file = ParamsFile::read(spec)?;
    let (params, note) = bind(spec, &file, &drive, allow_other)?;
    let drive = file.corrections.apply(&drive);
    Ok((params, drive, note, Some(file)))
}

/// A built-in scenario by name, or a scenario file (`.toml`).
pub fn scenario(spec: &str) -> Result<Scenario, Error> {
    let path = Path::new(spec);
    if path.extension().is_some_and(|e| e == "toml") || path.is_file() {
        return Ok(Scenario::load(path)?);
    }
    Ok(Scenario::builtin(spec)?)
}

/// Simulates `spec` with `seed` and writes the drive and
/// `truth_params.toml` into `dir` ([`write_simulated`]).
pub fn simulate_to(spec: &str, seed: u64, dir: &Path) -> Result<SimOutput, Error> {
    write_simulated(scenario(spec)?, spec, seed, dir)
}

/// Simulates a scenario and writes the drive and `truth_params.toml` into
/// `dir`, whole: a failure leaves no partial drive.
pub fn write_simulated(
    sc: Scenario,
    spec: &str,
    seed: u64,
    dir: &Path,
) -> Result<SimOutput, Error> {
    let out = deadreckon_sim::simulate(&sc, seed).doing(|| format!("simulating {spec}"))?;
    deadreckon_io::write_drive_whole(dir, &out.drive, |tmp| {
        deadreckon_io::write_truth_params(&tmp.join("truth_params.toml"), &out.truth_params)
    })
    .doing(|| format!("writing {}", dir.display()))?;
    Ok(out)
}

/// The one rule for a time range on the drive clock (`--from`, `--until`):
/// both finite, `from` before `until`.
pub fn check_range(from: Option<f64>, until: Option<f64>) -> Result<(), Error> {
    check_range_named(from, until, ["--from", "--until"])
}

/// [`check_range`] with the options' names as the caller spells them
/// (Python's `from_s`, `until_s`).
pub fn check_range_named(
    from: Option<f64>,
    until: Option<f64>,
    [from_name, until_name]: [&str; 2],
) -> Result<(), Error> {
    for v in [from, until].into_iter().flatten() {
        if !v.is_finite() {
            invalid!("{from_name} / {until_name} must be finite, got {v}");
        }
    }
    if let (Some(a), Some(b)) = (from, until) {
        if a.partial_cmp(&b) != Some(std::cmp::Ordering::Less) {
            invalid!("{from_name} {a} must be before {until_name} {b}");
        }
    }
    Ok(())
}

/// The drive cut to `[from, until)` (checked by [`check_range`]); the
/// drive itself when neither is given.
pub fn cut(drive: Drive, from: Option<f64>, until: Option<f64>) -> Result<Drive, Error> {
    check_range(from, until)?;
    Ok(if from.is_some() || until.is_some() {
        drive.time_range(from, until)
    } else {
        drive
    })
}
