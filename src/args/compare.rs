//! The arguments of `deadreckon compare`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The drive directory (or a recording read directly).
    pub dir: PathBuf,
    /// A GNSS outage `START_S:END_S` on the drive clock (repeatable).
    #[arg(long, required = true)]
    pub outage: Vec<String>,
    /// Four-wheel parameters (params.toml, its stored corrections applied, or `nominal`); default: as `evaluate`, the RTS calibration on the drive (with the outages hidden) after the corrections --corrections asks for.
    #[arg(long)]
    pub params: Option<String>,
    /// Without --params: the timing and mounting corrections estimated and
    /// applied before the calibration, as `evaluate --corrections` (auto:
    /// each only when it helps on held-back GNSS; all; gnss; none). With
    /// --params: those stored in the file are applied.
    #[arg(long, value_enum, default_value_t = super::CorrectionsArg::Auto)]
    pub corrections: super::CorrectionsArg,
    /// TedriS model (model.json); default: trained on the drive with the outages hidden.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// The vehicle shape (default: found from the data); compare runs the
    /// four-wheel filter and TedriS, so only a car is compared.
    #[arg(long, value_enum, help = super::kinematic::SHAPE_HELP)]
    pub shape: Option<super::kinematic::ShapeArg>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
}
