use super::*;

fn drive(n: usize) -> DiffDriveDrive {
    DiffDriveDrive {
        samples: (0..n)
            .map(|i| {
                let t = i as f64 * 0.1;
                DiffDriveSample {
                    t_s: t,
                    v_mps: 0.9 + 0.3 * (0.1 * t).sin()
                        - if (40.0..50.0).contains(&t) { 1.5 } else { 0.0 },
                    yaw_rate_rps: 0.2 * (0.05 * t).cos(),
                }
            })
            .collect(),
        fixes: Vec::new(),
        yaw_source: YawSource::Gyro,
    }
}

#[test]
fn antenna_jacobian_matches_finite_differences() {
    let d = drive(300);
    let p = [1.03, 0.97, 0.004, 0.3, -0.2];
    let tr = d.local_track(&p, 20, 280, true);
    for k in [1, 100, 260] {
        for q in 0..N_PARAMS {
            let h = 1e-6;
            let (mut hi, mut lo) = (p, p);
            hi[q] += h;
            lo[q] -= h;
            let (a, b) = (
                d.local_track(&hi, 20, 280, false),
                d.local_track(&lo, 20, 280, false),
            );
            for r in 0..2 {
                let fd = (a[k].0[r] - b[k].0[r]) / (2.0 * h);
                assert!(
                    (tr[k].1[r][q] - fd).abs() < 1e-6 * fd.abs().max(1.0),
                    "sample {k}, row {r}, d/d{}: {} vs {fd}",
                    NAMES[q],
                    tr[k].1[r][q]
                );
            }
        }
    }
}

#[test]
fn align_recovers_a_rigid_transform() {
    let p = [[0.0, 0.0], [1.0, 0.0], [2.0, 1.0], [0.5, -3.0]];
    let (th, t) = (0.7f64, [3.0, -1.0]);
    let q: Vec<[f64; 2]> = p
        .iter()
        .map(|v| {
            [
                t[0] + th.cos() * v[0] - th.sin() * v[1],
                t[1] + th.sin() * v[0] + th.cos() * v[1],
            ]
        })
        .collect();
    let (th2, t2) = align(&p, &q).unwrap();
    assert!(
        (th2 - th).abs() < 1e-12 && (t2[0] - t[0]).abs() < 1e-12 && (t2[1] - t[1]).abs() < 1e-12
    );
    assert!(align(&p[..1], &q[..1]).is_none());
}

#[test]
fn calibration_recovers_simulated_scales_bias_and_antenna() {
    // Fixes from the true parameters with a deterministic wiggle as noise.
    let mut d = drive(4000);
    let truth = [0.97, 1.04, 0.003, 0.25, -0.1];
    let tr = d.local_track(&truth, 0, 3999, false);
    d.fixes = (0..tr.len())
        .step_by(4)
        .map(|k| {
            let n = 0.05 * ((k * 7919) % 17) as f64 / 17.0;
            (
                tr[k].2 + 0.01,
                at(&tr, tr[k].2 + 0.01).0[0] + 5.0 + n,
                at(&tr, tr[k].2 + 0.01).0[1] - 2.0 - n,
            )
        })
        .collect();
    let c = calibrate_diff_drive(&d, &DiffDriveOptions::default()).unwrap();
    assert!(c.converged, "{c:?}");
    for (k, p) in c.params.iter().enumerate() {
        assert!(p.estimated, "{p:?}");
        assert!(
            (p.value - truth[k]).abs() < 0.02 * truth[k].abs().max(0.1),
            "{p:?} vs {}",
            truth[k]
        );
    }
    let ev = evaluate_diff_drive(&d, &c.values(), 30.0, 10.0, 60.0, &OutageStart::Align)
        .unwrap()
        .outages;
    let nominal = evaluate_diff_drive(
        &d,
        &DiffDriveDrive::nominal(),
        30.0,
        10.0,
        60.0,
        &OutageStart::Align,
    )
    .unwrap()
    .outages;
    assert!(
        ev.final_error().mean < 0.1 * nominal.final_error().mean,
        "{} vs {}",
        ev.final_error().mean,
        nominal.final_error().mean
    );
    // Zero windows above an impossible threshold: nothing estimated.
    let c = calibrate_diff_drive(
        &d,
        &DiffDriveOptions {
            min_speed_mps: 50.0,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(!c.converged && c.params.iter().all(|p| !p.estimated && p.reason.is_some()));
}
