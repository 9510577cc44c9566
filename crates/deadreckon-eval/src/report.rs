//! Estimator results as the HTML report's plain data model
//! (`deadreckon_report::ReportInput`): the calibrations made on a drive, the
//! filter's health, dead reckoning, drift, outages and the TedriS sections
//! (moved unchanged from the command line's `report`).

use deadreckon_core::calibrate::{self, Calibration, CalibrationOptions, Method};
use deadreckon_core::ekf::{FilterOptions, FilterStats, SensorKind};
use deadreckon_core::metrics;
use deadreckon_core::track as tracks;
use deadreckon_core::{outage, Drive, Params, ParamsWithStd, Track};
use deadreckon_report as rp;

use crate::{Error, Progress};

/// Where a parameter set comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Source {
    /// The vehicle's nominal values.
    Nominal,
    /// The ZUPT calibration (gyro bias at standstill).
    Zupt,
    /// The RTS calibration against GNSS (the paper's method; the report's
    /// iterations are drawn with it, and without given parameters its
    /// filter health and aided tracks, as `run` without --params).
    Rts,
    /// The calibration against the truth.
    Truth,
    /// Given by the user (a params.toml, or `nominal`): the filter health
    /// and the aided tracks are drawn with them, as `run --params` writes.
    Given,
}

impl Source {
    /// The name the report shows.
    pub fn name(self) -> &'static str {
        match self {
            Source::Nominal => "nominal",
            Source::Zupt => "ZUPT",
            Source::Rts => "RTS",
            Source::Truth => "truth",
            Source::Given => "given",
        }
    }
}

/// A parameter set for the report, named by where it comes from
/// ([`Source::name`]: a user's `--params` set is "given").
pub struct NamedParams {
    /// Where it comes from.
    pub source: Source,
    /// Parameters.
    pub params: ParamsWithStd,
    /// The calibration that produced them, if any.
    pub calibration: Option<Calibration>,
}

/// The parameter sets a report shows, and the calibrations it could not
/// make with why (shown in the report, not dropped).
pub struct Calibrations {
    /// The sets, nominal first.
    pub sets: Vec<NamedParams>,
    /// Calibrations the drive did not support, or that failed.
    pub skipped: Vec<rp::NotComputed>,
}

fn path_of(t: &Track) -> rp::EnPath {
    rp::EnPath {
        east_m: t.points.iter().map(|p| p.east_m).collect(),
        north_m: t.points.iter().map(|p| p.north_m).collect(),
        t_s: t.points.iter().map(|p| p.t_s).collect(),
    }
}

fn stream(name: &str, t: &[f64]) -> Option<rp::StreamInfo> {
    if t.is_empty() {
        return None;
    }
    let span = t[t.len() - 1] - t[0];
    Some(rp::StreamInfo {
        name: name.into(),
        samples: t.len(),
        rate_hz: (span > 0.0).then(|| (t.len() - 1) as f64 / span),
    })
}

