//! The arguments of `deadreckon report`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// Extra parameters to show and dead-reckon with (a params.toml), beside the calibrations made on the drive.
    #[arg(long)]
    pub params: Option<String>,
    /// A TedriS model.json: adds the TedriS sections.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Also run the sliding-window outage evaluation with windows of this length, s.
    #[arg(long, value_parser = super::positive)]
    pub outage: Option<f64>,
    /// Output HTML file.
    #[arg(long)]
    pub out: PathBuf,
}
