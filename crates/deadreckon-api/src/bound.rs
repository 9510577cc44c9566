//! The 95 % error bound ([`deadreckon_core::bound`]) as the commands show
//! it: the params.toml table `[bound]` (written by `calibrate`, read by
//! `evaluate`, `run` and `stream`), its `--json` shapes, and its text.
//!
//! ```toml
//! [bound]
//! method = "conformal"   # or "filter": the filter's covariance alone
//! k = 1.83               # the factor on the filter's covariance: bound = r(k² P + σ² I)
//! windows = 57           # outage windows of the calibration drive it was fitted on
//! outage_s = 30.0        # their length, s
//! step_s = 10.0          # the step between them, s
//! ```

use deadreckon_core::bound::{BoundFit, Method};
use deadreckon_core::outage::OutageEvaluation;
use serde_json::{json, Value};

use crate::params_tables::BoundTable;

/// The `[bound]` table of params.toml
/// ([`crate::params_tables::BoundTable`], the one layout; the kinematic
/// parameter files carry the same table).
pub fn bound_toml(fit: &BoundFit) -> toml::Table {
    toml::Table::try_from(BoundTable::of(fit)).unwrap_or_default()
}

/// The bound stored in the extra keys of a (kinematic) parameter file: its
/// `[bound]` table read as [`BoundTable`], or the filter's covariance alone
/// ([`BoundFit::FILTER`]) in a file without one (calibrated before the
/// bound existed).
pub fn bound_from_extra(extra: &toml::Table) -> Result<BoundFit, String> {
    let Some(t) = extra.get("bound") else {
        return Ok(BoundFit::FILTER);
    };
    let t: BoundTable = t
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| crate::params_file::toml_message("bound", &e))?;
    t.fit()
}

/// The bound's `--json` object.
pub fn bound_json(fit: &BoundFit) -> Value {
    json!({
        "method": fit.method.name(), "k": fit.k, "windows": fit.windows,
        "outage_s": fit.outage_s, "step_s": fit.step_s,
    })
}

/// Adds the bound to `evaluate --outage --json`'s object `v`: per window
/// (`outages[]`, `unsettled[]`) `bound_95_m` at the window's end and
/// `within_bound_95`, with `alert_m` the time and distance at which the
/// bound reaches it (`alert_time_s`, `alert_distance_m`, null when it
/// does not in the window); the summary `bound_95_coverage`,
/// `bound_95_sharpness` and the `bound` used.
pub fn add_outage_bound(
    v: &mut Value,
    ev: &OutageEvaluation,
    fit: &BoundFit,
    alert_m: Option<f64>,
) {
    for (key, windows) in [("outages", &ev.windows), ("unsettled", &ev.unsettled)] {
        let Some(items) = v.get_mut(key).and_then(Value::as_array_mut) else {
            continue;
        };
        for (item, w) in items.iter_mut().zip(windows) {
            item["bound_95_m"] = json!(w.bound_95_m(fit));
            item["within_bound_95"] = json!(w.within_bound(fit));
            if let Some(a) = alert_m {
                let reach = w.bound_reaches(fit, a);
                item["alert_time_s"] = json!(reach.map(|r| r.0));
                item["alert_distance_m"] = json!(reach.and_then(|r| r.1));
            }
        }
    }
    v["bound_95_coverage"] = json!(ev.bound_coverage(fit));
    v["bound_95_sharpness"] = json!(ev.bound_sharpness(fit));
    v["bound"] = bound_json(fit);
    if let Some(a) = alert_m {
        v["alert_m"] = json!(a);
    }
}

/// The text of the bound for `evaluate --outage`: coverage and sharpness,
/// and with `alert_m` when the bound reaches it.
pub fn outage_bound_lines(
    ev: &OutageEvaluation,
    fit: &BoundFit,
    alert_m: Option<f64>,
) -> Vec<String> {
    let mut out = Vec::new();
    let ends: Vec<f64> = ev
        .windows
        .iter()
        .filter_map(|w| w.bound_95_m(fit))
        .collect();
    let (Some(cover), Some(sharp)) = (ev.bound_coverage(fit), ev.bound_sharpness(fit)) else {
        out.push("95 % error bound: not computed (the estimator gave no covariance)".into());
        return out;
    };
    let within = ev
        .windows
        .iter()
        .filter(|w| w.within_bound(fit) == Some(true))
        .count();
    let s = deadreckon_core::metrics::Summary::of(&ends);
    // A row of the summary table, under the final error.
    out.extend(crate::text::summary_table(&[("95 % bound at the end (m)", s)]).pop());
    out.push(format!(
        "final error within the 95 % bound in {within} of {} windows ({:.0} %); median bound / \
         median final error {sharp:.2}",
        ev.windows.len(),
        100.0 * cover
    ));
    out.push(format!("  bound: {}", fit_text(fit)));
    if let Some(a) = alert_m {
        let reach: Vec<(f64, Option<f64>)> = ev
            .windows
            .iter()
            .filter_map(|w| w.bound_reaches(fit, a))
            .collect();
        if reach.is_empty() {
            out.push(format!(
                "the bound reaches {a} m in none of the {} windows",
                ev.windows.len()
            ));
        } else {
            let t = deadreckon_core::metrics::Summary::of(
                &reach.iter().map(|r| r.0).collect::<Vec<_>>(),
            );
            let d: Vec<f64> = reach.iter().filter_map(|r| r.1).collect();
            let dist = if d.is_empty() {
                String::new()
            } else {
                format!(
                    ", {:.0} m",
                    deadreckon_core::metrics::Summary::of(&d).median
                )
            };
            out.push(format!(
                "the bound reaches {a} m in {} of {} windows, after a median {:.1} s{dist} into the outage",
                reach.len(),
                ev.windows.len(),
                t.median
            ));
        }
    }
    out
}

