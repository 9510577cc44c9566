//! The kinematic shapes as the commands run them: a tricycle log calibrated
//! against its tracker and evaluated over sliding outages from the tracker
//! pose; a differential drive (odometry + GNSS) calibrated against its fixes
//! and evaluated over sliding GNSS outages started from the alignment of the
//! preceding dead reckoning to the fixes. Loading, the `--from`/`--until`
//! rule, parameter files, tables and `--json` objects.

use std::path::Path;

use deadreckon_core::kinematics::diff_drive::{
    self, calibrate_diff_drive, calibrate_held_back, evaluate_diff_drive, DiffDriveDrive,
    DiffDriveOptions, DiffDriveOutages, FilterNoise, OutageStart, YawSource,
};
use deadreckon_core::kinematics::tricycle::{TricycleDrive, TricycleGeometry, TricycleParams};
use deadreckon_core::kinematics::{
    self, KinematicCalibration, KinematicModel, KinematicOptions, KinematicOutages, Shape,
};
use deadreckon_core::{Drive, Track};
use deadreckon_io::kinematic_toml::{is_kinematic_params, KinematicParamsFile};

use crate::error::{invalid, While};
use crate::load::check_range;
use crate::Error;

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
    if d.samples.len() < 2 || d.fixes.len() < 3 {
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
                    source,
                }
            })?
        }
    };
    let cut = d.time_range(from, until);
    if cut.samples.len() < 2 {
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
                    source,
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

/// A kinematic calibration with what it was made against, as `calibrate`
/// prints and writes it.
#[derive(Debug, Clone)]
pub struct Calibrated {
    /// The shape calibrated.
    pub shape: Shape,
    /// What it was calibrated against (`truth`: the tracker; `gnss`).
    pub method: &'static str,
    /// A differential drive's yaw source.
    pub yaw: Option<YawSource>,
    /// The calibration.
    pub calibration: KinematicCalibration,
    /// A differential drive's 95 % error bound factor, fitted with the
    /// calibrated parameters on the calibration range's own hidden fixes
    /// (written as `[bound]`; `None` for the tricycle: no covariance).
    pub bound: Option<deadreckon_core::bound::BoundFit>,
}

impl Calibrated {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        let mut v =
            crate::json::kinematic_calibration_json(self.shape, self.method, &self.calibration);
        if let Some(y) = self.yaw {
            v["yaw_source"] = yaw_name(y).into();
        }
        if let Some(b) = &self.bound {
            v["bound"] = crate::bound::bound_json(b);
        }
        v
    }

    /// The table: value, standard error and status per parameter, the
    /// correlation of the estimated ones, the fit.
    pub fn lines(&self) -> Vec<String> {
        let mut out = crate::text::kinematic_table(&self.calibration);
        out.extend(held_back_lines(&self.calibration));
        if let Some(b) = &self.bound {
            out.push(format!("95 % error bound: {}", crate::bound::fit_text(b)));
        }
        out
    }

    /// Writes the kinematic params.toml (status, std and reason per
    /// parameter, correlation).
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let mut f =
            KinematicParamsFile::from_calibration(self.shape, self.method, &self.calibration);
        f.yaw_source = self.yaw.map(|y| yaw_name(y).to_string());
        f.bound = self.bound.as_ref().map(crate::bound::bound_toml);
        deadreckon_io::write_kinematic_params(path, &f)
            .doing(|| format!("writing {}", path.display()))
    }
}

