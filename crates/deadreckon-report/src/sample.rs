//! A synthetic [`ReportInput`] with every section filled, for previews, examples
//! and tests of the report itself. The numbers imitate the papers' tables; the
//! tracks are made up (deterministic, no estimator involved).

use std::f64::consts::{PI, TAU};

use crate::model::*;

/// A small deterministic generator (xorshift64*) with Gaussian draws (Box–Muller).
struct Noise(u64);

impl Noise {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let v = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        ((v >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (TAU * v).cos()
    }
}

fn params(b: f64, a: f64, c: [f64; 4]) -> Params {
    Params::from_array([b, a, c[0], c[1], c[2], c[3]])
}

/// A synthetic report input for a drive of `duration_s` seconds (wheels at 50 Hz,
/// GNSS at 10 Hz), with every section present.
pub fn sample_input(duration_s: f64) -> ReportInput {
    let mut rng = Noise(0x9e37_79b9_7f4a_7c15);
    let t0 = 1000.0;
    let wheel_hz = 50.0;
    let n = (duration_s * wheel_hz).max(2.0) as usize;
    let t: Vec<f64> = (0..n).map(|i| t0 + i as f64 / wheel_hz).collect();
    // A closed drive over a few kilometres: a Lissajous-like loop.
    let period = 900.0;
    let truth_at = |s: f64| {
        let w = TAU * s / period;
        (
            1500.0 * w.sin() + 200.0 * (3.0 * w).sin(),
            800.0 * (2.0 * w).sin() + 150.0 * w.cos(),
        )
    };
    let truth: Vec<(f64, f64)> = t.iter().map(|&s| truth_at(s - t0)).collect();
    let path = |f: &mut dyn FnMut(usize, (f64, f64)) -> (f64, f64)| {
        let (e, nn): (Vec<f64>, Vec<f64>) = truth.iter().enumerate().map(|(i, p)| f(i, *p)).unzip();
        EnPath {
            east_m: e,
            north_m: nn,
            t_s: t.clone(),
        }
    };
    // Dead reckoning drifts by a slowly growing rotation and scale about the start.
    let dr = |yaw_rate: f64, scale: f64| {
        let start = truth[0];
        path(&mut |i, (e, nn)| {
            let a = yaw_rate * i as f64 / wheel_hz;
            let (de, dn) = ((e - start.0) * scale, (nn - start.1) * scale);
            (
                start.0 + de * a.cos() - dn * a.sin(),
                start.1 + de * a.sin() + dn * a.cos(),
            )
        })
    };
    let jitter = |s: f64| {
        let mut r = Noise(rng.0 ^ (s.to_bits()));
        path(&mut |_, (e, nn)| (e + s * r.gauss(), nn + s * r.gauss()))
    };
    let filtered = jitter(0.4);
    let smoothed = jitter(0.1);
    // A GNSS outage of 5 % of the drive at 40 % of it (a tunnel).
    let gap = (0.40 * n as f64) as usize..(0.45 * n as f64) as usize;
    let gnss_idx: Vec<usize> = (0..n).step_by(5).filter(|i| !gap.contains(i)).collect();
    let mut gnss = EnPath::default();
    let mut gated = EnPath::default();
    for (k, &i) in gnss_idx.iter().enumerate() {
        let (e, nn) = truth[i];
        if k % 997 == 500 {
            gated.east_m.push(e + 25.0 + 5.0 * rng.gauss());
            gated.north_m.push(nn - 18.0 + 5.0 * rng.gauss());
            gated.t_s.push(t[i]);
        } else {
            gnss.east_m.push(e + 1.5 * rng.gauss());
            gnss.north_m.push(nn + 1.5 * rng.gauss());
            gnss.t_s.push(t[i]);
        }
    }
    let distance: f64 = truth
        .windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum();

    let header = Header {
        drive_name: "synthetic-loop".into(),
        duration_s: Some(duration_s),
        distance_m: Some(distance),
        start_t_s: Some(t0),
        streams: vec![
            StreamInfo {
                name: "wheel_ticks".into(),
                samples: n,
                rate_hz: Some(wheel_hz),
            },
            StreamInfo {
                name: "yaw_rate".into(),
                samples: n,
                rate_hz: Some(wheel_hz),
            },
            StreamInfo {
                name: "speed".into(),
                samples: n / 2,
                rate_hz: Some(25.0),
            },
            StreamInfo {
                name: "steering".into(),
                samples: n / 2,
                rate_hz: Some(25.0),
            },
            StreamInfo {
                name: "gnss".into(),
                samples: gnss_idx.len(),
                rate_hz: Some(10.0),
            },
            StreamInfo {
                name: "truth".into(),
                samples: n,
                rate_hz: Some(wheel_hz),
            },
        ],
        inputs: vec![NamedText {
            name: "params".into(),
            value: "params.toml".into(),
        }],
    };
    let trajectories = Trajectories {
        truth: Some(path(&mut |_, p| p)),
        gnss: Some(gnss),
        gnss_gated: Some(gated),
        filtered: Some(filtered),
        smoothed: Some(smoothed),
        aided_with: Some("RTS".into()),
        dead_reckoned: vec![
            MethodPath {
                method: "nominal".into(),
                path: dr(0.003 / 60.0, 1.004),
            },
            MethodPath {
                method: "ZUPT".into(),
                path: dr(0.001 / 60.0, 1.002),
            },
            MethodPath {
                method: "RTS".into(),
                path: dr(0.0003 / 60.0, 1.0005),
            },
            MethodPath {
                method: "truth".into(),
                path: dr(0.0002 / 60.0, 1.0003),
            },
        ],
    };

    let gt = params(-0.00298, 0.987, [1.9134, 1.9129, 1.9166, 1.9164]);
    let ours = params(-0.00279, 1.0, [1.9177, 1.9159, 1.9198, 1.9197]);
    let iterations: Vec<Params> = (0..7)
        .map(|k| {
            let f = (-(k as f64) / 1.5).exp();
            let nominal = [1.92; 4];
            let o = ours.to_array();
            let c = |j: usize| o[2 + j] + f * (nominal[j] - o[2 + j]);
            params(o[0] * (1.0 - f), o[1] + f * 0.01, [c(0), c(1), c(2), c(3)])
        })
        .collect();
    let iteration_std: Vec<Params> = (0..7)
        .map(|k| {
            let f = 1.0 + 2.0 * (-(k as f64)).exp();
            params(4e-5 * f, 0.002 * f, [6e-4 * f; 4])
        })
        .collect();
    let calibration = Calibration {
        rows: vec![
            CalibrationRow {
                method: "truth".into(),
                values: gt,
                std: None,
            },
            CalibrationRow {
                method: "RTS".into(),
                values: ours,
                std: Some(params(4e-5, 0.002, [6e-4, 6e-4, 5e-4, 5e-4])),
            },
            CalibrationRow {
                method: "ZUPT".into(),
                values: params(-0.00194, 1.0, [1.92; 4]),
                std: Some(params(1.2e-4, 0.0, [0.0; 4])),
            },
            CalibrationRow {
                method: "nominal".into(),
                values: params(0.0, 1.0, [1.92; 4]),
                std: None,
            },
        ],
        iterated_method: "RTS".into(),
        iterations,
        iteration_std,
        corrections: Some(Corrections {
            source: "estimated on this drive (--corrections gnss)".into(),
            rows: vec![
                CorrectionRow {
                    what: "GNSS delay".into(),
                    unit: "s".into(),
                    value: Some(0.1078),
                    std: Some(0.0069),
                    status: "estimated, applied".into(),
                },
                CorrectionRow {
                    what: "steering delay".into(),
                    unit: "s".into(),
                    value: None,
                    std: None,
                    status: "not estimated: too little excitation".into(),
                },
            ],
        }),
    };

    let mut drift_method = |name: &str, mean: f64, std: f64, reach: f64| DriftMethod {
        method: name.into(),
        error_after_segment_m: (0..(distance / 100.0) as usize)
            .map(|_| (mean + std * rng.gauss()).abs())
            .collect(),
        distance_to_threshold_m: (0..60)
            .map(|_| (reach * (1.0 + 0.35 * rng.gauss())).max(5.0))
            .collect(),
    };
    let drift = Drift {
        segment_m: 100.0,
        threshold_m: 1.0,
        methods: vec![
            drift_method("truth", 0.79, 0.39, 160.0),
            drift_method("RTS", 0.81, 0.51, 150.0),
            drift_method("ZUPT", 0.93, 0.57, 120.0),
            drift_method("nominal", 2.4, 1.1, 45.0),
        ],
    };

    let gyro_innov: Vec<f64> = (0..n).map(|_| 0.003 * rng.gauss()).collect();
    let tg: Vec<f64> = gnss_idx.iter().map(|&i| t[i]).collect();
    let ng = tg.len();
    let gate = 13.815_510_557_964_274;
    let g_gated: Vec<bool> = (0..ng).map(|k| k % 997 == 500).collect();
    let mut g_innov = |s: f64| -> Vec<f64> {
        (0..ng)
            .map(|k| {
                if g_gated[k] {
                    20.0 + 5.0 * rng.gauss()
                } else {
                    s * rng.gauss()
                }
            })
            .collect()
    };
    let ge = g_innov(1.6);
    let gn = g_innov(1.6);
    let g_nis: Vec<f64> = ge
        .iter()
        .zip(&gn)
        .map(|(e, nn)| (e * e + nn * nn) / (1.6 * 1.6))
        .collect();
    let w_nis: Vec<f64> = (0..n)
        .map(|_| (0..4).map(|_| rng.gauss().powi(2)).sum::<f64>() * 1.1)
        .collect();
    let health = FilterHealth {
        innovations: vec![
            InnovationSeries {
                sensor: "gyro".into(),
                unit: "rad/s".into(),
                t_s: t.clone(),
                innovation: gyro_innov,
                std: vec![0.0031; n],
                gated: Vec::new(),
            },
            InnovationSeries {
                sensor: "GNSS east".into(),
                unit: "m".into(),
                t_s: tg.clone(),
                innovation: ge,
                std: (0..ng)
                    .map(|k| 1.6 + 0.3 * (k as f64 / 300.0).sin())
                    .collect(),
                gated: g_gated.clone(),
            },
            InnovationSeries {
                sensor: "GNSS north".into(),
                unit: "m".into(),
                t_s: tg.clone(),
                innovation: gn,
                std: (0..ng)
                    .map(|k| 1.6 + 0.3 * (k as f64 / 300.0).sin())
                    .collect(),
                gated: g_gated.clone(),
            },
        ],
        nis: vec![
            NisSeries {
                sensor: "GNSS".into(),
                dof: 2,
                t_s: tg,
                nis: g_nis,
                gated: g_gated,
                gate_chi2: Some(gate),
            },
            NisSeries {
                sensor: "wheels".into(),
                dof: 4,
                t_s: t.clone(),
                nis: w_nis,
                gated: Vec::new(),
                gate_chi2: None,
            },
        ],
        nis_bound_probability: Some(0.95),
        ..Default::default()
    };

    let lag: Vec<i64> = (-30..=30).collect();
    let correlation: Vec<f64> = lag
        .iter()
        .map(|&l| {
            let d = (l as f64 + 2.4) / 6.0;
            0.95 * (-d * d).exp() + 0.03 * rng.gauss()
        })
        .collect();
    let train_n = (600.0 * 4.0) as usize;
    let tt: Vec<f64> = (0..train_n).map(|i| t0 + i as f64 / 4.0).collect();
    let heading: Vec<f64> = tt
        .iter()
        .map(|s| {
            let w = (s - t0) / 600.0;
            (PI / 2.0 + 3.0 * TAU * w + 0.8 * (TAU * 4.0 * w).sin()).rem_euclid(TAU) - PI
        })
        .collect();
    let training: Vec<f64> = heading
        .iter()
        .enumerate()
        .map(|(i, h)| h + 0.02 * (i as f64 / 200.0).sin() + 0.005 * rng.gauss())
        .collect();
    let index: Vec<i64> = (-8..=8).collect();
    let fill: Vec<u64> = index
        .iter()
        .map(|&k| (400.0 * (-(k as f64 / 4.0).powi(2)).exp()) as u64 + 12)
        .collect();
    let mut outage = |name: &str, len_s: f64, growth: f64| OutageRun {
        name: name.into(),
        series: ["TedriS", "RTS"]
            .iter()
            .enumerate()
            .map(|(m, method)| {
                let ts: Vec<f64> = (0..(len_s * 4.0) as usize)
                    .map(|i| 2000.0 + i as f64 / 4.0)
                    .collect();
                let g = growth * if m == 0 { 1.0 } else { 0.6 };
                let err = ts
                    .iter()
                    .map(|s| {
                        let x = s - 2000.0;
                        g * x * x / 1000.0 + 0.05 * rng.gauss().abs()
                    })
                    .collect();
                MethodSeries {
                    method: method.to_string(),
                    t_s: ts,
                    error_m: err,
                }
            })
            .collect(),
    };
    let tedris = Tedris {
        cross_correlation: Some(CrossCorrelation {
            lag,
            correlation,
            chosen_lag: Some(-2),
        }),
        models: vec![
            RegressionModel {
                name: "γ = α0 + α1·ω(t−2)".into(),
                coefficients: vec![
                    Coefficient {
                        name: "α0".into(),
                        estimate: 0.068529,
                        std_error: 0.003772,
                        t_value: 18.17,
                        p_value: 0.0,
                    },
                    Coefficient {
                        name: "α1".into(),
                        estimate: 2.251480,
                        std_error: 0.022151,
                        t_value: 101.64,
                        p_value: 0.0,
                    },
                ],
                statistics: vec![
                    NamedValue {
                        name: "R²".into(),
                        value: 0.912,
                    },
                    NamedValue {
                        name: "Box–Pierce p".into(),
                        value: 0.003,
                    },
                ],
            },
            RegressionModel {
                name: "with MA(2) residuals".into(),
                coefficients: vec![
                    Coefficient {
                        name: "MA2".into(),
                        estimate: 0.6333,
                        std_error: 0.0137,
                        t_value: 46.3037,
                        p_value: 0.0,
                    },
                    Coefficient {
                        name: "α0".into(),
                        estimate: 0.0,
                        std_error: 0.0001,
                        t_value: -0.2277,
                        p_value: 0.8199,
                    },
                    Coefficient {
                        name: "α1".into(),
                        estimate: 0.0492,
                        std_error: 0.0004,
                        t_value: 140.3375,
                        p_value: 0.0,
                    },
                ],
                statistics: vec![NamedValue {
                    name: "R²".into(),
                    value: 0.958,
                }],
            },
        ],
        gnss_heading_rad: Some(TimeSeries {
            t_s: tt.clone(),
            value: heading,
        }),
        training_heading_rad: Some(TimeSeries {
            t_s: tt,
            value: training,
        }),
        repositories: Some(Repositories {
            index,
            fill,
            min_fill: Some(20),
            max_fill: Some(400),
        }),
        outages: vec![
            outage("DR update", 60.0, 1.0),
            outage("outage 1", 80.0, 0.6),
            outage("outage 2", 85.0, 0.9),
        ],
        threshold_m: 1.0,
    };

    let mut final_errors = |scale: f64| -> Vec<f64> {
        (0..300)
            .map(|_| scale * (0.4 * rng.gauss()).exp())
            .collect()
    };
    let outages = OutageEvaluation {
        window_s: Some(30.0),
        methods: vec![
            MethodSample {
                method: "RTS".into(),
                final_error_m: final_errors(1.2),
            },
            MethodSample {
                method: "ZUPT".into(),
                final_error_m: final_errors(1.8),
            },
            MethodSample {
                method: "TedriS".into(),
                final_error_m: final_errors(2.6),
            },
        ],
        bound: Some(sample_bound(&mut rng)),
    };

    ReportInput {
        header,
        footer: Footer {
            version: "0.1.0".into(),
            command_line:
                "deadreckon report drives/synthetic-loop --params params.toml --out report.html"
                    .into(),
        },
        trajectories: Some(trajectories),
        calibration: Some(calibration),
        drift: Some(drift),
        health: Some(health),
        tedris: Some(tedris),
        outages: Some(outages),
        kinematic: None,
        not_computed: vec![NotComputed {
            what: "ZUPT calibration".into(),
            reason: "insufficient data: no standstill of 2 s to take the gyro bias from".into(),
        }],
    }
}

/// Twenty 30 s windows of error growing with time in outage, and a bound
/// 2.45 times the error's standard deviation (a circle's 95 % radius).
fn sample_bound(rng: &mut Noise) -> OutageBound {
    let (mut time_s, mut error_m, mut bound_m) = (Vec::new(), Vec::new(), Vec::new());
    let mut within = 0;
    for _ in 0..20 {
        let t: Vec<f64> = (0..=60).map(|k| 0.5 * k as f64).collect();
        let scale = (0.3 * rng.gauss()).exp();
        let e: Vec<f64> = t
            .iter()
            .map(|t| scale * (0.3 + 0.02 * t * t / 30.0 + 0.05 * t))
            .collect();
        let b: Vec<f64> = t.iter().map(|t| 2.45 * (0.3 + 0.035 * t)).collect();
        within += usize::from(e.last() <= b.last());
        time_s.push(t);
        error_m.push(e);
        bound_m.push(b);
    }
    OutageBound {
        method: "RTS".into(),
        factor: "1.40 × the filter's 95 % radius".into(),
        time_s,
        error_m,
        bound_m,
        within,
        sharpness: 2.1,
    }
}
