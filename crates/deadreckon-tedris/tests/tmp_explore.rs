// Temporary exploration (to be deleted).
use deadreckon_core::drive::Wheels;
use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::*;

fn oracle(run: &deadreckon_core::drive::Drive, start: f64, end: f64) -> f64 {
    let Wheels::Speeds(sp) = &run.wheels else {
        return f64::NAN;
    };
    let k = run.truth.partition_point(|q| q.t_s < start);
    let q0 = &run.truth[k];
    let (mut e, mut n, mut y) = (q0.east_m, q0.north_m, q0.yaw_rad);
    let mut errs = vec![];
    let mut last_t = q0.t_s;
    for w in sp.iter().filter(|w| w.t_s > q0.t_s && w.t_s < end) {
        let dt = w.t_s - last_t;
        last_t = w.t_s;
        let l = w.rl_mps * dt * 1.95195 / 1.95;
        let r = w.rr_mps * dt * 1.94805 / 1.95;
        let dy = (r - l) / 1.57;
        let d = 0.5 * (l + r);
        let mid = y + 0.5 * dy;
        e += d * mid.cos();
        n += d * mid.sin();
        y += dy;
        let j = run
            .truth
            .partition_point(|q| q.t_s < w.t_s)
            .min(run.truth.len() - 1);
        errs.push((e - run.truth[j].east_m).hypot(n - run.truth[j].north_m));
    }
    errs.iter().sum::<f64>() / errs.len() as f64
}

#[test]
#[ignore]
fn explore_car() {
    let sc = Scenario::builtin("tedris-car").unwrap();
    let cfgs: Vec<String> = std::env::var("CFGS")
        .unwrap_or("{}".into())
        .split('|')
        .map(String::from)
        .collect();
    let s0: u64 = std::env::var("S0")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let s1: u64 = std::env::var("S1")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(6);
    let wins: Vec<f64> = std::env::var("WINS")
        .unwrap_or("200,350,500".into())
        .split(',')
        .map(|v| v.parse().unwrap())
        .collect();
    let mut drives: Vec<_> = (s0..=s1)
        .map(|s| {
            (
                simulate(&sc, s).unwrap().drive,
                simulate(&sc, s + 100).unwrap().drive,
            )
        })
        .collect();
    if std::env::var("ANTREF").is_ok() {
        for (tr, _) in drives.iter_mut() {
            let truth = tr.truth.clone();
            for g in tr.gnss.iter_mut() {
                let j = truth
                    .partition_point(|q| q.t_s < g.t_s)
                    .min(truth.len() - 2)
                    .max(1);
                let rate = deadreckon_core::angle::diff(truth[j + 1].yaw_rad, truth[j - 1].yaw_rad)
                    / (truth[j + 1].t_s - truth[j - 1].t_s);
                let v = truth[j].speed_mps.unwrap();
                if g.course_deg.is_some() {
                    g.course_deg = Some(deadreckon_core::drive::yaw_rad_to_course_deg(
                        truth[j].yaw_rad
                            + (std::env::var("LSCALE").map_or(1.0, |v| v.parse::<f64>().unwrap())
                                * rate
                                / v)
                                .atan(),
                    ));
                }
            }
        }
    }
    if std::env::var("TRUTHREF").is_ok() {
        for (tr, _) in drives.iter_mut() {
            tr.vehicle.gnss_lever_arm_m = 0.0;
            let truth = tr.truth.clone();
            for g in tr.gnss.iter_mut() {
                let j = truth
                    .partition_point(|q| q.t_s < g.t_s)
                    .min(truth.len() - 1);
                if g.course_deg.is_some() {
                    g.course_deg = Some(deadreckon_core::drive::yaw_rad_to_course_deg(
                        truth[j].yaw_rad,
                    ));
                }
            }
        }
    }
    if std::env::var("ORACLE").is_ok() {
        let mut all = vec![];
        for (_, run) in &drives {
            for &w in &wins {
                all.push(oracle(run, w, w + 80.0));
            }
        }
        eprintln!(
            "oracle: mean {:.2} all {:?}",
            all.iter().sum::<f64>() / all.len() as f64,
            all.iter()
                .map(|v| (v * 10.0).round() / 10.0)
                .collect::<Vec<_>>()
        );
        eprintln!("drive length {:.0}", drives[0].1.truth.last().unwrap().t_s);
    }
    for c in &cfgs {
        let cfg: TedrisConfig = serde_json::from_str(c).unwrap();
        let mut all = vec![];
        let mut per_seed = vec![];
        for (tr, run) in &drives {
            let (model, _) = train(tr, cfg.clone(), None).unwrap();
            let mut ss = vec![];
            for &start in &wins {
                let o = Outage {
                    start_s: start,
                    end_s: start + 80.0,
                };
                let r = run_outages_with(run, &model, &[o], &RunOptions::default()).unwrap();
                ss.push(r.outages[0].mean_error_m);
                all.push(r.outages[0].mean_error_m);
            }
            per_seed.push(ss.iter().sum::<f64>() / ss.len() as f64);
            if std::env::var("VERB").is_ok() {
                let f = model.chosen_fit();
                eprintln!(
                    "  chosen {:?} lag {} beta {:?} dcf {:e} gain {} so {:?} sig {:e}",
                    model.chosen,
                    model.lag_samples,
                    f.global_beta,
                    model.dcf_rad,
                    model.turn_gain,
                    model.straight_omega,
                    model.straight_sigma_m
                );
            }
        }
        let mean = all.iter().sum::<f64>() / all.len() as f64;
        let mut s = all.clone();
        s.sort_by(f64::total_cmp);
        eprintln!(
            "{c}: mean {mean:.2} median {:.2} max {:.2} seeds {:?} all {:?}",
            s[s.len() / 2],
            s[s.len() - 1],
            per_seed
                .iter()
                .map(|v| (v * 100.0).round() / 100.0)
                .collect::<Vec<_>>(),
            all.iter()
                .map(|v| (v * 10.0).round() / 10.0)
                .collect::<Vec<_>>()
        );
    }
}

