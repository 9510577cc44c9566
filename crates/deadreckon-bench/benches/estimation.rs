//! EKF epochs per second, RTS epochs per second, the online filter's events
//! per second and latency, reading a drive's CSV (bytes per second), and a
//! whole 1-hour calibration with its peak heap per wheel epoch.
//!
//! Targets (issue 9): the 11-state filter step over 1.2 M epochs/s; reading
//! over 150 MB/s of CSV; `calibrate` under 300 bytes of peak heap per wheel
//! epoch on the 8-lap drive (printed once, measured by a counting allocator).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

/// The system allocator, counting the bytes live and their peak.
struct Counting;

static LIVE: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(layout) };
        if !p.is_null() {
            let live = LIVE.fetch_add(layout.size(), Ordering::Relaxed) + layout.size();
            PEAK.fetch_max(live, Ordering::Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) };
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let p = unsafe { System.realloc(ptr, layout, new_size) };
        if !p.is_null() {
            if new_size >= layout.size() {
                let live = LIVE.fetch_add(new_size - layout.size(), Ordering::Relaxed)
                    + (new_size - layout.size());
                PEAK.fetch_max(live, Ordering::Relaxed);
            } else {
                LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
            }
        }
        p
    }
}

#[global_allocator]
static ALLOCATOR: Counting = Counting;

/// Runs `f` and returns its result with the peak heap it added, bytes.
fn peak_heap<T>(f: impl FnOnce() -> T) -> (T, usize) {
    let base = LIVE.load(Ordering::Relaxed);
    PEAK.store(base, Ordering::Relaxed);
    let out = f();
    (out, PEAK.load(Ordering::Relaxed) - base)
}

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
    g.bench_function("augmented filter (11 states), step", |b| {
        let prior = CalibrationOptions::default().prior_std;
        let o = FilterOptions {
            record_epochs: false,
            ..Default::default()
        };
        b.iter(|| ekf::run_augmented(&drive, &params, &prior, &o).unwrap())
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

/// The 8-lap drive written as a drive directory once.
fn laps8_dir() -> (tempfile::TempDir, deadreckon_core::Drive) {
    let drive = deadreckon_bench::laps(8);
    let dir = tempfile::tempdir().expect("temporary directory");
    deadreckon_io::write_drive(dir.path(), &drive).expect("write drive");
    (dir, drive)
}

/// Bytes of the CSV files of `dir` (without `truth.csv` when `skip_truth`).
fn csv_bytes(dir: &std::path::Path, skip_truth: bool) -> u64 {
    std::fs::read_dir(dir)
        .expect("drive directory")
        .filter_map(|e| e.ok())
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.ends_with(".csv") && !(skip_truth && name == "truth.csv")
        })
        .map(|e| e.metadata().map_or(0, |m| m.len()))
        .sum()
}

fn reading(c: &mut Criterion) {
    let (dir, _) = laps8_dir();
    let mut g = c.benchmark_group("read");
    g.sample_size(10);
    for skip_truth in [false, true] {
        let opts = if skip_truth {
            deadreckon_io::ReadOptions::default().without_truth()
        } else {
            deadreckon_io::ReadOptions::default()
        };
        g.throughput(Throughput::Bytes(csv_bytes(dir.path(), skip_truth)));
        g.bench_function(
            if skip_truth {
                "8-lap drive directory without truth.csv (as calibrate reads it)"
            } else {
                "8-lap drive directory, every file"
            },
            |b| b.iter(|| deadreckon_io::read_drive_with(dir.path(), &opts).unwrap()),
        );
    }
    g.finish();
}

fn calibration(c: &mut Criterion) {
    // Peak heap of what `deadreckon calibrate DIR --method rts` does: read the
    // directory (without truth.csv) and calibrate.
    {
        let (dir, _) = laps8_dir();
        let opts = deadreckon_io::ReadOptions::default().without_truth();
        let (epochs, peak) = peak_heap(|| {
            let drive = deadreckon_io::read_drive_with(dir.path(), &opts).unwrap();
            calibrate::calibrate(&drive, &CalibrationOptions::default()).unwrap();
            drive.wheels.len()
        });
        eprintln!(
            "calibrate (read + RTS) of the 8-lap drive: peak heap {:.1} MB over {} wheel epochs = {:.0} B/epoch (target < 300)",
            peak as f64 / 1e6,
            epochs,
            peak as f64 / epochs as f64
        );
    }
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

criterion_group!(benches, filter_and_smoother, online, reading, calibration);
criterion_main!(benches);
