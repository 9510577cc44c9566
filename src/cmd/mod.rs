//! One module per subcommand.

/// `println!` that fails instead of panicking: a write error (a full disk)
/// becomes the command's error, and a closed pipe (`| head`) ends the command
/// quietly ([`BrokenPipe`] is recognised by `main`). Use inside functions
/// returning `anyhow::Result`.
macro_rules! outln {
    () => {
        $crate::cmd::write_line(format_args!(""))?
    };
    ($($arg:tt)*) => {
        $crate::cmd::write_line(format_args!($($arg)*))?
    };
}

/// `eprintln!` of a message for people (a warning, a summary) that
/// `--quiet` silences; errors are printed by `main` whatever `--quiet` says.
macro_rules! note {
    ($($arg:tt)*) => {
        if !$crate::cmd::is_quiet() {
            eprintln!($($arg)*)
        }
    };
}

/// `--quiet`: print nothing but errors and the data a command was asked
/// for (`--json`, tracks and events on standard output). Set once by `main`
/// before the command runs; an output policy, not reading state.
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Sets `--quiet` (see [`QUIET`]).
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
}

/// Whether `--quiet` was given.
pub fn is_quiet() -> bool {
    QUIET.load(std::sync::atomic::Ordering::Relaxed)
}

/// A closed standard output: not an error to report.
#[derive(Debug)]
pub struct BrokenPipe;

impl std::fmt::Display for BrokenPipe {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("standard output was closed")
    }
}

impl std::error::Error for BrokenPipe {}

/// Writes one line of text for people to standard output (see `outln!`);
/// nothing with `--quiet`.
pub fn write_line(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    if is_quiet() {
        return Ok(());
    }
    write_data_line(args)
}

/// Writes one line of data (JSON) to standard output, `--quiet` or not.
pub fn write_data_line(args: std::fmt::Arguments<'_>) -> anyhow::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match writeln!(out, "{args}") {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(BrokenPipe.into()),
        r => Ok(anyhow::Context::context(r, "writing to standard output")?),
    }
}
pub mod batch;
pub mod calibrate;
pub mod common;
pub mod compare;
pub mod demo;
pub mod evaluate;
pub mod events;
pub mod import;
pub mod progress;
pub mod report;
pub mod ros2;
pub mod run;
pub mod simulate;
pub mod stream;
pub mod tedris;

pub use common::Loader;
