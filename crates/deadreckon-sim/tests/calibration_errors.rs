//! The RTS calibration's standard errors and its check against the GNSS
//! chords (`deadreckon_core::chords`), on 600 s training drives of family
//! cars 1–32 (issue 13).
//!
//! Two regressions:
//! - The standard errors left out the receiver's slow error. The least
//!   squares fit the wheels against smoothed states the wheels themselves
//!   set, so with a wandering receiver (the family's Gauss–Markov error,
//!   0–1.5 m over 20–120 s) the circumferences were 1–5 mm off, all four
//!   alike, while their standard errors read 0.01–0.1 mm: up to 194 standard
//!   errors.
//! - A calibration whose smoothing filter lost the fixes was kept: car 30's,
//!   with white fixes, "converged" with its circumferences 225 mm (12 %) off,
//!   and car 22's ended 15 m off (not converged, but written). Their
//!   distance scales disagree with the GNSS chords by 5.1 and 30 standard
//!   errors; a calibration that does is now rejected.
//!
//! And the cause of those two: the augmented pass learnt the circumferences
//! while the heading from the first fixes was still unknown (car 30:
//! 13–20° off, standard deviation 17°, +107 mm at pull-away, +450 mm by
//! 50 s). It now holds them while the yaw standard deviation is above
//! `noise.scale_hold_yaw_std_rad` (2°), and every car calibrates; with the
//! hold off (`inf`) the rejection still catches car 30.

use deadreckon_core::calibrate::{self, CalibrationOptions};
use deadreckon_core::Error;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::simulate;

/// One calibration's circumference figures, m: the mean of the four errors,
/// the mean standard error, and the least squares' own (the chords taken
/// out again).
#[derive(Debug, Clone, Copy)]
struct Figures {
    err: f64,
    std: f64,
    ls: f64,
    /// The chords' mean residual in standard errors.
    chords: f64,
}

/// Family car `seed`'s 600 s training drive (no installation effects), with
/// its receiver's wander or, when `white`, without it, calibrated with RTS:
/// its figures, or the rejection's message. `hold` off learns the scale and
/// circumferences whatever the heading's uncertainty (`scale_hold_yaw_std_rad
/// = inf`).
fn calibrate(seed: u64, white: bool, hold: bool) -> Result<Figures, String> {
    let mut car = CarFamily::draw(seed);
    if white {
        car.gnss_markov = (0.0, 60.0);
    }
    let sc = car.drive(100 + seed, 600.0);
    let mut sim = simulate(&sc, 100 + seed).unwrap();
    if !hold {
        sim.drive.vehicle.noise.scale_hold_yaw_std_rad = f64::INFINITY;
    }
    let c = match calibrate::calibrate(&sim.drive, &CalibrationOptions::default()) {
        Ok(c) => c,
        Err(e @ Error::Rejected(_)) => return Err(e.to_string()),
        Err(e) => panic!("car {seed}: {e}"),
    };
    let (p, s, t) = (
        c.estimate.params.circumferences(),
        c.estimate.std.circumferences(),
        sim.truth_params.circumferences(),
    );
    let chords = c.gnss_chords.expect("a 600 s drive has chords");
    let rel = chords.std;
    Ok(Figures {
        chords: chords.sigmas(),
        err: (0..4).map(|i| p[i] - t[i]).sum::<f64>() / 4.0,
        std: s.iter().sum::<f64>() / 4.0,
        ls: (0..4)
            .map(|i| (s[i] * s[i] - (rel * p[i]).powi(2)).max(0.0).sqrt())
            .sum::<f64>()
            / 4.0,
    })
}

/// Every car: accepted within 3 standard errors, or rejected; returns the
/// rejected cars, the largest |error| / least-squares error and the largest
/// |error| / standard error.
fn every_car(white: bool) -> (Vec<u64>, f64, f64) {
    let (rejected, worst_ls, worst, largest_std) = cars(white, 1..=32);
    if white {
        // Measured 0.18–1.80 mm for errors of 0.00–1.83 mm.
        assert!(largest_std < 2.0e-3, "{largest_std}");
    }
    (rejected, worst_ls, worst)
}

