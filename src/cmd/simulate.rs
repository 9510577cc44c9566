//! `deadreckon simulate`: write a simulated drive directory with its truth.

use anyhow::Result;

use crate::args::simulate::SimulateArgs;

/// Runs `simulate`.
pub fn run(a: SimulateArgs) -> Result<()> {
    let sc = a.scenario_with_overrides()?;
    let out = deadreckon_api::load::write_simulated(sc, &a.scenario, a.seed, &a.out)?;
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
