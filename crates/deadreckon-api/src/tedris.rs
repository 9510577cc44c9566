//! TedriS models read from files, for the command line and the Python
//! bindings.

use std::path::Path;

use deadreckon_core::timing::KnownCorrections;
use deadreckon_core::Drive;
use deadreckon_tedris::{
    ModelChoice, ModelKind, ReferenceSource, RepositoryFit, TedrisConfig, TedrisModel, Variant,
};

use crate::Error;

/// How `tedris train` is configured (the command's options, Python's
/// arguments); `None` leaves the configuration's value.
#[derive(Debug, Clone, Default)]
pub struct TrainOptions {
    /// The reference heading (`None`: the course if the fixes have one,
    /// else the gyro).
    pub reference: Option<ReferenceSource>,
    /// A whole configuration (`--config`); without it the variant's preset,
    /// or the robot preset with the gyro reference, or the default.
    pub config: Option<TedrisConfig>,
    /// The method variant.
    pub variant: Option<Variant>,
    /// The regression kind (`None`: the automatic choice).
    pub model: Option<ModelKind>,
    /// τ, samples per block.
    pub tau_samples: Option<usize>,
    /// k of ε = k·(W_H − W_L) (`Some(None)`: one repository).
    pub epsilon_factor: Option<Option<f64>>,
    /// Fit each repository separately, as in the paper.
    pub separate_repositories: bool,
    /// A params.toml whose stored corrections (delays, IMU tilt, gyro
    /// scale) the drive gets before training; the model keeps them.
    pub params: Option<String>,
}

/// The corrections stored in the params.toml `spec`, `None` when it stores
/// none (or is `nominal`).
fn stored(spec: &str) -> Result<Option<KnownCorrections>, Error> {
    let k = crate::corrections::stored_in_file(Path::new(spec)).map_err(Error::Invalid)?;
    Ok((!k.is_empty()).then_some(k))
}

/// The reference heading and the configuration `o` asks for on `drive`,
/// checked: one rule for the command line and Python (each built its own).
pub fn train_config(
    drive: &Drive,
    o: &TrainOptions,
) -> Result<(Option<ReferenceSource>, TedrisConfig), Error> {
    let source = o.reference.or_else(|| ReferenceSource::auto(drive).ok());
    let mut cfg = match &o.config {
        Some(c) => c.clone(),
        None if o.variant == Some(Variant::Paper) => TedrisConfig::paper(),
        None if source == Some(ReferenceSource::Gyro) => TedrisConfig::robot(),
        None => TedrisConfig::default(),
    };
    if let Some(v) = o.variant {
        cfg.variant = v;
    }
    if let Some(k) = o.model {
        cfg.model = ModelChoice::Fixed(k);
    }
    if let Some(t) = o.tau_samples {
        cfg.tau_samples = t;
    }
    if let Some(k) = o.epsilon_factor {
        cfg.epsilon_factor = k;
    }
    if o.separate_repositories {
        cfg.repository_fit = RepositoryFit::Separate;
    }
    cfg.validate().map_err(Error::Tedris)?;
    Ok((source, cfg))
}

/// Trains a model on `drive` as `o` asks ([`train_config`]), with the
/// corrections of `o.params` applied first and kept in the model.
pub fn train(drive: &Drive, o: &TrainOptions) -> Result<(TedrisModel, ReferenceSource), Error> {
    let known = match &o.params {
        Some(p) => stored(p)?,
        None => None,
    };
    let corrected;
    let drive = match &known {
        Some(k) => {
            corrected = k.apply(drive);
            &corrected
        }
        None => drive,
    };
    let (source, cfg) = train_config(drive, o)?;
    let (mut m, source) = deadreckon_tedris::train(drive, cfg, source).map_err(Error::Tedris)?;
    m.corrections = known;
    Ok((m, source))
}

/// The drive a model runs on: with the corrections stored in `params` when
/// given, else with those the model was trained with; and which were
/// applied (`None`: none).
pub fn corrected_for_run(
    drive: &Drive,
    model: &TedrisModel,
    params: Option<&str>,
) -> Result<(Drive, Option<String>), Error> {
    let (known, from) = match params {
        Some(p) => (stored(p)?, format!("stored in {p}")),
        None => (model.corrections, "the model's (trained with them)".into()),
    };
    Ok(match known {
        Some(k) => (k.apply(drive), Some(from)),
        None => (drive.clone(), None),
    })
}

/// Writes a model as JSON, whole or not at all (a temporary beside it,
/// renamed), with the permissions of a model it replaces.
pub fn write_model(path: &Path, m: &TedrisModel) -> Result<(), Error> {
    use crate::error::While;
    let text = serde_json::to_string_pretty(m).doing(|| "the model as JSON".into())?;
    deadreckon_io::atomic_write(path, |w| w.write_all(text.as_bytes()))
        .doing(|| format!("writing {}", path.display()))
}

/// TedriS through outages as `tedris run` does it: the model run through
/// them, the track written as CSV to `track` if given.
pub fn run_outages(
    drive: &Drive,
    model: &TedrisModel,
    outages: &[deadreckon_tedris::Outage],
    opts: &deadreckon_tedris::RunOptions,
    track: Option<&Path>,
    params: Option<&str>,
) -> Result<(deadreckon_tedris::OutageReport, Option<String>), Error> {
    use crate::error::While;
    let (drive, corrections) = corrected_for_run(drive, model, params)?;
    let r = deadreckon_tedris::run_outages_with(&drive, model, outages, opts)
        .map_err(Error::Outages)?;
    if let Some(p) = track {
        deadreckon_io::write_track_csv(p, std::slice::from_ref(&r.track))
            .doing(|| format!("writing {}", p.display()))?;
    }
    Ok((r, corrections))
}

/// `tedris run --json`.
pub fn run_json(
    r: &deadreckon_tedris::OutageReport,
    model: &TedrisModel,
    track: Option<&Path>,
    corrections: Option<&str>,
) -> serde_json::Value {
    serde_json::json!({
        "corrections": corrections,
        "outages": r.outages,
        "reference": r.reference,
        "source": r.source,
        "model": model.chosen.name(),
        // The values the machine holds at the end of the run (it keeps
        // calibrating while the reference is good), with their standard
        // errors; null without a model.
        "calibrated": r.machine.model().map(crate::json::tedris_calibrated_json),
        // Not "checks": that key holds the plausibility checks of every --json object.
        "tedris_checks": r.machine.checks(),
        "track": track.map(|p| p.display().to_string()),
    })
}

/// The model in the JSON file `path` (`tedris train --out`), checked:
/// errors name the file.
pub fn read_model(path: &Path) -> Result<TedrisModel, Error> {
    let text = std::fs::read_to_string(path).map_err(|source| Error::ModelFile {
        path: path.to_path_buf(),
        source,
    })?;
    TedrisModel::from_json(&text).map_err(|source| Error::Model {
        path: path.to_path_buf(),
        source,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_report_and_compare_loaded_a_model_without_checking_it() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("m.json");
        let e = read_model(&p).unwrap_err();
        assert!(e.to_string().contains("m.json"), "{e}");
        std::fs::write(&p, "{").unwrap();
        let e = crate::chain_text(&read_model(&p).unwrap_err());
        assert!(e.contains("m.json") && e.contains("JSON"), "{e}");
    }
}
