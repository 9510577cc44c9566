//! `deadreckon stream`: the four-wheel filter on JSON-line events from
//! standard input, one JSON line per filter epoch on standard output.

use std::io::{BufRead, Write};

use anyhow::{Context, Result};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::online::{LearnTargets, Online, Start};
use deadreckon_core::{Params, ParamsWithStd};

use super::common;

use crate::args::stream::*;

/// Prior standard deviations of the learned parameters without a params.toml
/// [std] (those of the offline calibration's augmented pass).
fn default_prior() -> Params {
    deadreckon_core::calibrate::CalibrationOptions::default().prior_std
}

/// Runs `stream`.
pub fn run(a: StreamArgs) -> Result<()> {
    // The learned parameters and the state file (read, then written) are
    // outputs: neither may be the vehicle or the parameters read.
    let inputs = [a.vehicle.as_path(), std::path::Path::new(&a.params)];
    for out in a.params_out.iter().chain(a.state.iter()) {
        super::common::check_output(out, &inputs)?;
    }
    let vehicle = deadreckon_io::read_vehicle(&a.vehicle)
        .with_context(|| format!("reading {}", a.vehicle.display()))?;
    let (params, prior) = if a.params == "nominal" {
        let p = Params::nominal(&vehicle);
        (p, default_prior())
    } else {
        let p = deadreckon_api::load::params_file(&a.params)?;
        let stored = deadreckon_api::corrections::stored_in_file(std::path::Path::new(&a.params))
            .map_err(anyhow::Error::msg)?;
        if stored != Default::default() {
            // Live events cannot be re-timed or re-projected here: say so
            // rather than run as if they had been.
            eprintln!(
                "warning: {} stores corrections that `stream` does not apply to the events                  (delays {:?} s, IMU vertical {:?}, gyro scale error {}); its parameters were                  calibrated on corrected streams (calibrate --corrections none gives parameters                  for raw events)",
                a.params, stored.delays_s, stored.up, stored.gyro_scale_error
            );
        }
        // A std of 0 (a parameter the file fixes) would freeze it: keep the
        // default prior where the file's is not positive.
        let d = default_prior();
        let pick = |s: f64, d: f64| if s > 0.0 { s } else { d };
        let prior = Params {
            gyro_bias_rps: pick(p.std.gyro_bias_rps, d.gyro_bias_rps),
            speed_scale: pick(p.std.speed_scale, d.speed_scale),
            circumference_fl_m: pick(p.std.circumference_fl_m, d.circumference_fl_m),
            circumference_fr_m: pick(p.std.circumference_fr_m, d.circumference_fr_m),
            circumference_rl_m: pick(p.std.circumference_rl_m, d.circumference_rl_m),
            circumference_rr_m: pick(p.std.circumference_rr_m, d.circumference_rr_m),
        };
        (p.params, prior)
    };
    let opts = FilterOptions {
        timing: a.timing.into(),
        ..Default::default()
    };
    let mut online = match a.state.as_ref().filter(|p| p.exists()) {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading state {}", path.display()))?;
            serde_json::from_str::<Online>(&text)
                .with_context(|| format!("state {}", path.display()))?
        }
        None if a.learn => Online::learning(&vehicle, &params, &prior, &opts, Start::Gnss)?,
        None => Online::new(&vehicle, &params, &opts, Start::Gnss)?,
    };
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    let write_err: std::cell::RefCell<Option<std::io::Error>> = Default::default();
    let mut emit = |p: deadreckon_core::TrackPoint| {
        if write_err.borrow().is_some() {
            return;
        }
        let line = serde_json::to_string(&p).unwrap_or_default();
        if let Err(e) = writeln!(out, "{line}").and_then(|_| out.flush()) {
            *write_err.borrow_mut() = Some(e);
        }
    };
    let targets = LearnTargets::default();
    let mut skipped = 0u64;
    let mut last_save: Option<f64> = None;
    let stdin = std::io::stdin();
    for (i, line) in stdin.lock().lines().enumerate() {
        let line_no = i as u64 + 1;
        let line = line.with_context(|| format!("stdin: line {line_no}"))?;
        if line.trim().is_empty() {
            continue;
        }
        let ev = match deadreckon_io::events::parse_line(&line, "stdin", line_no) {
            Ok(ev) => ev,
            Err(e) if a.on_bad_line == OnBadLine::Skip => {
                eprintln!("skipped: {e}");
                skipped += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        online
            .push(ev, &mut emit)
            .with_context(|| format!("stdin: line {line_no}"))?;
        if let (Some(every), Some(path)) = (a.save_every_s, &a.params_out) {
            if last_save.is_none_or(|t| ev.t_s - t >= every) {
                if let Some(l) = online.learned(&targets) {
                    save_learned(path, &l)?;
                    last_save = Some(ev.t_s);
                }
            }
        }
        if write_err.borrow().is_some() {
            break;
        }
    }
    if write_err.borrow().is_none() {
        online.finish(&mut emit)?;
    }
    if let Some(e) = write_err.take() {
        return common::quiet_on_broken_pipe(Err(e));
    }
    if let Some(path) = &a.state {
        let text = serde_json::to_string(&online)?;
        deadreckon_io::atomic_write(path, |w| w.write_all(text.as_bytes()))
            .with_context(|| format!("writing state {}", path.display()))?;
    }
    if let Some(st) = online.stats() {
        eprintln!("{}", common::stats_line(&st));
    }
    if skipped > 0 {
        eprintln!("{skipped} bad lines skipped");
    }
    if let Some(l) = online.learned(&targets) {
        eprintln!(
            "learned: {:.0}% calibrated, {}",
            l.calibrated_pct,
            if l.valid { "valid" } else { "not yet valid" }
        );
        if let Some(path) = &a.params_out {
            save_learned(path, &l)?;
            eprintln!("wrote {}", path.display());
        }
    }
    Ok(())
}

fn save_learned(path: &std::path::Path, l: &deadreckon_core::online::Learned) -> Result<()> {
    let mut extra = toml::Table::new();
    extra.insert("method".into(), "online".into());
    extra.insert("valid".into(), l.valid.into());
    extra.insert("calibrated_pct".into(), l.calibrated_pct.into());
    deadreckon_io::write_params(
        path,
        &ParamsWithStd {
            params: l.params,
            std: l.std,
        },
        Some(&extra),
    )
    .with_context(|| format!("writing {}", path.display()))
}
