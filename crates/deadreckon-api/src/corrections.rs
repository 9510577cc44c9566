//! The timing and mounting corrections ([`deadreckon_core::timing`],
//! [`deadreckon_core::imu`]) as the CLI and the Python bindings show and store
//! them: JSON (`calibrate --json`, `evaluate --outage --json`), the
//! `[delays]`, `[imu]` and `[gyro_scale]` tables of params.toml, and those tables read back
//! and applied to another drive. A params.toml without them (older files)
//! applies nothing.

use deadreckon_core::imu::Tilt;
use deadreckon_core::timing::{self, Corrections, Delay, Stream};
use deadreckon_core::Drive;
use serde_json::{json, Value};

use crate::params_tables::ParamsTables;

fn delay_json(d: &Delay) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "delay_s": num(d.delay_s),
        "std_s": num(d.std_s),
        "applied_s": d.applied_s(),
        "samples": d.samples,
        "estimated": d.status.is_estimated(),
        "reason": d.status.reason(),
    })
}

/// The words after "applied" when the filter applies another delay than
/// the estimate (`Delay::step_offset_s`: the GNSS's with the paper's step,
/// issue 29; the scalar streams' half wheel period over the wheel
/// intervals, issue 28), else nothing.
pub fn step_offset_words(d: &Delay) -> String {
    if d.step_offset_s == 0.0 {
        return String::new();
    }
    format!(
        " as {:+.4} s (the filter's wheel step and streams add {:+.4} s)",
        d.applied_s(),
        d.step_offset_s
    )
}

fn tilt_json(t: &Tilt) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "tilt_deg": num(t.tilt_rad.to_degrees()),
        "std_deg": num(t.std_rad.to_degrees()),
        "pitch_deg": num(t.pitch_rad.to_degrees()),
        "pitch_std_deg": num(t.pitch_std_rad.to_degrees()),
        "roll_deg": num(t.roll_rad.to_degrees()),
        "roll_std_deg": num(t.roll_std_rad.to_degrees()),
        "std_blocks_deg": t.std_blocks_rad.map(|s| num(s.to_degrees())),
        "accel_error_mps2": num(t.accel_error_mps2),
        "gyro_bias": t.gyro_bias.map(|b| json!({
            "bias_rps": num(b.bias_rps),
            "std_rps": num(b.std_rps),
            "span_s": num(b.span_s),
        })),
        "up": t.up,
        "source": t.source.name(),
        "blocks": t.blocks,
        "estimated": t.is_estimated(),
        "reason": t.status.reason(),
    })
}

fn traction_json(t: &deadreckon_core::traction::TractionSlip) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "slip_per_mps2": num(t.slip_per_mps2),
        "std": num(t.std),
        "axle": (t.is_estimated() || t.status.is_measured_not_applied()).then(|| t.axle.name()),
        "blocks": t.blocks,
        "estimated": t.is_estimated(),
        "reason": t.status.reason(),
    })
}

fn scale_json(g: &deadreckon_core::gyro_scale::GyroScale) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "scale_error": num(g.scale_error),
        "std": num(g.std),
        "turns": g.turns,
        "estimated": g.is_estimated(),
        "reason": g.status.reason(),
    })
}

/// `--corrections auto`'s judgement: the windows, the held-back error
/// without corrections, and each candidate's error and decision.
fn held_back_json(h: &deadreckon_core::held_back::HeldBack) -> Value {
    let num = |x: f64| if x.is_finite() { json!(x) } else { Value::Null };
    json!({
        "windows": h.windows,
        "window_s": h.window_s,
        "without_m": num(h.without_m),
        "together_m": h.together_m.map(num),
        "not_judged": h.not_judged,
        "min_z": h.min_z,
        "candidates": h.judged.iter().map(|j| json!({
            "correction": j.correction.key(),
            "z": num(j.z),
            "with_m": num(j.with_m),
            "against_m": num(j.against_m),
            "t": num(j.t),
            "score_t": num(j.score_t),
            "applied": j.applied,
            "by_significance": j.by_significance,
        })).collect::<Vec<_>>(),
    })
}

/// `{"delays": {stream: {...}}, "traction": {...} | null, "imu": {...} | null,
/// "gyro_scale": {...} | null, "held_back": {...} | null}`.
pub fn corrections_json(c: &Corrections) -> Value {
    let delays: serde_json::Map<String, Value> = Stream::ALL
        .iter()
        .map(|&s| (s.name().to_string(), delay_json(c.delays.get(s))))
        .collect();
    json!({
        "delays": delays,
        "traction": c.traction.as_ref().map(traction_json),
        "imu": c.tilt.as_ref().map(tilt_json),
        "gyro_scale": c.gyro_scale.as_ref().map(scale_json),
        "held_back": c.held_back.as_ref().map(held_back_json),
        "model": serde_json::to_value(c.model).unwrap_or(Value::Null),
    })
}

