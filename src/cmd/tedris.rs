//! `deadreckon tedris ...` (owned by the TedriS work; placeholder until it lands).
use clap::Subcommand;

/// TedriS subcommands.
#[derive(Subcommand, Debug)]
pub enum TedrisCommand {
    /// Train a model on a drive.
    Train {
        /// The drive directory.
        dir: std::path::PathBuf,
    },
}

/// Runs a TedriS subcommand.
pub fn run(_c: TedrisCommand) -> anyhow::Result<()> {
    anyhow::bail!("tedris is not available yet")
}
