//! Unit tests of the history statistics on hand-made estimates.

use super::*;

fn drive(j: usize, value: f64, std: f64) -> HistoryDrive {
    HistoryDrive {
        path: PathBuf::from(format!("d{j:02}")),
        recorded_at: None,
        value: [value; 6],
        std: [std; 6],
        estimated: [true, false, false, false, false, false],
    }
}

fn exact() -> HistoryOptions {
    HistoryOptions {
        alpha: 1e-3,
        tolerance: [0.0; 6],
    }
}

#[test]
fn chi2_and_p_value_of_a_small_case() {
    // Values 0, 1, 2 with unit errors: mean 1, χ² = 2 on 2 degrees of
    // freedom, p = exp(−1).
    let d = (0..3).map(|j| drive(j, j as f64, 1.0)).collect();
    let h = vehicle_history("v", DriveOrder::Path, d, 0, &exact());
    let c = h.params[0].consistency;
    assert_eq!((c.drives, c.dof), (3, 2));
    assert!((h.params[0].mean - 1.0).abs() < 1e-15);
    assert!((c.chi2 - 2.0).abs() < 1e-12);
    assert!((c.p_value - (-1.0f64).exp()).abs() < 1e-12, "{}", c.p_value);
    assert!(c.consistent && h.params[0].changes.is_empty());
    // Only the estimated parameter counts overall.
    assert_eq!(h.overall.dof, 2);
    assert_eq!(h.params[1].consistency.drives, 0);
    assert!(h.params[1].mean.is_nan());
}

#[test]
fn a_step_is_found_at_the_first_drive_after_it() {
    // Eight drives, the last four 0.1 higher, errors 0.01 and a little noise.
    let noise = [0.004, -0.006, 0.002, 0.0, -0.003, 0.005, -0.001, 0.002];
    let d = (0..8)
        .map(|j| drive(j, if j < 4 { 1.0 } else { 1.1 } + noise[j], 0.01))
        .collect();
    let h = vehicle_history("v", DriveOrder::Path, d, 0, &exact());
    let p = &h.params[0];
    assert!(!p.consistency.consistent && p.consistency.p_value < 1e-20);
    assert_eq!(p.changes.len(), 1, "{:?}", p.changes);
    let c = &p.changes[0];
    assert_eq!(c.index, 4);
    assert!((c.shift - 0.1).abs() < 0.006, "{}", c.shift);
    assert!((c.shift_std - (2.0f64 / 4.0 * 1e-4).sqrt()).abs() < 1e-12);
    assert!(c.p_value < 1e-20);
}

#[test]
fn two_steps_are_both_found_and_a_tolerance_hides_a_small_one() {
    let v = [5.0, 5.0, 5.0, 5.2, 5.2, 5.2, 4.9, 4.9, 4.9];
    let d: Vec<_> = v
        .iter()
        .enumerate()
        .map(|(j, x)| drive(j, *x, 0.02))
        .collect();
    let h = vehicle_history("v", DriveOrder::Path, d.clone(), 0, &exact());
    let at: Vec<usize> = h.params[0].changes.iter().map(|c| c.index).collect();
    assert_eq!(at, vec![3, 6]);
    // A tolerance larger than the steps: consistent, nothing flagged.
    let loose = HistoryOptions {
        alpha: 1e-3,
        tolerance: [1.0; 6],
    };
    let h = vehicle_history("v", DriveOrder::Path, d, 0, &loose);
    assert!(h.params[0].consistency.consistent && h.params[0].changes.is_empty());
}

#[test]
fn options_are_checked() {
    let mut o = HistoryOptions {
        alpha: 0.0,
        ..Default::default()
    };
    assert!(o.validate().is_err());
    o.alpha = 0.01;
    o.tolerance[3] = -1.0;
    let e = o.validate().unwrap_err().to_string();
    assert!(e.contains("circumference_fr_m"), "{e}");
}
