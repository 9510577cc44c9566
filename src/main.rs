//! `deadreckon`: the command-line tool. Parses arguments, calls the library
//! crates, prints tables or JSON. All logic lives in the crates under `crates/`.

mod cmd;

use clap::{Parser, Subcommand};

/// Dead reckoning for cars and wheeled robots through GNSS outages.
#[derive(Parser, Debug)]
#[command(name = "deadreckon", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// TedriS time-series dead reckoning: train a model, predict through outages.
    #[command(subcommand)]
    Tedris(cmd::tedris::TedrisCommand),
    /// Convert a log (comma2k19, ROS bag, MCAP, CAN + DBC, tricycle) into a drive directory.
    Import(cmd::import::ImportArgs),
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Tedris(c) => cmd::tedris::run(c),
        Command::Import(a) => cmd::import::run(a),
    }
}
