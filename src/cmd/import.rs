//! `deadreckon import FORMAT SOURCE --out DIR`: read a log into a drive
//! directory. The options become a `deadreckon_api::import::ImportOptions`,
//! `deadreckon_api::import::import` returns the drive and a printable report;
//! the drive is written atomically (into a
//! temporary sibling directory renamed into place when `--out` is new; file by
//! file when it exists).

use std::path::Path;

use anyhow::{bail, Context, Result};
use deadreckon_api::import::{import, ImportFormat, ImportOptions, Imported};
use deadreckon_core::Drive;
use deadreckon_import::comma2k19::{Comma2k19Options, GyroSource, SpeedSource};
use deadreckon_import::TimeOrderPolicy;

use crate::args::import::*;

/// Runs an import.
pub fn run(a: ImportArgs, load: &super::common::Loader) -> Result<()> {
    let policy = if a.gate {
        TimeOrderPolicy::Gate
    } else {
        TimeOrderPolicy::Error
    };
    let vehicle = match &a.vehicle {
        Some(p) => Some(
            deadreckon_io::read_vehicle(p)
                .with_context(|| format!("reading vehicle {}", p.display()))?,
        ),
        None => None,
    };
    let comma_only = a.gyro != GyroArg::Raw
        || a.speed_source != SpeedSourceArg::Can
        || a.device_forward_m.is_some()
        || a.gnss_latency_s.is_some()
        || a.gnss_std_m.is_some();
    if a.format != FormatArg::Comma2k19 && comma_only {
        bail!("--gyro, --speed-source, --device-forward-m, --gnss-latency-s and --gnss-std-m apply to comma2k19 only");
    }
    if a.format != FormatArg::Can && (a.dbc.is_some() || a.map.is_some()) {
        bail!("--dbc and --map apply to the can format only");
    }
    if a.gate && matches!(a.format, FormatArg::Rosbag | FormatArg::Mcap) {
        // Their readers always drop and count (see the report); the topics
        // and the vehicle come from `--mapping` (default: the built-in Husky).
        bail!(
            "--gate does not apply to rosbag/mcap: their readers always drop and count bad samples"
        );
    }
    let d = Comma2k19Options::default();
    let options = ImportOptions {
        vehicle,
        dbc: a.dbc.clone(),
        can_map: a.map.clone(),
        ros_mapping: load.mapping.clone(),
        policy,
        comma2k19: Comma2k19Options {
            gyro: match a.gyro {
                GyroArg::Raw => GyroSource::Uncalibrated,
                GyroArg::Calibrated => GyroSource::Calibrated,
            },
            speed: match a.speed_source {
                SpeedSourceArg::Can => SpeedSource::CanSpeedMessage,
                SpeedSourceArg::Processed => SpeedSource::Processed,
            },
            device_forward_m: a.device_forward_m.unwrap_or(d.device_forward_m),
            gnss_latency_s: a.gnss_latency_s.unwrap_or(d.gnss_latency_s),
            gnss_std_m: a.gnss_std_m.unwrap_or(d.gnss_std_m),
            ..d
        },
    };
    let format = match a.format {
        FormatArg::Comma2k19 => ImportFormat::Comma2k19,
        FormatArg::Can => ImportFormat::Can,
        FormatArg::Tricycle => ImportFormat::Tricycle,
        FormatArg::Rosbag | FormatArg::Mcap => ImportFormat::Ros,
    };
    let Imported { drive, report } = import(format, &a.source, &options)?;
    write_new_or_update(&a.out, &drive)?;
    outln!("{}", report.trim_end_matches('\n'));
    print_counts(&drive)?;
    outln!("wrote {}", a.out.display());
    Ok(())
}

fn print_counts(d: &Drive) -> anyhow::Result<()> {
    let span = d.time_span().map_or(0.0, |(a, b)| b - a);
    outln!(
        "drive: {:.3} s, wheels {}, yaw_rate {}, speed {}, steering {}, gnss {}, truth {}",
        span,
        d.wheels.len(),
        d.yaw_rate.len(),
        d.speed.len(),
        d.steering.len(),
        d.gnss.len(),
        d.truth.len()
    );
    Ok(())
}

/// Writes `drive` into `out` whole (written beside it under a temporary name,
/// then renamed): a failure leaves the old drive or nothing, never a mixture.
fn write_new_or_update(out: &Path, drive: &Drive) -> Result<()> {
    deadreckon_io::write_drive_whole(out, drive, |_| Ok(()))
        .with_context(|| format!("writing drive {}", out.display()))
}
