//! The batch's outputs: the results CSV (one row per drive), the history CSV
//! (one row per vehicle and parameter, one more per change) and the printed
//! history table. Column contracts: `docs/fleet.md`.

use std::io::Write;
use std::path::Path;

use deadreckon_core::filter::SensorKind;
use deadreckon_core::timing::{Corrections, Stream};
use deadreckon_core::Params;

use crate::batch::DriveResult;
use crate::history::{Consistency, DriveOrder, VehicleHistory};
use crate::FleetError;

/// Shortest text that parses back to the same number (exponent form for
/// very small and very large magnitudes: `1.4e-265`, not 265 zeros).
fn num(v: f64) -> String {
    format!("{v:?}")
}

/// The header of the results CSV.
pub fn results_header() -> Vec<String> {
    let mut h: Vec<String> = [
        "path",
        "vehicle_id",
        "recorded_at",
        "status",
        "error",
        "elapsed_s",
        "duration_s",
        "iterations",
        "converged",
    ]
    .map(String::from)
    .to_vec();
    for p in Params::NAMES {
        h.push(p.to_string());
        h.push(format!("std_{p}"));
        h.push(format!("status_{p}"));
        h.push(format!("samples_{p}"));
    }
    for k in [
        "gnss_used",
        "gnss_rejected",
        "gnss_recoveries",
        "wheel_gaps",
    ] {
        h.push(k.into());
    }
    for s in SensorKind::ALL {
        h.push(format!("accepted_{}", s.name()));
        h.push(format!("rejected_{}", s.name()));
    }
    for k in [
        "outage_s",
        "outage_windows",
        "outage_reference",
        "outage_final_error_mean_m",
        "outage_final_error_p95_m",
        "outage_final_error_max_m",
        "outage_drift_mean_pct",
    ] {
        h.push(k.into());
    }
    for st in Stream::ALL {
        h.push(format!("delay_{}_s", st.name()));
        h.push(format!("std_delay_{}_s", st.name()));
        h.push(format!("status_delay_{}", st.name()));
    }
    for k in [
        "imu_tilt_deg",
        "std_imu_tilt_deg",
        "status_imu_tilt",
        "gyro_scale_error",
        "std_gyro_scale_error",
        "status_gyro_scale_error",
        "traction_slip_per_mps2",
        "std_traction_slip_per_mps2",
        "status_traction_slip",
    ] {
        h.push(k.into());
    }
    h
}

/// The corrections' columns: per stream its delay, standard error and
/// status (`applied`, `not-estimated`; empty without corrections), then the
/// IMU tilt, the gyro scale error and the driven axle's slip likewise
/// (`none` where the drive has no three-axis IMU or accelerometer, or the
/// scale was not attempted).
fn corrections_cells(c: &Corrections) -> Vec<String> {
    let value = |estimated: bool, v: f64| {
        if estimated && v.is_finite() {
            num(v)
        } else {
            String::new()
        }
    };
    let status = |estimated: bool| {
        if estimated {
            "applied"
        } else {
            "not-estimated"
        }
    };
    let mut row = Vec::new();
    for st in Stream::ALL {
        let d = c.delays.get(st);
        let e = d.status.is_estimated();
        row.extend([value(e, d.delay_s), value(e, d.std_s), status(e).into()]);
    }
    match &c.tilt {
        Some(t) => {
            let e = t.is_estimated();
            row.extend([
                value(e, t.tilt_rad.to_degrees()),
                value(e, t.std_rad.to_degrees()),
                status(e).into(),
            ]);
        }
        None => row.extend([String::new(), String::new(), "none".into()]),
    }
    match &c.gyro_scale {
        Some(g) => {
            let e = g.is_estimated();
            row.extend([value(e, g.scale_error), value(e, g.std), status(e).into()]);
        }
        None => row.extend([String::new(), String::new(), "none".into()]),
    }
    match &c.traction {
        Some(t) => {
            let e = t.is_estimated();
            row.extend([value(e, t.slip_per_mps2), value(e, t.std), status(e).into()]);
        }
        None => row.extend([String::new(), String::new(), "none".into()]),
    }
    row
}

