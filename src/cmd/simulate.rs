//! `deadreckon simulate`: write a simulated drive directory with its truth.

use std::path::PathBuf;

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_sim::Scenario;

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
}

/// Resolves a scenario name or file.
pub fn scenario(spec: &str) -> Result<Scenario> {
    let path = std::path::Path::new(spec);
    if path.extension().is_some_and(|e| e == "toml") || path.is_file() {
        let text = std::fs::read_to_string(path).with_context(|| format!("reading scenario {spec}"))?;
        let s: Scenario = toml::from_str(&text).with_context(|| format!("parsing scenario {spec}"))?;
        return Ok(s);
    }
    Scenario::builtin(spec).map_err(|e| anyhow::anyhow!("{e} (built-in scenarios: {})", Scenario::names().join(", ")))
}

/// Simulates and writes `drive` + `truth_params.toml` into `dir`.
pub fn simulate_to(spec: &str, seed: u64, dir: &std::path::Path) -> Result<deadreckon_sim::SimOutput> {
    let sc = scenario(spec)?;
    let out = deadreckon_sim::simulate(&sc, seed).with_context(|| format!("simulating {spec}"))?;
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    deadreckon_io::write_drive(dir, &out.drive).with_context(|| format!("writing {}", dir.display()))?;
    deadreckon_io::write_truth_params(&dir.join("truth_params.toml"), &out.truth_params)?;
    Ok(out)
}

/// Runs `simulate`.
pub fn run(a: SimulateArgs) -> Result<()> {
    let out = simulate_to(&a.scenario, a.seed, &a.out)?;
    let s = &out.stats;
    println!(
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
