//! The arguments of `deadreckon demo`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `demo`.
#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Where the simulated drives, parameters and report go.
    #[arg(long, default_value = "out/demo")]
    pub out: PathBuf,
    /// Seed of the calibration drive (the evaluation drive uses seed + 1).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Print JSON instead of tables.
    #[arg(long)]
    pub json: bool,
}
