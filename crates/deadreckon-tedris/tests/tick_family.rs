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
    let (mut st, mut sb, mut n) = (0.0, 0.0, 0);
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
        let eff = match std::env::var("EFFECTS").ok().as_deref() {
            Some("none") => Effects::none(),
            Some(x) if x.starts_with('-') => Effects::all_but(&x[1..]).unwrap(),
            Some(x) => Effects::only(x).unwrap(),
            None => Effects::all(),
        };
        let tr = simulate(&car.drive(1000 + seed, 900.0, &eff), 1000 + seed)
            .unwrap()
            .drive;
        let te = simulate(&car.drive(2000 + seed, 500.0, &eff), 2000 + seed)
            .unwrap()
            .drive;
        let t0 = std::time::Instant::now();
        let mut c = TedrisConfig::default();
        if let Ok(m) = std::env::var("MODEL") {
            c.model = serde_json::from_str(&format!("\"{m}\"")).unwrap();
        }
        let (model, _) = train(&tr, c, None).unwrap();
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
            "  blocks {:?}",
            model.blocks.map(|b| b.describe(model.sample_period_s))
        );
        if std::env::var("ACC").is_ok() {
            eprintln!("  acceptance {:?}", model.acceptance);
        }
        let b = Baseline::fit_blocks(&tr, 2.0).unwrap();
        let e = &car.base.errors;
        let tr_m = car.base.vehicle.track_rear_m;
        eprintln!("  truth per metre {:.3e} rad/m; tedris dcf_d {:.3e} (std {:?}) gain {:.4}; baseline b {:.3e}", (e.circumference_rr_m - e.circumference_rl_m) / (0.5 * (e.circumference_rr_m + e.circumference_rl_m)) / tr_m, model.dcf_distance_rad_per_m, model.dcf_distance_std_rad_per_m, model.turn_gain, b.per_metre_rad);
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
            let m = r.machine.model().unwrap();
            if std::env::var("DIAG")
                .ok()
                .and_then(|v| v.parse::<f64>().ok())
                == Some(s)
            {
                let mut next = s;
                for p in &r.track.points {
                    if p.t_s >= next && p.t_s < s + 81.0 {
                        let i = te
                            .truth
                            .partition_point(|q| q.t_s < p.t_s)
                            .min(te.truth.len() - 1);
                        let q = &te.truth[i];
                        let dy = deadreckon_core::angle::wrap(p.yaw_rad - q.yaw_rad);
                        eprintln!("    t {:.0}: truth yaw {:+.3} yaw err {:+.4} rad, pos err {:.2} m, speed {:.1}", p.t_s, q.yaw_rad, dy, (p.east_m - q.east_m).hypot(p.north_m - q.north_m), p.speed_mps);
                        next += 5.0;
                    }
                }
            }
            st += r.outages[0].mean_error_m();
            sb += e.mean_error_m();
            n += 1;
            eprintln!("  [{s}] tedris {:.2} m (max {:.2}), block baseline {:.2} m (end: {:?} {} gain {:.3} dcf_d {:.2e} scale {:.4}; alarms {} refits {}/{})", r.outages[0].mean_error_m(), r.outages[0].max_error_m(), e.mean_error_m(), m.chosen, m.chosen_fit().correction().label(), m.turn_gain, m.dcf_distance_rad_per_m, m.distance_scale.value, r.machine.model_alarms(), r.machine.accepted_refits(), r.machine.refused_refits());
        }
    }
    eprintln!(
        "mean tedris {:.2} m, block baseline {:.2} m over {n}",
        st / n as f64,
        sb / n as f64
    );
}
