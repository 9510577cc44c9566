//! One module per subcommand.
pub mod calibrate;
pub mod common;
pub mod demo;
pub mod evaluate;
pub mod import;
pub mod progress;
pub mod report;
pub mod run;
pub mod simulate;
pub mod tedris;

/// Writes tracks as MCAP with Foxglove schemas.
pub fn write_mcap(
    path: &std::path::Path,
    _tracks: &[deadreckon_core::Track],
) -> anyhow::Result<()> {
    anyhow::bail!(
        "MCAP output is not available in this build ({})",
        path.display()
    )
}
