//! `deadreckon`: the command-line tool. Parses arguments, calls the library
//! crates, prints tables or JSON. All logic lives in the crates under `crates/`.

mod args;
mod cmd;

use std::sync::atomic::{AtomicBool, Ordering};

use clap::{Parser, Subcommand};

/// Dead reckoning for cars and wheeled robots through GNSS outages.
#[derive(Parser, Debug)]
#[command(name = "deadreckon", version, about, long_about = None)]
struct Cli {
    /// Print nothing but errors and the data asked for (--json, tracks and events on standard output): no progress, no tables, no warnings.
    #[arg(long, global = true)]
    quiet: bool,
    /// Topic-to-stream mapping (TOML) for ROS bags and MCAP files (default: built-in Husky/Jackal).
    #[arg(long, global = true)]
    mapping: Option<std::path::PathBuf>,
    /// Read drives without the cross-stream plausibility checks (units,
    /// clocks, signs: see docs/checks.md).
    #[arg(long, global = true)]
    skip_checks: bool,
    /// The wheel file to read when a drive directory has both
    /// `wheel_ticks.csv` and `wheel_speeds.csv` (having both is otherwise an
    /// error; with only one, that one is read).
    #[arg(long, global = true, value_enum)]
    wheels: Option<args::WheelsArg>,
    /// Apply a params.toml calibrated for another vehicle than the drive's,
    /// or whose circumferences are implausible for it (more than 5 % from
    /// its nominal, millimetres for metres): refused without this option.
    #[arg(long, global = true)]
    params_for_other_vehicle: bool,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Simulate a drive with known truth into a drive directory.
    Simulate(args::simulate::SimulateArgs),
    /// Calibrate gyro bias, speed scale and wheel circumferences (rts, zupt, truth).
    Calibrate(args::calibrate::CalibrateArgs),
    /// Evaluate dead reckoning: drift per 100 m, distance before 1 m, sliding GNSS outages.
    Evaluate(args::evaluate::EvaluateArgs),
    /// Write the dead-reckoned (and filtered, smoothed) track with covariances.
    Run(args::run::RunArgs),
    /// Simulate, calibrate with every method, evaluate, print tables III and IV, write the report.
    Demo(args::demo::DemoArgs),
    /// TedriS and the calibrated four-wheel EKF through the same GNSS outages, in one table.
    Compare(args::compare::CompareArgs),
    /// Write one self-contained HTML report with the papers' tables and figures for a drive.
    Report(args::report::ReportArgs),
    /// TedriS time-series dead reckoning: train a model, predict through outages.
    #[command(subcommand)]
    Tedris(args::tedris::TedrisCommand),
    /// Print a drive as time-ordered JSON lines, one measurement a line (docs/events.md).
    Events(args::events::EventsArgs),
    /// Run the four-wheel filter on JSON-line events from standard input, one JSON line per epoch out.
    Stream(args::stream::StreamArgs),
    /// Run the online filter as a live ROS 2 node: mapped topics in, nav_msgs/Odometry out (docs/ros2.md).
    Ros2(args::ros2::Ros2Args),
    /// Convert a log (comma2k19, ROS bag, MCAP, CAN + DBC, tricycle) into a drive directory.
    Import(args::import::ImportArgs),
    /// Calibrate many drives in parallel, one CSV row each, and each vehicle's calibration history.
    Batch(args::batch::BatchArgs),
}

/// Set by `ros2`: a signal asks it to stop ([`STOP`]) instead of ending the process.
static GRACEFUL: AtomicBool = AtomicBool::new(false);
/// Set by the first SIGINT/SIGTERM while [`GRACEFUL`]: the node stops cleanly.
static STOP: AtomicBool = AtomicBool::new(false);

