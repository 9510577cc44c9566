//! Tyre side slip and the steering's understeer (issue 28), measured on the
//! dynamic family's cars (`deadreckon_sim::family::DynamicCar`, cars 1–10)
//! with two of its effects: the side slip (a quasi-steady single-track
//! model, `deadreckon_sim::dynamics`: side-slip gradients g of 0.003–0.007
//! rad per m/s², understeer 0.001–0.004) and the steering-wheel offset
//! (1–3°). The RTS calibration of a 1200 s drive estimates g
//! ([`deadreckon_core::side_slip`]) and the steering (ratio, offset,
//! understeer); a 300 s drive of the same car is then dead-reckoned through
//! sliding 30 s outages with the calibrated parameters: the paper's model
//! against the model with the side slip (and the steering) calibrated, and
//! the same without the gyro, where the steering sets the yaw rate.
//!
//! One-off runs on the same cars and drives without the wander: with no
//! effect (the kinematic world) the paper's model gives 1.611 m and g reads
//! 0 within its standard error on all ten (z −1.6..+1.0); with the
//! steering offset alone 1.634 m; with the side slip too 1.747 m, and with
//! the calibrated g 1.637 m: the slip's cost is recovered.
//!
//! Two receivers per car: the family's as drawn (white noise 0.3–1.5 m and a
//! Gauss–Markov wander of up to 1.5 m, 20–120 s), and the same without the
//! wander. Neither has latency: the GNSS delay is not what is measured here.
//!
//! ```text
//! cargo test --profile ci -p deadreckon-sim --test side_slip -- --nocapture
//! ```

use deadreckon_core::calibrate::{self, Calibration, CalibrationOptions};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::evaluate;
use deadreckon_core::{Drive, Params};
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;

/// Dynamic family cars measured (`DynamicCar::draw`).
const CARS: std::ops::RangeInclusive<u64> = 1..=10;

/// The effects of the drives: the side slip (and understeer) and the
/// steering offset, with the receiver's wander or without.
fn effects(wander: bool) -> Effects {
    Effects {
        side_slip: true,
        steering_offset: true,
        wander,
        ..Effects::none()
    }
}

/// One car with one receiver: the calibration and the evaluation drive.
struct Car {
    seed: u64,
    g_true: f64,
    k_us_true: f64,
    ratio_true: f64,
    offset_true: f64,
    calibration: Calibration,
    evaluation: Drive,
}

fn car(seed: u64, wander: bool) -> Car {
    let car = DynamicCar::draw(seed);
    let e = effects(wander);
    let cal = simulate(&car.drive(1000 + seed, 1200.0, &e), 1000 + seed).unwrap();
    let calibration = calibrate::calibrate(&cal.drive, &CalibrationOptions::default()).unwrap();
    let ev = simulate(&car.drive(2000 + seed, 300.0, &e), 2000 + seed).unwrap();
    let vehicle = &car.base.vehicle;
    Car {
        seed,
        g_true: car.dynamics.rear_slip_gradient_rad_per_mps2(vehicle),
        k_us_true: car.dynamics.understeer_gradient_rad_per_mps2(vehicle),
        ratio_true: vehicle.steering_ratio,
        offset_true: car.steering_offset_rad,
        calibration,
        evaluation: ev.drive,
    }
}

/// Mean final error of sliding 30 s outages (every 15 s) on `drive` with
/// `params`, m.
fn outage_error(drive: &Drive, params: &Params) -> f64 {
    evaluate(drive, params, 30.0, 15.0, 5.0, &FilterOptions::default())
        .unwrap()
        .final_error()
        .mean
}

/// `drive` with the calibrated g and steering of `c` set in its vehicle.
fn calibrated_model(c: &Car, drive: &Drive) -> Drive {
    let slip = c.calibration.side_slip.as_ref().expect("RTS: side slip");
    let st = c.calibration.steering.as_ref().expect("steering");
    let mut d = drive.clone();
    d.vehicle.rear_slip_gradient_rad_per_mps2 = slip.fitted;
    d.vehicle.steering_ratio = st.ratio.value;
    d.vehicle.steering_offset_rad = st.offset.value;
    if let Some(u) = st.understeer.as_ref().filter(|u| u.estimated) {
        d.vehicle.understeer_gradient_rad_per_mps2 = u.value;
    }
    d
}

/// The mean 30 s outage errors of `c`'s evaluation drive with its
/// calibrated parameters: the paper's model, with the calibrated g, and
/// with g and the calibrated steering.
fn outages(c: &Car) -> [f64; 3] {
    let slip = c.calibration.side_slip.as_ref().expect("RTS: side slip");
    let params = c.calibration.estimate.params;
    let paper = outage_error(&c.evaluation, &params);
    let mut slipping = c.evaluation.clone();
    slipping.vehicle.rear_slip_gradient_rad_per_mps2 = slip.fitted;
    let with_slip = outage_error(&slipping, &params);
    let steered = calibrated_model(c, &c.evaluation);
    [paper, with_slip, outage_error(&steered, &params)]
}