/// The header: drive name, duration, distance, streams.
pub fn header(drive: &Drive, name: &str, inputs: Vec<(String, String)>) -> rp::Header {
    let wheels: Vec<f64> = (0..drive.wheels.len())
        .map(|k| drive.wheels.t_s(k))
        .collect();
    let wheel_name = match drive.wheels {
        deadreckon_core::drive::Wheels::Ticks(_) => "wheel_ticks",
        deadreckon_core::drive::Wheels::Speeds(_) => "wheel_speeds",
    };
    let streams = [
        stream(wheel_name, &wheels),
        stream(
            "yaw_rate",
            &drive.yaw_rate.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        ),
        stream(
            "speed",
            &drive.speed.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        ),
        stream(
            "steering",
            &drive.steering.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        ),
        stream(
            "gnss",
            &drive.gnss.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        ),
        stream(
            "truth",
            &drive.truth.iter().map(|s| s.t_s).collect::<Vec<_>>(),
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    let distance_m = deadreckon_core::reference::Reference::from_truth(&drive.truth)
        .and_then(|r| r.distance().last().copied());
    rp::Header {
        drive_name: name.into(),
        duration_s: drive.time_span().map(|(a, b)| b - a),
        distance_m,
        start_t_s: drive.time_span().map(|s| s.0),
        streams,
        inputs: inputs
            .into_iter()
            .map(|(name, value)| rp::NamedText { name, value })
            .collect(),
    }
}

/// The calibrations of a drive: nominal always, then ZUPT, RTS and truth,
/// each kept when the drive supports it (a standstill, GNSS, a reference)
/// and otherwise listed in `skipped` with the calibration's error.
pub fn calibrations(drive: &Drive, steps: &dyn Progress) -> Calibrations {
    let nominal = Params::nominal(&drive.vehicle);
    let mut out = Calibrations {
        sets: vec![NamedParams {
            source: Source::Nominal,
            params: ParamsWithStd {
                params: nominal,
                std: Params::from_array([0.0; 6]),
            },
            calibration: None,
        }],
        skipped: Vec::new(),
    };
    for (source, method) in [
        (Source::Zupt, Method::Zupt),
        (Source::Rts, Method::Rts),
        (Source::Truth, Method::Truth),
    ] {
        steps.step(&format!("{} calibration", source.name()));
        match calibrate::calibrate(
            drive,
            &CalibrationOptions {
                method,
                ..Default::default()
            },
        ) {
            Ok(c) => out.sets.push(NamedParams {
                source,
                params: c.estimate,
                calibration: Some(c),
            }),
            Err(e) => out
                .skipped
                .push(not_computed(format!("{} calibration", source.name()), &e)),
        }
    }
    out
}

/// A [`rp::NotComputed`] from an error and its causes.
fn not_computed(what: String, e: &dyn std::error::Error) -> rp::NotComputed {
    let mut reason = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        let text = c.to_string();
        if !reason.contains(&text) {
            reason.push_str(": ");
            reason.push_str(&text);
        }
        cause = c.source();
    }
    rp::NotComputed { what, reason }
}

fn sensor_unit(k: SensorKind, ticks: bool) -> &'static str {
    match k {
        SensorKind::Wheel(_) if ticks => "ticks",
        SensorKind::Wheel(_) | SensorKind::Speed => "m/s",
        SensorKind::Gyro => "rad/s",
        SensorKind::Steering => "m/s",
        SensorKind::Gnss => "m",
        SensorKind::Course => "rad",
    }
}

/// What [`health`] returns: the report's section, the run's counters, the
/// filtered and smoothed tracks as the report draws them (`t`, east,
/// north), and the indices in `drive.gnss` of the fixes the gate rejected.
pub type Health = (rp::FilterHealth, FilterStats, [rp::EnPath; 2], Vec<usize>);

/// Filter health from the GNSS-aided run whose filtered and smoothed
/// tracks `run` writes ([`tracks::aided_tracks`], the filter of the layout
/// the vehicle's noise settings call for: the receiver's wander, the gyro
/// bias as a state, the gyro-bias switch), its innovations and points taken
/// into the report's series as the run makes them ([`tracks::aided_run`]);
/// the wheel monitor's lines are `run`'s ([`deadreckon_core::ekf::check_wheels`]).
pub fn health(drive: &Drive, params: &Params) -> Result<Health, Error> {
    let opts = FilterOptions::default();
    // The NEES first: its copy of the truth is gone before the run's series
    // exist.
    let consistency = consistency(drive, params);
    let mut taken = Taken::default();
    let run = tracks::aided_run(drive, params, &opts, &mut taken)?;
    let out = run.output;
    let wheel_health = deadreckon_core::ekf::check_wheels(drive, params, &opts)?;
    let ticks = matches!(drive.wheels, deadreckon_core::drive::Wheels::Ticks(_));
    let mut h = rp::FilterHealth {
        nis_bound_probability: Some(0.95),
        ..Default::default()
    };
    // Each sensor's series reduced to what its figures draw and say (the
    // same figures as the whole series', [`rp::DrawnInnovations::of`]) and
    // dropped before the next: the report holds no series to the end.
    let p = h.nis_probability();
    for (k, c) in std::mem::take(&mut taken.by_sensor) {
        let nis = c.nis();
        let mut innovations = rp::InnovationSeries {
            sensor: k.name().into(),
            unit: sensor_unit(k, ticks).into(),
            std: c.s.iter().map(|s| s.sqrt()).collect(),
            t_s: c.t_s,
            innovation: c.y,
            gated: c.gated,
        };
        h.drawn_innovations
            .push(rp::DrawnInnovations::of(&innovations)?);
        innovations.innovation = Vec::new();
        innovations.std = Vec::new();
        let nis = rp::NisSeries {
            sensor: k.name().into(),
            dof: k.dof() as u32,
            t_s: innovations.t_s,
            nis,
            gated: innovations.gated,
            gate_chi2: Some(deadreckon_core::filter::gate_chi2(&drive.vehicle.noise, k))
                .filter(|g| g.is_finite()),
        };
        h.drawn_nis.push(rp::DrawnNis::of(&nis, p)?);
    }
    h.consistency = consistency;
    h.wheel_health = wheel_health.lines();
    for (name, r) in deadreckon_core::wheel_health::WHEEL_NAMES
        .iter()
        .zip(&wheel_health.wheels)
    {
        h.wheel_health.extend(r.intervals.iter().map(|i| {
            format!(
                "wheel {name} out {:.2}..{:.2} s ({})",
                i.start_s,
                i.end_s,
                i.reason.name()
            )
        }));
    }
    let mut smoothed = taken.smoothed;
    // The smoother handed its points out last to first.
    smoothed.t_s.reverse();
    smoothed.east_m.reverse();
    smoothed.north_m.reverse();
    Ok((h, out.stats, [taken.filtered, smoothed], out.gnss_gated))
}

