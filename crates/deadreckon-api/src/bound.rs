//! The 95 % error bound ([`deadreckon_core::bound`]) as the commands show
//! it: the params.toml table `[bound]` (written by `calibrate`, read by
//! `evaluate`, `run` and `stream`), its `--json` shapes, and its text.
//!
//! ```toml
//! [bound]
//! method = "conformal"   # or "filter": the filter's covariance alone
//! k = 1.83               # the factor on the filter's 95 % radius
//! windows = 57           # outage windows of the calibration drive it was fitted on
//! outage_s = 30.0        # their length, s
//! step_s = 10.0          # the step between them, s
//! ```

use std::path::Path;

use deadreckon_core::bound::{BoundFit, Method};
use deadreckon_core::outage::OutageEvaluation;
use serde_json::{json, Value};

use crate::Error;

/// The `[bound]` table of params.toml.
pub fn bound_toml(fit: &BoundFit) -> toml::Table {
    let mut t = toml::Table::new();
    t.insert("method".into(), fit.method.name().into());
    t.insert("k".into(), fit.k.into());
    t.insert("windows".into(), (fit.windows as i64).into());
    t.insert("outage_s".into(), fit.outage_s.into());
    t.insert("step_s".into(), fit.step_s.into());
    t
}

/// The bound stored in the extra keys of a params.toml: its `[bound]`
/// table, or the filter's covariance alone ([`BoundFit::FILTER`]) in a
/// file without one (calibrated before the bound existed).
pub fn bound_from_extra(extra: &toml::Table) -> Result<BoundFit, String> {
    let Some(t) = extra.get("bound") else {
        return Ok(BoundFit::FILTER);
    };
    let t = t.as_table().ok_or("`bound` must be a table")?;
    let num = |k: &str| -> Result<f64, String> {
        t.get(k)
            .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
            .ok_or_else(|| format!("`bound.{k}` must be a number"))
    };
    let method = t
        .get("method")
        .and_then(|v| v.as_str())
        .and_then(Method::from_name)
        .ok_or("`bound.method` must be \"conformal\" or \"filter\"")?;
    let k = num("k")?;
    if !(k.is_finite() && k >= 0.0) {
        return Err(format!("`bound.k` = {k} must be finite and non-negative"));
    }
    let windows = num("windows")?;
    if !(windows >= 0.0 && windows.fract() == 0.0) {
        return Err(format!("`bound.windows` = {windows} must be a count"));
    }
    Ok(BoundFit {
        method,
        k,
        windows: windows as usize,
        outage_s: num("outage_s")?,
        step_s: num("step_s")?,
    })
}

/// The bound stored in the params.toml `spec` (`nominal`: the filter's
/// covariance alone).
pub fn stored_bound(spec: &str) -> Result<BoundFit, Error> {
    if spec == "nominal" {
        return Ok(BoundFit::FILTER);
    }
    let (_, extra) = deadreckon_io::read_params_with_extra(Path::new(spec))
        .map_err(|e| Error::Invalid(format!("reading the error bound of {spec}: {e}")))?;
    bound_from_extra(&extra).map_err(|e| Error::Invalid(format!("{spec}: {e}")))
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
        Method::Conformal => format!(
            "{} × the filter's 95 % radius, fitted on {} windows of {:.1} s of the calibration drive \
             against its hidden fixes",
            fmt_k(fit.k),
            fit.windows,
            fit.outage_s
        ),
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
