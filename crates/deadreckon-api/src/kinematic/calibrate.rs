//! A kinematic shape's calibration as `calibrate` runs it: the options
//! ([`CalibrateOptions`]), [`calibrate_tricycle`], [`calibrate_diff`] and
//! their result with its table and `--json` object ([`Calibrated`]).

use std::path::Path;

use deadreckon_core::kinematics::diff_drive::{
    self, calibrate_diff_drive, calibrate_held_back, DiffDriveOptions, FilterNoise, YawSource,
};
use deadreckon_core::kinematics::{self, KinematicCalibration, KinematicOptions, Shape};
use deadreckon_core::Drive;
use deadreckon_io::kinematic_toml::KinematicParamsFile;

use super::{load_tricycle_from, yaw_name};
use crate::error::{invalid, While};
use crate::Error;

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
        window_s: o.window_s.unwrap_or(KinematicOptions::default().window_s),
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
    let dd = super::diff_drive(drive, yaw, o.from_s, o.until_s)?;
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
