//! The kinematic shapes on the command line (tricycle logs): loading,
//! the parameter table and JSON, reading parameters for `evaluate`.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::kinematics::diff_drive::{DiffDriveDrive, YawSource};
use deadreckon_core::kinematics::tricycle::TricycleDrive;
use deadreckon_core::kinematics::{KinematicCalibration, KinematicModel, Shape};
use deadreckon_io::kinematic_toml::{is_kinematic_params, KinematicParamsFile};

use crate::args::kinematic::*;

/// A drive as a differential drive with the chosen yaw source, cut to `[from, until)`.
pub fn diff_drive(
    drive: &deadreckon_core::Drive,
    yaw: YawArg,
    from: Option<f64>,
    until: Option<f64>,
) -> Result<DiffDriveDrive> {
    let source = match yaw {
        YawArg::Gyro => YawSource::Gyro,
        YawArg::Odometry => YawSource::Odometry,
    };
    let d = DiffDriveDrive::from_drive(drive, source, from, until)?;
    anyhow::ensure!(
        d.samples.len() >= 2 && d.fixes.len() >= 3,
        "{} odometry samples and {} GNSS fixes in the range: a differential drive needs odometry and GNSS",
        d.samples.len(),
        d.fixes.len()
    );
    Ok(d)
}

/// Whether `path` is a recording read through a kinematic shape (a
/// tricycle `dataset.txt`), as the library's format detection says.
pub fn is_tricycle_log(path: &Path) -> bool {
    deadreckon_api::source::detect(path) == deadreckon_api::source::SourceKind::TricycleLog
}

/// Reads a tricycle log as a kinematic drive cut to `[from, until)`.
pub fn load_tricycle(path: &Path, from: Option<f64>, until: Option<f64>) -> Result<TricycleDrive> {
    let o = deadreckon_import::tricycle::TricycleOptions::default();
    let d = deadreckon_import::tricycle::read_tricycle_kinematic(path, &o)
        .with_context(|| format!("reading tricycle log {}", path.display()))?;
    let cut = d.time_range(from, until);
    if cut.samples.len() < 2 {
        anyhow::bail!(
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

/// Checks `--from` / `--until`.
pub fn check_range(from: Option<f64>, until: Option<f64>) -> Result<()> {
    for v in [from, until].into_iter().flatten() {
        anyhow::ensure!(v.is_finite(), "--from / --until must be finite, got {v}");
    }
    if let (Some(a), Some(b)) = (from, until) {
        anyhow::ensure!(a < b, "--from {a} must be before --until {b}");
    }
    Ok(())
}

/// `--params nominal` or a kinematic params.toml, as the model's vector and
/// a description of where it came from.
pub fn load_params<M: KinematicModel>(
    spec: &str,
    shape: Shape,
    model: &M,
) -> Result<(Vec<f64>, String)> {
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
) -> Result<(Vec<f64>, String)> {
    let path = Path::new(spec);
    if !is_kinematic_params(path) {
        anyhow::bail!(
            "{spec}: not a {} parameter file (no `shape` key): write one with `deadreckon calibrate <log> --method truth --out {spec}`",
            shape.name()
        );
    }
    let f = deadreckon_io::read_kinematic_params(path)
        .with_context(|| format!("reading parameters {spec}"))?;
    f.check(path, shape, names)?;
    if let (Some(want), Some(have)) = (yaw_source, f.yaw_source.as_deref()) {
        anyhow::ensure!(
            want == have,
            "{spec}: calibrated with --yaw {have}, evaluated with --yaw {want}"
        );
    }
    let n_not = f.param.iter().filter(|p| !p.estimated).count();
    let source = if n_not == 0 {
        spec.to_string()
    } else {
        format!("{spec} ({n_not} parameters not estimated: nominal)")
    };
    Ok((f.values(), source))
}

/// The calibration as a table: value, standard error, status; then the
/// correlation of the estimated parameters.
pub fn print_table(c: &KinematicCalibration) -> anyhow::Result<()> {
    outln!("{:<18} {:>12} {:>12}  status", "parameter", "value", "std");
    for p in &c.params {
        let std = p.std.map_or("-".to_string(), |s| format!("{s:.6}"));
        let status = match &p.reason {
            None => "estimated".to_string(),
            Some(r) => format!("NOT ESTIMATED (nominal kept): {r}"),
        };
        outln!("{:<18} {:>12.6} {:>12}  {status}", p.name, p.value, std);
    }
    if !c.correlated.is_empty() {
        outln!("correlation:");
        let mut header = format!("{:<18}", "");
        for n in &c.correlated {
            header.push_str(&format!(" {:>8}", abbreviate(n)));
        }
        outln!("{header}");
        for (n, row) in c.correlated.iter().zip(&c.correlation) {
            let mut line = format!("{n:<18}");
            for v in row {
                line.push_str(&format!(" {v:>8.3}"));
            }
            outln!("{line}");
        }
    }
    outln!(
        "{} of {} windows above {} m/s, RMS at the window ends {:.3} m / {:.4} rad; {} ({})",
        c.windows_used,
        c.windows_total,
        c.min_speed_mps,
        c.rms_position_m,
        c.rms_heading_rad,
        if c.converged {
            "converged"
        } else {
            "NOT converged"
        },
        c.termination
    );
    Ok(())
}

fn abbreviate(name: &str) -> String {
    name.chars().take(8).collect()
}

/// Writes the parameters file.
pub fn write_params(
    path: &Path,
    shape: Shape,
    method: &str,
    yaw_source: Option<&str>,
    c: &KinematicCalibration,
) -> Result<()> {
    let mut f = KinematicParamsFile::from_calibration(shape, method, c);
    f.yaw_source = yaw_source.map(str::to_string);
    deadreckon_io::write_kinematic_params(path, &f)
        .with_context(|| format!("writing {}", path.display()))
}
