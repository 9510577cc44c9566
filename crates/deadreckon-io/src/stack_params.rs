//! Calibrated parameters in the files localization stacks read: Autoware's
//! `imu_corrector` and `vehicle_velocity_converter` (ROS 2 parameter YAML), and
//! Eagleye's saved velocity scale factor with the `eagleye_config.yaml` keys
//! that load it and seed the yaw-rate offset. Names and units follow upstream
//! (autoware.universe `sensing/autoware_imu_corrector`,
//! `sensing/autoware_vehicle_velocity_converter`; MapIV/eagleye `eagleye_rt`);
//! the mapping and its sign conventions are in `docs/stack-params.md`.
//!
//! Our model: gyro = true yaw rate + b_gyro; CAN speed = a_v · true speed.
//!
//! - Autoware subtracts its offset (ω̃ − offset): `angular_velocity_offset_z = b_gyro`;
//!   it multiplies the reported speed: `speed_scale_factor = 1 / a_v`.
//! - Eagleye adds its offset (ω̃ + offset): `yaw_rate_offset_stop_in_skip_mode = −b_gyro`;
//!   it multiplies the CAN speed: `velocity_scale_factor = 1 / a_v`.
//!
//! A parameter the calibration did not estimate (no samples) is written as the
//! upstream default with a comment saying so, or, for Eagleye's scale factor
//! (which Eagleye would take as an estimate), not written at all. Every number
//! has a decimal point, so ROS 2 reads it as a double. Files are written
//! atomically.

use std::path::{Path, PathBuf};

use deadreckon_core::vehicle::Noise;
use deadreckon_core::ParamsWithStd;

use crate::{atomic_write, IoError};

/// File names written by [`write_autoware`] and [`write_eagleye`].
pub mod names {
    /// Autoware `imu_corrector` parameters.
    pub const IMU_CORRECTOR: &str = "imu_corrector.param.yaml";
    /// Autoware `vehicle_velocity_converter` parameters.
    pub const VEHICLE_VELOCITY_CONVERTER: &str = "vehicle_velocity_converter.param.yaml";
    /// The `eagleye_config.yaml` keys to merge into a full Eagleye configuration.
    pub const EAGLEYE_CONFIG: &str = "eagleye_config.calibration.yaml";
    /// Eagleye's saved velocity scale factor (the file its `velocity_scale_factor` node loads).
    pub const EAGLEYE_VELOCITY_SCALE_FACTOR: &str = "velocity_scale_factor.txt";
}

/// Defaults of the upstream nodes, written for what we do not estimate.
pub mod upstream_defaults {
    /// `imu_corrector`: `angular_velocity_stddev_{xx,yy,zz}` default, rad/s.
    pub const IMU_ANGULAR_VELOCITY_STDDEV_RPS: f64 = 0.03;
    /// `imu_corrector`: `acceleration_stddev` default, m/s².
    pub const IMU_ACCELERATION_STDDEV_MPS2: f64 = 10000.0;
    /// `vehicle_velocity_converter.param.yaml`: `angular_velocity_stddev_zz`, rad/s.
    pub const VVC_ANGULAR_VELOCITY_STDDEV_RPS: f64 = 0.1;
    /// `eagleye_config.yaml`: `velocity_scale_factor_save_str` (relative to the
    /// `eagleye_rt` package's share directory).
    pub const EAGLEYE_SAVE_STR: &str = "/config/velocity_scale_factor.txt";
}

/// A calibration to hand over: the estimates, how many samples each rests on
/// (0: not estimated), the vehicle's sensor noise, and where it comes from.
#[derive(Debug, Clone)]
pub struct StackExport<'a> {
    /// The estimates with their standard errors.
    pub estimate: &'a ParamsWithStd,
    /// Samples per parameter, in [`deadreckon_core::Params::to_array`] order.
    pub samples: [usize; 6],
    /// The vehicle's noise model (`[noise]` of `vehicle.toml`).
    pub noise: &'a Noise,
    /// One line saying where the numbers come from (drive, method, passes).
    pub provenance: String,
}

impl StackExport<'_> {
    fn gyro_estimated(&self) -> bool {
        self.samples[0] > 0
    }
    fn scale_estimated(&self) -> bool {
        self.samples[1] > 0
    }
    /// 1 / a_v and its standard error σ_a / a_v².
    fn speed_factor(&self, path: &Path) -> Result<(f64, f64), IoError> {
        let a = self.estimate.params.speed_scale;
        if !(a.is_finite() && a > 0.0) {
            return Err(IoError::Unwritable {
                path: path.to_path_buf(),
                message: format!("speed scale a_v = {a} has no inverse scale factor"),
            });
        }
        Ok((1.0 / a, self.estimate.std.speed_scale / (a * a)))
    }
}

/// A YAML float that always has a decimal point (a ROS 2 double, not an int).
fn float(v: f64, decimals: usize) -> String {
    format!("{v:.decimals$}")
}

