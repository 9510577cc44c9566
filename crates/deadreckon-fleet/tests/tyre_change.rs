//! The calibration history on simulated fleets: ten 300 s drives of one car
//! whose front-left tyre is replaced by one 1.5 % smaller before its sixth
//! drive, and ten of a car that does not change (seeded). The drives' names
//! are not in time order: `recorded_at` orders them.

use std::path::{Path, PathBuf};

use deadreckon_core::Drive;
use deadreckon_fleet::batch::{self, BatchOptions, DriveResult};
use deadreckon_fleet::history::{self, DriveOrder, HistoryOptions, VehicleHistory};
use deadreckon_fleet::output;
use deadreckon_sim::Scenario;

/// The built-in calibration scenario's true front-left circumference, m.
const FL_M: f64 = 1.9134;
/// The new tyre: 1.5 % smaller.
const NEW_FL_M: f64 = FL_M * 0.985;
/// The first drive (1-based, in time order) on the new tyre.
const CHANGE_AT: usize = 6;

/// Simulates ten drives of `id` into `root`; from drive `change_at` on the
/// front-left circumference is `NEW_FL_M`.
fn fleet(root: &Path, id: &str, seed0: u64, change_at: Option<usize>) -> Vec<PathBuf> {
    let base = Scenario::builtin("calibration")
        .expect("built-in")
        .with_duration_s(300.0);
    let mut dirs = Vec::new();
    for i in 1..=10usize {
        let mut errors = base.true_params();
        assert_eq!(errors.circumference_fl_m, FL_M);
        if change_at.is_some_and(|k| i >= k) {
            errors.circumference_fl_m = NEW_FL_M;
        }
        let mut sc = base.clone().with_errors(errors);
        sc.vehicle.vehicle_id = Some(id.to_string());
        sc.vehicle.recorded_at = Some(format!("2026-03-{i:02}T08:00:00Z"));
        let out = deadreckon_sim::simulate(&sc, seed0 + i as u64).expect("simulated");
        // Names out of time order: drive i is `drive-(7i mod 10)`.
        let dir = root.join(id).join(format!("drive-{}", (7 * i) % 10));
        deadreckon_io::write_drive(&dir, &out.drive).expect("written");
        dirs.push(dir);
    }
    dirs
}

fn load(p: &Path) -> Result<Drive, String> {
    deadreckon_io::read_drive_with(p, &deadreckon_io::ReadOptions::default().without_truth())
        .map_err(|e| e.to_string())
}

fn vehicle<'a>(h: &'a [VehicleHistory], id: &str) -> &'a VehicleHistory {
    h.iter()
        .find(|v| v.vehicle_id == id)
        .expect("vehicle in history")
}

#[test]
fn tyre_change_is_flagged_at_its_drive_and_wheel_and_a_steady_car_is_not() {
    let tmp = tempfile::tempdir().expect("temp dir");
    let tyre_paths = fleet(tmp.path(), "car-tyre", 100, Some(CHANGE_AT));
    let mut paths = tyre_paths.clone();
    paths.extend(fleet(tmp.path(), "car-same", 200, None));
    // A broken drive among them is a row with its error, not the end.
    let broken = tmp.path().join("broken");
    std::fs::create_dir(&broken).expect("dir");
    std::fs::write(broken.join("vehicle.toml"), "wheelbase_m = 2.6\nnonsense\n").expect("file");
    paths.insert(3, broken.clone());

    let done = std::sync::atomic::AtomicUsize::new(0);
    let options = BatchOptions {
        threads: 2,
        ..Default::default()
    };
    let results: Vec<DriveResult> = batch::run(&paths, &load, &options, &|_: &DriveResult| {
        done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    })
    .expect("batch runs");
    assert_eq!(done.into_inner(), 21);
    assert_eq!(results.len(), 21);
    // Results come in input order.
    for (r, p) in results.iter().zip(&paths) {
        assert_eq!(&r.path, p);
    }
    let e = results[3].outcome.as_ref().expect_err("broken drive");
    assert!(e.contains("vehicle.toml") && e.contains("line 2"), "{e}");
    assert_eq!(results.iter().filter(|r| r.outcome.is_ok()).count(), 20);

    let h = history::histories(&results, &HistoryOptions::default()).expect("history");
    assert_eq!(h.len(), 2);
    print!("{}", output::history_table(&h));

    let tyre = vehicle(&h, "car-tyre");
    assert_eq!(tyre.order, DriveOrder::RecordedAt);
    assert_eq!(tyre.drives.len(), 10);
    // Exactly one change, on the front-left wheel, at the sixth drive.
    for p in &tyre.params {
        if p.name == "circumference_fl_m" {
            assert_eq!(p.changes.len(), 1, "{:?}", p.changes);
            let c = &p.changes[0];
            assert_eq!(c.index + 1, CHANGE_AT);
            assert_eq!(
                tyre.drives[c.index].recorded_at.as_deref(),
                Some("2026-03-06T08:00:00Z")
            );
            assert_eq!(tyre.drives[c.index].path, tyre_paths[CHANGE_AT - 1]);
            assert!(tyre.drives[c.index].path.ends_with("drive-2"));
            // Measured: −0.028736 ± 0.000400 m against the true −0.028701 m
            // since ticks are fitted over 1 s blocks (−0.028755 ± 0.000918
            // per row, ± 0.000811 before the GNSS chords widened the
            // standard errors).
            let truth = NEW_FL_M - FL_M;
            assert!((c.shift - truth).abs() < 0.0002, "{} vs {truth}", c.shift);
            assert!(
                c.shift_std > 0.0003 && c.shift_std < 0.0005,
                "{}",
                c.shift_std
            );
            assert!(c.p_value < 1e-100, "{}", c.p_value);
            assert!(!p.consistency.consistent);
        } else {
            assert!(p.changes.is_empty(), "{} flagged: {:?}", p.name, p.changes);
            // Measured: lowest p of the other parameters 0.020 (gyro bias).
            assert!(
                p.consistency.p_value > 0.01,
                "{}: {:?}",
                p.name,
                p.consistency
            );
        }
    }
    assert!(!tyre.overall.consistent);

    let same = vehicle(&h, "car-same");
    assert_eq!(same.drives.len(), 10);
    for p in &same.params {
        assert!(p.changes.is_empty(), "{} flagged: {:?}", p.name, p.changes);
        // Measured: lowest p 0.996 (gyro bias; the speed scale 0.702
        // before the GNSS chords widened its standard error).
        assert!(
            p.consistency.p_value > 0.05,
            "{}: {:?}",
            p.name,
            p.consistency
        );
    }
    assert!(same.overall.consistent && same.overall.p_value > 0.5);

    // The CSVs: one row per drive; per vehicle 7 rows and one per change.
    let out = tmp.path().join("results.csv");
    output::write_results(&out, &results).expect("results written");
    let text = std::fs::read_to_string(&out).expect("read");
    assert_eq!(text.lines().count(), 22);
    let hist = tmp.path().join("history.csv");
    output::write_history(&hist, &h).expect("history written");
    let rows: Vec<String> = std::fs::read_to_string(&hist)
        .expect("read")
        .lines()
        .map(String::from)
        .collect();
    assert_eq!(rows.len(), 1 + 7 + 7 + 1);
    let change: Vec<&String> = rows.iter().filter(|r| r.contains(",6,")).collect();
    assert_eq!(change.len(), 1);
    assert!(change[0].starts_with("car-tyre,circumference_fl_m,10,recorded_at,"));
}