/// [`every_car`] over `seeds`, with the largest standard error, m.
fn cars(white: bool, seeds: std::ops::RangeInclusive<u64>) -> (Vec<u64>, f64, f64, f64) {
    let (mut rejected, mut worst_ls, mut worst) = (Vec::new(), 0.0f64, 0.0f64);
    let mut largest_std = 0.0f64;
    for seed in seeds {
        match calibrate(seed, white, true) {
            Ok(f) => {
                let (z, z_ls) = (f.err / f.std, f.err / f.ls);
                worst_ls = worst_ls.max(z_ls.abs());
                worst = worst.max(z.abs());
                println!(
                    "car {seed} (white fixes: {white}): circumference error {:+.2} mm, standard \
                     error {:.2} mm (z {z:+.2}); least squares alone {:.3} mm (z {z_ls:+.1}); \
                     chords {:+.2} standard errors",
                    1e3 * f.err,
                    1e3 * f.std,
                    1e3 * f.ls,
                    f.chords
                );
                assert!(z.abs() < 3.0, "car {seed}: z {z}");
                largest_std = largest_std.max(f.std);
            }
            Err(e) => {
                println!("car {seed} (white fixes: {white}): {e}");
                rejected.push(seed);
            }
        }
    }
    (rejected, worst_ls, worst, largest_std)
}

#[test]
fn the_rts_standard_errors_left_out_the_receivers_wander() {
    let (rejected, worst_ls, worst) = every_car(false);
    // Measured: the 32 cars within 2.28 standard errors (standard errors
    // 0.51–4.24 mm for errors up to 4.81 mm); without the chords up to 194
    // standard errors. Bounds: 2.5, and 20 for the least squares alone.
    assert!(worst_ls > 20.0, "{worst_ls}");
    assert!(worst < 2.5, "{worst}");
    assert_eq!(rejected, [] as [u64; 0]);
}

#[test]
fn a_calibration_whose_filter_lost_the_fixes_was_kept_as_converged() {
    // Measured: the 32 cars within 1.45 standard errors (car 30, +1.83 mm;
    // the others within 1.0, RMS error 0.28 mm: the chords are cautious with
    // white fixes). Bound 1.6.
    let (rejected, _, worst) = every_car(true);
    assert!(worst < 1.6, "{worst}");
    assert_eq!(rejected, [] as [u64; 0]);
    // The rejection still catches the filter that loses the fixes: car 30
    // with the scale learnt while the heading is unknown (its circumferences
    // 225 mm off, "converged" before the rejection).
    let e = calibrate(30, true, false).expect_err("car 30 without the hold");
    assert!(e.contains("disagrees with the GNSS chords"), "{e}");
}

#[test]
fn the_circumferences_were_learnt_while_the_heading_was_unknown() {
    // Car 30 pulls away with its heading from the first fixes 13–20° off.
    // Measured with the hold: +1.83 mm (white fixes) and +1.99 mm (its
    // wander), 1.45 and 1.76 standard errors. Bound 2.5 mm; without the hold
    // it is rejected (above), and was 225 mm off.
    for white in [true, false] {
        let f = calibrate(30, white, true).unwrap_or_else(|e| panic!("white {white}: {e}"));
        assert!(f.err.abs() < 2.5e-3, "white {white}: {f:?}");
    }
}

/// The scale hold (`noise.scale_hold_yaw_std_rad`) and the chords'
/// rejection were chosen and tested on cars 1–32; cars 101–132 saw no
/// choice (issue 33), run once when this test was written.
#[test]
fn the_hold_and_the_chords_on_held_out_cars() {
    let (rejected, worst_ls, worst, _) = cars(false, 101..=132);
    let (rejected_white, _, worst_white, std_white) = cars(true, 101..=132);
    println!(
        "held out: worst z {worst:.2} (least squares alone {worst_ls:.1}), white fixes {worst_white:.2} \
         (largest standard error {:.2} mm); rejected {rejected:?} / {rejected_white:?}",
        std_white * 1e3
    );
    // Measured: every car calibrated (none rejected) and within 1.93
    // standard errors with the wander (the least squares alone up to 178),
    // 0.52 with white fixes; the largest white-fix standard error 2.18 mm
    // (car 112, error 0.31 mm), above the dev cars' 1.80 mm. Bounds near
    // these.
    assert_eq!(rejected, [] as [u64; 0]);
    assert_eq!(rejected_white, [] as [u64; 0]);
    assert!(worst < 2.4, "{worst}");
    assert!(worst_ls > 20.0, "{worst_ls}");
    assert!(worst_white < 0.7, "{worst_white}");
    assert!(std_white < 2.7e-3, "{std_white}");
}
