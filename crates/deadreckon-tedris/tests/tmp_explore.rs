use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::*;
#[test]
#[ignore]
fn explore_car() {
    let sc = Scenario::builtin("tedris-car").unwrap();
    let cfgs: Vec<String> = std::env::var("CFGS")
        .unwrap_or("{}".into())
        .split('|')
        .map(String::from)
        .collect();
    let seeds: u64 = std::env::var("SEEDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(4);
    let drives: Vec<_> = (1..=seeds)
        .map(|s| {
            (
                simulate(&sc, s).unwrap().drive,
                simulate(&sc, s + 100).unwrap().drive,
            )
        })
        .collect();
    for c in &cfgs {
        let cfg: TedrisConfig = serde_json::from_str(c).unwrap();
        let mut all = vec![];
        for (tr, run) in &drives {
            let (model, _) = train(tr, cfg.clone(), None).unwrap();
            for start in [200.0, 350.0, 500.0] {
                let o = Outage {
                    start_s: start,
                    end_s: start + 80.0,
                };
                let r = run_outages_with(run, &model, &[o], &RunOptions::default()).unwrap();
                all.push(r.outages[0].mean_error_m);
            }
        }
        let mean = all.iter().sum::<f64>() / all.len() as f64;
        let mut s = all.clone();
        s.sort_by(f64::total_cmp);
        eprintln!(
            "{c}: mean {mean:.2} median {:.2} max {:.2} all {:?}",
            s[s.len() / 2],
            s[s.len() - 1],
            all.iter()
                .map(|v| (v * 10.0).round() / 10.0)
                .collect::<Vec<_>>()
        );
    }
}