#[test]
fn the_side_slip_gradient_is_within_3_sigma_and_modelling_it_shortens_outages() {
    for wander in [true, false] {
        let (mut within, mut estimated) = (0, 0);
        // Steering: (ratio, offset, K_us) each within 3σ, on the cars whose
        // K_us was estimated; and how many those were.
        let (mut steering_within, mut steering_cars) = ([0; 3], 0);
        let mut errors = Vec::new();
        // Without the gyro (the steering sets the yaw rate): paper, calibrated.
        let mut no_gyro = [0.0; 2];
        for seed in CARS {
            let c = car(seed, wander);
            let slip = c.calibration.side_slip.as_ref().expect("RTS: side slip");
            let (g, sd) = (slip.fitted, slip.fitted_std);
            let z = (g - c.g_true) / sd;
            within += usize::from(z.abs() <= 3.0);
            estimated += usize::from(slip.gradient.estimated);
            let e = outages(&c);
            let st = c.calibration.steering.as_ref().expect("steering");
            if let Some(u) = st.understeer.as_ref().filter(|u| u.estimated) {
                steering_cars += 1;
                for (k, (p, truth)) in [
                    (&st.ratio, c.ratio_true),
                    (&st.offset, c.offset_true),
                    (u, c.k_us_true),
                ]
                .into_iter()
                .enumerate()
                {
                    let z = (p.value - truth) / p.std.unwrap();
                    steering_within[k] += usize::from(z.abs() <= 3.0);
                }
            }
            println!(
                "car {} (wander {wander}): g {g:.5} ± {sd:.5} (truth {:.5}, {z:+.2} σ, {}, {} \
                 blocks, RMS a_y {:.2} m/s²); steering ratio {:.3} ± {:.3}, offset {:.4} ± \
                 {:.4} rad (truth {:.4}), K_us {} (truth {:.5}); 30 s outages: paper {:.3} m, slip {:.3} m, slip + steering \
                 {:.3} m",
                c.seed,
                c.g_true,
                if slip.gradient.estimated {
                    "estimated"
                } else {
                    "NOT estimated"
                },
                slip.blocks,
                slip.rms_lateral_accel_mps2,
                st.ratio.value,
                st.ratio.std.unwrap_or(f64::NAN),
                st.offset.value,
                st.offset.std.unwrap_or(f64::NAN),
                c.offset_true,
                st.understeer.as_ref().map_or("-".into(), |u| match u.std {
                    Some(s) => format!("{:.5} ± {s:.5}", u.value),
                    None => "not estimated".into(),
                }),
                c.k_us_true,
                e[0],
                e[1],
                e[2],
            );
            errors.push(e);
            if !wander {
                let mut d = c.evaluation.clone();
                d.yaw_rate.clear();
                let params = c.calibration.estimate.params;
                no_gyro[0] += outage_error(&d, &params) / CARS.count() as f64;
                no_gyro[1] +=
                    outage_error(&calibrated_model(&c, &d), &params) / CARS.count() as f64;
            }
        }
        let n = errors.len() as f64;
        let mean = |k: usize| errors.iter().map(|e| e[k]).sum::<f64>() / n;
        let (paper, slip, steer) = (mean(0), mean(1), mean(2));
        println!(
            "wander {wander}: {within} of {n} within 3σ, {estimated} estimated; mean 30 s outage \
             error: paper {paper:.3} m, slip {slip:.3} m, slip + steering {steer:.3} m; steering \
             with K_us on {steering_cars} cars, within 3σ: ratio {}, offset {}, K_us {}",
            steering_within[0], steering_within[1], steering_within[2]
        );
        // Measured (dynamic family cars 1–10, 1200 s calibration drives,
        // 300 s evaluation drives): with the wander 10 of 10 within 3σ,
        // none estimated (σ 0.0013–0.0047), outages 3.548 → 3.484 m
        // (−1.8 %), 3.480 m with the steering too; without it 10 of 10
        // within 3σ (z −1.94..+0.87), 8 estimated (σ 0.00036–0.00089; cars
        // 6 and 9, RMS a_y 0.51 and 0.38 m/s², not), outages 1.747 →
        // 1.637 m (−6.3 %), 1.621 m with the steering too.
        assert!(within as f64 >= 0.9 * n, "{within} of {n} within 3σ");
        let (most_estimated, gain) = if wander { (0, 0.99) } else { (7, 0.96) };
        assert!(estimated >= most_estimated, "{estimated} estimated");
        assert!(slip < gain * paper, "{slip} vs {paper}");
        assert!(steer < gain * paper, "{steer} vs {paper}");
        // The steering against the smoothed states (above 5 m/s): K_us
        // estimated on 9 of 10 cars (car 9, RMS a_y 0.38 m/s², not: its
        // two-parameter ratio, 17.07 for 16, holds the understeer), and
        // there ratio, offset and K_us each within 3σ on all 9, with and
        // without the wander.
        assert!(steering_cars >= 8, "K_us on {steering_cars} cars");
        if !wander {
            // Without the gyro the steering sets the yaw rate, and its
            // calibration (with g) matters: measured 13.790 → 4.366 m (the
            // offsets of 1–3° uncalibrated).
            println!(
                "without the gyro: paper {:.3} m, calibrated steering and slip {:.3} m",
                no_gyro[0], no_gyro[1]
            );
            assert!(no_gyro[1] < 0.4 * no_gyro[0], "{no_gyro:?}");
        }
        for (k, name) in ["ratio", "offset", "K_us"].iter().enumerate() {
            assert!(
                steering_within[k] as f64 >= 0.9 * steering_cars as f64,
                "{name}: {} of {steering_cars} within 3σ",
                steering_within[k]
            );
        }
    }
}
