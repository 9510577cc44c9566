//! Slipping and bad wheels (issue 13): the simulator's wheel faults, found by
//! the wheel-health monitor (`deadreckon_core::wheel_health`), and the drift
//! through GNSS outages with and without it, over a seeded family of drives.
//!
//! Print the figures: `cargo test --profile ci -p deadreckon-sim --test
//! wheel_faults -- --nocapture`.

use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::{through_windows, OutageEvaluation};
use deadreckon_core::wheel_health::{DropReason, WheelHealth, WheelMonitorConfig};
use deadreckon_core::{ekf, Drive, Params};
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::{simulate, ShrinkSpec, SpinSpec, WheelFaultsSpec};

/// The outage windows: 30 s every 60 s from 60 s on.
fn windows(drive: &Drive) -> Vec<(f64, f64)> {
    let end = drive.truth.last().map_or(0.0, |t| t.t_s) - 5.0;
    let mut w = Vec::new();
    let mut a = 60.0;
    while a + 30.0 <= end {
        w.push((a, a + 30.0));
        a += 60.0;
    }
    w
}

struct Case {
    drive: Drive,
    params: Params,
    bursts: Vec<(f64, f64)>,
    shrink_from_s: f64,
}

fn case(seed: u64, spin: bool, shrink: bool) -> Case {
    let car = CarFamily::draw(seed);
    // Forward only: with shunts (the family's default) the monitor's
    // verdicts differ (a spin burst while backing up is not dropped, the 3 %
    // wheel is dropped in two intervals instead of one); not studied yet.
    let base = car.drive_forward(seed, 600.0);
    let sim0 = simulate(&base, seed).unwrap();
    let mid = 0.5 * sim0.stats.duration_s;
    let faults = WheelFaultsSpec {
        spin: spin.then_some(SpinSpec {
            wheel: 2,
            slip: 0.3,
            duration_s: 1.0,
            mean_gap_s: 30.0,
            min_accel_mps2: 0.3,
        }),
        shrink: shrink.then_some(ShrinkSpec {
            wheel: 1,
            from_s: mid,
            factor: 0.97,
        }),
    };
    let sim = simulate(&base.with_wheel_faults(faults), seed).unwrap();
    Case {
        params: sim.truth_params,
        bursts: sim.stats.spin_bursts,
        drive: sim.drive,
        shrink_from_s: mid,
    }
}

fn opts(monitor: bool) -> FilterOptions {
    FilterOptions {
        wheel_monitor: monitor.then(WheelMonitorConfig::default),
        ..Default::default()
    }
}

fn outages(c: &Case, monitor: bool) -> OutageEvaluation {
    through_windows(&c.drive, &c.params, &windows(&c.drive), &opts(monitor)).unwrap()
}

fn health(c: &Case) -> WheelHealth {
    ekf::run(&c.drive, &c.params, &opts(true), &mut ())
        .unwrap()
        .wheel_health
        .unwrap()
}

/// Faults of one drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Fault {
    None,
    Spin,
    Shrink,
    Both,
}

const FAULTS: [Fault; 4] = [Fault::None, Fault::Spin, Fault::Shrink, Fault::Both];
const SEEDS: std::ops::RangeInclusive<u64> = 1..=6;

struct Result {
    seed: u64,
    fault: Fault,
    bursts: Vec<(f64, f64)>,
    shrink_from_s: f64,
    end_s: f64,
    health: WheelHealth,
    with: OutageEvaluation,
    without: OutageEvaluation,
}

/// Every seed and fault, computed once for all the tests.
fn results() -> &'static [Result] {
    static R: std::sync::OnceLock<Vec<Result>> = std::sync::OnceLock::new();
    R.get_or_init(|| {
        let mut out = Vec::new();
        for seed in SEEDS {
            for fault in FAULTS {
                let c = case(
                    seed,
                    matches!(fault, Fault::Spin | Fault::Both),
                    matches!(fault, Fault::Shrink | Fault::Both),
                );
                out.push(Result {
                    seed,
                    fault,
                    health: health(&c),
                    with: outages(&c, true),
                    without: outages(&c, false),
                    end_s: c.drive.wheels.t_s(c.drive.wheels.len() - 1),
                    bursts: c.bursts,
                    shrink_from_s: c.shrink_from_s,
                });
            }
        }
        out
    })
}

fn mean(v: impl Iterator<Item = f64>) -> f64 {
    let v: Vec<f64> = v.collect();
    v.iter().sum::<f64>() / v.len() as f64
}

/// Mean over the seeds of the mean final error and drift with and without the
/// monitor: `(final with, final without, drift with, drift without)`.
fn figures(fault: Fault) -> (f64, f64, f64, f64) {
    let r = || results().iter().filter(move |r| r.fault == fault);
    (
        mean(r().map(|r| r.with.final_error().mean)),
        mean(r().map(|r| r.without.final_error().mean)),
        mean(r().map(|r| r.with.drift_pct().mean)),
        mean(r().map(|r| r.without.drift_pct().mean)),
    )
}

#[test]
fn fault_free_drives_drop_no_wheel() {
    for r in results().iter().filter(|r| r.fault == Fault::None) {
        assert!(
            r.health.all_good(),
            "seed {}: {:?}",
            r.seed,
            r.health.lines()
        );
        // Without a drop the monitor changes nothing.
        assert_eq!(r.with, r.without, "seed {}", r.seed);
    }
}