/// The held-back judgement of a differential drive's parameters in words:
/// one line for the rule, one per candidate (empty when none was made).
pub fn held_back_lines(c: &KinematicCalibration) -> Vec<String> {
    let Some(h) = &c.held_back else {
        return Vec::new();
    };
    if let Some(why) = &h.not_judged {
        return vec![format!("held-back GNSS: not judged: {why}")];
    }
    if h.judged.is_empty() {
        return vec!["held-back GNSS: no parameter determined by the drive to judge".into()];
    }
    let mut out = vec![format!(
        "held-back GNSS ({} windows of {:.0} s hidden from the fit in two folds): nominal {}, chosen {}",
        h.windows,
        h.window_s,
        h.nominal_m.map_or("not computed".into(), |v| format!("{v:.3} m")),
        h.chosen_m.map_or("nothing (every parameter nominal)".into(), |v| format!("{v:.3} m")),
    )];
    for j in &h.judged {
        let t = if j.t.is_finite() {
            format!("paired t {:+.1}", j.t)
        } else {
            "paired t not computed (fewer than two windows)".to_string()
        };
        out.push(format!(
            "  {:<14} calibrated {:>10.6}: {:.3} m with it, {:.3} m without, {t}: {}",
            j.name,
            j.calibrated,
            j.with_m,
            j.without_m,
            if j.applied {
                "calibrated value used"
            } else {
                "nominal kept"
            }
        ));
    }
    out
}

/// The method a shape is calibrated with, or why `given` is refused.
fn method_for(shape: Shape, given: Option<&str>) -> Result<&'static str, Error> {
    let (want, why) = match shape {
        Shape::Tricycle => (
            "truth",
            "a tricycle log has no GNSS and no gyro: it is calibrated against its tracker with --method truth",
        ),
        _ => (
            "gnss",
            "a differential drive is calibrated against its GNSS fixes with --method gnss",
        ),
    };
    match given {
        None => Ok(want),
        Some(m) if m == want => Ok(want),
        Some(m) => invalid!("{why} (got `{m}`)"),
    }
}

/// Options of the kinematic calibrations; `None` takes the shape's default.
#[derive(Debug, Clone, Default)]
pub struct CalibrateOptions<'a> {
    /// The method asked for (`--method`), checked against the shape.
    pub method: Option<&'a str>,
    /// Window length, s.
    pub window_s: Option<f64>,
    /// Speed threshold, m/s.
    pub min_speed_mps: Option<f64>,
    /// Drive-clock range.
    pub from_s: Option<f64>,
    /// Drive-clock range end.
    pub until_s: Option<f64>,
    /// A differential drive: fit every determined parameter, without
    /// keeping the nominal value where the held-back GNSS prefers it
    /// (`diff_drive::held_back`; the default is the choice).
    pub every_param: bool,
}