/// Corrections read back from params.toml (applied as they are).
pub type Stored = timing::KnownCorrections;

/// The report's rows of what is applied: each stored delay, the tilt of
/// the stored vertical, the gyro scale error, the driven axle's slip (no
/// standard errors: params.toml keeps the values applied), and the
/// additions to the paper's model in words (`[model]`).
pub fn stored_rows(stored: &Stored) -> Vec<deadreckon_report::CorrectionRow> {
    let row = |what: String, unit: &str, value: f64| deadreckon_report::CorrectionRow {
        what,
        unit: unit.into(),
        value: Some(value),
        std: None,
        status: "stored, applied".into(),
    };
    let mut rows: Vec<_> = Stream::ALL
        .iter()
        .zip(stored.delays_s)
        .filter(|(_, d)| *d != 0.0)
        .map(|(s, d)| row(format!("{} delay", s.name()), "s", d))
        .collect();
    if let Some(up) = stored.up {
        rows.push(row(
            "IMU tilt".into(),
            "°",
            up[2].clamp(-1.0, 1.0).acos().to_degrees(),
        ));
    }
    if stored.gyro_scale_error != 0.0 {
        rows.push(row(
            "gyro scale error".into(),
            "%",
            100.0 * stored.gyro_scale_error,
        ));
    }
    let k = stored.traction_slip_per_mps2;
    if k != 0.0 {
        let axle = if k > 0.0 { "front" } else { "rear" };
        rows.push(row(
            format!("{axle} axle slip per m/s²"),
            "%",
            100.0 * k.abs(),
        ));
    }
    // The additions to the paper's model (`[model]`: the receiver's wander,
    // the walking gyro bias, ...) set on the vehicle with them.
    if !stored.model.is_empty() {
        rows.push(deadreckon_report::CorrectionRow {
            what: format!("model: {}", stored.model.words()),
            status: "stored, applied".into(),
            ..Default::default()
        });
    }
    rows
}

/// The corrections stored in the params.toml at `spec` (nothing for
/// `nominal`), as `--params` applies them in the CLI and the Python bindings
/// ([`crate::params_file::ParamsFile::read`]). The error names the file.
pub fn stored_in_file(spec: &std::path::Path) -> Result<Stored, String> {
    if spec.as_os_str() == "nominal" {
        return Ok(Stored::default());
    }
    crate::params_file::ParamsFile::read(&spec.to_string_lossy())
        .map(|f| f.corrections)
        .map_err(|e| crate::chain_text(&e))
}

/// Reads the `[delays]`, `[traction]`, `[imu]`, `[gyro_scale]` and `[model]`
/// tables from the keys of a params.toml (its extra keys, or the whole
/// file's table: the six parameters and `[std]` are left aside; absent:
/// nothing to apply), through the typed tables ([`ParamsTables`],
/// [`stored_of`]).
pub fn stored_corrections(extra: &toml::Table) -> Result<Stored, String> {
    let mut extra = extra.clone();
    for k in deadreckon_core::Params::NAMES.iter().chain(&["std"]) {
        extra.remove(*k);
    }
    let tables: ParamsTables = extra
        .try_into()
        .map_err(|e: toml::de::Error| crate::params_file::toml_message("", &e))?;
    stored_of(&tables)
}

/// The corrections a params.toml's tables store, checked: each delay
/// plausible (|d| < 10 s), the IMU's vertical a unit vector, the slip and
/// the gyro scale error within their limits, the model additions valid.
pub fn stored_of(t: &ParamsTables) -> Result<Stored, String> {
    let mut s = Stored::default();
    if let Some(m) = t.model {
        m.validate()?;
        s.model = m;
    }
    if let Some(d) = &t.delays {
        for (i, st) in Stream::ALL.iter().enumerate() {
            if let Some(dt) = d.get(*st) {
                let v = dt.delay_s;
                if !(v.is_finite() && v.abs() < 10.0) {
                    return Err(format!(
                        "`delays.{}.delay_s` = {v} is not a plausible delay (|d| < 10 s)",
                        st.name()
                    ));
                }
                s.delays_s[i] = v;
            }
        }
    }
    if let Some(up) = t.imu.as_ref().and_then(|imu| imu.up.as_ref()) {
        let n = up.iter().map(|x| x * x).sum::<f64>().sqrt();
        if up.len() != 3 || !(n - 1.0).abs().lt(&1e-3) {
            return Err("`imu.up` must be a unit vector of 3 numbers".into());
        }
        s.up = Some([up[0], up[1], up[2]]);
    }
    if let Some(tr) = &t.traction {
        if let Some(v) = tr.slip_per_mps2 {
            if !(v.is_finite() && v.abs() <= deadreckon_core::traction::MAX_SLIP_PER_MPS2) {
                return Err(format!(
                    "`traction.slip_per_mps2` = {v} is not a plausible tyre slip (|κ| ≤ {} per m/s²)",
                    deadreckon_core::traction::MAX_SLIP_PER_MPS2
                ));
            }
            s.traction_slip_per_mps2 = v;
        }
        if let Some(v) = tr.mean_force_mps2 {
            if !(v.is_finite() && v.abs() < 100.0) {
                return Err(format!(
                    "`traction.mean_force_mps2` = {v} is not a plausible mean forward specific force (|f| < 100 m/s²)"
                ));
            }
            s.traction_mean_force_mps2 = Some(v);
        }
    }
    if let Some(v) = t.gyro_scale.as_ref().and_then(|g| g.scale_error) {
        if !(v.is_finite() && v.abs() <= deadreckon_core::gyro_scale::MAX_SCALE_ERROR) {
            return Err(format!(
                "`gyro_scale.scale_error` = {v} is not a plausible gyro scale error"
            ));
        }
        s.gyro_scale_error = v;
    }
    Ok(s)
}

