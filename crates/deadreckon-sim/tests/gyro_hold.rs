//! A gyro a few milliseconds late must not hand the yaw rate to the steering
//! (issue 28, [`deadreckon_core::gyro_hold`]).
//!
//! Family cars with wheel speeds and gyro both at 100 Hz, the gyro's stamps
//! jittered (white, 2 ms: each ECU stamps on its own clock) and a steering
//! wheel at 100 Hz that reads 5° off straight ahead. 30 s outages every
//! 10 s with the true parameters (no calibration: the filter alone), with
//! and without the steering stream.

use deadreckon_core::drive::Drive;
use deadreckon_core::ekf::{FilterOptions, Timing};
use deadreckon_core::outage::evaluate;
use deadreckon_sim::family::CarFamily;
use deadreckon_sim::{simulate, SimOutput, SteeringSpec};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_pcg::Pcg64;

/// Car `seed`'s 300 s drive with a 100 Hz steering wheel 5° off and the
/// gyro's stamps jittered by `jitter_s` (white, seeded).
fn drive(seed: u64, jitter_s: f64) -> SimOutput {
    let car = CarFamily::draw(seed);
    let mut sc = car.drive(700 + seed, 300.0);
    sc.sensors.wheels.rate_hz = 100.0;
    sc.sensors.wheels.offset_s = 0.0;
    let g = sc.sensors.gyro.as_mut().expect("family gyro");
    g.offset_s = 0.0;
    // The receiver's latency and wander apart: the filter's yaw is what is measured.
    let r = sc.sensors.gnss.as_mut().expect("family GNSS");
    (r.latency_s, r.markov_std_m) = (0.0, 0.0);
    sc.sensors.steering = Some(SteeringSpec {
        rate_hz: 100.0,
        offset_s: 0.0,
        noise_std: 0.02,
        latency_s: 0.0,
        true_ratio: None,
        wheel_offset_rad: 5f64.to_radians(),
        clock: None,
    });
    let mut sim = simulate(&sc, 700 + seed).unwrap();
    if jitter_s > 0.0 {
        let mut r = Pcg64::seed_from_u64(seed);
        let n = Normal::new(0.0, jitter_s).unwrap();
        for g in &mut sim.drive.yaw_rate {
            g.t_s += n.sample(&mut r);
        }
        sim.drive.yaw_rate.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    }
    sim
}

fn mean_final(drive: &Drive, sim: &SimOutput, timing: Timing) -> f64 {
    let opts = FilterOptions {
        timing,
        ..FilterOptions::default()
    };
    evaluate(drive, &sim.truth_params, 30.0, 10.0, 5.0, &opts)
        .unwrap()
        .final_error()
        .mean
}

/// Regression: with the paper's timing each gyro reading was used at most
/// once, so the wheel rows that a jittered gyro reading missed took their
/// yaw rate from the steering, whose offset then turned the heading. Mean
/// final error of 30 s outages (the pull-away windows apart) before, jittered
/// gyro with steering / without / the unjittered drive with steering: car 1
/// 2.841 / 0.578 / 0.349 m, car 2 3.681 / 3.518 / 0.351 m, car 3 4.283 /
/// 2.153 / 0.239 m. With the steering waiting for the gyro: 0.619, 3.420
/// and 2.062 m with the steering (without it unchanged: 7.1 %, 2.8 %, 4.2 %
/// apart).
///
/// What the jitter still costs (car 2: 3.5 m against 0.35 m) is the wheels'
/// noise setting the yaw rate at those epochs: table I's yaw-rate process
/// noise (1 rad/s per 20 ms) lets any measurement set it, and these cars'
/// tone-ring jitter differenced at 100 Hz is above the filter's 0.05 m/s.
/// Per-reading timing with a physical yaw-rate process noise (0.03 rad/s per
/// 20 ms, speed 0.5 m/s) removes it here (jittered / unjittered 0.395 /
/// 0.365, 0.348 / 0.353, 0.267 / 0.245 m), but on the comma2k19 segment
/// calibrated on one half and evaluated on the other it gave 0.888 / 1.372 m
/// against the default's 0.807 / 0.511 m (median, the pull-away windows
/// apart), so it is not the default.
#[test]
fn a_late_gyro_reading_handed_the_yaw_rate_to_the_steering() {
    for seed in 1..=3 {
        let jittered = drive(seed, 0.002);
        let clean = drive(seed, 0.0);
        let mut no_steering = jittered.drive.clone();
        no_steering.steering.clear();
        let with = mean_final(&jittered.drive, &jittered, Timing::WheelEpochs);
        let without = mean_final(&no_steering, &jittered, Timing::WheelEpochs);
        let sync = mean_final(&clean.drive, &clean, Timing::WheelEpochs);
        println!(
            "car {seed}: mean final error, jittered gyro with steering {with:.3} m, without \
             {without:.3} m; unjittered with steering {sync:.3} m"
        );
        // Removing the steering changes the error by little (measured 7.1 %,
        // 2.8 %, 4.2 %; before, +392 %, +4.6 %, +99 %).
        assert!((with - without).abs() < 0.10 * without, "car {seed}");
        assert!(sync < with, "car {seed}: the jitter costs nothing?");
    }
}

