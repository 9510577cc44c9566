//! `deadreckon events`: a drive as time-ordered JSON lines, one measurement a
//! line (the schema is in `docs/events.md`).

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;
use clap::Args;
use deadreckon_core::ekf::DriveEvents;

use super::common;

/// Arguments of `events`.
#[derive(Args, Debug)]
pub struct EventsArgs {
    /// The drive: a directory or any recording the other commands read.
    pub dir: PathBuf,
}

/// Runs `events`.
pub fn run(a: EventsArgs, load: &common::Loader) -> Result<()> {
    let drive = load.drive(&a.dir)?;
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    let result = (|| -> std::io::Result<()> {
        for ev in DriveEvents::all(&drive) {
            w.write_all(deadreckon_io::events::to_line(&ev).as_bytes())?;
            w.write_all(b"\n")?;
        }
        w.flush()
    })();
    common::quiet_on_broken_pipe(result)
}
