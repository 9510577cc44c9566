//! The arguments of `deadreckon simulate`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `simulate`.
#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// A built-in scenario (calibration, evaluation, tedris-car, tedris-robot) or a scenario TOML file.
    #[arg(long)]
    pub scenario: String,
    /// Seed of the noise generators.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Output drive directory (created).
    #[arg(long)]
    pub out: PathBuf,
    /// Vehicle geometry and noise from a vehicle.toml instead of the scenario's.
    #[arg(long)]
    pub vehicle: Option<PathBuf>,
    /// True gyro bias, rad/s.
    #[arg(long, allow_hyphen_values = true, value_parser = super::finite)]
    pub gyro_bias: Option<f64>,
    /// True CAN speed scale factor.
    #[arg(long, value_parser = super::positive)]
    pub speed_scale: Option<f64>,
    /// True wheel circumferences FL,FR,RL,RR in metres.
    #[arg(long, value_delimiter = ',', value_parser = super::positive)]
    pub circumferences: Option<Vec<f64>>,
    /// GNSS noise standard deviation, m.
    #[arg(long, value_parser = super::positive)]
    pub gnss_std: Option<f64>,
    /// Number of laps of the route.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..))]
    pub laps: Option<u32>,
    /// Drive duration, s (laps repeat until then).
    #[arg(long, value_parser = super::positive)]
    pub duration: Option<f64>,
    /// Geodetic origin LAT,LON[,HEIGHT] (degrees, WGS84; height above the
    /// ellipsoid in metres, default 0) written into vehicle.toml, so that
    /// tracks can be written as GeoJSON.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = super::finite)]
    pub origin: Option<Vec<f64>>,
    /// The vehicle id written to vehicle.toml (drives with one id form a calibration history).
    #[arg(long)]
    pub vehicle_id: Option<String>,
    /// The recording time written to vehicle.toml, UTC: YYYY-MM-DD or YYYY-MM-DDTHH:MM:SS[Z].
    #[arg(long)]
    pub recorded_at: Option<String>,
}
