//! The C API's cost per event against the Rust loop of `deadreckon stream`
//! over the same events (issue 32: within 10 %): `Online::push` with the
//! poses collected, against the exported `dr_push_*` functions with the poses
//! drained by `dr_next_pose`; and a line parsed by the io parser then pushed,
//! against `dr_push_line`. The filter is the 5-state one and, for events, the
//! 11-state learner.
//!
//! `cargo bench -p deadreckon-bench --bench ffi`

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::ekf::{DriveEvents, Event, FilterOptions};
use deadreckon_core::online::{Online, Start};
use deadreckon_core::Params;
use deadreckon_ffi::*;

/// The Rust loop: each event into the filter, each pose kept.
fn rust_events(mut o: Online, events: &[Event]) -> usize {
    let mut poses = Vec::new();
    for ev in events {
        o.push(*ev, &mut |p| poses.push(p)).unwrap();
    }
    poses.len()
}

/// A filter through the C API from the vehicle's text.
fn c_filter(vehicle: &str, options: DrOptions) -> *mut DrFilter {
    let mut f = std::ptr::null_mut();
    // SAFETY: valid text, options and out pointer.
    let s = unsafe {
        dr_filter_new(
            vehicle.as_ptr().cast(),
            vehicle.len(),
            std::ptr::null(),
            0,
            &options,
            &mut f,
        )
    };
    assert_eq!(s, DrStatus::Ok);
    f
}

/// Every pose waiting, through `dr_next_pose`.
fn c_drain(f: *mut DrFilter, poses: &mut Vec<DrPose>) {
    let mut p = std::mem::MaybeUninit::<DrPose>::uninit();
    // SAFETY: a live handle, a writable pose, read only when written.
    unsafe {
        while dr_next_pose(f, p.as_mut_ptr()) == DrStatus::Ok {
            poses.push(p.assume_init());
        }
    }
}

/// The same through the C ABI: typed pushes, poses drained after each.
fn c_events(vehicle: &str, options: DrOptions, events: &[Event]) -> usize {
    let f = c_filter(vehicle, options);
    let mut poses = Vec::new();
    for ev in events {
        // SAFETY: a live handle of this thread.
        assert_eq!(unsafe { push_typed(f, ev) }, DrStatus::Ok);
        c_drain(f, &mut poses);
    }
    // SAFETY: freed once.
    unsafe { dr_filter_free(f) };
    poses.len()
}

/// The Rust loop on lines: the io parser, then the filter.
fn rust_lines(mut o: Online, lines: &[String]) -> usize {
    let mut poses = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        let ev = deadreckon_io::events::parse_line(line, "events", i as u64 + 1).unwrap();
        o.push(ev, &mut |p| poses.push(p)).unwrap();
    }
    poses.len()
}

/// The same through `dr_push_line`.
fn c_lines(vehicle: &str, lines: &[String]) -> usize {
    let f = c_filter(vehicle, dr_default_options());
    let mut poses = Vec::new();
    for line in lines {
        // SAFETY: a live handle; `line.len()` readable bytes.
        assert_eq!(
            unsafe { dr_push_line(f, line.as_ptr().cast(), line.len()) },
            DrStatus::Ok
        );
        c_drain(f, &mut poses);
    }
    // SAFETY: freed once.
    unsafe { dr_filter_free(f) };
    poses.len()
}

fn ffi(c: &mut Criterion) {
    let drive = deadreckon_bench::drive(600.0);
    let events: Vec<Event> = DriveEvents::all(&drive).collect();
    let lines: Vec<String> = events.iter().map(deadreckon_io::events::to_line).collect();
    let vehicle = toml::to_string(&drive.vehicle).unwrap();
    let params = Params::nominal(&drive.vehicle);
    let prior = CalibrationOptions::default().prior_std;
    let opts = FilterOptions::default();
    let online = |learn: bool| {
        if learn {
            Online::learning(&drive.vehicle, &params, &prior, &opts, Start::Gnss).unwrap()
        } else {
            Online::new(&drive.vehicle, &params, &opts, Start::Gnss).unwrap()
        }
    };
    let learning = DrOptions {
        learn: true,
        ..dr_default_options()
    };
    // DEADRECKON_BENCH_ONLY=rust|c runs one path DEADRECKON_BENCH_RUNS times
    // (default 2) and exits: for instruction counts, which the machine's
    // load does not move (`valgrind --tool=callgrind`, minus a run of 0).
    if let Ok(which) = std::env::var("DEADRECKON_BENCH_ONLY") {
        let runs: usize = std::env::var("DEADRECKON_BENCH_RUNS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or(2);
        for _ in 0..runs {
            std::hint::black_box(if which == "c" {
                c_events(&vehicle, dr_default_options(), &events)
            } else {
                rust_events(online(false), &events)
            });
        }
        return;
    }
    // Both paths give the same number of poses.
    let n = rust_events(online(false), &events);
    assert_eq!(n, c_events(&vehicle, dr_default_options(), &events));
    assert_eq!(n, c_lines(&vehicle, &lines));

    // On a shared machine criterion's means move with the load; the
    // minimum over interleaved runs of each pair is the cost without it.
    let min_ns_per_event = |f: &dyn Fn() -> usize| {
        let t = std::time::Instant::now();
        std::hint::black_box(f());
        t.elapsed().as_secs_f64() * 1e9 / events.len() as f64
    };
    type Run<'a> = &'a dyn Fn() -> usize;
    let pairs: [(&str, Run, Run); 3] = [
        ("events", &|| rust_events(online(false), &events), &|| {
            c_events(&vehicle, dr_default_options(), &events)
        }),
        (
            "events learning",
            &|| rust_events(online(true), &events),
            &|| c_events(&vehicle, learning, &events),
        ),
        ("lines", &|| rust_lines(online(false), &lines), &|| {
            c_lines(&vehicle, &lines)
        }),
    ];
    for (what, rust, c_api) in pairs {
        let (mut r, mut k) = (f64::INFINITY, f64::INFINITY);
        for _ in 0..15 {
            r = r.min(min_ns_per_event(rust));
            k = k.min(min_ns_per_event(c_api));
        }
        eprintln!(
            "{what}: Rust {r:.1} ns/event, C API {k:.1} ns/event ({:+.1} %), minimum of 15 interleaved runs over {} events",
            100.0 * (k / r - 1.0),
            events.len()
        );
    }

    let mut g = c.benchmark_group("c api");
    g.throughput(Throughput::Elements(events.len() as u64));
    g.sample_size(20);
    g.bench_function("events, Rust Online::push", |b| {
        b.iter(|| rust_events(online(false), &events))
    });
    g.bench_function("events, C dr_push_*", |b| {
        b.iter(|| c_events(&vehicle, dr_default_options(), &events))
    });
    g.bench_function("events learning, Rust Online::push", |b| {
        b.iter(|| rust_events(online(true), &events))
    });
    g.bench_function("events learning, C dr_push_*", |b| {
        b.iter(|| c_events(&vehicle, learning, &events))
    });
    g.bench_function("lines, Rust parse_line + push", |b| {
        b.iter(|| rust_lines(online(false), &lines))
    });
    g.bench_function("lines, C dr_push_line", |b| {
        b.iter(|| c_lines(&vehicle, &lines))
    });
    g.finish();
}

criterion_group!(benches, ffi);
criterion_main!(benches);
