//! The objects the commands print with `--json`, built from library results.
//! The command line prints them; the Python bindings return them as dicts.

use deadreckon_core::calibrate::Calibration;
use deadreckon_core::evo::{self, TrajectoryError};
use deadreckon_core::filter::GateCounts;
use deadreckon_core::metrics::{DriftResult, ResetResult, Summary};
use deadreckon_core::outage::OutageEvaluation;
use deadreckon_core::Params;
use deadreckon_tedris::{ReferenceSource, TedrisModel};
use serde_json::{json, Value};

/// The `calibrate --json` object: the six parameters, `std`, `iterations`,
/// `converged`, `method` (the word given), `samples`, `history` and, when the
/// filter ran, `gnss`, `wheel_gaps` and `gates`.
pub fn calibration_json(method: &str, c: &Calibration) -> Value {
    let mut m = serde_json::Map::new();
    let a = c.estimate.params.to_array();
    let s = c.estimate.std.to_array();
    let mut std = serde_json::Map::new();
    for (i, name) in Params::NAMES.iter().enumerate() {
        m.insert((*name).into(), a[i].into());
        std.insert((*name).into(), s[i].into());
    }
    m.insert("std".into(), std.into());
    m.insert("iterations".into(), c.iterations.into());
    m.insert("converged".into(), c.converged.into());
    m.insert("method".into(), method.into());
    m.insert("samples".into(), json!(c.samples));
    m.insert(
        "history".into(),
        c.history
            .iter()
            .map(|p| json!(p.to_array()))
            .collect::<Vec<_>>()
            .into(),
    );
    if let Some(st) = &c.filter_stats {
        m.insert(
            "gnss".into(),
            json!({"used": st.gnss_updates, "rejected": st.gnss_rejected, "recoveries": st.gnss_recoveries, "hidden": st.gnss_hidden}),
        );
        m.insert("wheel_gaps".into(), st.wheel_gaps.into());
        m.insert("gates".into(), gates_json(&st.gates));
    }
    if let Some(ch) = &c.gnss_chords {
        m.insert(
            "gnss_chords".into(),
            json!({"mean_pct": 100.0 * ch.mean, "std_pct": 100.0 * ch.std,
                "blocks": ch.blocks, "block_s": deadreckon_core::chords::BLOCK_S}),
        );
    }
    if let Some(h) = &c.wheel_health {
        m.insert("wheel_health".into(), wheel_health_json(h));
    }
    if let Some(mv) = &c.manoeuvres {
        m.insert("manoeuvres".into(), json!(mv));
        m.insert("lacking".into(), json!(mv.lacking()));
    }
    Value::Object(m)
}

/// The per-sensor χ² gate counters: `{sensor: {accepted, rejected, recovered}}`.
pub fn gates_json(g: &GateCounts) -> Value {
    g.rows()
        .into_iter()
        .map(|(name, a, r, rec)| {
            (
                name.to_string(),
                json!({"accepted": a, "rejected": r, "recovered": rec}),
            )
        })
        .collect::<serde_json::Map<_, _>>()
        .into()
}

/// A summary of values: mean, median, p95, min, max, std, n.
pub fn summary_json(s: &Summary) -> Value {
    json!({"mean": s.mean, "median": s.median, "p95": s.p95, "min": s.min, "max": s.max, "std": s.std, "n": s.n})
}

/// Which of the calibrated streams a drive lacks altogether: a parameter
/// with no sample is then said to have no stream, not no sample above the
/// speed threshold.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Absent {
    /// No yaw-rate stream (`yaw_rate.csv`): the gyro bias has no reading.
    pub gyro: bool,
    /// No CAN speed stream (`speed.csv`): the speed scale has no reading.
    pub speed: bool,
}

impl Absent {
    /// What `drive` lacks.
    pub fn of(drive: &deadreckon_core::Drive) -> Absent {
        Absent {
            gyro: drive.yaw_rate.is_empty(),
            speed: drive.speed.is_empty(),
        }
    }
}

