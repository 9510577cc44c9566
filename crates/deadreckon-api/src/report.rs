//! `deadreckon report`: one self-contained HTML page for a drive. The
//! calibrations the drive allows (a skipped one is shown with its reason), a
//! user's parameters as "given", filter health, dead reckoning, drift,
//! outages ([`deadreckon_eval::report`]) and, with a trained model, the
//! TedriS sections; written whole by [`deadreckon_report::write_report`].
//!
//! Every section reads the drive with the same timing and mounting
//! corrections, shown in the calibration section: with `--params`, those
//! the file stores (its parameters were calibrated on streams corrected
//! so; none for `nominal` or a file without them), as `run --params`
//! applies them; without it, those estimated on the drive as `calibrate
//! --corrections` would.
//!
//! The filtered and smoothed tracks and the filter health come from
//! `run`'s function ([`deadreckon_core::track::aided_tracks`], through
//! [`deadreckon_eval::report::health`]) with the parameters `run` applies:
//! the given ones, or without `--params` the RTS calibration on the drive.
//! The same drive and params file give `run`'s tracks
//! (`report_drew_the_five_state_filter_where_run_carried_the_wander`).

use std::path::Path;

use deadreckon_core::{Drive, Params, ParamsWithStd};
use deadreckon_eval::report::{
    calibrations, four_wheel_input, header, tedris_from_model, NamedParams, Source,
};
use deadreckon_eval::Progress;
use deadreckon_report as rp;

use crate::error::While;
use crate::params_file::ParamsFile;
use crate::Error;

/// What goes into a drive's report besides the drive.
#[derive(Debug, Clone, Copy)]
pub struct ReportOptions<'a> {
    /// The drive's path, named in the header.
    pub dir: &'a Path,
    /// A user's parameters (`nominal` or a params.toml), shown as "given".
    pub params: Option<&'a str>,
    /// A trained TedriS model: its sections.
    pub model: Option<&'a Path>,
    /// The outage length, s (default: the report's and TedriS's own).
    pub outage_s: Option<f64>,
    /// The step between the four-wheel outage windows, s (default half
    /// their length).
    pub step_s: Option<f64>,
    /// The corrections estimated on the drive without `params` (with it,
    /// those the file stores: [`corrected`]).
    pub corrections: deadreckon_core::timing::Which,
    /// The shape asked for (`--shape`; `None`: found from the data,
    /// [`crate::shape`]).
    pub shape: Option<deadreckon_core::kinematics::Shape>,
}

/// The drive with the corrections every section uses applied, and their
/// rows: with `o.params`, those stored in `file` (`o.params` read,
/// [`given_file`]; `None` for `nominal` or a file storing none), as
/// [`crate::evaluate::parameters`] applies them for `run`; without it, those
/// `o.corrections` asks to estimate (`None` when none are asked).
///
/// The drive is handed over: the drive as read is corrected in place, or
/// dropped once the corrected one exists, so the report holds one copy of
/// the drive after this (it held both to the end: 42 MB more on the hour,
/// issue 30).
pub fn corrected(
    drive: Drive,
    o: &ReportOptions,
    file: Option<&ParamsFile>,
    steps: &dyn Progress,
) -> Result<(Drive, Option<rp::Corrections>), Error> {
    use deadreckon_core::timing::Which;
    if let Some(p) = o.params {
        let Some(stored) = file.map(|f| &f.corrections).filter(|c| !c.is_empty()) else {
            return Ok((drive, None));
        };
        let c = rp::Corrections {
            source: format!("{} {p}", crate::report_labels::READ_FROM),
            rows: crate::corrections::stored_rows(stored)
                .into_iter()
                .map(|r| rp::CorrectionRow {
                    status: format!("{} {p}, applied", crate::report_labels::READ_FROM),
                    ..r
                })
                .collect(),
        };
        return Ok((stored.apply_to(drive), Some(c)));
    }
    if o.corrections == Which::None {
        return Ok((drive, None));
    }
    let name = o.corrections.name();
    steps.step("corrections");
    let copts = deadreckon_core::calibrate::CalibrationOptions::default();
    // Estimated on the drive without its truth where the calibration does
    // not read it (the choice's working copies leave it out already), and
    // the truth handed to the corrected drive: not held twice while the
    // choice runs (17 MB on the hour, issue 30). The corrections do not
    // touch the truth.
    let mut drive = drive;
    let truth = if copts.reads_truth() {
        Vec::new()
    } else {
        std::mem::take(&mut drive.truth)
    };
    let (mut d, c) = crate::corrections::estimate_and_apply(&drive, &copts, o.corrections)?;
    drop(drive);
    if !truth.is_empty() {
        d.truth = truth;
    }
    let rows = rp::Corrections {
        source: format!("estimated on this drive (--corrections {name})"),
        rows: deadreckon_eval::report::correction_rows(&c),
    };
    Ok((d, Some(rows)))
}

