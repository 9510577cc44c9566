//! The commands' own cost, beside the kernel's (`estimation.rs`): each
//! command's library path end to end, reading the drive directory included
//! ([`deadreckon_bench::command`]), on a simulated 10-minute and 1-hour
//! drive (the calibration scenario, seed 1, written once). `calibrate` is
//! measured with each choice of corrections: the default (`auto`, chosen on
//! held-back GNSS), `gnss` (the GNSS delay's steps alone) and `none`.
//!
//! Targets (issue 30, on the 2-core machines): `calibrate` with the default
//! corrections under 0.12 s on the 10-minute drive, and at most 1.5 times
//! `--corrections none`. Peak memory per wheel epoch is measured per
//! process by the `command_cost` example (`table`), not here: criterion's
//! own allocations would be counted.

use criterion::{criterion_group, criterion_main, Criterion};
use deadreckon_bench::command::{write_drive, Command};

fn commands(c: &mut Criterion) {
    for (label, duration_s) in [("10 min", 600.0), ("1 h", 3600.0)] {
        let dir = tempfile::tempdir().expect("temporary directory");
        write_drive(dir.path(), duration_s).expect("simulated drive");
        let out = dir.path().join("tracks.csv");
        let mut g = c.benchmark_group(format!("command, {label} drive"));
        g.sample_size(10);
        for cmd in Command::ALL {
            g.bench_function(cmd.command_line(), |b| {
                b.iter(|| cmd.run(dir.path(), &out).expect("command"))
            });
        }
        g.finish();
    }
}

criterion_group!(benches, commands);
criterion_main!(benches);