/// Calibrates a tricycle against its tracker: the log at `path`, or
/// `drive` read from it (an imported tricycle directory,
/// [`load_tricycle_from`]).
pub fn calibrate_tricycle(
    path: &Path,
    drive: Option<&Drive>,
    o: &CalibrateOptions,
) -> Result<Calibrated, Error> {
    let shape = Shape::Tricycle;
    let method = method_for(shape, o.method)?;
    let drive = load_tricycle_from(path, drive, o.from_s, o.until_s)?;
    let opts = KinematicOptions {
        window_s: o.window_s.unwrap_or(2.0),
        min_speed_mps: o.min_speed_mps.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let calibration =
        kinematics::calibrate(&drive, &opts).doing(|| format!("calibrating {}", path.display()))?;
    Ok(Calibrated {
        shape,
        method,
        yaw: None,
        calibration,
        bound: None,
    })
}

/// Calibrates a differential drive (the drive read from `path`) against its
/// GNSS fixes.
pub fn calibrate_diff(
    drive: &Drive,
    path: &Path,
    yaw: YawSource,
    o: &CalibrateOptions,
) -> Result<Calibrated, Error> {
    let shape = Shape::DiffDrive;
    let method = method_for(shape, o.method)?;
    let dd = diff_drive(drive, yaw, o.from_s, o.until_s)?;
    let opts = DiffDriveOptions {
        window_s: o.window_s.unwrap_or(DiffDriveOptions::default().window_s),
        min_speed_mps: o.min_speed_mps.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let calibration = if o.every_param {
        calibrate_diff_drive(&dd, &opts)
    } else {
        // Each parameter judged through the filter the outages start from.
        calibrate_held_back(&dd, &opts, &FilterNoise::default())
    }
    .doing(|| format!("calibrating {}", path.display()))?;
    // The bound's factor on the calibration range's own outages, started
    // from the filter as `evaluate` starts them (its priors from the
    // calibration's standard errors).
    let std: Vec<Option<f64>> = calibration
        .params
        .iter()
        .map(|p| if p.estimated { p.std } else { None })
        .collect();
    let noise = diff_drive::FilterNoise::default().with_param_std(&std);
    let bound = deadreckon_core::bound_diff::fit_diff_drive(
        &dd,
        &calibration.values(),
        &noise,
        diff_drive::DEFAULT_WARMUP_S,
    );
    Ok(Calibrated {
        shape,
        method,
        yaw: Some(yaw),
        calibration,
        bound: Some(bound),
    })
}

/// Sliding-outage evaluation of a kinematic shape, as `evaluate` prints it.
#[derive(Debug, Clone)]
pub struct Evaluated {
    /// The shape.
    pub shape: Shape,
    /// Outage length, s.
    pub length_s: f64,
    /// Where the parameters came from.
    pub source: String,
    /// A differential drive's warm-up (and alignment span), s.
    pub align_s: Option<f64>,
    /// The windows and their errors.
    pub evaluation: KinematicOutages,
    /// A differential drive's outages: how they started, the filter's fix
    /// counts and predicted errors.
    pub diff: Option<DiffDriveOutages>,
    /// The 95 % error bound's factor (issue 31): the differential drive's
    /// filter only (`None`: no covariance to bound, the tricycle's
    /// kinematics and the alignment start; [`crate::bound::NO_COVARIANCE`]).
    pub bound: Option<deadreckon_core::bound::BoundFit>,
}

impl Evaluated {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        let mut v = crate::json::kinematic_outages_json(self.shape, &self.evaluation, &self.source);
        v["params_source"] = self.source.clone().into();
        if let Some(align) = self.align_s {
            v["align_s"] = align.into();
        }
        if let Some(d) = &self.diff {
            v["start"] = d.start.name().into();
            match d.start {
                OutageStart::Align => {
                    v["reference"] =
                        "gnss (hidden fixes; start aligned to the preceding fixes)".into();
                }
                OutageStart::Filter(_) => {
                    v["reference"] =
                        "gnss (hidden fixes; start from the GNSS-aided filter, fix wander carried)"
                            .into();
                    v["fixes_used"] = d.fixes_used.into();
                    v["fixes_rejected"] = d.fixes_rejected.into();
                    v["fix_jumps"] = d.fix_jumps.into();
                    if let Some((predicted, achieved)) = d.rms_per_axis() {
                        v["predicted_rms_per_axis_m"] = predicted.into();
                        v["achieved_rms_per_axis_m"] = achieved.into();
                    }
                }
            }
        }
        crate::bound::add_kinematic_bound(&mut v, self.diff.as_ref(), self.bound.as_ref());
        v
    }

    /// The text: windows, their start, the final-error line.
    pub fn lines(&self) -> Vec<String> {
        let n = self.evaluation.windows.len();
        let len = self.length_s;
        let source = &self.source;
        let start = self.diff.as_ref().map(|d| d.start);
        let mut out = vec![match (self.align_s, start) {
            (Some(a), Some(OutageStart::Align)) => format!("{n} outage windows of {len} s, each started from {a} s of dead reckoning aligned to the fixes (parameters: {source})"),
            (Some(a), Some(OutageStart::Filter(_))) => format!("{n} outage windows of {len} s (the first {a} s in), each started from the GNSS-aided filter (parameters: {source})"),
            _ => format!("{n} outage windows of {len} s from the reference pose (parameters: {source})"),
        }];
        out.extend(crate::text::summary_table(&[(
            "final error (m)",
            self.evaluation.final_error(),
        )]));
        if let Some(d) = self.diff.as_ref().filter(|d| d.start != OutageStart::Align) {
            out.push(format!(
                "filter: {} fixes used, {} rejected by the gate, {} jumps of the fixes taken",
                d.fixes_used, d.fixes_rejected, d.fix_jumps
            ));
            if let Some((predicted, achieved)) = d.rms_per_axis() {
                out.push(format!(
                    "final error per axis (RMS): predicted {predicted:.3} m, achieved {achieved:.3} m"
                ));
            }
        }
        out.extend(crate::bound::kinematic_bound_lines(
            self.diff.as_ref(),
            self.bound.as_ref(),
        ));
        out
    }
}

/// A tricycle (the log at `path`, or `drive` read from it) over sliding
/// outages from the tracker pose, scored at the tracked point with the
/// calibrated mounting; without `params`, calibrated on the evaluated range
/// itself (said in the source).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_tricycle(
    path: &Path,
    drive: Option<&Drive>,
    params: Option<&str>,
    length_s: f64,
    step_s: f64,
    from_s: Option<f64>,
    until_s: Option<f64>,
) -> Result<Evaluated, Error> {
    let shape = Shape::Tricycle;
    let drive = load_tricycle_from(path, drive, from_s, until_s)?;
    let (params, source) = match params {
        Some(p) => load_params(p, shape, &drive)?,
        None => {
            let o = KinematicOptions {
                min_speed_mps: shape.default_min_speed_mps(),
                ..Default::default()
            };
            let c = kinematics::calibrate(&drive, &o)
                .doing(|| "calibrating against the tracker".to_string())?;
            (
                c.values(),
                format!(
                    "{} (truth: the tracker, over the evaluated range)",
                    crate::evaluate::CALIBRATED_HERE
                ),
            )
        }
    };
    let evaluation = kinematics::evaluate(&drive, &params, length_s, step_s)?;
    Ok(Evaluated {
        shape,
        length_s,
        source,
        align_s: None,
        evaluation,
        diff: None,
        bound: None,
    })
}

