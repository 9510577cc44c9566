//! EKF epochs per second, RTS epochs per second, and a whole 1-hour calibration.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::ekf::{self, FilterOptions, SensorSet};
use deadreckon_core::{rts, Params};

fn filter_and_smoother(c: &mut Criterion) {
    let drive = deadreckon_bench::drive(600.0);
    let params = Params::nominal(&drive.vehicle);
    let opts = FilterOptions {
        record_epochs: true,
        ..Default::default()
    };
    let out = ekf::run(&drive, &params, &opts, &mut ()).unwrap();
    let n = out.epochs.len() as u64;

    let mut g = c.benchmark_group("epochs");
    g.throughput(Throughput::Elements(n));
    g.bench_function(
        "filter, dead reckoning (wheels, gyro, speed, steering)",
        |b| {
            let o = FilterOptions {
                sensors: SensorSet::dead_reckoning(),
                record_epochs: false,
                ..Default::default()
            };
            b.iter(|| ekf::run(&drive, &params, &o, &mut ()).unwrap())
        },
    );
    g.bench_function("filter with GNSS, recording epochs", |b| {
        b.iter(|| ekf::run(&drive, &params, &opts, &mut ()).unwrap())
    });
    g.bench_function("augmented filter (11 states), recording epochs", |b| {
        let prior = CalibrationOptions::default().prior_std;
        b.iter(|| ekf::run_augmented(&drive, &params, &prior, &opts).unwrap())
    });
    g.bench_function("RTS smoother", |b| {
        b.iter(|| rts::smooth(&out.epochs).unwrap())
    });
    g.finish();
}

fn calibration(c: &mut Criterion) {
    let drive = deadreckon_bench::laps(8);
    let (t0, t1) = drive.time_span().unwrap();
    let mut g = c.benchmark_group("calibration");
    g.sample_size(10);
    g.bench_function(
        format!(
            "RTS calibration of a {:.0} min 50 Hz drive",
            (t1 - t0) / 60.0
        ),
        |b| b.iter(|| calibrate::calibrate(&drive, &CalibrationOptions::default()).unwrap()),
    );
    g.finish();
}

criterion_group!(benches, filter_and_smoother, calibration);
criterion_main!(benches);
