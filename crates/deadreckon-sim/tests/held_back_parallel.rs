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
    let (d, c, cal) = pool.install(|| {
        held_back::prepare_calibrated(
            drive,
            &CalibrationOptions::default(),
            &DelayOptions::default(),
            Which::Auto,
        )
        .expect("corrections")
    });
    let text = format!(
        "{c:?}\n{:?}\n{:?}",
        d.gnss.iter().map(|g| g.t_s).collect::<Vec<_>>(),
        cal.map(|c| (c.estimate, c.history))
    );
    (text, c)
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