fn main() {
    // Large blocks freed go back to the system (the peak RSS of
    // `evaluate --outage` and `calibrate` on long drives:
    // deadreckon_api::process).
    deadreckon_api::process::return_large_blocks_when_freed();
    let cli = Cli::parse();
    // An interrupted command leaves no temporary file or directory behind:
    // the writes register them (deadreckon_io::temporaries). Exit status as
    // a shell reports a SIGINT (128 + 2). A running ROS 2 node is asked to
    // stop instead (it finishes the filter and writes its state); a second
    // signal ends it at once.
    if let Err(e) = ctrlc::set_handler(|| {
        if GRACEFUL.load(Ordering::SeqCst) && !STOP.swap(true, Ordering::SeqCst) {
            return;
        }
        deadreckon_io::temporaries::remove_all();
        eprintln!("interrupted");
        std::process::exit(130);
    }) {
        eprintln!(
            "warning: no signal handler ({e}): an interrupted write may leave a temporary file"
        );
    }
    if let Err(e) = run(cli) {
        // A closed standard output (`| head`) ends the command quietly.
        if closed_pipe(&e) {
            return;
        }
        eprintln!("error: {}", message(&e));
        std::process::exit(1);
    }
}

/// Whether `e` comes from writing to a closed pipe.
fn closed_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.is::<cmd::BrokenPipe>()
            || c.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}

/// The error and its causes joined by ": ", leaving out a cause whose text the
/// message already holds (error types that print their source and also return
/// it from `source()` would otherwise repeat the OS error).
fn message(e: &anyhow::Error) -> String {
    let mut msg = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        if !msg.contains(&c) {
            msg.push_str(": ");
            msg.push_str(&c);
        }
    }
    if let Some(hint) = e
        .chain()
        .find_map(|c| c.downcast_ref::<deadreckon_core::Error>())
        .and_then(flag_hint)
    {
        msg.push_str(" (");
        msg.push_str(hint);
        msg.push(')');
    }
    msg
}

/// The command line's words for a library error that a flag answers: the
/// library's messages name no flag (its C, Python and ROS 2 users have
/// none), so the CLI adds them here (issue 34).
fn flag_hint(e: &deadreckon_core::Error) -> Option<&'static str> {
    use deadreckon_core::{Error, Input, Need, Task};
    match e {
        Error::Insufficient {
            need: Need::InitialPose,
        } => Some("give one with --init-pose EAST_M,NORTH_M,YAW_RAD"),
        Error::Insufficient {
            need:
                Need::Input {
                    task: Task::GyroYaw,
                    input: Input::Gyro,
                },
        } => Some("--yaw gyro needs one; --yaw odometry takes the yaw from the wheels"),
        Error::NoiseTooHighForPerReadingTiming { .. } => Some(
            "per-reading timing is --timing each; --timing wheel times them at the wheel epochs",
        ),
        _ => None,
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    cmd::set_quiet(cli.quiet);
    // The global reading options, passed to each command (no global state).
    let mut load = cmd::Loader::new(
        cli.mapping,
        cli.skip_checks,
        cli.wheels.map(Into::into),
        Some(|path, f| {
            if !cmd::is_quiet() {
                eprintln!("warning: {}: {} ({})", path.display(), f.message, f.check)
            }
        }),
    );
    load.params_for_other_vehicle = cli.params_for_other_vehicle;
    match cli.command {
        Command::Simulate(a) => cmd::simulate::run(a),
        Command::Calibrate(a) => cmd::calibrate::run(a, &load),
        Command::Events(a) => cmd::events::run(a, &load),
        Command::Stream(a) => cmd::stream::run(a),
        Command::Ros2(a) => {
            GRACEFUL.store(true, Ordering::SeqCst);
            cmd::ros2::run(a, &load, &STOP)
        }
        Command::Evaluate(a) => cmd::evaluate::run(a, &load),
        Command::Run(a) => cmd::run::run(a, &load),
        Command::Demo(a) => cmd::demo::run(a, cli.quiet, &load),
        Command::Compare(a) => cmd::compare::run(a, &load),
        Command::Report(a) => cmd::report::run(a, cli.quiet, &load),
        Command::Tedris(c) => cmd::tedris::run(c, &load),
        Command::Import(a) => cmd::import::run(a, &load),
        Command::Batch(a) => cmd::batch::run(a, cli.quiet, &load),
    }
}
