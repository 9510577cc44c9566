//! `deadreckon stream`: the four-wheel filter on JSON-line events
//! (`docs/events.md`), one JSON pose per filter epoch out, resumable from a
//! state file, optionally learning the six parameters and saving them as it
//! goes. The corrections a params.toml stores (delays, IMU tilt, gyro
//! scale, driven-axle slip) are applied to the events as `run --params`
//! applies them to a drive ([`deadreckon_core::live_corrections`]). Each
//! pose carries its 95 % bound (`bound_95_m`, with the factor the
//! params.toml's `[bound]` stores: [`deadreckon_core::bound_pose`]), equal
//! to `run`'s on the filtered track.

use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};

use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::online::{LearnTargets, Learned, Online, Start};
use deadreckon_core::{Params, ParamsWithStd, Vehicle};

use crate::error::While;
use crate::Error;

/// Prior standard deviations of the learned parameters without a
/// params.toml `[std]` (those of the offline calibration's augmented pass).
pub fn default_prior() -> Params {
    deadreckon_core::calibrate::CalibrationOptions::default().prior_std
}

/// What a stream starts from: the parameters, the learning prior, the
/// corrections to apply and the 95 % bound's factor, all from one read of
/// the params.toml ([`crate::params_file::ParamsFile::read`]).
#[derive(Debug, Clone, PartialEq)]
pub struct StartParams {
    /// The starting parameters.
    pub params: Params,
    /// The prior standard deviations of the learned parameters.
    pub prior: Params,
    /// The corrections the file stores, applied to the events.
    pub stored: crate::corrections::Stored,
    /// The bound's factor the file stores (its `[bound]`, else the
    /// filter's covariance alone).
    pub bound: deadreckon_core::bound::BoundFit,
}

/// The start of `nominal` (the vehicle's parameters, the default prior,
/// no corrections, the filter's covariance alone) or of a params.toml (its
/// values; its `[std]` where positive — a std of 0 would freeze a
/// parameter —, else the default prior; the corrections and the bound it
/// stores), the file read once as `--params` reads it for every other
/// command, its circumferences checked against `vehicle`.
pub fn start_params(spec: &str, vehicle: &Vehicle) -> Result<StartParams, Error> {
    if spec == "nominal" {
        return Ok(StartParams {
            params: Params::nominal(vehicle),
            prior: default_prior(),
            stored: Default::default(),
            bound: deadreckon_core::bound::BoundFit::FILTER,
        });
    }
    let file = crate::params_file::ParamsFile::read(spec)?;
    crate::load::check_against_vehicle(spec, &file.estimate.params, vehicle)?;
    Ok(started_from(file))
}

/// One pose line of `stream` (without the newline): the pose's keys
/// (`t_s`, `east_m`, …, `cov_pose`), then `bound_95_m` (null when not a
/// number).
pub fn pose_line(p: &deadreckon_core::bound_pose::Pose) -> String {
    let mut line = serde_json::to_string(&p.point).unwrap_or_default();
    if line.ends_with('}') {
        line.pop();
        let b = serde_json::to_string(&p.bound_95_m).unwrap_or_else(|_| "null".into());
        line.push_str(&format!(",\"bound_95_m\":{b}}}"));
    }
    line
}

/// [`start_params`] on the text of a params.toml (the C API is handed text);
/// `name` names it in errors.
pub fn start_params_from_text(text: &str, name: &str) -> Result<StartParams, Error> {
    Ok(started_from(crate::params_file::ParamsFile::parse(
        text, name,
    )?))
}

/// Stored corrections in words: each stream's delay by its name, the IMU's
/// tilt, the gyro scale error and the driven axle's slip, the zero ones left
/// out.
fn stored_words(stored: &crate::corrections::Stored) -> String {
    let mut text = crate::text::known_corrections_text(stored);
    if stored.traction_slip_per_mps2 != 0.0 {
        if !text.is_empty() {
            text.push_str(", ");
        }
        text.push_str(&format!(
            "driven-axle slip {:+.3}% per m/s²",
            100.0 * stored.traction_slip_per_mps2
        ));
    }
    text
}

/// What the filter does with the corrections of the params.toml `name`, in
/// words for stderr (`None` when it stores none): which it applies and the
/// latency their reorder buffer adds.
pub fn corrections_note(name: &str, online: &Online) -> Option<String> {
    let c = online.corrections();
    if c.known().is_empty() {
        return None;
    }
    Some(format!(
        "applying the corrections {name} stores ({}): poses {}",
        stored_words(c.known()),
        latency_words(online.hold_s())
    ))
}

/// The latency the corrections add, in words.
fn latency_words(hold_s: f64) -> String {
    if hold_s > 0.0 {
        format!("held back {hold_s:.3} s of stream time (events reordered on corrected time)")
    } else {
        "not held back (no positive delay, no slip)".into()
    }
}