/// One row of the results CSV (empty fields where a value does not apply).
pub fn results_row(r: &DriveResult) -> Vec<String> {
    let mut row = vec![
        r.path.display().to_string(),
        r.vehicle_id.clone().unwrap_or_default(),
        r.recorded_at.clone().unwrap_or_default(),
    ];
    let width = results_header().len();
    match &r.outcome {
        Err(e) => {
            row.push("error".into());
            row.push(e.replace(['\n', '\r'], " "));
            row.push(num(r.elapsed_s));
        }
        Ok(c) => {
            row.extend(["ok".into(), String::new(), num(r.elapsed_s)]);
            let cal = &c.car.calibration;
            row.push(num(c.duration_s));
            row.push(cal.iterations.to_string());
            row.push(cal.converged.to_string());
            let (v, s) = (cal.estimate.params.to_array(), cal.estimate.std.to_array());
            let status = c.car.status();
            for i in 0..6 {
                row.push(num(v[i]));
                row.push(num(s[i]));
                row.push(status[i].name().into());
                row.push(cal.samples[i].to_string());
            }
            match &cal.filter_stats {
                Some(st) => {
                    for n in [
                        st.gnss_updates,
                        st.gnss_rejected,
                        st.gnss_recoveries,
                        st.wheel_gaps,
                    ] {
                        row.push(n.to_string());
                    }
                    for s in SensorKind::ALL {
                        row.push(st.gates.accepted(s).to_string());
                        row.push(st.gates.rejected(s).to_string());
                    }
                }
                None => row.extend(std::iter::repeat_n(String::new(), 4 + 18)),
            }
            match &c.outage {
                Some(o) => row.extend([
                    num(o.options.length_s),
                    o.final_error_m.n.to_string(),
                    o.reference.to_string(),
                    num(o.final_error_m.mean),
                    num(o.final_error_m.p95),
                    num(o.final_error_m.max),
                    num(o.drift_pct.mean),
                ]),
                None => row.extend(std::iter::repeat_n(String::new(), 7)),
            }
            if let Some(k) = c.corrections() {
                row.extend(corrections_cells(k));
            }
        }
    }
    row.resize(width, String::new());
    row
}

fn csv_error(path: &Path, e: csv::Error) -> std::io::Error {
    std::io::Error::other(format!("{}: {e}", path.display()))
}

fn write_csv(path: &Path, header: Vec<String>, rows: Vec<Vec<String>>) -> Result<(), FleetError> {
    deadreckon_io::atomic_write(path, |w: &mut dyn Write| {
        let mut c = csv::Writer::from_writer(w);
        c.write_record(&header).map_err(|e| csv_error(path, e))?;
        for r in &rows {
            c.write_record(r).map_err(|e| csv_error(path, e))?;
        }
        c.flush()
    })?;
    Ok(())
}

/// Writes the results CSV atomically (temporary file beside it, renamed).
pub fn write_results(path: &Path, results: &[DriveResult]) -> Result<(), FleetError> {
    write_csv(
        path,
        results_header(),
        results.iter().map(results_row).collect(),
    )
}

/// The header of the history CSV.
pub fn history_header() -> Vec<String> {
    [
        "vehicle_id",
        "parameter",
        "drives",
        "order",
        "mean",
        "chi2",
        "dof",
        "p_value",
        "consistent",
        "change_drive",
        "change_path",
        "change_recorded_at",
        "before",
        "after",
        "shift",
        "shift_std",
        "change_chi2",
        "change_p_value",
    ]
    .map(String::from)
    .to_vec()
}

fn order_name(o: DriveOrder) -> &'static str {
    match o {
        DriveOrder::RecordedAt => "recorded_at",
        DriveOrder::Path => "path",
    }
}

/// The history CSV's rows: per vehicle, one per parameter, one `all`, then
/// one per change (the parameter's columns repeated, the change's filled).
pub fn history_rows(histories: &[VehicleHistory]) -> Vec<Vec<String>> {
    let mut rows = Vec::new();
    for h in histories {
        let base = |name: &str, mean: Option<f64>, c: &Consistency| -> Vec<String> {
            vec![
                h.vehicle_id.clone(),
                name.to_string(),
                c.drives.to_string(),
                order_name(h.order).into(),
                mean.filter(|m| m.is_finite()).map(num).unwrap_or_default(),
                num(c.chi2),
                c.dof.to_string(),
                num(c.p_value),
                c.consistent.to_string(),
            ]
        };
        for p in &h.params {
            let mut r = base(p.name, Some(p.mean), &p.consistency);
            r.resize(history_header().len(), String::new());
            rows.push(r);
        }
        let mut r = base("all", None, &h.overall);
        r.resize(history_header().len(), String::new());
        rows.push(r);
        for p in &h.params {
            for c in &p.changes {
                let d = &h.drives[c.index];
                let mut r = base(p.name, Some(p.mean), &p.consistency);
                r.extend([
                    (c.index + 1).to_string(),
                    d.path.display().to_string(),
                    d.recorded_at.clone().unwrap_or_default(),
                    num(c.before),
                    num(c.after),
                    num(c.shift),
                    num(c.shift_std),
                    num(c.chi2),
                    num(c.p_value),
                ]);
                rows.push(r);
            }
        }
    }
    rows
}

/// Writes the history CSV atomically.
pub fn write_history(path: &Path, histories: &[VehicleHistory]) -> Result<(), FleetError> {
    write_csv(path, history_header(), history_rows(histories))
}

fn p_text(p: f64) -> String {
    if p >= 1e-3 {
        format!("{p:.3}")
    } else {
        format!("{p:.1e}")
    }
}

