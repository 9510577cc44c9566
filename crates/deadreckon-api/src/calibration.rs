//! The one home of a car calibration: one request ([`CalibrationRequest`],
//! whose `Default` holds every default once), one function
//! ([`calibrate`]) and one result ([`CarCalibration`]).
//!
//! `deadreckon calibrate`, `batch` (through `deadreckon-fleet`), Python's
//! `calibrate` and the self-calibration of `evaluate` call [`calibrate`];
//! the command line's option defaults are read from
//! [`CalibrationRequest::default`], not restated. The result renders as the
//! `calibrate --json` object (its `Serialize` is that object, and Python's
//! dict is the same value), as params.toml ([`CarCalibration::write`]) and
//! as the text table ([`CarCalibration::lines`]); `batch`'s CSV row reads
//! its fields, and whether a parameter was estimated is one rule,
//! [`CarCalibration::status`].

use deadreckon_core::bound::BoundFit;
use deadreckon_core::calibrate::{self, CalibrationOptions, Method};
use deadreckon_core::timing::{Corrections, Which};
use deadreckon_core::Drive;

pub use crate::calibrate::CarCalibration;
use crate::Error;

/// What to calibrate with: the method and its options, and the timing and
/// mounting corrections estimated (and applied) before calibrating.
///
/// `Default` is the command's default: the method, passes, speed threshold,
/// timing and wheel-health monitor of [`CalibrationOptions::default`] (the
/// one place their values are written) and `--corrections auto`
/// ([`Which::default`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CalibrationRequest {
    /// The method and its options.
    pub options: CalibrationOptions,
    /// The corrections estimated and applied before calibrating.
    pub corrections: Which,
    /// Fit the 95 % error bound's factor on the drive's own hidden fixes
    /// (params.toml's `[bound]`); without it the bound is the filter's
    /// covariance alone ([`BoundFit::FILTER`]). `batch`, which shows no
    /// bound, skips it: the fit took 1.0 of the 1.7 s of a 10-minute
    /// simulated drive (`deadreckon batch d1 d2 --threads 1`, elapsed_s).
    pub fit_bound: bool,
}

impl Default for CalibrationRequest {
    fn default() -> Self {
        CalibrationRequest {
            options: CalibrationOptions::default(),
            corrections: Which::default(),
            fit_bound: true,
        }
    }
}

impl CalibrationRequest {
    /// The default request with these corrections (`batch`'s default is
    /// [`Which::None`]).
    pub fn with_corrections(corrections: Which) -> CalibrationRequest {
        CalibrationRequest {
            corrections,
            ..Default::default()
        }
    }

    /// The method's word: `rts`, `zupt` or `truth` (what `--method` and
    /// Python's `method` take, what params.toml's `method` records).
    pub fn method_name(&self) -> &'static str {
        method_name(self.options.method)
    }
}

/// A calibration request in the option words of the command line, each
/// `None` when not given: what Python's `calibrate(...)` hands over (its
/// keyword arguments default to `None`), so that a default is
/// [`CalibrationRequest::default`]'s and nowhere else.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct RequestWords<'a> {
    /// `rts`, `zupt` or `truth`.
    pub method: Option<&'a str>,
    /// `augmented` or `paper`.
    pub state: Option<&'a str>,
    /// `anderson` or `plain`.
    pub iteration: Option<&'a str>,
    /// Smoothing passes at most.
    pub max_iterations: Option<usize>,
    /// `wheel` or `each`.
    pub timing: Option<&'a str>,
    /// The speed threshold, m/s.
    pub min_speed_mps: Option<f64>,
    /// `auto`, `gnss`, `all` or `none`.
    pub corrections: Option<&'a str>,
}

impl CalibrationRequest {
    /// The request the words ask for, the default where a word is not given;
    /// an unknown word is an error naming what is allowed.
    pub fn from_words(w: &RequestWords<'_>) -> Result<CalibrationRequest, Error> {
        use crate::options::{parse_corrections, parse_iteration, parse_pass_state, parse_timing};
        let d = CalibrationRequest::default();
        let o = &d.options;
        Ok(CalibrationRequest {
            options: CalibrationOptions {
                method: w.method.map_or(Ok(o.method), str::parse)?,
                state: w.state.map_or(Ok(o.state), parse_pass_state)?,
                iteration: w.iteration.map_or(Ok(o.iteration), parse_iteration)?,
                max_iterations: w.max_iterations.unwrap_or(o.max_iterations),
                min_speed_mps: w.min_speed_mps.unwrap_or(o.min_speed_mps),
                filter: deadreckon_core::ekf::FilterOptions {
                    timing: w.timing.map_or(Ok(o.filter.timing), parse_timing)?,
                    ..o.filter.clone()
                },
                ..o.clone()
            },
            corrections: w.corrections.map_or(Ok(d.corrections), parse_corrections)?,
            ..d.clone()
        })
    }
}