/// Regression, per reading: a steering reading between two gyro readings
/// set the yaw rate (car 2: 6.118 m with the steering against 1.549 m
/// without); it now waits for the next gyro reading (1.527 m).
#[test]
fn per_reading_steering_waits_for_the_gyro() {
    let seed = 2;
    let jittered = drive(seed, 0.002);
    let mut no_steering = jittered.drive.clone();
    no_steering.steering.clear();
    let with = mean_final(&jittered.drive, &jittered, Timing::EachMeasurement);
    let without = mean_final(&no_steering, &jittered, Timing::EachMeasurement);
    println!("car {seed}, per reading: with steering {with:.3} m, without {without:.3} m");
    assert!((with - without).abs() < 0.03 * without);
}

/// Regression: at a wheel epoch whose gyro reading came a few milliseconds
/// late the wheels' speed difference over one 10 ms period set the yaw rate
/// (table I: 1 rad/s per 20 ms), and the heading kept its error: car 2
/// 3.518 m against 0.351 m unjittered (the test above, without the
/// steering). With the yaw rate held at those epochs
/// (`Noise::gyro_gap_process_yaw_rate_rps` at the candidate
/// `model_options::GYRO_GAP_PROCESS_YAW_RATE_RPS`), measured jittered
/// without / with the hold / unjittered: car 1 0.578 / 0.434 / 0.349 m,
/// car 2 3.518 / 1.383 / 0.351 m, car 3 2.153 / 0.694 / 0.239 m. A quarter
/// of these drives' wheel intervals have no gyro reading (2 ms of white
/// jitter on a 10 ms period, more than the dynamic family's ECUs have);
/// what the hold leaves is the wheels' noise that still reaches the yaw
/// rate at those epochs.
#[test]
fn a_late_gyro_reading_let_the_wheels_set_the_yaw_rate() {
    use deadreckon_core::model_options::{gyro_gap_share, GYRO_GAP_PROCESS_YAW_RATE_RPS};
    for seed in 1..=3 {
        let jittered = drive(seed, 0.002);
        let clean = drive(seed, 0.0);
        let share = gyro_gap_share(&jittered.drive);
        // 100 Hz wheels and gyro, 2 ms of jitter: a quarter of the wheel
        // intervals have no gyro reading (measured 0.248–0.251); none
        // without the jitter.
        assert!((0.2..0.3).contains(&share), "car {seed}: share {share}");
        assert_eq!(gyro_gap_share(&clean.drive), 0.0, "car {seed}");
        let mut held = jittered.drive.clone();
        held.steering.clear();
        held.vehicle.noise.gyro_gap_process_yaw_rate_rps = GYRO_GAP_PROCESS_YAW_RATE_RPS;
        let free = {
            let mut d = jittered.drive.clone();
            d.steering.clear();
            mean_final(&d, &jittered, Timing::WheelEpochs)
        };
        let with_hold = mean_final(&held, &jittered, Timing::WheelEpochs);
        let sync = mean_final(&clean.drive, &clean, Timing::WheelEpochs);
        println!(
            "car {seed}: gap share {share:.3}; jittered without the hold {free:.3} m, with it \
             {with_hold:.3} m; unjittered {sync:.3} m"
        );
        // Measured with / without the hold 0.75, 0.39, 0.32.
        assert!(
            with_hold < 0.8 * free,
            "car {seed}: {with_hold} against {free}"
        );
        assert!(
            with_hold < 1.5 && sync < with_hold,
            "car {seed}: {with_hold}, {sync}"
        );
    }
}
