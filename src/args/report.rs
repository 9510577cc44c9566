//! The arguments of `deadreckon report`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `report`.
#[derive(Args, Debug)]
pub struct ReportArgs {
    /// The drive directory (or a recording read directly).
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
    /// Step between the outage windows, s (default: half the outage length), as `evaluate --step`.
    #[arg(long, value_parser = super::positive, requires = "outage")]
    pub step: Option<f64>,
    /// Without --params: the timing and mounting corrections estimated on the
    /// drive and applied for every section: auto, all, gnss or none (as
    /// `calibrate --corrections`). With --params: those stored in the file
    /// are applied (none for nominal), as `run --params` applies them.
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::Auto)]
    pub corrections: super::CorrectionsArg,
    /// The vehicle shape (default: found from the data). A tricycle or a
    /// differential drive gets its kinematic calibration's sections.
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<super::kinematic::ShapeArg>,
    /// Output HTML file.
    #[arg(long)]
    pub out: PathBuf,
}
