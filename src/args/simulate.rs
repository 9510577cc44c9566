//! The arguments of `deadreckon simulate`.

use anyhow::{Context, Result};
use deadreckon_sim::Scenario;

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
    /// Drive duration, s (laps repeat until then: with --laps, that many laps and standstill after them).
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

impl SimulateArgs {
    /// The scenario asked for with the command-line overrides applied.
    pub fn scenario_with_overrides(&self) -> Result<Scenario> {
        let a = self;
        let mut sc = deadreckon_api::load::scenario(&a.scenario)?;
        if let Some(v) = &a.vehicle {
            sc = sc.with_vehicle(deadreckon_io::read_vehicle(v)?);
        }
        if a.vehicle_id.is_some() {
            sc.vehicle.vehicle_id = a.vehicle_id.clone();
        }
        if a.recorded_at.is_some() {
            sc.vehicle.recorded_at = a.recorded_at.clone();
        }
        let mut e = sc.true_params();
        if let Some(b) = a.gyro_bias {
            e.gyro_bias_rps = b;
        }
        if let Some(s) = a.speed_scale {
            e.speed_scale = s;
        }
        if let Some(c) = &a.circumferences {
            anyhow::ensure!(
                c.len() == 4,
                "--circumferences takes four values FL,FR,RL,RR (m), got {}",
                c.len()
            );
            e.set_circumferences([c[0], c[1], c[2], c[3]]);
        }
        e.validate()?;
        sc = sc.with_errors(e);
        if let Some(g) = a.gnss_std {
            sc = sc.with_gnss_std_m(g);
        }
        if let Some(l) = a.laps {
            sc = sc.with_laps(l);
        }
        if let Some(d) = a.duration {
            if a.laps.is_none() {
                let laps = sc.laps_lasting(d)?;
                sc = sc.with_laps(laps);
            }
            sc = sc.with_duration_s(d);
        }
        if let Some(o) = &a.origin {
            let (lat_deg, lon_deg, height_m) = match *o.as_slice() {
            [lat, lon] => (lat, lon, 0.0),
            [lat, lon, h] => (lat, lon, h),
            _ => anyhow::bail!(
                "--origin takes LAT,LON[,HEIGHT] (degrees, metres above the WGS84 ellipsoid), got {} values",
                o.len()
            ),
        };
            sc.vehicle.origin = Some(deadreckon_core::vehicle::Origin {
                lat_deg,
                lon_deg,
                height_m,
            });
            sc.vehicle.validate().context("--origin")?;
        }
        sc.validate()?;
        Ok(sc)
    }
}