/// The yaw source a differential drive is evaluated with: the one asked
/// for, else the params file's, else the gyro.
pub fn diff_yaw(params: Option<&str>, asked: Option<YawSource>) -> YawSource {
    if let Some(y) = asked {
        return y;
    }
    let file_yaw = params
        .filter(|p| *p != "nominal")
        .and_then(|p| deadreckon_io::read_kinematic_params(Path::new(p)).ok())
        .and_then(|f| f.yaw_source);
    match file_yaw.as_deref() {
        Some("odometry") => YawSource::Odometry,
        _ => YawSource::Gyro,
    }
}

/// A differential drive over sliding GNSS outages (with `params`, else
/// calibrated against the fixes of the evaluated range, as
/// [`crate::evaluate::RULE`] says), the first `align_s` in,
/// each started as `start` says (the alignment spans the preceding
/// `align_s`; the filter's priors on the scales and the bias are the
/// params file's standard errors where it states them) and scored against
/// the hidden fix at its end.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_diff(
    drive: &Drive,
    params: Option<&str>,
    yaw: YawSource,
    length_s: f64,
    step_s: f64,
    align_s: f64,
    start: &OutageStart,
    from_s: Option<f64>,
    until_s: Option<f64>,
) -> Result<Evaluated, Error> {
    let (calibrated_here, spec) = (params.is_none(), params);
    let LoadedParams {
        values: params,
        std,
        source,
    } = match params {
        // The one rule for no parameters (crate::evaluate::RULE): calibrated
        // against the fixes of the evaluated range itself.
        None => {
            let o = CalibrateOptions {
                from_s,
                until_s,
                ..Default::default()
            };
            let c = calibrate_diff(drive, Path::new("the drive"), yaw, &o)?;
            LoadedParams {
                values: c.calibration.values(),
                std: c
                    .calibration
                    .params
                    .iter()
                    .map(|p| if p.estimated { p.std } else { None })
                    .collect(),
                source: format!("{} (gnss)", crate::evaluate::CALIBRATED_HERE),
            }
        }
        Some("nominal") => LoadedParams {
            values: DiffDriveDrive::nominal(),
            std: vec![None; diff_drive::N_PARAMS],
            source: "nominal".to_string(),
        },
        Some(spec) => load_params_file_with_std(
            spec,
            Shape::DiffDrive,
            &diff_drive::NAMES,
            Some(yaw_name(yaw)),
        )?,
    };
    // The filter refines the scales and the bias from their stated
    // standard errors (the defaults where none is stated).
    let start = match start {
        OutageStart::Filter(noise) => OutageStart::Filter(noise.with_param_std(&std)),
        OutageStart::Align => OutageStart::Align,
    };
    let dd = diff_drive(drive, yaw, from_s, until_s)?;
    let diff = evaluate_diff_drive(&dd, &params, length_s, step_s, align_s, &start)?;
    let bound = diff_bound(&dd, &params, &start, align_s, calibrated_here, spec)?;
    Ok(Evaluated {
        shape: Shape::DiffDrive,
        length_s,
        source: format!("{source}, yaw {}", yaw_name(yaw)),
        align_s: Some(align_s),
        evaluation: diff.outages.clone(),
        diff: Some(diff),
        bound,
    })
}

