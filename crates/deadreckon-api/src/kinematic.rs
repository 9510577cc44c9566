//! The kinematic shapes as the commands run them: a tricycle log calibrated
//! against its tracker and evaluated over sliding outages from the tracker
//! pose; a differential drive (odometry + GNSS) calibrated against its fixes
//! and evaluated over sliding GNSS outages started from the alignment of the
//! preceding dead reckoning to the fixes. Loading, the `--from`/`--until`
//! rule, parameter files, tables and `--json` objects.

use std::path::Path;

use deadreckon_core::kinematics::diff_drive::{DiffDriveDrive, YawSource};
use deadreckon_core::kinematics::tricycle::{TricycleDrive, TricycleGeometry, TricycleParams};
use deadreckon_core::kinematics::{KinematicModel, Shape};
use deadreckon_core::Drive;
use deadreckon_io::kinematic_toml::is_kinematic_params;

use crate::error::{invalid, While};
use crate::load::check_range;
use crate::Error;

/// Fewest odometry samples in a range a kinematic drive is read from.
pub const MIN_ODOMETRY_SAMPLES: usize = 2;
/// Fewest GNSS fixes in a range a differential drive is calibrated or
/// evaluated on (two give a heading, one more says anything of it).
pub const MIN_DIFF_DRIVE_FIXES: usize = 3;

/// Whether `path` is a recording read through a kinematic shape (a
/// tricycle `dataset.txt`), as the format detection says.
pub fn is_tricycle_log(path: &Path) -> bool {
    crate::source::detect(path) == crate::source::SourceKind::TricycleLog
}

/// The name a yaw source has in params.toml and on the command line.
pub fn yaw_name(yaw: YawSource) -> &'static str {
    match yaw {
        YawSource::Gyro => "gyro",
        YawSource::Odometry => "odometry",
    }
}

/// A drive as a differential drive with the chosen yaw source, cut to
/// `[from, until)`; refused without odometry and GNSS.
pub fn diff_drive(
    drive: &Drive,
    yaw: YawSource,
    from: Option<f64>,
    until: Option<f64>,
) -> Result<DiffDriveDrive, Error> {
    check_range(from, until)?;
    let d = DiffDriveDrive::from_drive(drive, yaw, from, until)?;
    if d.samples.len() < MIN_ODOMETRY_SAMPLES || d.fixes.len() < MIN_DIFF_DRIVE_FIXES {
        invalid!(
            "{} odometry samples and {} GNSS fixes in the range: a differential drive needs odometry and GNSS",
            d.samples.len(),
            d.fixes.len()
        );
    }
    Ok(d)
}

/// Reads a tricycle log as a kinematic drive cut to `[from, until)`.
pub fn load_tricycle(
    path: &Path,
    from: Option<f64>,
    until: Option<f64>,
) -> Result<TricycleDrive, Error> {
    load_tricycle_from(path, None, from, until)
}

/// A tricycle cut to `[from, until)`: `drive` (a drive directory, as
/// `import tricycle` writes one) through [`tricycle_of_drive`], or without
/// it the tricycle log at `path` read through its own kinematics.
pub fn load_tricycle_from(
    path: &Path,
    drive: Option<&Drive>,
    from: Option<f64>,
    until: Option<f64>,
) -> Result<TricycleDrive, Error> {
    check_range(from, until)?;
    let d = match drive {
        Some(drive) => {
            let file = read_tricycle_file(path)?;
            tricycle_of_drive(drive, file.as_ref())
                .doing(|| format!("{} as a tricycle", path.display()))?
        }
        None => {
            let o = deadreckon_import::tricycle::TricycleOptions::default();
            deadreckon_import::tricycle::read_tricycle_kinematic(path, &o).map_err(|source| {
                Error::Tricycle {
                    path: path.to_path_buf(),
                    source: Box::new(source),
                }
            })?
        }
    };
    let cut = d.time_range(from, until);
    if cut.samples.len() < MIN_ODOMETRY_SAMPLES {
        invalid!(
            "{}: {} samples in the range --from {} --until {} (the log runs from {:.3} to {:.3} s)",
            path.display(),
            cut.samples.len(),
            from.map_or("start".into(), |v| v.to_string()),
            until.map_or("end".into(), |v| v.to_string()),
            d.samples.first().map_or(f64::NAN, |s| s.t_s),
            d.samples.last().map_or(f64::NAN, |s| s.t_s),
        );
    }
    Ok(cut)
}

/// Steering-encoder counts per turn a drive directory's steering stream is
/// read at ([`tricycle_of_drive`]): the stream holds angles, so any fine
/// grid will do; 2^24 rounds them by at most 2e-7 rad (the log's own
/// encoder has 8192 counts, 4e-4 rad).
pub const DRIVE_STEER_COUNTS_PER_REV: u32 = 1 << 24;

/// The file `import tricycle` writes beside the drive: the log header's
/// encoder geometry and nominal parameters, the tracker's mounting
/// included (the drive's truth is the base, moved from the tracker by it).
pub const TRICYCLE_FILE: &str = "tricycle.toml";

