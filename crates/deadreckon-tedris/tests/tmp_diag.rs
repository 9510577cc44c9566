use deadreckon_sim::{simulate, Scenario};
use deadreckon_tedris::*;
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
    let m = r.machine.model().unwrap();
    eprintln!(
        "dcf {:e} gain {} centre {:?} sigma {:e} beta0 {:?}",
        m.dcf_rad,
        m.turn_gain,
        m.straight_omega,
        m.straight_sigma_m,
        m.chosen_fit().beta(0)
    );
    let pts: Vec<_> = r
        .track
        .points
        .iter()
        .filter(|p| p.t_s >= 540.0 && p.t_s < 570.0)
        .collect();
    let mr = pts.iter().map(|p| p.yaw_rate_rps).sum::<f64>() / pts.len() as f64;
    let frac0 =
        pts.iter().filter(|p| p.yaw_rate_rps.abs() < 1e-3).count() as f64 / pts.len() as f64;
    eprintln!("mean predicted rate 540-570: {mr:e} rad/s; fraction |rate|<1e-3: {frac0}");
    let ytr =
        deadreckon_core::angle::unwrap(&run.truth.iter().map(|q| q.yaw_rad).collect::<Vec<_>>());
    for p in r
        .track
        .points
        .iter()
        .filter(|p| p.t_s >= start - 4.0 && p.t_s < start + 80.0)
        .step_by(50)
    {
        let k = run.truth.partition_point(|q| q.t_s < p.t_s);
        let q = &run.truth[k];
        eprintln!(
            "t {:.0} yaw err {:.4} pos err {:.2} v {:.1} truth yaw {:.3}",
            p.t_s,
            deadreckon_core::angle::diff(p.yaw_rad, q.yaw_rad),
            (p.east_m - q.east_m).hypot(p.north_m - q.north_m),
            q.speed_mps.unwrap(),
            ytr[k]
        );
    }
}