/// The parameters of `c` no sample above `min_speed_mps` informed (they keep
/// their nominal value), with why: `(name, reason)`; `absent` names the
/// streams the drive has none of.
pub fn not_estimated(
    c: &Calibration,
    min_speed_mps: f64,
    absent: Absent,
) -> Vec<(&'static str, String)> {
    Params::NAMES
        .iter()
        .zip(c.samples)
        .enumerate()
        .filter(|(_, (_, n))| *n == 0)
        .map(|(i, (name, _))| {
            let why = match i {
                0 if absent.gyro => {
                    "the drive has no yaw_rate.csv, no gyro to read the bias from: nominal kept"
                        .to_string()
                }
                1 if absent.speed => {
                    "the drive has no speed.csv, no CAN speed to scale: nominal kept".to_string()
                }
                _ => {
                    format!("0 samples above the speed threshold {min_speed_mps} m/s: nominal kept")
                }
            };
            (*name, why)
        })
        .collect()
}

/// The steering calibration of a car, as `calibrate --json` reports it.
pub fn steering_json(st: &deadreckon_core::kinematics::steering::SteeringCalibration) -> Value {
    let mut v = json!({"ratio": st.ratio, "offset_rad": st.offset, "samples": st.samples, "rms_rad": st.rms_rad});
    if let Some(u) = &st.understeer {
        v["understeer_gradient_rad_per_mps2"] = json!(u);
    }
    v
}

/// The car's steering ratio and offset against the truth, as `calibrate
/// --method truth` fits them beside the six parameters (`None` for other
/// methods, or without truth or steering).
pub fn car_steering(
    drive: &deadreckon_core::Drive,
    method: deadreckon_core::calibrate::Method,
    min_speed_mps: f64,
) -> Result<
    Option<deadreckon_core::kinematics::steering::SteeringCalibration>,
    deadreckon_core::Error,
> {
    use deadreckon_core::calibrate::Method;
    use deadreckon_core::reference::Reference;
    match (method, Reference::from_truth(&drive.truth)) {
        (Method::Truth, Some(r)) if !drive.steering.is_empty() => {
            deadreckon_core::kinematics::steering::calibrate_steering(drive, &r, min_speed_mps)
                .map(Some)
        }
        _ => Ok(None),
    }
}

/// The `calibrate --json` object: [`calibration_json`] with the parameters
/// not estimated and, when fitted, the steering.
pub fn calibrate_json(
    method: &str,
    c: &Calibration,
    min_speed_mps: f64,
    absent: Absent,
    steering: Option<&deadreckon_core::kinematics::steering::SteeringCalibration>,
) -> Value {
    let mut v = calibration_json(method, c);
    v["not_estimated"] = not_estimated(c, min_speed_mps, absent)
        .into_iter()
        .map(|(k, why)| (k.to_string(), Value::from(why)))
        .collect::<serde_json::Map<_, _>>()
        .into();
    if let Some(st) = steering {
        v["steering"] = steering_json(st);
    }
    if let Some(s) = &c.side_slip {
        v["side_slip"] = side_slip_json(s);
    }
    v
}

/// The rear-axle side-slip gradient of an RTS calibration, as `calibrate
/// --json` reports it: the estimate (value, std, estimated, reason), the
/// fitted value even when not reported as estimated (null without a fit),
/// the nuisance scale and yaw offset, the blocks and their RMS lateral
/// acceleration.
pub fn side_slip_json(s: &deadreckon_core::side_slip::SideSlip) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "rear_slip_gradient_rad_per_mps2": s.gradient,
        "fitted": num(s.fitted),
        "fitted_std": num(s.fitted_std),
        "scale_residual": num(s.scale_residual),
        "yaw_offset_rad": num(s.yaw_offset_rad),
        "blocks": s.blocks,
        "rms_lateral_accel_mps2": num(s.rms_lateral_accel_mps2),
    })
}

