//! The arguments of `deadreckon stream`.

use std::path::PathBuf;

use clap::{Args, ValueEnum};

/// What to do with a line that is not a valid event.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum OnBadLine {
    /// Stop with an error naming the line.
    Refuse,
    /// Report it on standard error with its line number, count it and go on.
    Skip,
}

/// What an online filter starts from (`stream`, `ros2`).
#[derive(Args, Debug)]
pub struct OnlineStartArgs {
    /// The vehicle description (vehicle.toml).
    #[arg(long)]
    pub vehicle: PathBuf,
    /// `nominal` or a params.toml (with --learn, its [std] is the prior).
    #[arg(long, default_value = "nominal")]
    pub params: String,
    /// Filter timing.
    #[arg(long, value_enum, default_value = "wheel")]
    pub timing: super::TimingArg,
}

impl OnlineStartArgs {
    /// The filter's options: the timing, the rest default.
    pub fn filter(&self) -> deadreckon_core::ekf::FilterOptions {
        deadreckon_core::ekf::FilterOptions {
            timing: self.timing.into(),
            ..Default::default()
        }
    }

    /// The files read, which no output may be.
    pub fn inputs(&self) -> [&std::path::Path; 2] {
        [self.vehicle.as_path(), std::path::Path::new(&self.params)]
    }
}

/// Arguments of `stream`.
#[derive(Args, Debug)]
pub struct StreamArgs {
    /// The vehicle, the parameters, the timing.
    #[command(flatten)]
    pub start: OnlineStartArgs,
    /// Resume from this state file if it exists, and write the state to it at the end.
    #[arg(long)]
    pub state: Option<PathBuf>,
    /// With --state: this input is the stream's last part; release at its end
    /// the events the params.toml's stored delays or slip hold back (without
    /// it they stay in the state for the next part).
    #[arg(long, requires = "state")]
    pub last_part: bool,
    /// What to do with a line that is not a valid event.
    #[arg(long, value_enum, default_value = "refuse")]
    pub on_bad_line: OnBadLine,
    /// Learn the six parameters while filtering (the 11-state filter).
    #[arg(long)]
    pub learn: bool,
    /// With --learn: write the learned parameters (params.toml) here at the end,
    /// and every --save-every-s seconds of stream time.
    #[arg(long, requires = "learn")]
    pub params_out: Option<PathBuf>,
    /// With --params-out: also write them every this many seconds of stream time.
    #[arg(long, requires = "params_out", value_parser = super::positive)]
    pub save_every_s: Option<f64>,
}