/// The differential drive's 95 % bound factor (issue 31): none from the
/// alignment (no covariance); the `[bound]` table of a params file that
/// has one, else the filter's covariance alone (`nominal` too); fitted on
/// the evaluated drive's own windows against its hidden fixes when the
/// parameters were calibrated on it (in-sample, as a car's `evaluate`
/// without `--params`: [`deadreckon_core::bound_diff::fit_diff_drive`]).
fn diff_bound(
    dd: &DiffDriveDrive,
    params: &[f64],
    start: &OutageStart,
    align_s: f64,
    calibrated_here: bool,
    spec: Option<&str>,
) -> Result<Option<deadreckon_core::bound::BoundFit>, Error> {
    use deadreckon_core::bound::BoundFit;
    let OutageStart::Filter(noise) = start else {
        return Ok(None);
    };
    if calibrated_here {
        return Ok(Some(deadreckon_core::bound_diff::fit_diff_drive(
            dd, params, noise, align_s,
        )));
    }
    let stored = match spec.filter(|s| *s != "nominal") {
        Some(file) => {
            let text = std::fs::read_to_string(file).doing(|| format!("reading {file}"))?;
            let t: toml::Table =
                toml::from_str(&text).map_err(|e| Error::Invalid(format!("{file}: {e}")))?;
            crate::bound::bound_from_extra(&t)
                .map_err(|e| Error::Invalid(format!("{file}: {e}")))?
        }
        None => BoundFit::FILTER,
    };
    Ok(Some(stored))
}

/// A tricycle's tracks (dead-reckoned through its own kinematics from the
/// first tracker pose, and the tracker's) with `params`, or without them
/// calibrated against the tracker ([`crate::evaluate::RULE`]); and which
/// parameters were applied (`"params_source"`).
pub fn tricycle_tracks(
    path: &Path,
    drive: Option<&Drive>,
    params: Option<&str>,
) -> Result<(Vec<Track>, String), Error> {
    let drive = load_tricycle_from(path, drive, None, None)?;
    let (p, source) = match params {
        Some(spec) => (
            load_params(spec, Shape::Tricycle, &drive)?.0,
            spec.to_string(),
        ),
        None => {
            let o = KinematicOptions {
                min_speed_mps: Shape::Tricycle.default_min_speed_mps(),
                ..Default::default()
            };
            let c = kinematics::calibrate(&drive, &o)
                .doing(|| "calibrating against the tracker".to_string())?;
            (
                c.values(),
                format!("{} (truth: the tracker)", crate::evaluate::CALIBRATED_HERE),
            )
        }
    };
    let params = TricycleParams::from_slice(&p)?;
    Ok((drive.tracks(&params)?, source))
}