/// The wheel-health monitor's report: per wheel (`fl`, `fr`, `rl`, `rr`)
/// the epochs checked and dropped, the largest normalised window sums, and
/// every dropped stretch (`start_s`, `end_s`, `reason` slip or bias,
/// `peak_sigma`).
pub fn wheel_health_json(h: &deadreckon_core::wheel_health::WheelHealth) -> Value {
    let mut m = serde_json::Map::new();
    for (name, w) in deadreckon_core::wheel_health::WHEEL_NAMES
        .iter()
        .zip(&h.wheels)
    {
        if w.epochs_checked == 0 {
            continue;
        }
        m.insert(
            (*name).into(),
            json!({
                "epochs_checked": w.epochs_checked,
                "epochs_dropped": w.epochs_dropped,
                "dropped_s": w.dropped_s(),
                "slip_intervals": w.count(deadreckon_core::wheel_health::DropReason::Slip),
                "bias_intervals": w.count(deadreckon_core::wheel_health::DropReason::Bias),
                "max_short_sigma": w.max_short_sigma,
                "max_long_sigma": w.max_long_sigma,
                "intervals": w.intervals.iter().map(|i| json!({
                    "start_s": i.start_s, "end_s": i.end_s, "reason": i.reason.name(), "peak_sigma": i.peak_sigma,
                })).collect::<Vec<_>>(),
            }),
        );
    }
    Value::Object(m)
}

/// `evaluate --outage LEN --json`: sliding outages of `outage_s` with the
/// parameters from `params` (their source, as printed).
pub fn outage_json(outage_s: f64, params: &str, ev: &OutageEvaluation) -> Value {
    json!({
        "outage_s": outage_s,
        "windows": ev.windows.len(),
        "reference": ev.reference.name(),
        "params": params,
        "start_error_m": summary_json(&ev.start_error()),
        "final_error_m": summary_json(&ev.final_error()),
        "drift_pct": summary_json(&ev.drift_pct()),
        "distance_to_1m_m": summary_json(&ev.distance_to_1m()),
        "windows_reaching_1m": ev.windows.iter().filter(|w| w.time_to(1.0).is_some()).count(),
        "gates": gates_json(&ev.gates),
        "outages": ev.windows.iter().map(outage_window_json).collect::<Vec<_>>(),
        "heading_limit_deg": ev.heading_limit_rad.is_finite().then(|| ev.heading_limit_rad.to_degrees()),
        "unsettled": ev.unsettled.iter().map(outage_window_json).collect::<Vec<_>>(),
        "gyro_bias_switch": ev.bias_switch.as_ref().map(bias_switch_json),
    })
}

/// The gyro-bias switch of an aided run (`run` and `evaluate --outage`
/// `--json`): its threshold, the log-likelihood ratio and the fixes it
/// counted, and when it fired (`null`: the constant bias throughout;
/// `deadreckon_core::aided::switch`).
pub fn bias_switch_json(s: &deadreckon_core::aided::BiasSwitch) -> Value {
    json!({
        "threshold_llr": s.threshold,
        "llr": s.llr,
        "fixes": s.fixes,
        "fired_at_s": s.fired_at_s,
    })
}

/// One outage window of `evaluate --outage --json` (`outages[]`, `unsettled[]`).
fn outage_window_json(w: &deadreckon_core::outage::OutageResult) -> Value {
    json!({
        "start_s": w.start_s, "end_s": w.end_s,
        "start_error_m": w.start_m(), "mean_error_m": w.mean_m(),
        "max_error_m": w.max_m(), "final_error_m": w.final_m(),
        "distance_m": w.distance_m, "time_to_1m_s": w.time_to(1.0),
        "start_yaw_std_deg": w.start_yaw_std_rad.map(f64::to_degrees),
    })
}

/// `evaluate --metric drift --json`, segments of `segment_m`.
pub fn drift_json(r: &DriftResult, segment_m: f64) -> Value {
    let s = Summary::of(&r.errors_pct());
    json!({"metric": "drift", "mean_pct": s.mean, "std_pct": s.std, "n": s.n,
        "median_pct": s.median, "p95_pct": s.p95, "max_pct": s.max, "segment_m": segment_m, "errors_m": r.errors_m, "gates": gates_json(&r.gates)})
}

