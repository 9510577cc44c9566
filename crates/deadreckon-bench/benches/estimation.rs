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

/// The online filter one event at a time (`deadreckon stream`): events per
/// second, and the per-event latency quantiles printed once.
fn online(c: &mut Criterion) {
    use deadreckon_core::ekf::DriveEvents;
    use deadreckon_core::online::{Online, Start};
    let drive = deadreckon_bench::drive(600.0);
    let params = Params::nominal(&drive.vehicle);
    let events: Vec<_> = DriveEvents::all(&drive).collect();
    let opts = FilterOptions::default();
    let run_all = |learn: bool| {
        let mut o = if learn {
            let prior = CalibrationOptions::default().prior_std;
            Online::learning(&drive.vehicle, &params, &prior, &opts, Start::Gnss).unwrap()
        } else {
            Online::new(&drive.vehicle, &params, &opts, Start::Gnss).unwrap()
        };
        let mut n = 0usize;
        for ev in &events {
            o.push(*ev, &mut |_| n += 1).unwrap();
        }
        n
    };
    // Latency of each push once started (µs), median and p99.
    for learn in [false, true] {
        let mut o = if learn {
            let prior = CalibrationOptions::default().prior_std;
            Online::learning(&drive.vehicle, &params, &prior, &opts, Start::Gnss).unwrap()
        } else {
            Online::new(&drive.vehicle, &params, &opts, Start::Gnss).unwrap()
        };
        let mut lat = Vec::with_capacity(events.len());
        for ev in &events {
            let started = o.is_started();
            let t = std::time::Instant::now();
            o.push(*ev, &mut |p| {
                std::hint::black_box(p);
            })
            .unwrap();
            if started {
                lat.push(t.elapsed().as_secs_f64() * 1e6);
            }
        }
        lat.sort_by(f64::total_cmp);
        eprintln!(
            "stream{} per-event latency over {} events: median {:.2} µs, p99 {:.2} µs",
            if learn { " --learn" } else { "" },
            lat.len(),
            lat[lat.len() / 2],
            lat[lat.len() * 99 / 100]
        );
    }
    let mut g = c.benchmark_group("stream");
    g.throughput(Throughput::Elements(events.len() as u64));
    g.bench_function("online filter, events", |b| b.iter(|| run_all(false)));
    g.bench_function("online learner (11 states), events", |b| {
        b.iter(|| run_all(true))
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

criterion_group!(benches, filter_and_smoother, online, calibration);
criterion_main!(benches);