/// What [`TRICYCLE_FILE`] holds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TricycleFile {
    /// The encoders' ticks and counts per turn.
    pub geometry: TricycleGeometry,
    /// The header's nominal parameters, the tracker's mounting included.
    pub nominal: TricycleParams,
}

impl TricycleFile {
    /// The header of the tricycle log at `log` ([`TRICYCLE_FILE`]'s content).
    pub fn of_log(log: &Path) -> Result<TricycleFile, Error> {
        let o = deadreckon_import::tricycle::TricycleOptions::default();
        let d =
            deadreckon_import::tricycle::read_tricycle_kinematic(log, &o).map_err(|source| {
                Error::Tricycle {
                    path: log.to_path_buf(),
                    source: Box::new(source),
                }
            })?;
        Ok(TricycleFile {
            geometry: d.geometry,
            nominal: d.nominal,
        })
    }

    /// The TOML text.
    pub fn to_toml(&self) -> Result<String, Error> {
        let mut t = toml::Table::new();
        let value = |v: Result<toml::Value, toml::ser::Error>| {
            v.map_err(|e| Error::Invalid(format!("{TRICYCLE_FILE}: {e}")))
        };
        t.insert(
            "geometry".into(),
            value(toml::Value::try_from(self.geometry))?,
        );
        t.insert(
            "nominal".into(),
            value(toml::Value::try_from(self.nominal))?,
        );
        let body =
            toml::to_string(&t).map_err(|e| Error::Invalid(format!("{TRICYCLE_FILE}: {e}")))?;
        Ok(format!(
            "# The tricycle log's header (deadreckon import tricycle): encoder geometry and\n\
             # nominal parameters; truth.csv holds the base, moved from the tracker by nominal.mount.\n{body}"
        ))
    }
}

/// The [`TRICYCLE_FILE`] of the drive directory `dir`, if it has one.
pub fn read_tricycle_file(dir: &Path) -> Result<Option<TricycleFile>, Error> {
    let p = dir.join(TRICYCLE_FILE);
    if !dir.is_dir() || !p.is_file() {
        return Ok(None);
    }
    let text =
        std::fs::read_to_string(&p).map_err(|e| Error::Invalid(format!("{}: {e}", p.display())))?;
    let bad = |e: String| Error::Invalid(format!("{}: {e}", p.display()));
    let t: toml::Table = text
        .parse()
        .map_err(|e: toml::de::Error| bad(e.to_string()))?;
    let get = |k: &str| {
        t.get(k)
            .cloned()
            .ok_or_else(|| bad(format!("missing `{k}`")))
    };
    let f = TricycleFile {
        geometry: get("geometry")?
            .try_into()
            .map_err(|e: toml::de::Error| bad(e.to_string()))?,
        nominal: get("nominal")?
            .try_into()
            .map_err(|e: toml::de::Error| bad(e.to_string()))?,
    };
    f.nominal.validate().map_err(|e| bad(e.to_string()))?;
    Ok(Some(f))
}

/// A drive as a tricycle (what `import tricycle` writes: the traction
/// wheel's ticks in its one present wheel column, the steering stream as
/// the encoder angle plus the offset over Ksteer, `steering_ratio` =
/// 1/Ksteer, the truth at the base). With the log header `file`
/// ([`TRICYCLE_FILE`]) the samples are the log's own: the encoder counts
/// recovered, the reference moved back to the tracker by its mounting, the
/// nominal parameters the header's. Without it the nominal parameters are
/// the vehicle's (Ktraction its `wheel_circumference_m`, Ksteer
/// 1/`steering_ratio`, the offset −`steering_offset_rad`·Ksteer, the axle its
/// `wheelbase_m`, the mounting zero: the truth is the base) and the
/// steering angles are read on a grid of [`DRIVE_STEER_COUNTS_PER_REV`].
/// Each wheel row is a sample, at the latest steering reading not after
/// it, with the truth pose at its time as the reference when there is one.
pub fn tricycle_of_drive(
    drive: &Drive,
    file: Option<&TricycleFile>,
) -> Result<TricycleDrive, Error> {
    use deadreckon_core::drive::Wheels;
    use deadreckon_core::kinematics::tricycle::TricycleSample;
    use deadreckon_core::kinematics::Pose2;
    let v = &drive.vehicle;
    let Wheels::Ticks(rows) = &drive.wheels else {
        invalid!("a tricycle's drive has wheel ticks (its traction encoder), not wheel speeds");
    };
    if drive.steering.is_empty() {
        invalid!("a tricycle's drive needs its steering stream (steering.csv)");
    }
    if !(v.steering_ratio.is_finite() && v.steering_ratio != 0.0) {
        invalid!(
            "a tricycle's steering_ratio (1/Ksteer) must be finite and not 0, got {}",
            v.steering_ratio
        );
    }
    let wheel = v.wheels_present.iter().position(|p| *p).unwrap_or(0);
    let ksteer = 1.0 / v.steering_ratio;
    let (geometry, nominal, stream_offset) = match file {
        // The stream is 2π·s/counts + offset·steering_ratio.
        Some(f) => (
            f.geometry,
            f.nominal,
            f.nominal.steer_offset_rad * v.steering_ratio,
        ),
        None => (
            TricycleGeometry {
                ticks_per_rev: v.ticks_per_rev,
                steer_counts_per_rev: DRIVE_STEER_COUNTS_PER_REV,
            },
            TricycleParams {
                ktraction_m: v.wheel_circumference_m,
                ksteer,
                steer_offset_rad: -v.steering_offset_rad * ksteer,
                axle_length_m: v.wheelbase_m,
                mount: Pose2::new(0.0, 0.0, 0.0),
            },
            0.0,
        ),
    };
    let m = nominal.mount;
    let counts_per_rad = f64::from(geometry.steer_counts_per_rev) / std::f64::consts::TAU;
    let mut ticks = 0i64;
    let mut samples = Vec::with_capacity(rows.len());
    for r in rows {
        ticks += [r.fl, r.fr, r.rl, r.rr][wheel];
        let k = drive.steering.partition_point(|s| s.t_s <= r.t_s);
        let steer = drive.steering[k.saturating_sub(1)].value - stream_offset;
        let j = drive.truth.partition_point(|p| p.t_s < r.t_s);
        // The measured point: the base moved by the mounting.
        let reference = drive.truth.get(j).filter(|p| p.t_s == r.t_s).map(|p| {
            let (c, s) = (p.yaw_rad.cos(), p.yaw_rad.sin());
            Pose2::new(
                p.east_m + c * m.x_m - s * m.y_m,
                p.north_m + s * m.x_m + c * m.y_m,
                p.yaw_rad + m.yaw_rad,
            )
        });
        samples.push(TricycleSample {
            t_s: r.t_s,
            ticks,
            steer_counts: (steer * counts_per_rad).round() as i64,
            reference,
        });
    }
    let d = TricycleDrive {
        geometry,
        nominal,
        samples,
    };
    d.validate()?;
    Ok(d)
}