#[test]
#[ignore]
fn diag() {
    let sc = Scenario::builtin("tedris-car").unwrap();
    let seed: u64 = std::env::var("SEED").unwrap().parse().unwrap();
    let start: f64 = std::env::var("START").unwrap().parse().unwrap();
    let cfg: TedrisConfig = serde_json::from_str(&std::env::var("CFG").unwrap()).unwrap();
    let (tr, run) = (
        simulate(&sc, seed).unwrap().drive,
        simulate(&sc, seed + 100).unwrap().drive,
    );
    let (model, _) = train(&tr, cfg, None).unwrap();
    let r = run_outages_with(
        &run,
        &model,
        &[Outage {
            start_s: start,
            end_s: start + 80.0,
        }],
        &RunOptions::default(),
    )
    .unwrap();
    eprintln!(
        "mean err {:.2} oracle {:.2}",
        r.outages[0].mean_error_m,
        oracle(&run, start, start + 80.0)
    );
    let m = r.machine.model().unwrap();
    eprintln!(
        "end: beta {:?} dcf {:e} gain {}",
        m.chosen_fit().global_beta,
        m.dcf_rad,
        m.turn_gain
    );
    let mut last_yaw_truth = None;
    for p in r
        .track
        .points
        .iter()
        .filter(|p| p.t_s >= start - 10.0 && p.t_s < start + 80.0)
        .step_by(50)
    {
        let k = run.truth.partition_point(|q| q.t_s < p.t_s);
        let q = &run.truth[k];
        let dy = last_yaw_truth.map_or(0.0, |l: f64| deadreckon_core::angle::diff(q.yaw_rad, l));
        last_yaw_truth = Some(q.yaw_rad);
        eprintln!(
            "t {:.0} yaw err {:.4} pos err {:.2} v {:.1} dyaw {:.3}",
            p.t_s,
            deadreckon_core::angle::diff(p.yaw_rad, q.yaw_rad),
            (p.east_m - q.east_m).hypot(p.north_m - q.north_m),
            q.speed_mps.unwrap(),
            dy
        );
    }
}

#[test]
#[ignore]
fn diag2() {
    use deadreckon_tedris::input::{drive_input, Event};
    let sc = Scenario::builtin("tedris-car").unwrap();
    let seed: u64 = std::env::var("SEED").unwrap().parse().unwrap();
    let start: f64 = std::env::var("START").unwrap().parse().unwrap();
    let cfg: TedrisConfig = serde_json::from_str(&std::env::var("CFG").unwrap()).unwrap();
    let (tr, run) = (
        simulate(&sc, seed).unwrap().drive,
        simulate(&sc, seed + 100).unwrap().drive,
    );
    let (model, _) = train(&tr, cfg, None).unwrap();
    eprintln!(
        "trained: beta {:?} dcf {:e} dcf0 {:e} bound {:e} gain {} corr {:?}",
        model.chosen_fit().global_beta,
        model.dcf_rad,
        model.dcf0_rad,
        model.dcf_bound_rad,
        model.turn_gain,
        model.chosen_fit().correction()
    );
    let input = drive_input(&run, None, &[(start, start + 80.0)]).unwrap();
    let mut m = Tedris::with_model(model, input.geometry).unwrap();
    let mut next_print = 0.0;
    for e in &input.events {
        if e.t_s() > start + 1.0 {
            break;
        }
        match e {
            Event::Wheel(w) => {
                let _ = m.push_wheel(*w);
            }
            Event::Heading(h) => {
                let _ = m.push_heading(*h);
            }
            Event::Fix(f) => {
                let _ = m.push_fix(*f);
            }
        }
        if e.t_s() >= next_print {
            next_print += 20.0;
            let md = m.model().unwrap();
            eprintln!(
                "t {:.0} phase {:?} beta {:?} dcf {:e} gain {}",
                e.t_s(),
                m.phase(),
                md.chosen_fit().repositories.get(&0),
                md.dcf_rad,
                md.turn_gain
            );
        }
    }
    let md = m.model().unwrap();
    eprintln!(
        "at start: phase {:?} repos {:?} dcf {:e} gain {}",
        m.phase(),
        md.chosen_fit().repositories,
        md.dcf_rad,
        md.turn_gain
    );
}