/// `rts`, `zupt` or `truth`: the word [`Method`]'s `FromStr` reads.
pub fn method_name(m: Method) -> &'static str {
    match m {
        Method::Rts => "rts",
        Method::Zupt => "zupt",
        Method::Truth => "truth",
    }
}

/// Whether a parameter was estimated on the drive: the one rule of the
/// JSON's `not_estimated`, params.toml's `[not_estimated]` and `batch`'s
/// `status_*` columns.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamStatus {
    /// Informed by at least one sample (above the speed threshold for the
    /// speed-dependent parameters).
    Estimated,
    /// No sample informed it: kept at its nominal value (a stream the
    /// drive lacks, a ZUPT calibration's speed parameters, a wheel never
    /// above the threshold).
    NotEstimated,
}

impl ParamStatus {
    /// The rule: estimated when at least one sample informed it.
    pub fn of_samples(samples: usize) -> ParamStatus {
        if samples > 0 {
            ParamStatus::Estimated
        } else {
            ParamStatus::NotEstimated
        }
    }

    /// `estimated` or `not-estimated` (`batch`'s CSV values).
    pub fn name(self) -> &'static str {
        match self {
            ParamStatus::Estimated => "estimated",
            ParamStatus::NotEstimated => "not-estimated",
        }
    }
}

impl std::fmt::Display for ParamStatus {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            ParamStatus::Estimated => "estimated",
            ParamStatus::NotEstimated => "not estimated",
        })
    }
}

/// Calibrates the car on `drive` as `request` asks: the corrections
/// estimated and applied (with `auto`, those the held-back GNSS chose), the
/// six parameters calibrated on the corrected drive, the steering fitted
/// (truth method; the RTS calibration's own fit otherwise), the 95 % error
/// bound's factor fitted on the drive's own hidden fixes, the vehicle
/// recorded. `name` (the drive's path) goes into the error.
pub fn calibrate(
    drive: &Drive,
    request: &CalibrationRequest,
    name: &str,
) -> Result<CarCalibration, Error> {
    calibrate_corrected(drive, request, name).map(|(c, _)| c)
}

/// [`calibrate`], also returning the drive the corrections were applied to
/// (`None` when none were asked for: the drive itself), on which the
/// calibrated parameters hold (`evaluate` and `run` measure on it).
pub fn calibrate_corrected(
    drive: &Drive,
    request: &CalibrationRequest,
    name: &str,
) -> Result<(CarCalibration, Option<Drive>), Error> {
    // Without corrections the drive is calibrated as it is, not a copy.
    let (corrected, corrections, calibrated) = if request.corrections == Which::None {
        (None, Corrections::none(), None)
    } else {
        let (d, c, cal) = crate::corrections::estimate_and_apply_calibrated(
            drive,
            &request.options,
            request.corrections,
        )?;
        (Some(d), c, cal)
    };
    let car = calibrate_prepared(
        corrected.as_ref().unwrap_or(drive),
        corrections,
        calibrated,
        request,
        name,
    )?;
    Ok((car, corrected))
}

/// [`calibrate_corrected`] of a drive handed over (the command line's
/// `calibrate`, which reads nothing of the drive afterwards): the
/// corrections' working drives borrow its streams and the corrections are
/// applied to it in place, so the drive is held once instead of twice
/// ([`deadreckon_core::held_back::prepare_calibrated_owned`];
/// docs/performance.md, "Eighth round"). Returns the calibration and the
/// drive it holds for (the corrected drive, or the drive itself). The same
/// numbers bit for bit.
pub fn calibrate_owned(
    drive: Drive,
    request: &CalibrationRequest,
    name: &str,
) -> Result<(CarCalibration, Drive), Error> {
    let (drive, corrections, calibrated) = if request.corrections == Which::None {
        (drive, Corrections::none(), None)
    } else {
        crate::corrections::estimate_and_apply_owned(drive, &request.options, request.corrections)?
    };
    let car = calibrate_prepared(&drive, corrections, calibrated, request, name)?;
    Ok((car, drive))
}