/// What the report takes from the aided run as it goes: each sensor's
/// innovations (in `SensorKind`'s order, as the report lists them) and
/// the two tracks' times and positions (the run kept every innovation and
/// both tracks' whole points first: 105 MB and 43 MB on the hour, issue 30).
#[derive(Default)]
struct Taken {
    by_sensor: std::collections::BTreeMap<SensorKind, Columns>,
    filtered: rp::EnPath,
    smoothed: rp::EnPath,
}

fn push_point(p: &mut rp::EnPath, q: &deadreckon_core::TrackPoint) {
    p.t_s.push(q.t_s);
    p.east_m.push(q.east_m);
    p.north_m.push(q.north_m);
}

impl tracks::AidedObserver for Taken {
    fn innovation(&mut self, r: deadreckon_core::ekf::InnovationRecord) {
        self.by_sensor.entry(r.sensor).or_default().push(&r);
    }
    fn filtered(&mut self, p: deadreckon_core::TrackPoint) {
        push_point(&mut self.filtered, &p);
    }
    fn smoothed(&mut self, p: deadreckon_core::TrackPoint) {
        push_point(&mut self.smoothed, &p);
    }
}

/// One sensor's innovations as the run makes them: the columns of its
/// [`rp::InnovationSeries`] and [`rp::NisSeries`], the NIS kept only where
/// it is not `y²/S` (a scalar observation's is, bit for bit: 8 bytes an
/// innovation less, 10 MB on the hour; a GNSS fix's is not).
#[derive(Default)]
struct Columns {
    t_s: Vec<f64>,
    y: Vec<f64>,
    s: Vec<f64>,
    gated: Vec<bool>,
    /// The NIS where it is not `y²/S`, by index.
    nis_otherwise: Vec<(usize, f64)>,
}

impl Columns {
    fn push(&mut self, r: &deadreckon_core::ekf::InnovationRecord) {
        if (r.y * r.y / r.s).to_bits() != r.nis.to_bits() {
            self.nis_otherwise.push((self.t_s.len(), r.nis));
        }
        self.t_s.push(r.t_s);
        self.y.push(r.y);
        self.s.push(r.s);
        self.gated.push(!r.accepted);
    }

    /// Every NIS, as recorded.
    fn nis(&self) -> Vec<f64> {
        let mut v: Vec<f64> = self.y.iter().zip(&self.s).map(|(y, s)| y * y / s).collect();
        for &(k, nis) in &self.nis_otherwise {
            v[k] = nis;
        }
        v
    }
}

