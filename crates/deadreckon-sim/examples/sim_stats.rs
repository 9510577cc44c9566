//! Prints the statistics of every built-in scenario and the simulation time.
//!
//! `cargo run --release -p deadreckon-sim --example sim_stats [SEED [NAME]]`

use deadreckon_sim::{simulate, Scenario, SimError};

fn main() -> Result<(), SimError> {
    let seed = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let only = std::env::args().nth(2);
    for name in Scenario::names()
        .into_iter()
        .filter(|n| only.as_deref().is_none_or(|o| o == *n))
    {
        let scenario = Scenario::builtin(name)?;
        let start = std::time::Instant::now();
        let out = simulate(&scenario, seed)?;
        let elapsed = start.elapsed();
        let s = &out.stats;
        let stops: Vec<String> = s
            .stops
            .iter()
            .map(|(t, d)| format!("{d:.0}s@{t:.0}"))
            .collect();
        println!(
            "{name}: {:.0} m in {:.0} s ({:.1} min), mean {:.1} km/h, max {:.1} km/h, max |yaw rate| {:.3} rad/s, \
             max lat {:.2} m/s², turn {:.1}°, {} stops [{}], wheels {} epochs, gnss {}, simulated in {:.3} s",
            s.distance_m,
            s.duration_s,
            s.duration_s / 60.0,
            s.mean_speed_mps * 3.6,
            s.max_speed_mps * 3.6,
            s.max_abs_yaw_rate_rps,
            s.max_abs_lateral_accel_mps2,
            s.heading_change_rad.to_degrees(),
            s.stops.len(),
            stops.join(" "),
            out.drive.wheels.len(),
            out.drive.gnss.len(),
            elapsed.as_secs_f64()
        );
    }
    Ok(())
}