fn comment_block(lines: &[String]) -> String {
    // One comment line per line given, whatever it holds.
    lines
        .iter()
        .flat_map(|l| l.lines().map(|l| format!("# {l}\n")).collect::<Vec<_>>())
        .collect()
}

fn finite(path: &Path, what: &str, v: f64) -> Result<f64, IoError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(IoError::Unwritable {
            path: path.to_path_buf(),
            message: format!("{what} is {v}"),
        })
    }
}

/// The text of `imu_corrector.param.yaml`.
pub fn imu_corrector_yaml(x: &StackExport<'_>, path: &Path) -> Result<String, IoError> {
    let p = &x.estimate.params;
    let s = &x.estimate.std;
    let b = finite(path, "b_gyro", p.gyro_bias_rps)?;
    let noise = finite(path, "[noise] gyro_rps", x.noise.gyro_rps)?;
    let (z, z_note) = if x.gyro_estimated() {
        (
            b,
            format!(
                "b_gyro ± {} rad/s (1σ) over {} samples",
                float(s.gyro_bias_rps, 9),
                x.samples[0]
            ),
        )
    } else {
        (
            0.0,
            "not estimated by this calibration (node default)".into(),
        )
    };
    let head = comment_block(&[
        "Autoware imu_corrector parameters written by deadreckon calibrate.".into(),
        x.provenance.clone(),
        "imu_corrector subtracts the offsets from the IMU's angular velocity (imu_link).".into(),
        "z is the calibrated gyro bias (gyro = true yaw rate + b_gyro), valid for an".into(),
        "imu_link whose z axis points up; x and y are not estimated (node defaults).".into(),
        "angular_velocity_stddev_zz: the gyro noise the calibration assumed".into(),
        "([noise] gyro_rps of vehicle.toml); the others are the node defaults.".into(),
    ]);
    let d = upstream_defaults::IMU_ANGULAR_VELOCITY_STDDEV_RPS;
    Ok(format!(
        "{head}/**:\n  ros__parameters:\n\
         \x20   angular_velocity_offset_x: {}  # [rad/s] not estimated\n\
         \x20   angular_velocity_offset_y: {}  # [rad/s] not estimated\n\
         \x20   angular_velocity_offset_z: {}  # [rad/s] {z_note}\n\
         \x20   angular_velocity_stddev_xx: {}  # [rad/s] not estimated (node default)\n\
         \x20   angular_velocity_stddev_yy: {}  # [rad/s] not estimated (node default)\n\
         \x20   angular_velocity_stddev_zz: {}  # [rad/s] gyro noise, vehicle.toml [noise] gyro_rps\n\
         \x20   acceleration_stddev: {}  # [m/s^2] not estimated (node default)\n",
        float(0.0, 12),
        float(0.0, 12),
        float(z, 12),
        float(d, 9),
        float(d, 9),
        float(noise, 9),
        float(upstream_defaults::IMU_ACCELERATION_STDDEV_MPS2, 1),
    ))
}

/// The text of `vehicle_velocity_converter.param.yaml`.
pub fn vehicle_velocity_converter_yaml(
    x: &StackExport<'_>,
    path: &Path,
) -> Result<String, IoError> {
    let noise = finite(path, "[noise] speed_mps", x.noise.speed_mps)?;
    let (factor, note) = if x.scale_estimated() {
        let (f, sf) = x.speed_factor(path)?;
        (
            f,
            format!(
                "1 / a_v, ± {} (1σ); a_v = {} over {} samples",
                float(sf, 9),
                float(x.estimate.params.speed_scale, 9),
                x.samples[1]
            ),
        )
    } else {
        (
            1.0,
            "not estimated by this calibration (ideal value)".into(),
        )
    };
    let head = comment_block(&[
        "Autoware vehicle_velocity_converter parameters written by deadreckon calibrate.".into(),
        x.provenance.clone(),
        "The converter multiplies the reported longitudinal speed by speed_scale_factor;".into(),
        "our CAN speed = a_v · true speed, so the factor is 1 / a_v.".into(),
        "velocity_stddev_xx: the CAN speed noise the calibration assumed ([noise] speed_mps);"
            .into(),
        "angular_velocity_stddev_zz (the report's heading rate): not estimated (upstream value)."
            .into(),
    ]);
    Ok(format!(
        "{head}/**:\n  ros__parameters:\n\
         \x20   speed_scale_factor: {}  # [.] {note}\n\
         \x20   velocity_stddev_xx: {}  # [m/s] CAN speed noise, vehicle.toml [noise] speed_mps\n\
         \x20   angular_velocity_stddev_zz: {}  # [rad/s] not estimated (upstream value)\n\
         \x20   frame_id: base_link\n",
        float(factor, 9),
        float(noise, 9),
        float(upstream_defaults::VVC_ANGULAR_VELOCITY_STDDEV_RPS, 9),
    ))
}