/// NEES through 30 s dead-reckoning windows every 60 s against the truth
/// (`deadreckon_core::consistency`); `None` without truth or windows.
fn consistency(drive: &Drive, params: &Params) -> Option<rp::NeesConsistency> {
    use deadreckon_core::consistency as cs;
    let w = cs::windows(drive, 30.0, 60.0, 60.0);
    let c = cs::nees_through_windows(drive, params, &w, &FilterOptions::default()).ok()?;
    let rows = [&c.pose, &c.motion]
        .into_iter()
        .flat_map(|b| {
            b.points.iter().map(|p| rp::NeesRow {
                block: b.name.clone(),
                dof: b.dof as u32,
                fraction: p.fraction,
                windows: p.windows as u32,
                nees: p.nees,
                lower: p.lower,
                upper: p.upper,
                verdict: p.verdict.to_string(),
            })
        })
        .collect();
    Some(rp::NeesConsistency {
        outage_s: c.outage_s,
        summary: c.summary(),
        rows,
    })
}

/// Builds the four-wheel part of a report for `drive` with the given
/// parameter sets. What cannot be computed (a skipped calibration, a failed
/// step) is listed in the report's `not_computed`, never dropped silently.
/// `outage_s` adds sliding outages of that length, every `step_s` (default
/// half the length), as `evaluate --outage LEN --step STEP` runs them.
pub fn four_wheel_input(
    drive: &Drive,
    calibrations: &Calibrations,
    outage_s: Option<f64>,
    step_s: Option<f64>,
    steps: &dyn Progress,
) -> Result<rp::ReportInput, Error> {
    let methods = &calibrations.sets;
    let mut input = rp::ReportInput {
        not_computed: calibrations.skipped.clone(),
        ..Default::default()
    };
    let mut traj = rp::Trajectories::default();
    // Filter health and the aided tracks with the parameters `run` applies
    // to this drive (`deadreckon_api::evaluate::parameters`): the given
    // ones, or else those calibrated on the drive (RTS), or else the last.
    let best = methods
        .iter()
        .find(|m| m.source == Source::Given)
        .or_else(|| methods.iter().find(|m| m.source == Source::Rts))
        .or_else(|| methods.last());
    if let (Some(params), true) = (best.map(|m| m.params.params), drive.gnss.len() >= 2) {
        steps.step("filter health");
        let health = health(drive, &params);
        if let Err(e) = &health {
            input
                .not_computed
                .push(not_computed("filter health".into(), e));
        }
        if let Ok((h, st, tracks, gated)) = health {
            traj.gnss = Some(rp::EnPath {
                east_m: drive.gnss.iter().map(|g| g.east_m).collect(),
                north_m: drive.gnss.iter().map(|g| g.north_m).collect(),
                t_s: drive.gnss.iter().map(|g| g.t_s).collect(),
            });
            if st.gnss_rejected > 0 {
                // The fixes the filter says it gated (they were matched by
                // time within 0.011 s of the wheel epoch that used them).
                let gg: Vec<_> = gated.iter().filter_map(|&i| drive.gnss.get(i)).collect();
                traj.gnss_gated = Some(rp::EnPath {
                    east_m: gg.iter().map(|g| g.east_m).collect(),
                    north_m: gg.iter().map(|g| g.north_m).collect(),
                    t_s: gg.iter().map(|g| g.t_s).collect(),
                });
            }
            let [filtered, smoothed] = tracks;
            traj.filtered = Some(filtered);
            traj.smoothed = Some(smoothed);
            traj.aided_with = best.map(|m| m.source.name().to_string());
            input.health = Some(h);
        }
    }
    // The truth's positions (the reference's east and north are the
    // poses'), made after the filter health's peak (issue 30).
    if deadreckon_core::reference::TruthPositions::new(&drive.truth).is_some() {
        traj.truth = Some(rp::EnPath {
            east_m: drive.truth.iter().map(|p| p.east_m).collect(),
            north_m: drive.truth.iter().map(|p| p.north_m).collect(),
            t_s: drive.truth.iter().map(|p| p.t_s).collect(),
        });
    }
    // Dead reckoning with each parameter set.
    let opts = FilterOptions::default();
    for m in methods {
        steps.step(&format!("dead reckoning with {}", m.source.name()));
        // From the truth's start, or (no truth: the Husky) from the start of
        // the smoothed track as `run` does; the report drew no DR track there.
        let dr = if drive.truth.is_empty() {
            tracks::drive_tracks(drive, &m.params.params, &opts, None).map(|mut t| t.remove(0))
        } else {
            tracks::dead_reckoning_init(drive, None, None)
                .and_then(|i| tracks::dead_reckoned(drive, &m.params.params, &opts, i))
        };
        match dr {
            Ok(dr) => traj.dead_reckoned.push(rp::MethodPath {
                method: m.source.name().into(),
                path: path_of(&dr),
            }),
            Err(e) => input.not_computed.push(not_computed(
                format!("dead reckoning with {}", m.source.name()),
                &e,
            )),
        }
    }
    input.trajectories = Some(traj);
    // Calibration table and the iterations of the RTS calibration.
    let mut cal = rp::Calibration::default();
    for m in methods {
        let has_std = m.params.std.to_array().iter().any(|s| *s > 0.0);
        cal.rows.push(rp::CalibrationRow {
            method: m.source.name().into(),
            values: m.params.params,
            std: has_std.then_some(m.params.std),
        });
    }
    if let Some(c) = methods
        .iter()
        .find(|m| m.source == Source::Rts)
        .and_then(|m| m.calibration.as_ref())
    {
        cal.iterated_method = Source::Rts.name().into();
        cal.iterations = std::iter::once(Params::nominal(&drive.vehicle))
            .chain(c.history.iter().copied())
            .collect();
    }
    input.calibration = Some(cal);
    // Drift and distance before 1 m, against the truth.
    if !drive.truth.is_empty() {
        let mut d = rp::Drift::default();
        for m in methods {
            steps.step(&format!("drift with {}", m.source.name()));
            let p = &m.params.params;
            let (dr, rs) = match (
                metrics::drift(drive, p, 100.0, opts.timing),
                metrics::reset_on_error(drive, p, 1.0, opts.timing),
            ) {
                (Ok(dr), Ok(rs)) => (dr, rs),
                (Err(e), _) | (_, Err(e)) => {
                    input
                        .not_computed
                        .push(not_computed(format!("drift with {}", m.source.name()), &e));
                    continue;
                }
            };
            d.methods.push(rp::DriftMethod {
                method: m.source.name().into(),
                error_after_segment_m: dr.errors_m,
                distance_to_threshold_m: rs.distances_m,
            });
        }
        input.drift = Some(d);
    }
    // Sliding outages.
    if let Some(len) = outage_s {
        let mut ev = rp::OutageEvaluation {
            window_s: Some(len),
            methods: Vec::new(),
            bound: None,
        };
        // The 95 % bound is drawn for the RTS calibration's parameters
        // (fitted in-sample, as `evaluate` without --params fits it), or
        // the last set's.
        let bounded = methods
            .iter()
            .position(|m| m.source == Source::Rts)
            .or(methods.len().checked_sub(1));
        for (i, m) in methods.iter().enumerate() {
            steps.step(&format!("{len} s outages with {}", m.source.name()));
            let step = step_s.unwrap_or(len / 2.0);
            match outage::evaluate(drive, &m.params.params, len, step, 5.0, &opts) {
                Ok(o) => {
                    if Some(i) == bounded {
                        steps.step(&format!("the 95 % bound with {}", m.source.name()));
                        ev.bound = outage_bound(drive, m, &o, &opts);
                    }
                    ev.methods.push(rp::MethodSample {
                        method: m.source.name().into(),
                        final_error_m: o.windows.iter().map(|w| w.final_m()).collect(),
                    })
                }
                Err(e) => input.not_computed.push(not_computed(
                    format!("{len} s outages with {}", m.source.name()),
                    &e,
                )),
            }
        }
        if !ev.methods.is_empty() {
            input.outages = Some(ev);
        }
    }
    Ok(input)
}

