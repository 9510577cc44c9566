//! `deadreckon import`: a log read into a drive, by format, with the
//! importer's printable report. The command line parses the options, calls
//! [`import`], writes the drive and prints the report.

use std::path::{Path, PathBuf};

use deadreckon_core::{Drive, Vehicle};
use deadreckon_import::can::{self, Database, Mapping};
use deadreckon_import::comma2k19::Comma2k19Options;
use deadreckon_import::tricycle::TricycleOptions;
use deadreckon_import::TimeOrderPolicy;

use crate::Error;

/// What the source of an import is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImportFormat {
    /// A comma2k19 segment directory.
    Comma2k19,
    /// A candump log or a comma2k19 `raw_can` directory, decoded with a DBC.
    Can,
    /// A tricycle `dataset.txt`.
    Tricycle,
    /// A ROS1 `.bag`, a ROS2 `.mcap` or a rosbag2 directory (with a topic
    /// mapping).
    Ros,
}

/// The options of an import (each format reads those it knows).
#[derive(Debug, Clone, Default)]
pub struct ImportOptions {
    /// The vehicle description to use instead of the format's default.
    pub vehicle: Option<Vehicle>,
    /// CAN: the DBC file (default: the built-in Toyota RAV4 subset).
    pub dbc: Option<PathBuf>,
    /// CAN: the signal-to-stream mapping (default: the built-in RAV4 one).
    pub can_map: Option<PathBuf>,
    /// ROS: the topic mapping (default: the built-in Husky or Jackal one).
    pub ros_mapping: Option<PathBuf>,
    /// Samples out of order, duplicated or invalid: an error, or dropped
    /// and counted (ROS readers always drop and count).
    pub policy: TimeOrderPolicy,
    /// comma2k19: the streams and the device's mounting (default: the
    /// importer's).
    pub comma2k19: Comma2k19Options,
}

/// A drive imported, with the importer's report (what was read, dropped,
/// counted).
pub struct Imported {
    /// The drive.
    pub drive: Drive,
    /// The report, printable.
    pub report: String,
    /// Files written into the drive directory beside the drive, by name
    /// (a tricycle's [`crate::kinematic::TRICYCLE_FILE`]).
    pub files: Vec<(String, String)>,
}

/// Reads `source` as `format` into a drive.
pub fn import(format: ImportFormat, source: &Path, o: &ImportOptions) -> Result<Imported, Error> {
    let err = |source_err: deadreckon_import::ImportError| Error::Import {
        path: source.to_path_buf(),
        source: Box::new(source_err),
    };
    Ok(match format {
        ImportFormat::Comma2k19 => {
            let opts = Comma2k19Options {
                vehicle: o.vehicle.clone(),
                policy: o.policy,
                ..o.comma2k19.clone()
            };
            let i = deadreckon_import::read_comma2k19_with(source, &opts).map_err(err)?;
            Imported {
                drive: i.drive,
                report: i.report.to_string(),
                files: Vec::new(),
            }
        }
        ImportFormat::Can => {
            let builtin = o.dbc.is_none() && o.can_map.is_none();
            let db = match &o.dbc {
                Some(p) => Database::read(p),
                None => Database::parse(
                    can::TOYOTA_RAV4_DBC,
                    Path::new("<built-in toyota_rav4_subset.dbc>"),
                ),
            }
            .map_err(err)?;
            let map = match &o.can_map {
                Some(p) => Mapping::read(p, &db),
                None => Mapping::parse(
                    can::TOYOTA_RAV4_MAP,
                    &db,
                    Path::new("<built-in toyota_rav4_comma2k19.toml>"),
                ),
            }
            .map_err(err)?;
            let vehicle = match &o.vehicle {
                Some(v) => v.clone(),
                None if builtin => deadreckon_import::profiles::toyota_rav4(),
                None => return Err(Error::NeedsVehicle),
            };
            let frames = if source.is_dir() {
                can::read_raw_can(source)
            } else {
                can::read_candump(source)
            }
            .map_err(err)?;
            let i = can::decode_frames(&frames, &map, vehicle, o.policy, source).map_err(err)?;
            Imported {
                drive: i.drive,
                report: format!("{} frames read\n{}", frames.len(), i.report),
                files: Vec::new(),
            }
        }
        ImportFormat::Tricycle => {
            let opts = TricycleOptions {
                vehicle: o.vehicle.clone(),
                policy: o.policy,
                ..Default::default()
            };
            let i = deadreckon_import::tricycle::read_tricycle(source, &opts).map_err(err)?;
            // The header's geometry and mounting, which the drive's streams
            // do not carry, so the directory is read as the log is.
            let header = crate::kinematic::TricycleFile::of_log(source)?.to_toml()?;
            Imported {
                drive: i.drive,
                report: i.report.to_string(),
                files: vec![(crate::kinematic::TRICYCLE_FILE.to_string(), header)],
            }
        }
        ImportFormat::Ros => {
            let (mut drive, report, said) =
                crate::source::read_ros_saying(source, o.ros_mapping.as_deref())?;
            if let Some(v) = &o.vehicle {
                let origin = drive.vehicle.origin;
                drive.vehicle = Vehicle {
                    origin: v.origin.or(origin),
                    ..v.clone()
                };
            }
            Imported {
                drive,
                report: format!("{said}\n{report}\n"),
                files: Vec::new(),
            }
        }
    })
}

/// Writes an imported drive into `out` whole (written beside it under a
/// temporary name, then renamed): a failure leaves the old drive or
/// nothing, never a mixture.
pub fn write(out: &Path, drive: &Drive) -> Result<(), Error> {
    write_with(out, drive, &[])
}

/// [`write`] with `files` (name, content) written into the directory
/// beside the drive, in the same whole write.
pub fn write_with(out: &Path, drive: &Drive, files: &[(String, String)]) -> Result<(), Error> {
    use crate::error::While;
    deadreckon_io::write_drive_whole(out, drive, |tmp| {
        for (name, text) in files {
            let p = tmp.join(name);
            std::fs::write(&p, text).map_err(|source| deadreckon_io::IoError::Io {
                path: p.clone(),
                source,
            })?;
        }
        Ok(())
    })
    .doing(|| format!("writing drive {}", out.display()))
}

/// The line `import` prints of what the drive holds.
pub fn counts_line(d: &Drive) -> String {
    let span = d.time_span().map_or(0.0, |(a, b)| b - a);
    format!(
        "drive: {:.3} s, wheels {}, yaw_rate {}, speed {}, steering {}, gnss {}, truth {}",
        span,
        d.wheels.len(),
        d.yaw_rate.len(),
        d.speed.len(),
        d.steering.len(),
        d.gnss.len(),
        d.truth.len()
    )
}
