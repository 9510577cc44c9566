//! The held-back choice of corrections (`deadreckon_core::held_back`) runs
//! its two folds in parallel, and the calibration's smoothing re-runs its
//! segments two at a time (`deadreckon_core::checkpoint`, issue 30): the
//! numbers must be those of one fold and one segment after the other, bit
//! for bit, whatever the number of threads.
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test held_back_parallel
//! ```

use deadreckon_core::calibrate::CalibrationOptions;
use deadreckon_core::held_back;
use deadreckon_core::timing::{DelayOptions, Which};
use deadreckon_sim::{simulate, Scenario};

/// `auto` on `drive` in a pool of `threads` threads: its corrections, the
/// corrected drive's GNSS delay applied, and the calibration it handed
/// back, as text (`Debug` prints every f64 to the last bit; NaN, which
/// the judgement holds for figures not computed, compares equal as text).
fn auto_in_pool(
    drive: &deadreckon_core::Drive,
    threads: usize,
) -> (String, deadreckon_core::timing::Corrections) {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("thread pool");
    pool.install(|| auto_text(drive))
}

/// `auto` on `drive` on the calling thread, as [`auto_in_pool`] gives it.
fn auto_text(drive: &deadreckon_core::Drive) -> (String, deadreckon_core::timing::Corrections) {
    let (d, c, cal) = auto_drive(drive);
    let text = format!(
        "{c:?}\n{:?}\n{:?}",
        d.gnss.iter().map(|g| g.t_s).collect::<Vec<_>>(),
        cal.map(|c| (c.estimate, c.history))
    );
    (text, c)
}

/// `auto` on `drive` on the calling thread.
fn auto_drive(
    drive: &deadreckon_core::Drive,
) -> (
    deadreckon_core::Drive,
    deadreckon_core::timing::Corrections,
    Option<deadreckon_core::calibrate::Calibration>,
) {
    held_back::prepare_calibrated(
        drive,
        &CalibrationOptions::default(),
        &DelayOptions::default(),
        Which::Auto,
    )
    .expect("corrections")
}

/// The evaluation drive (seed 25) cut to 300 s (see
/// [`parallel_folds_and_segments_give_the_sequential_numbers`]).
fn evaluation_300s() -> deadreckon_core::Drive {
    let mut sc = Scenario::builtin("evaluation").unwrap();
    sc.duration_s = Some(300.0);
    simulate(&sc, 25).unwrap().drive
}

/// Called from a thread outside rayon's pool, as the command line calls
/// it, the passes on that thread re-run their segments two at a time and
/// the folds' passes (on the pool's workers) one segment after the other
/// through one buffer (docs/performance.md, "Fifth round"); in a pool of
/// one thread every pass goes one segment after the other. The same
/// numbers, bit for bit.
#[test]
fn segments_one_after_the_other_on_the_pools_workers_give_the_pipelined_numbers() {
    let drive = evaluation_300s();
    let (outside, _) = auto_text(&drive);
    let (one, _) = auto_in_pool(&drive, 1);
    assert_eq!(outside, one);
}

/// The choice's drives are copied without the truth (nothing in it reads
/// the truth with the default options): a drive read with its truth is
/// judged as the same drive without it, and the drive handed back keeps
/// its truth (evaluate measures against it).
#[test]
fn auto_judged_a_drive_with_its_truth_as_without_it_and_kept_the_truth() {
    let drive = evaluation_300s();
    assert!(drive.truth.len() > 1000, "{}", drive.truth.len());
    let (with, c_with, cal_with) = auto_drive(&drive);
    let (without, c_without, cal_without) = auto_drive(&drive.clone_without_truth());
    assert_eq!(format!("{c_with:?}"), format!("{c_without:?}"));
    assert_eq!(
        format!("{:?}", cal_with.map(|c| (c.estimate, c.history))),
        format!("{:?}", cal_without.map(|c| (c.estimate, c.history)))
    );
    assert_eq!(with.gnss, without.gnss);
    assert_eq!(with.yaw_rate, without.yaw_rate);
    assert_eq!(with.truth, drive.truth);
    assert!(without.truth.is_empty());
}
/// The evaluation drive (seed 25) cut to 300 s: eight held-back windows,
/// and candidates judged on them (measured: the gyro's and the CAN speed's
/// delays and the walking gyro bias), so both folds and the candidates'
/// calibrations run.
#[test]
fn parallel_folds_and_segments_give_the_sequential_numbers() {
    let mut sc = Scenario::builtin("evaluation").unwrap();
    sc.duration_s = Some(300.0);
    let sim = simulate(&sc, 25).unwrap();
    let (one, c) = auto_in_pool(&sim.drive, 1);
    let held = c.held_back.expect("auto reports its judgement");
    assert!(held.windows >= 6, "{held:?}");
    assert!(
        held.judged.iter().any(|j| !j.by_significance),
        "no candidate judged on the held-back fixes: {held:?}"
    );
    let (two, _) = auto_in_pool(&sim.drive, 2);
    assert_eq!(one, two);
}
