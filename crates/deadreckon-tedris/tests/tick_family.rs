//! scratch
use deadreckon_sim::family::{DynamicCar, Effects};
use deadreckon_sim::simulate;
use deadreckon_tedris::baseline::Baseline;
use deadreckon_tedris::{run_outages, train, Outage, TedrisConfig};

#[test]
#[ignore]
fn scratch() {
    let seeds: Vec<u64> = std::env::var("SEEDS")
        .unwrap()
        .split(',')
        .map(|s| s.parse().unwrap())
        .collect();
    let plain = std::env::var("PLAIN").is_ok();
    for seed in seeds {
        let car = if plain {
            DynamicCar::draw(seed)
        } else {
            DynamicCar::draw_tick_counter(seed)
        };
        eprintln!(
            "car {seed}: {:?} {} teeth {} Hz track {:.3}",
            car.wheel_kind,
            car.base.vehicle.ticks_per_rev,
            car.wheel_rate_hz,
            car.base.vehicle.track_rear_m
        );
        let tr = simulate(&car.drive(1000 + seed, 900.0, &Effects::all()), 1000 + seed)
            .unwrap()
            .drive;
        let te = simulate(&car.drive(2000 + seed, 500.0, &Effects::all()), 2000 + seed)
            .unwrap()
            .drive;
        let t0 = std::time::Instant::now();
        let (model, _) = train(&tr, TedrisConfig::default(), None).unwrap();
        let f = model.chosen_fit();
        let a1 = f
            .global
            .coefficients
            .iter()
            .find(|c| c.name == "alpha1")
            .map(|c| c.estimate);
        eprintln!(
            "  trained in {:.1} s: kind {:?} alpha1 {:?} (x track {:?}) gain {} R2 {:.3} ccf {:.3}",
            t0.elapsed().as_secs_f64(),
            model.chosen,
            a1,
            a1.map(|a| a * car.base.vehicle.track_rear_m),
            model.turn_gain,
            f.global.r_squared,
            model.ccf.values.iter().copied().fold(f64::MIN, f64::max)
        );
        eprintln!(
            "  blocks {:?}\n  acceptance {:?}",
            model.blocks.map(|b| b.describe(model.sample_period_s)),
            model.acceptance
        );
        let b = Baseline::fit_blocks(&tr, 2.0).unwrap();
        eprintln!(
            "  block baseline k {:.3}",
            b.gain_rad_per_m * car.base.vehicle.track_rear_m
        );
        for s in [120.0, 200.0, 280.0, 360.0] {
            let o = Outage {
                start_s: s,
                end_s: s + 80.0,
            };
            let r = run_outages(&te, &model, &[o]).unwrap();
            let e = b.run_outage(&te, &o).unwrap();
            eprintln!(
                "  [{s}] tedris {:.2} m, block baseline {:.2} m",
                r.outages[0].mean_error_m(),
                e.mean_error_m()
            );
        }
    }
}