/// The error and the 95 % bound through the windows of `o` (issue 31),
/// with the factor fitted on the drive's own hidden fixes with `m`'s
/// parameters (in-sample, as `evaluate` without `--params` fits it);
/// `None` without covariances.
fn outage_bound(
    drive: &Drive,
    m: &NamedParams,
    o: &outage::OutageEvaluation,
    opts: &FilterOptions,
) -> Option<rp::OutageBound> {
    let fit = deadreckon_core::bound::fit_on_drive(drive, &m.params.params, opts);
    let within = o
        .windows
        .iter()
        .filter(|w| w.within_bound(&fit) == Some(true))
        .count();
    let sharpness = o.bound_sharpness(&fit)?;
    let ws: Vec<_> = o
        .windows
        .iter()
        .filter(|w| w.covariances_m2.len() == w.errors.len())
        .collect();
    let factor = match fit.method {
        deadreckon_core::bound::Method::Conformal => format!(
            "the filter's covariance inflated by k = {:.2} (k² P) over the last fix's declared \
             accuracy, fitted on {} windows of {:.1} s of this drive against its own hidden fixes \
             (in-sample)",
            fit.k, fit.windows, fit.outage_s
        ),
        deadreckon_core::bound::Method::Filter => fit.method.to_string(),
    };
    Some(rp::OutageBound {
        method: m.source.name().into(),
        factor,
        time_s: ws
            .iter()
            .map(|w| w.errors.iter().map(|e| e.0).collect())
            .collect(),
        error_m: ws
            .iter()
            .map(|w| w.errors.iter().map(|e| e.1).collect())
            .collect(),
        bound_m: ws.iter().map(|w| w.bounds_95_m(&fit)).collect(),
        within,
        sharpness,
    })
}