/// The warning of a params.toml whose stored corrections the filter cannot
/// apply as `run` does: a driven-axle slip without the mean forward
/// specific force it is applied at (files written before it).
pub fn corrections_warning(name: &str, online: &Online) -> Option<String> {
    online.corrections().slip_left_out().then(|| {
        format!(
            "{name} stores a driven-axle slip without `traction.mean_force_mps2` (written before it): a stream cannot know the drive's mean forward specific force, so the slip is not applied (`run` applies it at each drive's own mean); calibrate again to store it"
        )
    })
}

/// The starting parameters and the prior of a read params.toml.
fn started_from(file: crate::params_file::ParamsFile) -> StartParams {
    let d = default_prior().to_array();
    let s = file.estimate.std.to_array();
    let prior = Params::from_array(std::array::from_fn(
        |i| if s[i] > 0.0 { s[i] } else { d[i] },
    ));
    StartParams {
        params: file.estimate.params,
        prior,
        stored: file.corrections,
        bound: file.bound,
    }
}

/// How a stream runs.
#[derive(Debug, Clone)]
pub struct StreamOptions {
    /// The filter's options.
    pub filter: FilterOptions,
    /// Resume from this state file if it exists, and write the state to it
    /// at the end.
    pub state: Option<PathBuf>,
    /// Learn the six parameters (the 11-state filter).
    pub learn: bool,
    /// Write the learned parameters here at the end (and every
    /// `save_every_s` of stream time).
    pub params_out: Option<PathBuf>,
    /// Save period, s of stream time.
    pub save_every_s: Option<f64>,
    /// Skip (and count) bad lines instead of refusing them.
    pub skip_bad_lines: bool,
    /// With `state`: this input is the stream's last part, so what the
    /// stored corrections hold back is released at its end (without it the
    /// held-back events stay in the state for the next part). Without
    /// `state` everything is always released at the end.
    pub last_part: bool,
}

/// What a stream did.
#[derive(Debug)]
pub struct StreamSummary {
    /// The filter's statistics line.
    pub stats: Option<String>,
    /// The bad lines skipped.
    pub skipped: u64,
    /// The parameters learned at the end.
    pub learned: Option<Learned>,
    /// The writing of the poses failed (a closed pipe): the stream stopped
    /// there, and neither the state nor the learned parameters were written.
    pub write_error: Option<std::io::Error>,
    /// How long the stored corrections held events back, s of stream time
    /// (the latency they add to every pose; 0 without delays or slip).
    pub hold_s: f64,
    /// Events still held back at the end and kept in the state file (with
    /// `--state`: the resumed stream releases them; without, everything is
    /// released at the end and this is 0).
    pub held_in_state: usize,
}

/// The filter: resumed from `o.state` if that file exists (with the
/// corrections, and the events they held back, saved in it), else started
/// from GNSS with `params` (learning from `prior` with `o.learn`), applying
/// the stored `corrections` to the events
/// ([`deadreckon_core::online::Online::with_corrections`]).
pub fn open(
    vehicle: &Vehicle,
    params: &Params,
    prior: &Params,
    corrections: &crate::corrections::Stored,
    o: &StreamOptions,
) -> Result<Online, Error> {
    let fresh = match o.state.as_ref().filter(|p| p.exists()) {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .doing(|| format!("reading state {}", path.display()))?;
            return state_from_text(&text, &path.display().to_string());
        }
        None if o.learn => Online::learning(
            &with_model(vehicle, corrections),
            params,
            prior,
            &o.filter,
            Start::Gnss,
        )?,
        None => Online::new(
            &with_model(vehicle, corrections),
            params,
            &o.filter,
            Start::Gnss,
        )?,
    };
    fresh
        .with_corrections(corrections)
        .map_err(|e| Error::Invalid(format!("stored corrections: {e}")))
}

/// `vehicle` with the additions to the paper's model that `corrections`
/// stores ([`deadreckon_core::model_options`]), as `run` applies them to a
/// drive's vehicle ([`deadreckon_core::timing::KnownCorrections::apply`]).
fn with_model(vehicle: &Vehicle, corrections: &crate::corrections::Stored) -> Vehicle {
    let mut v = vehicle.clone();
    corrections.model.apply_to(&mut v);
    v
}

/// What a live filter starts from: the vehicle read from `vehicle`, the
/// filter ([`open`]: resumed from `o.state`, else started with the
/// parameters and corrections `params` names, [`start_params`]) and what to
/// tell of the corrections ([`corrections_note`], [`corrections_warning`]).
/// A filter not resumed gives its poses the bound `params` stores
/// ([`StartParams::bound`]); a resumed one keeps its state's.
pub fn start(
    vehicle: &Path,
    params: &str,
    o: &StreamOptions,
) -> Result<(Vehicle, Online, Option<String>), Error> {
    let v =
        deadreckon_io::read_vehicle(vehicle).doing(|| format!("reading {}", vehicle.display()))?;
    let start = start_params(params, &v)?;
    let resumed = o.state.as_ref().is_some_and(|p| p.exists());
    let mut online = open(&v, &start.params, &start.prior, &start.stored, o)?;
    if !resumed {
        online = online.with_bound(start.bound);
    }
    let warning = corrections_warning(params, &online);
    Ok((v, online, warning))
}