/// `evaluate --metric reset-1m --json`, resets at `threshold_m`.
pub fn reset_json(r: &ResetResult, threshold_m: f64) -> Value {
    let s = Summary::of(&r.distances_m);
    json!({"metric": "reset-1m", "mean_m": s.mean, "median_m": s.median, "min_m": s.min, "max_m": s.max, "n": s.n,
        "threshold_m": threshold_m, "distances_m": r.distances_m, "gates": gates_json(&r.gates)})
}

/// What an `evaluate --metric rpe|ape` asked for, to print beside the result.
#[derive(Debug, Clone, Copy)]
pub struct EvoQuery<'a> {
    /// `rpe` or `ape`.
    pub metric: &'a str,
    /// The estimated track's name.
    pub track: &'a str,
    /// The reference track's name.
    pub reference: &'a str,
    /// Largest time difference of associated poses, s.
    pub max_diff_s: f64,
    /// RPE: path length between the poses of a pair, m.
    pub delta_m: f64,
    /// RPE: `estimate` or `reference`.
    pub pairs_from: &'a str,
}

/// `evaluate --metric rpe|ape --json`.
pub fn evo_json(q: &EvoQuery<'_>, r: &TrajectoryError) -> Value {
    let mut v = json!({
        "metric": q.metric,
        "track": q.track,
        "reference": q.reference,
        "matched": r.matched,
        "n": r.errors_m.len(),
        "stats_m": r.stats,
        "errors_m": r.errors_m,
        "t_s": r.t_s,
        "evo_version": evo::EVO_VERSION,
        "max_diff_s": q.max_diff_s,
    });
    if q.metric == "rpe" {
        v["delta_m"] = json!(q.delta_m);
        v["pairs_from"] = json!(q.pairs_from);
    }
    v
}

/// `tedris train --json`: the trained model's summary.
pub fn tedris_train_json(m: &TedrisModel, source: ReferenceSource) -> Value {
    let s = m.straight();
    let mut v = json!({
        "source": source,
        "chosen": m.chosen.name(),
        "lag_samples": m.lag_samples,
        "tau_samples": m.tau(),
        // Block means for quantised wheel ticks (issue 35), with why; null:
        // the configured tau_samples with block medians.
        "blocks": m.blocks,
        "blocks_chosen_because": m.blocks.map(|b| b.describe(m.sample_period_s)),
        // The physical acceptance's checks per kind (null for a model read
        // from a file: they are not kept in it) and the kinds it refused.
        "acceptance": m.acceptance,
        "refused_kinds": m.refused_kinds,
        "sample_period_s": m.sample_period_s,
        "mu_m": s.mu_m,
        "w_low_m": s.w_low_m,
        "w_high_m": s.w_high_m,
        "epsilon_m": s.epsilon_m,
        "dcf0_rad": m.dcf0_rad,
        // Not a parameter of the per-metre form (no heading per sample).
        "gyro_bias": m.gyro_bias,
        // From GNSS chords; null while not estimated.
        "distance_scale": m.distance_scale.estimated(),
        "distance_scale_chords": m.distance_scale.chords,
        // The corrections the training drive had (from --params); null: none.
        "corrections": m.corrections,
        "per_metre_straight": m.per_metre_straight,
        "course_convention": m.course_convention,
        "complete": m.complete,
        "fill": m.repositories.fill(m.config.required_bins),
        "fits": m.fits,
    });
    if let (Some(o), Value::Object(c)) = (v.as_object_mut(), tedris_calibrated_json(m)) {
        o.extend(c);
    }
    v
}