/// Writes Autoware's two parameter files into `dir` (created if missing) and
/// returns their paths.
pub fn write_autoware(dir: &Path, x: &StackExport<'_>) -> Result<Vec<PathBuf>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
    let imu = dir.join(names::IMU_CORRECTOR);
    let vvc = dir.join(names::VEHICLE_VELOCITY_CONVERTER);
    let imu_text = imu_corrector_yaml(x, &imu)?;
    let vvc_text = vehicle_velocity_converter_yaml(x, &vvc)?;
    atomic_write(&imu, |w| w.write_all(imu_text.as_bytes()))?;
    atomic_write(&vvc, |w| w.write_all(vvc_text.as_bytes()))?;
    Ok(vec![imu, vvc])
}

/// The text of Eagleye's `velocity_scale_factor.txt`, as its
/// `velocity_scale_factor` node saves and loads it: the lines
/// `estimated_number`, a count, `velocity_scale_factor`, the factor.
/// `None` when the calibration did not estimate the speed scale.
pub fn eagleye_velocity_scale_factor_txt(
    x: &StackExport<'_>,
    path: &Path,
) -> Result<Option<String>, IoError> {
    if !x.scale_estimated() {
        return Ok(None);
    }
    let (f, _) = x.speed_factor(path)?;
    Ok(Some(format!(
        "estimated_number\n{}\nvelocity_scale_factor\n{}\n",
        x.samples[1],
        float(f, 9)
    )))
}

/// The text of the `eagleye_config.yaml` keys to merge.
pub fn eagleye_config_yaml(x: &StackExport<'_>, path: &Path) -> Result<String, IoError> {
    let b = finite(path, "b_gyro", x.estimate.params.gyro_bias_rps)?;
    let scale = x.scale_estimated();
    let gyro = x.gyro_estimated();
    let mut head = vec![
        "Eagleye (eagleye_rt) configuration keys written by deadreckon calibrate:".into(),
        "merge them into your eagleye_config.yaml (Eagleye reads every key from one file).".into(),
        x.provenance.clone(),
    ];
    if scale {
        let (f, sf) = x.speed_factor(path)?;
        head.push(format!(
            "velocity scale factor 1 / a_v = {} ± {} (1σ), in {}: copy it to the",
            float(f, 9),
            float(sf, 9),
            names::EAGLEYE_VELOCITY_SCALE_FACTOR
        ));
        head.push(
            "eagleye_rt share directory at velocity_scale_factor_save_str; Eagleye loads it".into(),
        );
        head.push("at start and keeps refining and saving it.".into());
    } else {
        head.push(
            "The speed scale was not estimated: no scale factor file, saving left off.".into(),
        );
    }
    if gyro {
        head.push(format!(
            "Eagleye adds its yaw-rate offset (ω + offset): offset = −b_gyro, b_gyro = {} ± {} rad/s.",
            float(b, 12),
            float(x.estimate.std.gyro_bias_rps, 9)
        ));
        head.push(
            "It seeds yaw_rate_offset_stop, so heading starts without the standstill;".into(),
        );
        head.push("Eagleye's 1st and 2nd yaw-rate offsets are still estimated online.".into());
    } else {
        head.push("The gyro bias was not estimated: the static initialisation stays on.".into());
    }
    Ok(format!(
        "{}/**:\n  ros__parameters:\n\
         \x20   velocity_scale_factor:\n\
         \x20     velocity_scale_factor_save_str: {}\n\
         \x20     save_velocity_scale_factor: {scale}\n\
         \x20   heading:\n\
         \x20     skip_static_initialization: {gyro}\n\
         \x20     yaw_rate_offset_stop_in_skip_mode: {}  # [rad/s] {}\n",
        comment_block(&head),
        upstream_defaults::EAGLEYE_SAVE_STR,
        float(if gyro { -b } else { 0.0 }, 12),
        if gyro { "−b_gyro" } else { "not estimated" },
    ))
}

/// Writes Eagleye's files into `dir` (created if missing): the configuration
/// keys and, when the speed scale was estimated, the saved scale factor.
/// Returns the paths written.
pub fn write_eagleye(dir: &Path, x: &StackExport<'_>) -> Result<Vec<PathBuf>, IoError> {
    std::fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
    let config = dir.join(names::EAGLEYE_CONFIG);
    let vsf = dir.join(names::EAGLEYE_VELOCITY_SCALE_FACTOR);
    let config_text = eagleye_config_yaml(x, &config)?;
    let vsf_text = eagleye_velocity_scale_factor_txt(x, &vsf)?;
    let mut out = Vec::new();
    if let Some(t) = vsf_text {
        atomic_write(&vsf, |w| w.write_all(t.as_bytes()))?;
        out.push(vsf);
    }
    atomic_write(&config, |w| w.write_all(config_text.as_bytes()))?;
    out.insert(0, config);
    Ok(out)
}