/// The rest of [`calibrate_corrected`] once the corrections are applied to
/// `drive`: the calibration (`calibrated`, if the choice of corrections
/// ran it already), its plausibility, the steering, the bound.
fn calibrate_prepared(
    drive: &Drive,
    corrections: Corrections,
    calibrated: Option<calibrate::Calibration>,
    request: &CalibrationRequest,
    name: &str,
) -> Result<CarCalibration, Error> {
    let options = &request.options;
    // The choice of corrections may have calibrated this drive already.
    let calibration = match calibrated {
        Some(c) => c,
        None => calibrate::calibrate(drive, options).map_err(|source| Error::Step {
            step: format!("calibrating {name}"),
            source,
        })?,
    };
    // A fit no tyre can have is rejected, not written: `evaluate --params`
    // would refuse it (crate::binding). On drives with several effects at
    // once the calibration can settle at such a point with no other check
    // firing (a dynamic family car: +10 %, the distance scale right).
    if let Some(bad) =
        crate::binding::implausible_circumference(&calibration.estimate.params, &drive.vehicle)
    {
        return Err(Error::Invalid(format!(
            "calibrating {name}: estimate rejected: {} (speed scale {:.4}, gyro bias {:.5} \
             rad/s): the calibration did not settle at the vehicle's values",
            bad.describe(Some(4), ""),
            calibration.estimate.params.speed_scale,
            calibration.estimate.params.gyro_bias_rps,
        )));
    }
    let steering = crate::json::car_steering(drive, options.method, options.min_speed_mps)
        .map_err(|source| Error::Step {
            step: "calibrating the steering".into(),
            source,
        })?
        // The RTS calibration's fit against its smoothed states.
        .or_else(|| calibration.steering.clone());
    let (bound, fit_windows) = if request.fit_bound {
        deadreckon_core::bound::fit_on_drive_with_windows(
            drive,
            &calibration.estimate.params,
            &deadreckon_core::ekf::FilterOptions {
                timing: options.filter.timing,
                ..Default::default()
            },
        )
    } else {
        (BoundFit::FILTER, None)
    };
    let bound_reach_1m = fit_windows
        .as_ref()
        .and_then(|ev| deadreckon_core::bound::reach(ev, &bound, 1.0));
    let car = CarCalibration {
        request: request.clone(),
        calibration,
        corrections,
        steering,
        absent: crate::json::Absent::of(drive),
        vehicle: crate::binding::VehicleRecord::of(&drive.vehicle),
        bound,
        bound_reach_1m,
    };
    Ok(car)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_request_is_the_cores_defaults_with_auto_corrections() {
        let r = CalibrationRequest::default();
        assert_eq!(r.options, CalibrationOptions::default());
        assert_eq!(r.corrections, Which::Auto);
        assert!(r.fit_bound);
        assert_eq!(r.method_name(), "rts");
        for m in [Method::Rts, Method::Zupt, Method::Truth] {
            assert_eq!(method_name(m).parse::<Method>().unwrap(), m);
        }
    }

    /// Python's `calibrate()` hands its keyword arguments over as
    /// [`RequestWords`], each `None` unless given: with none given, the
    /// request is the library's default, and each word the command line
    /// takes gives the same option.
    #[test]
    fn pythons_defaults_are_the_librarys_request() {
        let none = CalibrationRequest::from_words(&RequestWords::default()).unwrap();
        assert_eq!(none, CalibrationRequest::default());
        let d = CalibrationRequest::default();
        let words = RequestWords {
            method: Some(d.method_name()),
            state: Some("augmented"),
            iteration: Some("anderson"),
            max_iterations: Some(d.options.max_iterations),
            timing: Some("wheel"),
            min_speed_mps: Some(d.options.min_speed_mps),
            corrections: Some("auto"),
        };
        assert_eq!(CalibrationRequest::from_words(&words).unwrap(), d);
        let other = RequestWords {
            method: Some("zupt"),
            max_iterations: Some(7),
            corrections: Some("none"),
            ..Default::default()
        };
        let r = CalibrationRequest::from_words(&other).unwrap();
        assert_eq!(r.options.method, Method::Zupt);
        assert_eq!(r.options.max_iterations, 7);
        assert_eq!(r.corrections, Which::None);
        assert!(CalibrationRequest::from_words(&RequestWords {
            timing: Some("every"),
            ..Default::default()
        })
        .is_err());
    }

    #[test]
    fn a_parameter_is_estimated_when_a_sample_informed_it() {
        assert_eq!(ParamStatus::of_samples(0), ParamStatus::NotEstimated);
        assert_eq!(ParamStatus::of_samples(1), ParamStatus::Estimated);
        assert_eq!(ParamStatus::NotEstimated.name(), "not-estimated");
    }
}
