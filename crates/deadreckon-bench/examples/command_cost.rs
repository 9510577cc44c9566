//! The commands' own cost: wall time and peak resident memory of the whole
//! process running one command's library path ([`deadreckon_bench::command`]),
//! and the memory's growth per wheel epoch from a short to a long drive.
//!
//! ```sh
//! cargo build --profile ci -p deadreckon-bench --example command_cost
//! B=$CARGO_TARGET_DIR/ci/examples/command_cost
//! $B write /tmp/p10 600 && $B write /tmp/p60 3600     # the simulated drives
//! /usr/bin/time -f "%e s %M KB" $B calibrate /tmp/p10  # one command, one process
//! $B table /tmp/p10 /tmp/p60                           # every command on both, one process each
//! ```
//!
//! A command run prints `command wall_s cpu_s peak_rss_kb wheel_epochs`; the peak
//! is the kernel's high-water mark of the process (`VmHWM`, what
//! `/usr/bin/time` reports as `%M`). `table` runs each command in a fresh
//! process on each drive and prints the growth of the peak per extra wheel
//! epoch, `(peak_long − peak_short) / (epochs_long − epochs_short)`.

use std::path::{Path, PathBuf};
use std::process::Command as Process;
use std::time::Instant;

use deadreckon_bench::command::{write_drive, Command};

/// The process's peak resident set, kB (`VmHWM` of /proc/self/status; 0
/// where there is none).
fn peak_rss_kb() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|v| v.parse().ok())
        })
        .unwrap_or(0)
}

/// The process's CPU time so far (user + system), s, from /proc/self/stat
/// (clock ticks of 1/100 s; 0 where there is none). On a machine shared
/// with other work the wall time varies with their load; the CPU time much
/// less.
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // The fields after the command name in parentheses.
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split_whitespace().collect();
            let ticks = f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?;
            Some(ticks / 100.0)
        })
        .unwrap_or(0.0)
}

/// One command in this process: `(wall_s, cpu_s, peak_rss_kb, wheel_epochs)`.
fn run_one(c: Command, dir: &Path) -> (f64, f64, u64, usize) {
    let out = std::env::temp_dir().join(format!("command_cost_{}.csv", std::process::id()));
    let t0 = Instant::now();
    let epochs = c
        .run(dir, &out)
        .unwrap_or_else(|e| panic!("{} on {}: {e}", c.name(), dir.display()));
    let wall = t0.elapsed().as_secs_f64();
    let _ = std::fs::remove_file(&out);
    (wall, cpu_s(), peak_rss_kb(), epochs)
}

/// One command in a fresh process (this program with the command's name).
fn run_child(c: Command, dir: &Path) -> (f64, f64, u64, usize) {
    let exe = std::env::current_exe().expect("this program");
    let out = Process::new(exe)
        .arg(c.name())
        .arg(dir)
        .output()
        .expect("run a child");
    assert!(
        out.status.success(),
        "{} on {}: {}",
        c.name(),
        dir.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    let f: Vec<&str> = text.split_whitespace().collect();
    (
        f[1].parse().expect("wall"),
        f[2].parse().expect("cpu"),
        f[3].parse().expect("peak"),
        f[4].parse().expect("epochs"),
    )
}

fn main() {
    // As the command line's process does first
    // (deadreckon_api::process::return_large_blocks_when_freed).
    deadreckon_api::process::return_large_blocks_when_freed();
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage =
        "usage: command_cost write DIR DURATION_S | COMMAND DIR | table SHORT_DIR LONG_DIR \
                 (COMMAND: calibrate, calibrate-gnss, calibrate-none, evaluate-outage, run, report)";
    match args
        .iter()
        .map(String::as_str)
        .collect::<Vec<_>>()
        .as_slice()
    {
        ["write", dir, duration] => {
            let d: f64 = duration.parse().expect(usage);
            write_drive(Path::new(dir), d).expect("write the drive");
        }
        ["table", short, long] => {
            let (short, long) = (PathBuf::from(short), PathBuf::from(long));
            println!(
                "{:<54} {:>7} {:>7} {:>8} {:>7} {:>7} {:>8} {:>8}",
                "command (wall s, CPU s, peak MB)",
                "short",
                "cpu",
                "MB",
                "long",
                "cpu",
                "MB",
                "B/epoch"
            );
            for c in Command::ALL {
                let (ws, cs, ps, es) = run_child(c, &short);
                let (wl, cl, pl, el) = run_child(c, &long);
                let growth = (pl as f64 - ps as f64) * 1024.0 / (el as f64 - es as f64);
                println!(
                    "{:<54} {:>7.2} {:>7.2} {:>8.1} {:>7.2} {:>7.2} {:>8.1} {:>8.0}",
                    c.command_line(),
                    ws,
                    cs,
                    ps as f64 / 1024.0,
                    wl,
                    cl,
                    pl as f64 / 1024.0,
                    growth
                );
            }
        }
        [name, dir] => {
            let c = Command::from_name(name).expect(usage);
            let (wall, cpu, peak, epochs) = run_one(c, Path::new(dir));
            println!("{} {wall:.3} {cpu:.2} {peak} {epochs}", c.name());
        }
        _ => {
            eprintln!("{usage}");
            std::process::exit(2);
        }
    }
}