/// The TedriS sections of a report for a trained model `m`: the
/// cross-correlation, the regression tables, the repositories, and from the
/// comparison `c` (made with `m`) the training heading and the error curves
/// through its outages, so the report shows the numbers the comparison
/// table prints (they used to come from other windows).
pub fn tedris_from_model(
    drive: &Drive,
    m: &deadreckon_tedris::TedrisModel,
    c: &crate::compare::Comparison,
) -> Result<rp::Tedris, Error> {
    let mut t = rp::Tedris {
        cross_correlation: Some(rp::CrossCorrelation {
            lag: m.ccf.lags.clone(),
            correlation: m.ccf.values.clone(),
            chosen_lag: Some(m.lag_samples),
        }),
        ..Default::default()
    };
    for f in &m.fits {
        let nv = |name: &str, value: f64| rp::NamedValue {
            name: name.into(),
            value,
        };
        let name = if f.kind == m.chosen {
            format!("{} (chosen)", f.kind.name())
        } else {
            f.kind.name().to_string()
        };
        t.models.push(rp::RegressionModel {
            name,
            coefficients: f
                .global
                .coefficients
                .iter()
                .map(|c| rp::Coefficient {
                    name: c.name.clone(),
                    estimate: c.estimate,
                    std_error: c.std_error,
                    t_value: c.t_value,
                    p_value: c.p_value,
                })
                .collect(),
            statistics: vec![
                nv("n", f.global.n as f64),
                nv("R²", f.global.r_squared),
                nv("AIC", f.global.aic),
                nv("BIC", f.global.bic),
                nv("Box–Pierce Q", f.box_pierce.statistic),
                nv("Box–Pierce p", f.box_pierce.p_value),
                nv("Ljung–Box Q*", f.ljung_box.statistic),
                nv("Ljung–Box p", f.ljung_box.p_value),
            ],
        });
    }
    let fill = m.repositories.fill(m.config.required_bins);
    t.repositories = Some(rp::Repositories {
        index: fill.iter().map(|f| f.index as i64).collect(),
        fill: fill.iter().map(|f| f.tuples as u64).collect(),
        min_fill: Some(m.config.min_fill as u64),
        max_fill: Some(m.config.max_fill as u64),
    });
    let (t0, _) = drive.time_span().ok_or(Error::EmptyDrive)?;
    // Training heading (TedriS's own estimate outside outages) against the reference course.
    let course: Vec<(f64, f64)> = drive
        .gnss
        .iter()
        .filter_map(|g| g.course_yaw_rad().map(|c| (g.t_s, c)))
        .collect();
    if !course.is_empty() {
        let unwrap = |v: Vec<(f64, f64)>| -> rp::TimeSeries {
            let a = deadreckon_core::angle::unwrap(&v.iter().map(|x| x.1).collect::<Vec<_>>());
            rp::TimeSeries {
                t_s: v.iter().map(|x| x.0).collect(),
                value: a,
            }
        };
        t.gnss_heading_rad = Some(unwrap(course));
        t.training_heading_rad = Some(unwrap(
            c.tedris_track
                .points
                .iter()
                .map(|p| (p.t_s, p.yaw_rad))
                .collect(),
        ));
    }
    // Each outage's errors as the comparison measured and printed them.
    for (o, four_wheel, tedris) in &c.rows {
        let mut series = Vec::new();
        for (name, row) in [("TedriS", tedris), ("four-wheel", four_wheel)] {
            if let Some(r) = row {
                series.push(rp::MethodSeries {
                    method: name.into(),
                    t_s: r.errors.iter().map(|e| e.0).collect(),
                    error_m: r.errors.iter().map(|e| e.1).collect(),
                });
            }
        }
        if !series.is_empty() {
            t.outages.push(rp::OutageRun {
                name: format!("outage {:.0}–{:.0} s", o.start_s - t0, o.end_s - t0),
                series,
            });
        }
    }
    Ok(t)
}