#[test]
fn every_spin_burst_drops_the_spinning_wheel_as_slip() {
    for r in results().iter().filter(|r| r.fault == Fault::Spin) {
        assert!(
            r.bursts.len() >= 8,
            "seed {}: {} bursts",
            r.seed,
            r.bursts.len()
        );
        let rl = &r.health.wheels[2];
        for &(a, b) in &r.bursts {
            let hit = rl
                .intervals
                .iter()
                .any(|i| i.reason == DropReason::Slip && i.start_s <= b && i.end_s >= a);
            assert!(hit, "seed {}: burst {a:.1}..{b:.1} not dropped", r.seed);
        }
        // Out only around the bursts: each stretch starts within a burst.
        for i in &rl.intervals {
            assert!(
                r.bursts
                    .iter()
                    .any(|&(a, b)| i.start_s >= a && i.start_s <= b),
                "seed {}: drop at {:.1} s outside every burst",
                r.seed,
                i.start_s
            );
            assert!(i.end_s - i.start_s < 3.0, "seed {}: {i:?}", r.seed);
        }
        for w in [0, 1, 3] {
            assert!(r.health.wheels[w].intervals.is_empty(), "seed {}", r.seed);
        }
    }
}

#[test]
fn a_three_percent_smaller_wheel_is_dropped_for_the_rest_of_the_drive() {
    for r in results().iter().filter(|r| r.fault == Fault::Shrink) {
        let fr = &r.health.wheels[1];
        assert_eq!(fr.intervals.len(), 1, "seed {}: {:?}", r.seed, fr.intervals);
        let i = fr.intervals[0];
        assert_eq!(i.reason, DropReason::Bias, "seed {}", r.seed);
        let delay = i.start_s - r.shrink_from_s;
        println!("seed {}: dropped {delay:.1} s after the change", r.seed);
        // Measured 3.9–14.5 s over seeds 1..=4 (a 50 m window to fill).
        assert!(
            (0.0..25.0).contains(&delay),
            "seed {}: delay {delay}",
            r.seed
        );
        assert!(
            r.end_s - i.end_s < 0.1,
            "seed {}: readmitted at {}",
            r.seed,
            i.end_s
        );
        for w in [0, 2, 3] {
            assert!(r.health.wheels[w].intervals.is_empty(), "seed {}", r.seed);
        }
    }
}

#[test]
fn the_monitor_brings_the_outage_drift_back_to_the_fault_free_one() {
    println!("30 s GNSS outages every 60 s, truth parameters, mean over seeds 1..=6:");
    println!("fault      final with / without (m)   drift with / without (% of distance)");
    for f in FAULTS {
        let (fw, fo, dw, d_o) = figures(f);
        println!("{f:<8?} {fw:>10.3} / {fo:<10.3}       {dw:>8.3} / {d_o:.3}");
    }
    let (clean, _, clean_d, _) = figures(Fault::None);
    for f in [Fault::Spin, Fault::Shrink, Fault::Both] {
        let (fw, fo, dw, d_o) = figures(f);
        // Measured: with the monitor within 0.6 % of the fault-free figures
        // (final error 1.867–1.883 m against 1.875 m, drift 1.314–1.325 %
        // against 1.322 %), bound 3 %; without it the final error 1.61–2.40
        // times and the drift 1.37–1.72 times the fault-free ones, bounds
        // 1.4 and 1.25.
        assert!(fw < 1.03 * clean && dw < 1.03 * clean_d, "{f:?}: {fw} {dw}");
        assert!(
            fo > 1.4 * clean && d_o > 1.25 * clean_d,
            "{f:?}: {fo} {d_o}"
        );
    }
}

/// Regression (issue 13): the sliding outage evaluation started every
/// window from a fresh filter, whose wheel monitor had forgotten that a wheel
/// was out, so a 3 % smaller wheel was fused again at every window start
/// until the monitor had seen enough of it again.
#[test]
fn sliding_outage_windows_forgot_the_wheel_monitors_verdict() {
    use deadreckon_core::outage::evaluate;
    for seed in [1, 2, 3] {
        let late = |c: &Case, from_s: f64, monitor: bool| {
            let ev = evaluate(&c.drive, &c.params, 30.0, 15.0, 5.0, &opts(monitor)).unwrap();
            let w: Vec<f64> = ev
                .windows
                .iter()
                .filter(|w| w.start_s > from_s)
                .map(|w| w.final_m())
                .collect();
            assert!(w.len() >= 10, "seed {seed}: {} windows", w.len());
            w.iter().sum::<f64>() / w.len() as f64
        };
        let faulty = case(seed, false, true);
        let from_s = faulty.shrink_from_s + 30.0;
        let clean = late(&case(seed, false, false), from_s, true);
        let (with, without) = (late(&faulty, from_s, true), late(&faulty, from_s, false));
        println!(
            "seed {seed}: windows after the change, mean final error {with:.3} m with the monitor, \
             {without:.3} m without, {clean:.3} m on the fault-free drive"
        );
        // Measured 1.000, 1.000, 0.997 × the fault-free drive's; before the
        // fix 1.30, 1.05, 1.06.
        assert!(with < 1.02 * clean, "seed {seed}: {with} vs {clean}");
        assert!(with < 0.7 * without, "seed {seed}: {with} vs {without}");
    }
}
