//! What part of the dynamic family's `clocks` effect costs (issue 28):
//! each car calibrated on one 300 s drive (`calibration::calibrate`, the
//! default corrections) and evaluated on another (30 s outages every 10 s),
//! with the `clocks` effect alone and one part of it switched off:
//!
//! ```text
//! CLK_CARS=1,2,… CLK_VARIANT=drawn|off|nodrift|nojitter|nooffset|samedrift|wheeldrift0 \
//!   [CLK_GAP_Q=0.03] [CLK_WHICH=none|gnss] \
//!   cargo test --profile ci -p deadreckon-api --test clock_parts -- --ignored --nocapture
//! ```
//!
//! `CLK_GAP_Q` sets `Noise::gyro_gap_process_yaw_rate_rps` on both drives'
//! vehicles (the held yaw rate forced on, not chosen). Measured on cars
//! 1–30 (29: car 18's drive fails to simulate), mean final error: `off`
//! (no clocks) 0.432 m, `drawn` 0.584, `nojitter` 0.477, `nodrift` 0.764;
//! by wheels, `off` / `drawn` / `drawn` with `CLK_GAP_Q=0.03` / 0.1:
//! ticks 50 Hz 0.460 / 0.473 / 0.472 / 0.472, speeds 50 Hz 0.377 / 0.445 /
//! 0.445 / 0.445, speeds 100 Hz 0.303 / 0.549 / 0.399 / 0.514, ticks
//! 100 Hz 0.635 / 1.075 / 0.632 / 0.644. Without drift the 100 Hz tick cars
//! lost most (2.202 m): with the wheel and gyro clocks in a fixed phase up
//! to a quarter of the wheel epochs had no gyro reading. This chose
//! `model_options::GYRO_GAP_PROCESS_YAW_RATE_RPS`.
use deadreckon_api::corrections::stored_corrections;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::outage::evaluate;
use deadreckon_core::timing::Which;
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;
use rayon::prelude::*;

/// One car's mean final and start errors, m, and what the calibration
/// found (delays, filter counts).
fn user_path(
    car: &DynamicCar,
    effects: &Effects,
    which: Which,
    drive_s: f64,
) -> Result<(f64, f64, String), String> {
    let seed = car.base.seed;
    let mut cal = simulate(&car.drive(1000 + seed, drive_s, effects), 1000 + seed)
        .map_err(|e| e.to_string())?;
    let mut ev = simulate(&car.drive(2000 + seed, drive_s, effects), 2000 + seed)
        .map_err(|e| e.to_string())?;
    if let Some(q) = std::env::var("CLK_GAP_Q")
        .ok()
        .and_then(|q| q.parse::<f64>().ok())
    {
        cal.drive.vehicle.noise.gyro_gap_process_yaw_rate_rps = q;
        ev.drive.vehicle.noise.gyro_gap_process_yaw_rate_rps = q;
    }
    let c = deadreckon_api::calibration::calibrate(
        &cal.drive,
        &deadreckon_api::calibration::CalibrationRequest::with_corrections(which),
        "cal",
    )
    .map_err(|e| e.to_string())?;
    let stored = stored_corrections(&c.params_extra()).map_err(|e| format!("stored: {e}"))?;
    let d = &c.corrections;
    let dl = &d.delays;
    let delays = format!(
        "{:?}",
        [
            ("gyro", &dl.gyro),
            ("speed", &dl.speed),
            ("steer", &dl.steering),
            ("gnss", &dl.gnss)
        ]
        .iter()
        .map(|(n, x)| (
            *n,
            (x.delay_s * 1000.0).round(),
            (x.std_s * 1000.0).round(),
            format!("{:?}", x.status)
                .chars()
                .take(12)
                .collect::<String>()
        ))
        .collect::<Vec<_>>()
    );
    let drive = stored.apply(&ev.drive);
    let st = deadreckon_core::ekf::run(
        &drive,
        &c.calibration.estimate.params,
        &FilterOptions::default(),
        &mut (),
    )
    .map(|o| o.stats)
    .map_err(|e| e.to_string())?;
    let delays = format!(
        "{delays} epochs {} gyro {} superseded {} steer {} deferred {} gnss rej {}",
        st.epochs,
        st.gyro_updates,
        st.readings_superseded,
        st.steering_updates,
        st.steering_deferred,
        st.gnss_rejected
    );
    let out = evaluate(
        &drive,
        &c.calibration.estimate.params,
        30.0,
        10.0,
        5.0,
        &FilterOptions::default(),
    )
    .map_err(|e| e.to_string())?;
    let starts: Vec<f64> = out.windows.iter().map(|w| w.start_m()).collect();
    Ok((
        out.final_error().mean,
        starts.iter().sum::<f64>() / starts.len().max(1) as f64,
        delays,
    ))
}

/// The table of the module docs, one variant per run.
#[test]
#[ignore = "an experiment: 30 cars, about 2 min per variant on 2 cores"]
fn clock_parts() {
    let cars: Vec<u64> = std::env::var("CLK_CARS")
        .map(|s| s.split(',').map(|x| x.parse().unwrap()).collect())
        .unwrap_or((1..=6).collect());
    let variant = std::env::var("CLK_VARIANT").unwrap_or("drawn".into());
    let which = match std::env::var("CLK_WHICH").as_deref() {
        Ok("none") => Which::None,
        Ok("gnss") => Which::Gnss,
        _ => Which::Auto,
    };
    let effects = if variant == "off" {
        Effects::none()
    } else {
        Effects::only("clocks").unwrap()
    };
    let res: Vec<_> = cars
        .par_iter()
        .map(|&s| {
            let mut car = DynamicCar::draw(s);
            let c = &mut car.clocks;
            for k in c.each_mut() {
                match variant.as_str() {
                    "nodrift" => k.drift_ppm = 0.0,
                    "nojitter" => k.jitter_std_s = 0.0,
                    "nooffset" => k.offset_s = 0.0,
                    "onlydrift" => {
                        k.jitter_std_s = 0.0;
                        k.offset_s = 0.0
                    }
                    "wheeldrift0" => {}
                    _ => {}
                }
            }
            if variant == "wheeldrift0" {
                c.wheels.drift_ppm = 0.0;
            }
            if variant == "samedrift" {
                let w = c.wheels.drift_ppm;
                c.gyro.drift_ppm = w;
                c.speed.drift_ppm = w;
                c.steering.drift_ppm = w;
            }
            let kind = format!(
                "{:?} {} Hz wheels {:.0} ppm gyro {:.0} ppm off {:.1}/{:.1} ms",
                car.wheel_kind,
                car.wheel_rate_hz,
                car.clocks.wheels.drift_ppm,
                car.clocks.gyro.drift_ppm,
                car.clocks.wheels.offset_s * 1e3,
                car.clocks.gyro.offset_s * 1e3
            );
            (s, kind, user_path(&car, &effects, which, 300.0))
        })
        .collect();
    let mut sum = 0.0;
    let mut n = 0;
    for (s, kind, r) in &res {
        match r {
            Ok((f, st, d)) => {
                sum += f;
                n += 1;
                println!("{variant} car {s} [{kind}]: final {f:.3} start {st:.3} {d}");
            }
            Err(e) => println!("{variant} car {s}: {e}"),
        }
    }
    println!("{variant}: mean {:.3} over {n}", sum / n as f64);
}