/// `o.params` read and validated once, for its corrections and its
/// parameters (`None` without it or for `nominal`).
pub fn given_file(o: &ReportOptions) -> Result<Option<ParamsFile>, Error> {
    o.params
        .filter(|p| *p != "nominal")
        .map(ParamsFile::read)
        .transpose()
}

/// Builds the report of `drive` and writes it to `out` (the drive handed
/// over: [`corrected`]).
pub fn write(
    drive: Drive,
    o: &ReportOptions,
    out: &Path,
    steps: &dyn Progress,
    footer: &rp::Footer,
) -> Result<(), Error> {
    let found = crate::shape::detect(o.dir, Some(&drive), o.shape);
    if found.shape != deadreckon_core::kinematics::Shape::FourWheel {
        return crate::report_kinematic::write(&drive, &found, o, out, steps, footer);
    }
    let mut input = car_input(drive, o, steps)?;
    input.footer = footer.clone();
    rp::write_report(out, &input).doing(|| format!("writing {}", out.display()))
}

/// The report of a car's `drive` as data (what [`write`] renders for a
/// car, without the footer; the drive handed over: [`corrected`]).
pub fn car_input(
    drive: Drive,
    o: &ReportOptions,
    steps: &dyn Progress,
) -> Result<rp::ReportInput, Error> {
    let file = given_file(o)?;
    let (corrected, corrections) = corrected(drive, o, file.as_ref(), steps)?;
    let drive = &corrected;
    let mut methods = calibrations(drive, steps);
    if let Some(p) = o.params {
        let params = match &file {
            Some(f) => crate::load::bind(p, f, drive, false)?.0,
            None => crate::load::params(p, drive)?,
        };
        methods.sets.push(NamedParams {
            source: Source::Given,
            params: ParamsWithStd {
                params,
                std: Params::from_array([0.0; 6]),
            },
            calibration: None,
        });
    }
    let mut input = four_wheel_input(drive, &methods, o.outage_s, o.step_s, steps)?;
    crate::report_labels::say_what_was_applied(&mut input, o.params, corrections.as_ref());
    input
        .calibration
        .get_or_insert_with(Default::default)
        .corrections = corrections;
    if let Some(m) = o.model {
        steps.step("TedriS");
        input.tedris = Some(tedris_section(drive, m, o.outage_s)?);
    }
    let name = o
        .dir
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| o.dir.display().to_string());
    input.header = header(
        drive,
        &name,
        vec![("drive".into(), o.dir.display().to_string())],
    );
    Ok(input)
}

/// The TedriS sections for a drive and a trained model: the
/// cross-correlation, the regression tables of every model kind, the
/// repositories, the training heading against the reference, and the errors
/// through outages of `outage_s` (default 80 s) at a quarter, half and three
/// quarters of the drive, as `compare --model` gives them for those windows.
pub fn tedris_section(
    drive: &Drive,
    model_path: &Path,
    outage_s: Option<f64>,
) -> Result<rp::Tedris, Error> {
    let m = crate::tedris::read_model(model_path)?;
    let windows = deadreckon_eval::compare::default_windows(drive, outage_s.unwrap_or(80.0))?;
    let c = deadreckon_eval::compare::compare(
        drive,
        &windows,
        None,
        Some((m, model_path.display().to_string())),
    )?;
    Ok(tedris_from_model(drive, &c.model, &c)?)
}
