//! `deadreckon import ...` (owned by the importers work; placeholder until it lands).
use clap::Args;

/// Import arguments.
#[derive(Args, Debug)]
pub struct ImportArgs {
    /// Input format.
    pub format: String,
    /// Source file or directory.
    pub source: std::path::PathBuf,
    /// Output drive directory.
    #[arg(long)]
    pub out: std::path::PathBuf,
}

/// Runs an import.
pub fn run(_a: ImportArgs) -> anyhow::Result<()> {
    anyhow::bail!("import is not available yet")
}