/// Runs the filter over the event lines of `input` (named `source` in
/// errors), writing one JSON pose a line to `out`; saves the learned
/// parameters as asked and the state at the end. A bad line skipped is
/// told to `on_skipped` as it comes.
pub fn run(
    online: &mut Online,
    input: impl BufRead,
    source: &str,
    mut out: impl Write,
    o: &StreamOptions,
    on_skipped: &mut dyn FnMut(&str),
) -> Result<StreamSummary, Error> {
    let write_error: std::cell::RefCell<Option<std::io::Error>> = Default::default();
    let mut emit = |p: deadreckon_core::bound_pose::Pose| {
        if write_error.borrow().is_some() {
            return;
        }
        let line = pose_line(&p);
        if let Err(e) = writeln!(out, "{line}").and_then(|_| out.flush()) {
            *write_error.borrow_mut() = Some(e);
        }
    };
    let targets = LearnTargets::default();
    let mut skipped = 0;
    let mut last_save: Option<f64> = None;
    for (i, line) in input.lines().enumerate() {
        let line_no = i as u64 + 1;
        let line = line.doing(|| format!("{source}: line {line_no}"))?;
        if line.trim().is_empty() {
            continue;
        }
        let ev = match deadreckon_io::events::parse_line(&line, source, line_no) {
            Ok(ev) => ev,
            Err(e) if o.skip_bad_lines => {
                on_skipped(&e.to_string());
                skipped += 1;
                continue;
            }
            Err(e) => return Err(e.into()),
        };
        online
            .push_poses(ev, &mut emit)
            .doing(|| format!("{source}: line {line_no}"))?;
        if let (Some(every), Some(path)) = (o.save_every_s, &o.params_out) {
            if last_save.is_none_or(|t| ev.t_s - t >= every) {
                if let Some(l) = online.learned(&targets) {
                    save_learned(path, &l, online.corrections().known())?;
                    last_save = Some(ev.t_s);
                }
            }
        }
        if write_error.borrow().is_some() {
            break;
        }
    }
    if write_error.borrow().is_none() {
        if o.state.is_some() && !o.last_part {
            // The stream may be resumed: what the corrections hold back
            // stays in the state, and the resumed stream releases it.
            online.finish_poses(&mut emit)?;
        } else {
            online.end_poses(&mut emit)?;
        }
    }
    let write_error = write_error.take();
    let learned = online.learned(&targets);
    if write_error.is_none() {
        if let Some(path) = &o.state {
            save_state(path, online)?;
        }
        if let (Some(l), Some(path)) = (&learned, &o.params_out) {
            save_learned(path, l, online.corrections().known())?;
        }
    }
    Ok(StreamSummary {
        stats: online.stats().map(|s| crate::text::stats_line(&s)),
        skipped,
        learned,
        write_error,
        hold_s: online.hold_s(),
        held_in_state: if o.state.is_some() && !o.last_part {
            online.corrections().held()
        } else {
            0
        },
    })
}

/// Writes the filter's state to `path` (atomically), which [`open`] resumes
/// from: `stream --state` and `ros2 --state` share the file.
pub fn save_state(path: &Path, online: &Online) -> Result<(), Error> {
    let text = state_text(online)?;
    deadreckon_io::atomic_write(path, |w| w.write_all(text.as_bytes()))
        .doing(|| format!("writing state {}", path.display()))
}

/// The filter's whole state as the text `--state` writes (JSON): what the C
/// API's `dr_save_state` returns as bytes.
pub fn state_text(online: &Online) -> Result<String, Error> {
    serde_json::to_string(online).doing(|| "the filter's state".into())
}

/// The filter from [`state_text`]'s text; `name` names it in errors.
pub fn state_from_text(text: &str, name: &str) -> Result<Online, Error> {
    serde_json::from_str::<Online>(text).doing(|| format!("state {name}"))
}

/// Writes learned parameters as a params.toml (method `online`, whether
/// they are valid yet, the percentage calibrated), with the stored
/// corrections the events were corrected with (the parameters belong to
/// the corrected streams: [`crate::corrections::stored_tables`]).
pub fn save_learned(
    path: &Path,
    l: &Learned,
    corrections: &crate::corrections::Stored,
) -> Result<(), Error> {
    let tables = crate::params_file::ParamsTables {
        method: Some("online".into()),
        valid: Some(l.valid),
        calibrated_pct: Some(l.calibrated_pct),
        ..crate::corrections::stored_tables(corrections)
    };
    let estimate = ParamsWithStd {
        params: l.params,
        std: l.std,
    };
    crate::params_file::ParamsFile::new(estimate, tables, &path.display().to_string())?.write(path)
}
