//! TedriS end to end on the real Clearpath Husky bag
//! (`/work/shared/data/husky-gps-bag/husky_gps.bag`, 395 s at about 1 m/s, SBAS
//! GNSS with 0.9 m noise at 2.5 Hz, wheel odometry at 10 Hz, IMU gyro): train on
//! the first half with the gyro reference (the Husky's GNSS has no course), then
//! blank GNSS for 30 s and 60 s in the second half and measure the error against
//! the hidden fixes. The bag is required: the test fails when it is absent.
//!
//! `cargo test --release -p deadreckon-tedris --test husky_bag -- --nocapture`

use deadreckon_tedris::{
    run_outages_with, train, Outage, OutageError, ReferenceSource, RunOptions, TedrisConfig,
};

const BAG: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/husky-gps-bag/husky_gps.bag"
);

fn run(source: ReferenceSource, cfg: TedrisConfig, rel_outages: &[(f64, f64)]) -> Vec<OutageError> {
    assert!(
        std::path::Path::new(BAG).exists(),
        "{BAG} not found: the shared data must sit beside the project"
    );
    let (drive, _) = deadreckon_ros::read_log(BAG, &deadreckon_ros::Mapping::husky()).unwrap();
    let (t0, t1) = drive.time_span().unwrap();
    let half = 0.5 * (t0 + t1);
    let (model, _) = train(&drive.time_range(None, Some(half)), cfg, Some(source)).unwrap();
    let outages: Vec<Outage> = rel_outages
        .iter()
        .map(|&(a, b)| Outage {
            start_s: half + a,
            end_s: half + b,
        })
        .collect();
    let mut errs = Vec::new();
    // One outage per run, so that each starts from a machine anchored to GNSS.
    for o in &outages {
        let r = run_outages_with(
            &drive,
            &model,
            std::slice::from_ref(o),
            &RunOptions {
                source: Some(source),
                threshold_m: None,
            },
        )
        .unwrap();
        assert_eq!(r.reference.name(), "gnss");
        let e = r.outages[0].clone();
        eprintln!(
            "husky {source:?} (lag {}): outage [{:.0}, {:.0}) s after the half: mean {:.2} m, max {:.2} m, final {:.2} m ({} fixes; refits {} accepted, {} refused)",
            model.lag_samples,
            o.start_s - half,
            o.end_s - half,
            e.mean_error_m(),
            e.max_error_m(),
            e.final_error_m(),
            e.result.points(),
            r.machine.accepted_refits(),
            r.machine.refused_refits()
        );
        errs.push(e);
    }
    errs
}

const OUT_30: [(f64, f64); 5] = [
    (5.0, 35.0),
    (45.0, 75.0),
    (85.0, 115.0),
    (125.0, 155.0),
    (160.0, 190.0),
];
const OUT_60: [(f64, f64); 3] = [(5.0, 65.0), (65.0, 125.0), (125.0, 185.0)];

#[test]
fn husky_gyro_reference_30_and_60_s_outages() {
    let e30 = run(ReferenceSource::Gyro, TedrisConfig::robot(), &OUT_30);
    let e60 = run(ReferenceSource::Gyro, TedrisConfig::robot(), &OUT_60);
    // No course on the Husky: the automatic reference is the gyro.
    let (drive, _) = deadreckon_ros::read_log(BAG, &deadreckon_ros::Mapping::husky()).unwrap();
    assert_eq!(
        ReferenceSource::auto(&drive).unwrap(),
        ReferenceSource::Gyro
    );
    let mean = |e: &[OutageError]| e.iter().map(|o| o.mean_error_m()).sum::<f64>() / e.len() as f64;
    eprintln!(
        "husky gyro: 30 s outages mean {:.2} m, 60 s outages mean {:.2} m",
        mean(&e30),
        mean(&e60)
    );
    // Measured (against fixes with 0.9 m noise): 30 s means 0.63–2.10 m (max 4.38 m),
    // 60 s means 0.77–2.39 m (max 4.70 m); averages 1.41 m (30 s) and 1.48 m
    // (60 s). Bounds: the largest measured + 25% (3.0 m mean, 6.0 m max) and
    // the averages + 25% (1.9 m). The 60 s target is 2.30 m per window:
    // [125, 185) is above it, by the DCF it starts with (crate docs, "Measured
    // on the simulator": 2.34 m before the held-back calibration, a difference
    // not significant against the fixes' noise).
    for e in e30.iter().chain(&e60) {
        assert!(
            e.result.points() > 50 && e.predicted_fraction > 0.95,
            "{e:?}"
        );
        assert!(e.mean_error_m() < 3.0, "{e:?}");
        assert!(e.max_error_m() < 6.0, "{e:?}");
    }
    assert!(mean(&e30) < 1.9 && mean(&e60) < 1.9);
}

#[test]
fn husky_fix_track_reference_is_refused_by_the_physical_acceptance() {
    // The course from chords between fixes is too noisy at 1 m/s for the block
    // regression (cross-correlation peak about 0.06). This test once ran the
    // model it gave (2.84–12.13 m mean, 21.17 m largest, over the 30 s
    // outages): its distance kind turned the wrong way (turn gain α1·track =
    // −0.385) with R² 0.038, the baseline kind 5.3 times too much (R² −1.13),
    // and the cross-correlation peak was 0.196 where the turning of the
    // wheels and of the chords should give 0.517 (0.38 of it: above
    // `tuning::MIN_CCF_SHARE`, 0.35). The physical acceptance
    // (issue 35, `deadreckon_tedris::acceptance`) now refuses it, and says
    // which checks failed and what to do.
    let cfg = TedrisConfig {
        min_course_speed_mps: 0.3,
        init_s: 60.0,
        required_bins: 0,
        min_ccf_peak: 0.0,
        ..TedrisConfig::default()
    };
    let (drive, _) = deadreckon_ros::read_log(BAG, &deadreckon_ros::Mapping::husky()).unwrap();
    let (t0, t1) = drive.time_span().unwrap();
    let half = 0.5 * (t0 + t1);
    let err = train(
        &drive.time_range(None, Some(half)),
        cfg,
        Some(ReferenceSource::GnssTrack),
    )
    .expect_err("a model turning the wrong way is refused");
    let text = err.to_string();
    for what in ["turn gain", "what to do"] {
        assert!(text.contains(what), "{what}: {text}");
    }
}
