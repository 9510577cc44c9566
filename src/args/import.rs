//! The arguments of `deadreckon import`.

use deadreckon_api::import::{ImportFormat, ImportOptions};
use deadreckon_import::comma2k19::{Comma2k19Options, GyroSource, SpeedSource};
use deadreckon_import::TimeOrderPolicy;

use std::path::PathBuf;

use clap::Args;

/// `import FORMAT`: what the source is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FormatArg {
    /// A comma2k19 segment directory.
    Comma2k19,
    /// A candump log or a comma2k19 raw_can directory, decoded with a DBC.
    Can,
    /// A tricycle dataset.txt.
    Tricycle,
    /// A ROS1 .bag.
    Rosbag,
    /// A ROS2 .mcap, or a rosbag2 directory holding one.
    Mcap,
}

/// `import comma2k19 --gyro`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum GyroArg {
    /// gyro_uncalibrated, bias kept.
    Raw,
    /// The phone's calibrated gyro.
    Calibrated,
}

/// `import comma2k19 --speed-source`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SpeedSourceArg {
    /// The CAN SPEED message (0xB4).
    Can,
    /// The mean of the four wheel speeds.
    Processed,
}

/// Import arguments.
#[derive(Args, Debug)]
pub struct ImportArgs {
    /// Input format: comma2k19 (segment directory), can (candump log or
    /// comma2k19 raw_can directory), tricycle (dataset.txt), rosbag (ROS1
    /// .bag), mcap (ROS2 .mcap file, or a rosbag2 directory holding one).
    #[arg(value_enum)]
    pub format: FormatArg,
    /// Source file or directory.
    pub source: PathBuf,
    /// Output drive directory (new or empty; an existing drive is replaced only with --force).
    #[arg(long)]
    pub out: PathBuf,
    /// Replace the files of an existing, non-empty --out directory.
    #[arg(long)]
    pub force: bool,
    /// vehicle.toml to use (default: comma2k19 the built-in RAV4 profile,
    /// can the built-in RAV4 profile with the built-in DBC, tricycle the log's header).
    #[arg(long)]
    pub vehicle: Option<PathBuf>,
    /// can: DBC file (default: the built-in Toyota RAV4 subset).
    #[arg(long)]
    pub dbc: Option<PathBuf>,
    /// can: signal-to-stream mapping TOML (default: the built-in RAV4 mapping).
    #[arg(long)]
    pub map: Option<PathBuf>,
    /// Drop and count unsorted, duplicate or invalid samples instead of failing.
    #[arg(long)]
    pub gate: bool,
    /// comma2k19: gyro stream, `raw` (gyro_uncalibrated, bias kept) or `calibrated`.
    #[arg(long, value_enum, default_value_t = GyroArg::Raw)]
    pub gyro: GyroArg,
    /// comma2k19: speed stream, `can` (SPEED message 0xB4) or `processed` (mean of the wheel speeds).
    #[arg(long, value_enum, default_value_t = SpeedSourceArg::Can)]
    pub speed_source: SpeedSourceArg,
    /// comma2k19: forward distance from the rear axle to the device, m (default 1.5).
    #[arg(long, value_parser = super::finite, allow_hyphen_values = true)]
    pub device_forward_m: Option<f64>,
    /// comma2k19: u-blox fix latency subtracted from its log time, s (default 0: fixes at their log time; calibrate estimates the delay, about 0.09 s on the RAV4 segment).
    #[arg(long, value_parser = super::finite, allow_hyphen_values = true)]
    pub gnss_latency_s: Option<f64>,
    /// comma2k19: standard deviation given to each u-blox fix, m (default 1.0).
    #[arg(long, value_parser = super::positive)]
    pub gnss_std_m: Option<f64>,
}

impl ImportArgs {
    /// The format and the importer's options (`mapping`: the global
    /// `--mapping`); options that do not apply to the format refused.
    pub fn options(
        &self,
        mapping: Option<std::path::PathBuf>,
    ) -> anyhow::Result<(ImportFormat, ImportOptions)> {
        use anyhow::{bail, Context};
        let a = self;
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
            ros_mapping: mapping,
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
        Ok((format, options))
    }
}