/// `nominal` or a kinematic params.toml, as the model's vector and a
/// description of where it came from.
pub fn load_params<M: KinematicModel>(
    spec: &str,
    shape: Shape,
    model: &M,
) -> Result<(Vec<f64>, String), Error> {
    if spec == "nominal" {
        return Ok((model.nominal(), "nominal".into()));
    }
    load_params_file(spec, shape, model.names(), None)
}

/// A kinematic params.toml for `shape` with these parameter names (and, for
/// a differential drive, this yaw source).
pub fn load_params_file(
    spec: &str,
    shape: Shape,
    names: &[&str],
    yaw_source: Option<&str>,
) -> Result<(Vec<f64>, String), Error> {
    let p = load_params_file_with_std(spec, shape, names, yaw_source)?;
    Ok((p.values, p.source))
}

/// A kinematic params.toml as read: values, standard errors, where from.
#[derive(Debug, Clone, PartialEq)]
pub struct LoadedParams {
    /// The values, in the shape's order.
    pub values: Vec<f64>,
    /// Each one's standard error (`None` where it was not estimated).
    pub std: Vec<Option<f64>>,
    /// Where they came from, for reports.
    pub source: String,
}

/// [`load_params_file`] with each parameter's standard error.
pub fn load_params_file_with_std(
    spec: &str,
    shape: Shape,
    names: &[&str],
    yaw_source: Option<&str>,
) -> Result<LoadedParams, Error> {
    let path = Path::new(spec);
    if !is_kinematic_params(path) {
        // A differential drive is calibrated against GNSS, a tricycle
        // against its tracker.
        let how = match shape {
            Shape::DiffDrive => "--shape diff-drive --method gnss",
            _ => "--method truth",
        };
        invalid!(
            "{spec}: not a {} parameter file (no `shape` key: a four-wheel car's parameters?): write one with `deadreckon calibrate <log> {how} --out {spec}`",
            shape.name()
        );
    }
    let f = deadreckon_io::read_kinematic_params(path)
        .doing(|| format!("reading parameters {spec}"))?;
    f.check(path, shape, names)?;
    if let (Some(want), Some(have)) = (yaw_source, f.yaw_source.as_deref()) {
        if want != have {
            invalid!("{spec}: calibrated with --yaw {have}, evaluated with --yaw {want}");
        }
    }
    let n_not = f.param.iter().filter(|p| !p.estimated).count();
    let source = if n_not == 0 {
        spec.to_string()
    } else {
        format!("{spec} ({n_not} parameters not estimated: nominal)")
    };
    let std = f
        .param
        .iter()
        .map(|p| if p.estimated { p.std } else { None })
        .collect();
    Ok(LoadedParams {
        values: f.values(),
        std,
        source,
    })
}

mod calibrate;
mod evaluate;

pub use calibrate::{
    calibrate_diff, calibrate_tricycle, held_back_lines, CalibrateOptions, Calibrated,
};
pub use evaluate::{diff_yaw, evaluate_diff, evaluate_tricycle, tricycle_tracks, Evaluated};
