//! `deadreckon simulate`: write a simulated drive directory with its truth.

use anyhow::{Context, Result};
use deadreckon_sim::Scenario;

use super::common;

use crate::args::simulate::*;

/// Applies the command-line overrides to a scenario.
fn with_overrides(mut sc: Scenario, a: &SimulateArgs) -> Result<Scenario> {
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

/// Runs `simulate`.
pub fn run(a: SimulateArgs) -> Result<()> {
    let sc = with_overrides(common::scenario(&a.scenario)?, &a)?;
    let out = common::write_scenario(sc, &a.scenario, a.seed, &a.out)?;
    let s = &out.stats;
    outln!(
        "simulated {} (seed {}): {:.2} km in {:.0} s, mean {:.1} km/h, max {:.1} km/h, {} stops -> {}",
        a.scenario,
        a.seed,
        s.distance_m / 1000.0,
        s.duration_s,
        s.mean_speed_mps * 3.6,
        s.max_speed_mps * 3.6,
        s.stops.len(),
        a.out.display()
    );
    Ok(())
}