/// The corrections estimated on a drive ([`deadreckon_core::timing::prepare_with`])
/// as the report's rows: each stream's delay, the driven axle's slip, the IMU
/// tilt, the gyro scale error, with their standard errors and whether they
/// were applied.
pub fn correction_rows(c: &deadreckon_core::timing::Corrections) -> Vec<rp::CorrectionRow> {
    use deadreckon_core::timing::Stream;
    let finite = |v: f64| v.is_finite().then_some(v);
    use deadreckon_core::timing::MEASURED;
    let status = |reason: Option<&str>| match reason {
        None => "estimated, applied".to_string(),
        Some(r) if r.starts_with(MEASURED) => r.to_string(),
        Some(r) => format!("not estimated: {r}"),
    };
    let mut rows: Vec<rp::CorrectionRow> = Stream::ALL
        .iter()
        .map(|&s| {
            let d = c.delays.get(s);
            let estimated = d.status.is_estimated() || d.status.is_measured_not_applied();
            rp::CorrectionRow {
                what: format!("{} delay", s.name()),
                unit: "s".into(),
                value: finite(d.delay_s).filter(|_| estimated),
                std: finite(d.std_s).filter(|_| estimated),
                status: status(d.status.reason()),
            }
        })
        .collect();
    if let Some(t) = &c.traction {
        let estimated = t.is_estimated() || t.status.is_measured_not_applied();
        rows.push(rp::CorrectionRow {
            what: "driven axle slip per m/s²".into(),
            unit: "%".into(),
            value: finite(100.0 * t.slip_per_mps2.abs()).filter(|_| estimated),
            std: finite(100.0 * t.std).filter(|_| estimated),
            status: match t.status.reason() {
                None => format!(
                    "estimated on the {} axle from the front/rear wheel speeds against the forward specific force, its wheel speeds corrected",
                    t.axle.name()
                ),
                Some(r) if r.starts_with(MEASURED) => r.to_string(),
                Some(r) => format!("not estimated: {r}"),
            },
        });
    }
    if let Some(t) = &c.tilt {
        let estimated = t.is_estimated() || t.status.is_measured_not_applied();
        rows.push(rp::CorrectionRow {
            what: "IMU tilt".into(),
            unit: "°".into(),
            value: finite(t.tilt_rad.to_degrees()).filter(|_| estimated),
            std: finite(t.std_rad.to_degrees()).filter(|_| estimated),
            status: match t.status.reason() {
                None => format!(
                    "estimated from gravity while {} (pitch {:+.2}°, roll {:+.2}°), yaw rate projected on the vertical",
                    t.source.name(),
                    t.pitch_rad.to_degrees(),
                    t.roll_rad.to_degrees()
                ),
                Some(r) if r.starts_with(MEASURED) => r.to_string(),
                Some(r) => format!("not estimated: {r}"),
            },
        });
    }
    if let Some(g) = &c.gyro_scale {
        let estimated = g.is_estimated() || g.status.is_measured_not_applied();
        rows.push(rp::CorrectionRow {
            what: "gyro scale error".into(),
            unit: "%".into(),
            value: finite(100.0 * g.scale_error).filter(|_| estimated),
            std: finite(100.0 * g.std).filter(|_| estimated),
            status: match g.status.reason() {
                None => format!("estimated from {} turns, applied", g.turns),
                Some(r) if r.starts_with(MEASURED) => r.to_string(),
                Some(r) => format!("not estimated: {r}"),
            },
        });
    }
    rows
}
