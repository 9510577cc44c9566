//! How far the online learner (`deadreckon stream --learn`) has to drive before
//! its parameters come within the offline RTS calibration's error bounds (gyro
//! bias 5%, speed scale 0.3%, circumferences 0.1%) and stay there.
//!
//! ```sh
//! cargo run --release --example learn_convergence -- 8 101 102 103 104 105
//! ```
//!
//! The first argument is the number of laps of the built-in `calibration`
//! scenario; the others are simulator seeds (none of them used to tune anything:
//! the learner has no tuned constants beyond the offline calibration's priors).

use deadreckon_core::ekf::{DriveEvents, FilterOptions};
use deadreckon_core::online::{LearnTargets, Online, Start};
use deadreckon_core::Params;
use deadreckon_sim::{simulate, Scenario};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let laps: u32 = args.first().and_then(|a| a.parse().ok()).unwrap_or(4);
    let seeds: Vec<u64> = args.iter().skip(1).filter_map(|a| a.parse().ok()).collect();
    let seeds = if seeds.is_empty() {
        vec![101, 102, 103]
    } else {
        seeds
    };
    let bounds = [0.05, 0.003, 0.001, 0.001, 0.001, 0.001];
    println!(
        "seed  km_total  km_to_within_bounds (bias, scale, rho_FL, rho_FR, rho_RL, rho_RR, all)  km_to_valid  valid_at_end  calibrated_pct"
    );
    for seed in seeds {
        let sc = Scenario::builtin("calibration").unwrap().with_laps(laps);
        let sim = simulate(&sc, seed).unwrap();
        let d = sim.drive;
        let truth = sim.truth_params.to_array();
        let prior = deadreckon_core::calibrate::CalibrationOptions::default().prior_std;
        let mut o = Online::learning(
            &d.vehicle,
            &Params::nominal(&d.vehicle),
            &prior,
            &FilterOptions::default(),
            Start::Gnss,
        )
        .unwrap();
        // Distance from the filter's own speed, and the last distance at which
        // each parameter was outside its bound.
        let mut km = 0.0;
        let mut last_t: Option<f64> = None;
        let mut last_out = [0.0f64; 6];
        let mut valid_km: Option<f64> = None;
        let targets = LearnTargets::default();
        let mut pts = Vec::new();
        for ev in DriveEvents::all(&d) {
            pts.clear();
            o.push(ev, &mut |p| pts.push(p)).unwrap();
            for p in &pts {
                if let Some(t) = last_t {
                    km += p.speed_mps.abs() * (p.t_s - t) / 1000.0;
                }
                last_t = Some(p.t_s);
            }
            if pts.is_empty() {
                continue;
            }
            let l = o.learned(&targets).unwrap();
            if l.valid && valid_km.is_none() {
                valid_km = Some(km);
            }
            let e = l.params.to_array();
            for i in 0..6 {
                if ((e[i] - truth[i]) / truth[i]).abs() > bounds[i] {
                    last_out[i] = km;
                }
            }
        }
        let l = o.learned(&targets).unwrap();
        let all = last_out.iter().cloned().fold(0.0, f64::max);
        let cell = |x: f64| {
            if x >= km - 1e-9 {
                "never".to_string()
            } else {
                format!("{x:.2}")
            }
        };
        println!(
            "{seed:<5} {km:8.2}  {}  {:>6}  {:>5}  {:5.1}",
            last_out
                .iter()
                .chain(std::iter::once(&all))
                .map(|x| cell(*x))
                .collect::<Vec<_>>()
                .join(" "),
            valid_km.map_or("never".into(), |k| format!("{k:.2}")),
            l.valid,
            l.calibrated_pct
        );
    }
}
