//! The arguments of `deadreckon events`.

use std::path::PathBuf;

use clap::Args;

/// Arguments of `events`.
#[derive(Args, Debug)]
pub struct EventsArgs {
    /// The drive: a directory or any recording the other commands read.
    pub dir: PathBuf,
}