/// The tables of stored corrections, the zero ones left out: what a file
/// of parameters learned on corrected events carries on (`stream --learn`),
/// so that the next stream given it applies them too. [`stored_of`] reads
/// them back as they were.
pub fn stored_tables(stored: &Stored) -> ParamsTables {
    use crate::params_tables::{DelayTable, DelaysTable, GyroScaleTable, ImuTable, TractionTable};
    let mut delays = DelaysTable::default();
    for (st, d) in Stream::ALL.iter().zip(stored.delays_s) {
        if d != 0.0 {
            *delays.get_mut(*st) = Some(DelayTable {
                delay_s: d,
                ..Default::default()
            });
        }
    }
    ParamsTables {
        delays: (delays != DelaysTable::default()).then_some(delays),
        imu: stored.up.map(|up| ImuTable {
            up: Some(up.to_vec()),
            ..Default::default()
        }),
        gyro_scale: (stored.gyro_scale_error != 0.0).then(|| GyroScaleTable {
            scale_error: Some(stored.gyro_scale_error),
            ..Default::default()
        }),
        traction: (stored.traction_slip_per_mps2 != 0.0).then(|| TractionTable {
            slip_per_mps2: Some(stored.traction_slip_per_mps2),
            mean_force_mps2: stored.traction_mean_force_mps2,
            ..Default::default()
        }),
        model: (!stored.model.is_empty()).then_some(stored.model),
        ..Default::default()
    }
}

/// Estimates the corrections `which` asks for (driven axle's slip, IMU tilt,
/// delays, gyro scale) and applies them (with `auto`, those the held-back
/// GNSS chose: [`deadreckon_core::held_back`]): the drive a calibration
/// runs on, and what was found.
/// The one call `calibrate`, `evaluate` and Python make.
pub fn estimate_and_apply(
    drive: &Drive,
    copts: &deadreckon_core::calibrate::CalibrationOptions,
    which: timing::Which,
) -> Result<(Drive, Corrections), crate::Error> {
    estimate_and_apply_calibrated(drive, copts, which).map(|(d, c, _)| (d, c))
}

/// The corrected drive, what was found, and the drive's calibration when
/// choosing the corrections ran it already.
pub type Corrected = (
    Drive,
    Corrections,
    Option<deadreckon_core::calibrate::Calibration>,
);

/// [`estimate_and_apply`], also returning the corrected drive's calibration
/// with `copts` when choosing the corrections ran it already
/// ([`deadreckon_core::held_back::prepare_calibrated`]).
pub fn estimate_and_apply_calibrated(
    drive: &Drive,
    copts: &deadreckon_core::calibrate::CalibrationOptions,
    which: timing::Which,
) -> Result<Corrected, crate::Error> {
    deadreckon_core::held_back::prepare_calibrated(
        drive,
        copts,
        &timing::DelayOptions::default(),
        which,
    )
    .map_err(estimating)
}

/// [`estimate_and_apply_calibrated`] of a drive handed over, corrected in
/// place ([`deadreckon_core::held_back::prepare_calibrated_owned`]).
pub fn estimate_and_apply_owned(
    drive: Drive,
    copts: &deadreckon_core::calibrate::CalibrationOptions,
    which: timing::Which,
) -> Result<Corrected, crate::Error> {
    deadreckon_core::held_back::prepare_calibrated_owned(
        drive,
        copts,
        &timing::DelayOptions::default(),
        which,
    )
    .map_err(estimating)
}

/// The error of estimating the corrections.
fn estimating(source: deadreckon_core::Error) -> crate::Error {
    crate::Error::Calibration {
        what: "estimating the streams' delays and the IMU tilt",
        source,
    }
}
