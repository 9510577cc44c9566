//! # deadreckon-io
//!
//! Reads and writes the drive directory format of deadreckon (specified in
//! `docs/drive-format.md`): a directory of CSV files with a header row, one per
//! sensor stream, plus `vehicle.toml`; and the files around it: calibrated
//! parameters (`params.toml`, `truth_params.toml`; for the kinematic shapes,
//! tricycle and differential drive, the [`kinematic_toml`] form with a status
//! and reason per parameter; the files Autoware and Eagleye read,
//! [`stack_params`]) and estimated tracks (one CSV, GeoJSON for maps, one
//! track as TUM or KITTI for trajectory tools such as `evo`). Everything it
//! reads is checked, and every error names
//! the file, the 1-based line (the header is line 1) and the column.
//!
//! ## Conventions
//!
//! - `t_s`: seconds, one clock for every file, any epoch, strictly increasing.
//! - Positions in metres east (`east_m`) and north (`north_m`) of a local origin,
//!   or latitude/longitude (`lat_deg`, `lon_deg`, WGS84) converted on reading.
//! - Angles in radians, counter-clockwise positive; yaw from east. The one
//!   exception says so in its name: GNSS `course_deg`, degrees clockwise from north.
//! - Files are written atomically (temporary file + rename, see [`atomic_write`]),
//!   floats in their shortest exact form, so a drive round-trips bit for bit.
//!
//! ```
//! use deadreckon_core::drive::{WheelTicks, Wheels};
//! use deadreckon_core::{Drive, Vehicle};
//!
//! let dir = tempfile::tempdir().unwrap();
//! let mut drive = Drive::empty(Vehicle::paper_car());
//! drive.wheels = Wheels::Ticks(vec![
//!     WheelTicks { t_s: 0.0, fl: 0, fr: 0, rl: 0, rr: 0 },
//!     WheelTicks { t_s: 0.02, fl: 1, fr: 1, rl: 1, rr: 1 },
//! ]);
//! deadreckon_io::write_drive(dir.path(), &drive).unwrap();
//! assert_eq!(deadreckon_io::read_drive(dir.path()).unwrap(), drive);
//! ```
#![deny(missing_docs)]

mod atomic;
mod error;
mod read;
mod table;
mod toml_files;
mod track_out;
mod track_text;
mod whole;

pub mod kinematic_toml;
mod write;

pub mod stack_params;
pub mod temporaries;

pub mod events;
pub use atomic::atomic_write;
/// Latitude/longitude ↔ local east-north (re-exported from `deadreckon-core`).
pub use deadreckon_core::geo;
pub use error::IoError;
pub use kinematic_toml::{read_kinematic_params, write_kinematic_params, KinematicParamsFile};
pub use read::{read_drive, read_drive_with, ReadOptions, WheelFile};
pub use toml_files::{
    parse_params_with_extra, parse_vehicle, read_params, read_params_with_extra, read_truth_params,
    read_vehicle, write_params, write_truth_params, write_vehicle,
};
pub use track_out::{
    carries_no_covariance, write_track_csv, write_track_csv_with_bounds, write_track_geojson,
    write_track_geojson_with, GeoJsonOptions, TRACK_CSV_COLUMNS,
};
pub use track_text::{
    kitti_line, kitti_times_path, tum_line, write_track_kitti, write_track_tum, TrackFormat,
    TUM_HEADER,
};
pub use whole::write_drive_whole;
pub use write::write_drive;

/// File names of the drive directory contract.
pub mod files {
    /// Vehicle geometry, nominal parameters and noise (required).
    pub const VEHICLE: &str = "vehicle.toml";
    /// Encoder ticks since the previous row (this or [`WHEEL_SPEEDS`] required).
    pub const WHEEL_TICKS: &str = "wheel_ticks.csv";
    /// Wheel speeds (this or [`WHEEL_TICKS`] required).
    pub const WHEEL_SPEEDS: &str = "wheel_speeds.csv";
    /// Raw gyro yaw rate, or a three-axis gyro (optional).
    pub const YAW_RATE: &str = "yaw_rate.csv";
    /// Three-axis accelerometer, specific force (optional).
    pub const ACCEL: &str = "accel.csv";
    /// CAN vehicle speed (optional).
    pub const SPEED: &str = "speed.csv";
    /// Steering wheel angle (optional).
    pub const STEERING: &str = "steering.csv";
    /// GNSS fixes (optional).
    pub const GNSS: &str = "gnss.csv";
    /// Reference trajectory (optional).
    pub const TRUTH: &str = "truth.csv";
    /// Every CSV stream of the contract.
    pub const STREAMS: [&str; 8] = [
        WHEEL_TICKS,
        WHEEL_SPEEDS,
        YAW_RATE,
        ACCEL,
        SPEED,
        STEERING,
        GNSS,
        TRUTH,
    ];
    /// Calibrated parameters with standard errors (output of calibration).
    pub const PARAMS: &str = "params.toml";
    /// The true parameters of a simulated drive.
    pub const TRUTH_PARAMS: &str = "truth_params.toml";
}

/// Refuses an output path that is one of a command's inputs: the input file
/// itself (`run x.mcap --out x.mcap`) or, for a drive directory, one of the
/// files it is read from (`calibrate D --out D/vehicle.toml`). Other files in
/// the directory (`D/params.toml`, `D/track.csv`) are fine.
pub fn check_not_an_input(out: &std::path::Path, input: &std::path::Path) -> Result<(), IoError> {
    let refuse = |what: String| IoError::Unwritable {
        path: out.to_path_buf(),
        message: what,
    };
    let Ok(input) = input.canonicalize() else {
        return Ok(());
    };
    // The output may not exist yet: its directory does, or writing fails anyway.
    let dir = match out.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => std::path::Path::new("."),
    };
    let (Ok(dir), Some(name)) = (dir.canonicalize(), out.file_name()) else {
        return Ok(());
    };
    let target = dir.join(name);
    if target == input {
        return Err(refuse(format!(
            "is the input {}: refusing to write over it",
            input.display()
        )));
    }
    let drive_file = [files::VEHICLE]
        .iter()
        .chain(files::STREAMS.iter())
        .any(|f| std::ffi::OsStr::new(f) == name);
    if input.is_dir() && dir == input && drive_file {
        return Err(refuse(format!(
            "is one of the files the drive {} is read from: refusing to write over it",
            input.display()
        )));
    }
    Ok(())
}