/// The calibrated values of a TedriS model with their standard errors
/// (autocorrelation-robust, from the joint calibration that installed
/// them): `dcf_rad`, `dcf_distance_rad_per_m`, `turn_gain` and their
/// `*_std*`. Null: not estimated (not a parameter of the form, not
/// estimated by the variant, or no standard error), never 0.
pub fn tedris_calibrated_json(m: &TedrisModel) -> Value {
    let joint = m.config.joint_calibration();
    json!({
        // Not a parameter of the per-metre form (no heading per sample).
        "dcf_rad": (!m.per_metre_straight).then_some(m.dcf_rad),
        "dcf_std_rad": m.dcf_std_rad.filter(|_| !m.per_metre_straight),
        // Estimated by the joint calibration only (the extended variant):
        // otherwise not estimated, not a nominal value.
        "dcf_distance_rad_per_m": joint.then_some(m.dcf_distance_rad_per_m),
        "dcf_distance_std_rad_per_m": m.dcf_distance_std_rad_per_m.filter(|_| joint),
        "turn_gain": m.config.turn_gain().then_some(m.turn_gain),
        "turn_gain_std": m.turn_gain_std.filter(|_| m.config.turn_gain()),
    })
}

/// The object of `compare --json` (and the demo's `tedris_comparison`).
pub fn comparison_json(c: &deadreckon_eval::compare::Comparison) -> Value {
    let row_json = |r: &Option<deadreckon_core::compared::OutageResult>| match r {
        Some(r) => json!({
            "mean_error_m": r.mean_m(), "max_error_m": r.max_m(), "final_error_m": r.final_m(),
            "time_to_1m_s": r.time_to(1.0), "point": r.point.name(),
        }),
        None => Value::Null,
    };
    json!({
        "reference": {"four_wheel": c.four_wheel_reference, "tedris": c.tedris_reference},
        "four_wheel_params": c.params_source,
        "four_wheel_values": deadreckon_core::Params::NAMES
            .iter()
            .zip(c.params.to_array())
            .map(|(k, v)| (k.to_string(), json!(v)))
            .collect::<serde_json::Map<_, _>>(),
        "tedris_model": c.model_source,
        "four_wheel_gates": gates_json(&c.four_wheel_gates),
        "tedris_checks": c.tedris_checks,
        "outages": c.rows.iter().map(|(o, f, t)| json!({
            "start_s": o.start_s, "end_s": o.end_s,
            "four_wheel": row_json(f), "tedris": row_json(t),
        })).collect::<Vec<_>>(),
    })
}

/// The `calibrate --json` object of a kinematic shape.
pub fn kinematic_calibration_json(
    shape: deadreckon_core::kinematics::Shape,
    method: &str,
    c: &deadreckon_core::kinematics::KinematicCalibration,
) -> Value {
    let params: serde_json::Map<String, Value> = c
        .params
        .iter()
        .map(|p| {
            (
                p.name.clone(),
                json!({"value": p.value, "std": p.std, "estimated": p.estimated, "reason": p.reason}),
            )
        })
        .collect();
    json!({
        "shape": shape.name(),
        "method": method,
        "params": params,
        "correlation": {"names": c.correlated, "matrix": c.correlation},
        "converged": c.converged,
        "termination": c.termination,
        "evaluations": c.evaluations,
        "windows_used": c.windows_used,
        "windows_total": c.windows_total,
        "min_speed_mps": c.min_speed_mps,
        "rms_position_m": c.rms_position_m,
        "rms_heading_rad": c.rms_heading_rad,
        "held_back": c.held_back,
    })
}

/// The `evaluate --outage --json` object (the shape of the car's: `windows`,
/// `final_error_m` with `mean`, `median`, `p95`, `max`).
pub fn kinematic_outages_json(
    shape: deadreckon_core::kinematics::Shape,
    ev: &deadreckon_core::kinematics::KinematicOutages,
    source: &str,
) -> Value {
    let s = ev.final_error();
    json!({
        "outage_s": ev.outage_s,
        "step_s": ev.step_s,
        "windows": ev.windows.len(),
        "reference": "reference pose (start) and measured point (error)",
        "shape": shape.name(),
        "params": source,
        "final_error_m": {"mean": s.mean, "median": s.median, "p95": s.p95, "min": s.min, "max": s.max, "std": s.std, "n": s.n},
    })
}