/// The printed history: per vehicle, a line with the overall test, a table of
/// the parameters (mean, χ², dof, p-value, verdict) and one line per change.
pub fn history_table(histories: &[VehicleHistory]) -> String {
    let mut s = String::new();
    for h in histories {
        let o = &h.overall;
        s.push_str(&format!(
            "vehicle {}: {} drives (ordered by {}), {} failed; overall χ² {:.1} on {} dof, p = {}: {}\n",
            h.vehicle_id,
            h.drives.len(),
            order_name(h.order),
            h.failed,
            o.chi2,
            o.dof,
            p_text(o.p_value),
            if o.consistent { "consistent" } else { "INCONSISTENT" }
        ));
        s.push_str(&format!(
            "  {:<20} {:>14} {:>10} {:>4} {:>9}  {:<10} changes\n",
            "parameter", "mean", "χ²", "dof", "p", "verdict"
        ));
        for p in &h.params {
            let c = &p.consistency;
            let changes: Vec<String> = p
                .changes
                .iter()
                .map(|ch| {
                    let d = &h.drives[ch.index];
                    format!(
                        "from drive {} ({}{}): {:+.6} ± {:.6}, p = {}",
                        ch.index + 1,
                        d.path.display(),
                        d.recorded_at
                            .as_deref()
                            .map(|t| format!(", {t}"))
                            .unwrap_or_default(),
                        ch.shift,
                        ch.shift_std,
                        p_text(ch.p_value)
                    )
                })
                .collect();
            s.push_str(&format!(
                "  {:<20} {:>14} {:>10.2} {:>4} {:>9}  {:<10} {}\n",
                p.name,
                if p.mean.is_finite() {
                    format!("{:.6}", p.mean)
                } else {
                    "-".into()
                },
                c.chi2,
                c.dof,
                p_text(c.p_value),
                if c.drives == 0 {
                    "not estimated"
                } else if c.consistent {
                    "consistent"
                } else if p.changes.is_empty() {
                    "INCONSISTENT"
                } else {
                    "MOVED"
                },
                if changes.is_empty() {
                    "-".to_string()
                } else {
                    changes.join("; ")
                }
            ));
        }
    }
    s
}

/// One line on the batch: drives, failures, wall time and drives per second.
pub fn summary_line(results: &[DriveResult], wall_s: f64, threads: usize) -> String {
    let failed = results.iter().filter(|r| r.outcome.is_err()).count();
    format!(
        "{} drives: {} calibrated, {} failed, in {:.2} s on {} threads ({:.2} drives/s)",
        results.len(),
        results.len() - failed,
        failed,
        wall_s,
        threads,
        results.len() as f64 / wall_s.max(1e-9)
    )
}

/// What `batch` prints: the summary line, the files written, and each
/// vehicle's calibration history (or why there is none).
pub fn summary_text(
    results: &[DriveResult],
    histories: &[VehicleHistory],
    wall_s: f64,
    threads: usize,
    written: &[&Path],
) -> String {
    let mut text = summary_line(results, wall_s, threads);
    for w in written {
        text.push_str(&format!("\nwrote {}", w.display()));
    }
    text.push('\n');
    if histories.is_empty() {
        text.push_str("no drive has a vehicle_id in its vehicle.toml: no calibration history\n");
    } else {
        text.push_str(&history_table(histories));
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::history::{vehicle_history, HistoryDrive, HistoryOptions};

    fn drives(values: &[f64]) -> Vec<HistoryDrive> {
        values
            .iter()
            .enumerate()
            .map(|(j, v)| HistoryDrive {
                path: format!("d{j}").into(),
                recorded_at: Some(format!("2026-01-0{}", j + 1)),
                value: [*v; 6],
                std: [0.01; 6],
                estimated: [true, true, false, false, false, false],
            })
            .collect()
    }

    #[test]
    fn verdicts_and_history_rows() {
        let o = HistoryOptions {
            alpha: 1e-3,
            tolerance: [0.0; 6],
        };
        // A step: MOVED with the change; alternating values: INCONSISTENT
        // without a single change.
        let step = vehicle_history(
            "a",
            DriveOrder::RecordedAt,
            drives(&[1.0, 1.0, 1.0, 1.2, 1.2, 1.2]),
            0,
            &o,
        );
        let zigzag = vehicle_history(
            "b",
            DriveOrder::Path,
            drives(&[1.0, 1.06, 1.0, 1.06, 1.0, 1.06]),
            1,
            &o,
        );
        let table = history_table(&[step.clone(), zigzag.clone()]);
        assert!(
            table.contains("MOVED      from drive 4 (d3, 2026-01-04): +0.200000 ± 0.008165"),
            "{table}"
        );
        assert!(table.contains("INCONSISTENT -"), "{table}");
        assert!(
            table.contains("circumference_fl_m") && table.contains("not estimated"),
            "{table}"
        );
        assert!(
            table.contains("vehicle b: 6 drives (ordered by path), 1 failed"),
            "{table}"
        );
        let rows = history_rows(&[step, zigzag]);
        // 7 rows per vehicle, plus one per change (two parameters moved in `a`).
        assert_eq!(rows.len(), 7 + 2 + 7);
        assert!(rows.iter().all(|r| r.len() == history_header().len()));
        let change = &rows[7];
        assert_eq!(
            &change[..2],
            &["a".to_string(), "gyro_bias_rps".to_string()]
        );
        assert_eq!(
            &change[9..12],
            &["4".to_string(), "d3".to_string(), "2026-01-04".to_string()]
        );
    }
}
