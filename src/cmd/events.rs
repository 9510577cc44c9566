//! `deadreckon events`: a drive as time-ordered JSON lines, one measurement a
//! line (the schema is in `docs/events.md`).

use std::io::Write;

use anyhow::Result;
use deadreckon_core::live_corrections::input_events;

use super::common;

use crate::args::events::*;

/// Runs `events`.
pub fn run(a: EventsArgs, load: &common::Loader) -> Result<()> {
    let drive = load.drive(&a.dir)?;
    let stdout = std::io::stdout();
    let mut w = std::io::BufWriter::new(stdout.lock());
    let result = (|| -> std::io::Result<()> {
        // Every reading, the three-axis gyro, the accelerometer and those
        // after the last wheel row included: `stream --params` applies the
        // stored corrections to them as `run --params` does to the drive.
        for ev in input_events(&drive) {
            w.write_all(deadreckon_io::events::to_line(&ev).as_bytes())?;
            w.write_all(b"\n")?;
        }
        w.flush()
    })();
    common::quiet_on_broken_pipe(result)
}