/// The bound in words: the method and its factor.
pub fn fit_text(fit: &BoundFit) -> String {
    match fit.method {
        Method::Conformal => {
            format!(
                "the filter's covariance inflated by k = {} (k² P) over the last fix's declared \
             accuracy, fitted on {} windows of {:.1} s of the calibration drive against its hidden \
             fixes",
                fmt_k(fit.k),
                fit.windows,
                fit.outage_s
            ) + if fit.k == 0.0 {
                " (the declared accuracy explains every window's error: the bound is that floor)"
            } else {
                ""
            }
        }
        Method::Filter => fit.method.to_string(),
    }
}

fn fmt_k(k: f64) -> String {
    format!("{k:.2}")
}

/// `calibrate`'s lines of the bound: the factor, and when a 1 m bound is
/// reached in the calibration drive's outages.
pub fn calibrate_lines(
    fit: &BoundFit,
    reach: Option<&deadreckon_core::bound::Reach>,
) -> Vec<String> {
    let mut out = vec![format!("95 % error bound: {}", fit_text(fit))];
    if let Some(r) = reach {
        let dist = if r.distance_m.is_finite() {
            format!(" ({:.0} m)", r.distance_m)
        } else {
            String::new()
        };
        out.push(format!(
            "with these parameters a {} m bound is reached after {:.1} s{dist} of dead reckoning \
             (median of {} of {} windows, at a median {:.1} m/s)",
            r.alert_m, r.time_s, r.windows, r.of, r.speed_mps
        ));
    }
    out
}

/// Why a kinematic shape's outages have no bound: the tricycle's kinematic
/// dead reckoning (and the differential drive started from the alignment)
/// carries no covariance, as TedriS's prediction does not.
pub const NO_COVARIANCE: &str =
    "not computed: this dead reckoning carries no covariance (kinematic integration from the reference pose, or started from the alignment), so it gives no uncertainty to bound";

/// Adds the bound to a kinematic shape's `evaluate --outage --json`
/// object: with `fit` and the differential drive's filter covariances,
/// `outages[]` (each window's `start_s`, `end_s`, `final_error_m`,
/// `bound_95_m`, `within_bound_95`), `bound_95_coverage`,
/// `bound_95_sharpness` and the `bound` used; otherwise those keys null
/// and `bound_95_note` saying why.
pub fn add_kinematic_bound(
    v: &mut Value,
    diff: Option<&deadreckon_core::kinematics::diff_drive::DiffDriveOutages>,
    fit: Option<&BoundFit>,
) {
    use deadreckon_core::bound_diff;
    let bounds = diff.zip(fit).and_then(|(d, f)| {
        bound_diff::window_bounds(d, f).map(|b| (d, f, b, bound_diff::coverage_and_sharpness(d, f)))
    });
    match bounds {
        Some((d, f, b, cs)) => {
            v["outages"] = d
                .outages
                .windows
                .iter()
                .zip(&b)
                .map(|(w, (bound, within))| {
                    json!({"start_s": w.start_s, "end_s": w.end_s, "final_error_m": w.final_error_m,
                           "bound_95_m": bound, "within_bound_95": within})
                })
                .collect();
            v["bound_95_coverage"] = json!(cs.map(|c| c.0));
            v["bound_95_sharpness"] = json!(cs.map(|c| c.1));
            v["bound"] = bound_json(f);
        }
        None => {
            v["bound_95_coverage"] = Value::Null;
            v["bound_95_sharpness"] = Value::Null;
            v["bound"] = Value::Null;
            v["bound_95_note"] = NO_COVARIANCE.into();
        }
    }
}

/// The text of a kinematic shape's bound, as [`outage_bound_lines`] for a
/// car: the bound's row, coverage and sharpness, the factor; or why there
/// is none.
pub fn kinematic_bound_lines(
    diff: Option<&deadreckon_core::kinematics::diff_drive::DiffDriveOutages>,
    fit: Option<&BoundFit>,
) -> Vec<String> {
    use deadreckon_core::bound_diff;
    let Some((d, f)) = diff.zip(fit) else {
        return vec![format!("95 % error bound: {NO_COVARIANCE}")];
    };
    let (Some(b), Some((cover, sharp))) = (
        bound_diff::window_bounds(d, f),
        bound_diff::coverage_and_sharpness(d, f),
    ) else {
        return vec![format!("95 % error bound: {NO_COVARIANCE}")];
    };
    let ends: Vec<f64> = b.iter().map(|x| x.0).collect();
    let within = b.iter().filter(|x| x.1).count();
    let mut out = Vec::new();
    out.extend(
        crate::text::summary_table(&[(
            "95 % bound at the end (m)",
            deadreckon_core::metrics::Summary::of(&ends),
        )])
        .pop(),
    );
    out.push(format!(
        "final error within the 95 % bound in {within} of {} windows ({:.0} %); median bound / \
         median final error {sharp:.2}",
        b.len(),
        100.0 * cover
    ));
    out.push(format!("  bound: {}", kinematic_fit_text(f)));
    out
}

/// A kinematic bound in words (fitted on the evaluated drive's own
/// windows, or stored).
fn kinematic_fit_text(fit: &BoundFit) -> String {
    match fit.method {
        Method::Conformal => format!(
            "{} × the filter's 95 % radius, fitted on {} windows of {:.1} s against hidden fixes",
            fmt_k(fit.k),
            fit.windows,
            fit.outage_s
        ),
        Method::Filter => fit.method.to_string(),
    }
}
