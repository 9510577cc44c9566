//! The input of the report: plain, serialisable data, filled by the command line
//! from the estimators' results.
//!
//! Every section is optional, and inside a section every series may be empty: the
//! report renders a section (and a figure inside it) only when it has data. Units are
//! SI (m, s, rad, rad/s) and named in the field names; the report converts for
//! display (headings to degrees, drift to %). Methods (calibrations, estimators) are
//! plain strings: the same string gets the same colour in every figure, and the
//! well-known names `truth`/`GT`, `nominal`, `ZUPT`, `RTS`/`ours`, `filtered`,
//! `smoothed`, `GNSS` and `TedriS` get fixed colours (case-insensitive).

pub use deadreckon_core::Params;
use serde::{Deserialize, Serialize};

/// Everything the report can show. `Default` gives an empty report (header and
/// footer only).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ReportInput {
    /// The drive: name, duration, distance, streams.
    pub header: Header,
    /// Version and command line.
    pub footer: Footer,
    /// Trajectories in the east-north plane (figure 6 of the four-wheel paper).
    pub trajectories: Option<Trajectories>,
    /// Calibrated parameters by method and their path over the iterations (table III).
    pub calibration: Option<Calibration>,
    /// Dead-reckoning drift per segment and distance to the error threshold (table IV, figures 4–5).
    pub drift: Option<Drift>,
    /// Innovations and normalised innovation squared of the filter.
    pub health: Option<FilterHealth>,
    /// TedriS training and dead reckoning (figures 5–8 and table 1 of the TedriS paper).
    pub tedris: Option<Tedris>,
    /// Final errors of sliding simulated GNSS outages.
    pub outages: Option<OutageEvaluation>,
    /// A kinematic shape's calibration (a tricycle, a differential drive),
    /// shown instead of the car's circumference table.
    pub kinematic: Option<Kinematic>,
    /// What the report could not compute, and why (a calibration a drive
    /// does not support, a failed step): shown first, never dropped.
    pub not_computed: Vec<NotComputed>,
}

/// Something the report does not show, with the reason.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NotComputed {
    /// What (`ZUPT calibration`, `filter health`, `drift with RTS`).
    pub what: String,
    /// Why (the error or the missing stream).
    pub reason: String,
}

/// The report header: what was driven and which sensor streams the drive has.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Header {
    /// Name of the drive (usually its directory name).
    pub drive_name: String,
    /// Duration of the drive, s.
    pub duration_s: Option<f64>,
    /// Distance driven, m.
    pub distance_m: Option<f64>,
    /// Timestamp subtracted from every time axis, s (usually the first wheel epoch);
    /// `None` plots the timestamps as they are.
    pub start_t_s: Option<f64>,
    /// The sensor streams present.
    pub streams: Vec<StreamInfo>,
    /// Input files other than the drive (e.g. `params.toml`, the TedriS model), as given.
    pub inputs: Vec<NamedText>,
}

/// One sensor stream of the drive.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StreamInfo {
    /// Stream name, e.g. `wheel_ticks`, `yaw_rate`, `gnss`.
    pub name: String,
    /// Number of samples.
    pub samples: usize,
    /// Mean sample rate, Hz, where known.
    pub rate_hz: Option<f64>,
}

/// A label with a free-text value.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NamedText {
    /// The label.
    pub name: String,
    /// The value.
    pub value: String,
}

/// The report footer.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Footer {
    /// The deadreckon version that wrote the report.
    pub version: String,
    /// The command line that produced the report, as typed.
    pub command_line: String,
}

/// A path in the local east-north frame; `east_m` and `north_m` have equal lengths.
/// Non-finite values break the line.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EnPath {
    /// East of the origin, m.
    pub east_m: Vec<f64>,
    /// North of the origin, m.
    pub north_m: Vec<f64>,
    /// The time of each point, s, increasing: empty (not known: the path
    /// is drawn in the east-north plane only), or as long as `east_m`.
    /// With times, the report draws each track's error against the
    /// reference through time and distance.
    pub t_s: Vec<f64>,
}

/// A path produced by one method (e.g. dead reckoning with one calibration).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MethodPath {
    /// The method, e.g. `nominal`, `ZUPT`, `RTS`, `truth`.
    pub method: String,
    /// The path.
    pub path: EnPath,
}

/// The trajectories figure (figure 6 of the four-wheel paper).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Trajectories {
    /// The reference trajectory.
    pub truth: Option<EnPath>,
    /// GNSS fixes used by the filter (drawn as points).
    pub gnss: Option<EnPath>,
    /// GNSS fixes rejected by the Mahalanobis gate (drawn as crosses).
    pub gnss_gated: Option<EnPath>,
    /// The filtered (EKF) trajectory.
    pub filtered: Option<EnPath>,
    /// The smoothed (RTS) trajectory.
    pub smoothed: Option<EnPath>,
    /// The parameter set the filtered and smoothed trajectories ran with
    /// (a method's label, as the calibration table names it).
    pub aided_with: Option<String>,
    /// Dead reckoning from the start with each calibration.
    pub dead_reckoned: Vec<MethodPath>,
}

/// One row of the calibration table: the parameters as the calibration
/// holds them ([`Params`], the params.toml keys).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CalibrationRow {
    /// The method, e.g. `truth`, `RTS`, `ZUPT`, `nominal`.
    pub method: String,
    /// The estimates.
    pub values: Params,
    /// One standard error for each estimate, where the method gives one.
    pub std: Option<Params>,
}

impl Default for CalibrationRow {
    /// An empty row (no method, every value 0).
    fn default() -> Self {
        CalibrationRow {
            method: String::new(),
            values: Params::from_array([0.0; 6]),
            std: None,
        }
    }
}

/// The calibration table (table III) and the path of the iterated calibration.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Calibration {
    /// One row per method.
    pub rows: Vec<CalibrationRow>,
    /// The method whose iterations are given (its colour in the iteration plots), e.g. `RTS`.
    pub iterated_method: String,
    /// The parameters after each smoothing–calibration iteration; index 0 is the start.
    pub iterations: Vec<Params>,
    /// Standard errors after each iteration: empty, or as long as `iterations`.
    pub iteration_std: Vec<Params>,
    /// The timing and mounting corrections every section's streams had
    /// applied (`None`: not given).
    pub corrections: Option<Corrections>,
}

/// The timing and mounting corrections of the drive's streams (delays, IMU
/// tilt, gyro scale): where they came from and one row each.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Corrections {
    /// Where they come from (`estimated on this drive (--corrections gnss)`,
    /// `stored in params.toml`).
    pub source: String,
    /// One row per correction.
    pub rows: Vec<CorrectionRow>,
}

/// One correction.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CorrectionRow {
    /// What (`GNSS delay`, `IMU tilt`, `gyro scale error`).
    pub what: String,
    /// Its unit (`s`, `°`, `%`).
    pub unit: String,
    /// The value (`None`: not estimated).
    pub value: Option<f64>,
    /// Its standard error (`None`: not known, as for a stored value).
    pub std: Option<f64>,
    /// Applied, reported only, or not estimated and why.
    pub status: String,
}

/// The drift evaluation of one method.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DriftMethod {
    /// The method (calibration), e.g. `RTS`.
    pub method: String,
    /// Horizontal error at the end of each dead-reckoned segment of `segment_m`, m.
    pub error_after_segment_m: Vec<f64>,
    /// Distance dead-reckoned before the error first reached `threshold_m`, m, one per run.
    pub distance_to_threshold_m: Vec<f64>,
}

/// The drift table (table IV) and figures 4–5 of the four-wheel paper.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Drift {
    /// Length of each dead-reckoned segment, m (the paper: 100).
    pub segment_m: f64,
    /// Error threshold of the distance test, m (the paper: 1).
    pub threshold_m: f64,
    /// One entry per method.
    pub methods: Vec<DriftMethod>,
}

impl Default for Drift {
    fn default() -> Self {
        Drift {
            segment_m: 100.0,
            threshold_m: 1.0,
            methods: Vec::new(),
        }
    }
}

/// The innovations of one scalar observation (one component of a sensor).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct InnovationSeries {
    /// Sensor and component, e.g. `gyro`, `GNSS east`.
    pub sensor: String,
    /// Unit of the innovation, e.g. `rad/s`, `m`.
    pub unit: String,
    /// Timestamps, s.
    pub t_s: Vec<f64>,
    /// Innovation y = z − h(x), in `unit`.
    pub innovation: Vec<f64>,
    /// Predicted standard deviation √S, in `unit`: empty, or as long as `t_s`.
    pub std: Vec<f64>,
    /// True where the observation was rejected by the gate: empty, or as long as `t_s`.
    pub gated: Vec<bool>,
}

/// The normalised innovation squared yᵀS⁻¹y of one sensor.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NisSeries {
    /// Sensor, e.g. `GNSS`, `wheels`.
    pub sensor: String,
    /// Degrees of freedom (dimension of the observation).
    pub dof: u32,
    /// Timestamps, s.
    pub t_s: Vec<f64>,
    /// NIS values.
    pub nis: Vec<f64>,
    /// True where the observation was rejected by the gate: empty, or as long as `t_s`.
    pub gated: Vec<bool>,
    /// The gate (chi-square value above which observations are rejected), if any.
    pub gate_chi2: Option<f64>,
}

/// An [`InnovationSeries`] reduced to what its figure draws and its
/// caption says ([`DrawnInnovations::of`]): the counts and quantiles of
/// every observation, exactly, and the samples the figure draws (at most
/// [`crate::MAX_POINTS`] of the ±2σ band, [`crate::MAX_SCATTER_POINTS`]
/// points, [`crate::MAX_POINTS`] gated ones). The figure is the same as the
/// full series'; a long drive's series need not be held whole (issue 30:
/// 72 MB on the hour's report).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DrawnInnovations {
    /// Sensor and component, as the series'.
    pub sensor: String,
    /// Unit of the innovation, as the series'.
    pub unit: String,
    /// Observations in the series.
    pub observations: usize,
    /// Observations the gate rejected.
    pub gated: usize,
    /// Accepted observations outside ±2σ.
    pub outside_two_sigma: usize,
    /// Whether the series has its predicted σ.
    pub has_std: bool,
    /// Whether the series says which observations were gated.
    pub has_gated: bool,
    /// First and last finite time, s (`None`: no figure).
    pub span_s: Option<(f64, f64)>,
    /// Half the height of the y range, in `unit`.
    pub half_range: f64,
    /// The band's samples drawn: times, s, and 2σ, in `unit`.
    pub band_t_s: Vec<f64>,
    /// 2σ at `band_t_s`.
    pub band_two_sigma: Vec<f64>,
    /// The points drawn: times, s, and the accepted innovations (NaN where gated).
    pub points_t_s: Vec<f64>,
    /// Accepted innovations at `points_t_s`.
    pub points: Vec<f64>,
    /// The gated observations drawn: times, s.
    pub gated_t_s: Vec<f64>,
    /// Innovations at `gated_t_s`.
    pub gated_values: Vec<f64>,
    /// The band's width against the innovations, when it dwarfs them.
    pub wide_band: Option<WideBand>,
}

/// A ±2σ band much wider than the innovations it should enclose.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct WideBand {
    /// The median 2σ, in the series' unit.
    pub band_half_width: f64,
    /// The 95th percentile of the accepted |innovation|.
    pub p95_abs: f64,
    /// `band_half_width / p95_abs`.
    pub ratio: f64,
}

/// A [`NisSeries`] reduced to what its figure draws and its caption says
/// ([`DrawnNis::of`]), as [`DrawnInnovations`].
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DrawnNis {
    /// Sensor, as the series'.
    pub sensor: String,
    /// Degrees of freedom, as the series'.
    pub dof: u32,
    /// The gate, as the series'.
    pub gate_chi2: Option<f64>,
    /// The two-sided probability of the bounds the counts are against.
    pub probability: f64,
    /// Observations in the series.
    pub observations: usize,
    /// Observations the gate rejected.
    pub gated: usize,
    /// Whether the series says which observations were gated.
    pub has_gated: bool,
    /// Accepted observations with a finite NIS.
    pub accepted: usize,
    /// Of those, inside the bounds.
    pub inside: usize,
    /// Their mean (NaN without any).
    pub mean: f64,
    /// Their 99th percentile (0 without any).
    pub p99: f64,
    /// First and last finite time, s (`None`: no figure).
    pub span_s: Option<(f64, f64)>,
    /// The points drawn: times, s, and the accepted NIS (NaN where gated).
    pub points_t_s: Vec<f64>,
    /// Accepted NIS at `points_t_s`.
    pub points: Vec<f64>,
    /// The gated observations drawn: times, s.
    pub gated_t_s: Vec<f64>,
    /// NIS at `gated_t_s`.
    pub gated_values: Vec<f64>,
}

/// Filter health: innovations and NIS over time.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FilterHealth {
    /// One series per sensor component.
    pub innovations: Vec<InnovationSeries>,
    /// One series per sensor.
    pub nis: Vec<NisSeries>,
    /// Series already reduced to their figures ([`DrawnInnovations::of`]),
    /// drawn after `innovations`.
    pub drawn_innovations: Vec<DrawnInnovations>,
    /// NIS series already reduced ([`DrawnNis::of`]), drawn after `nis`.
    pub drawn_nis: Vec<DrawnNis>,
    /// Two-sided probability of the NIS bounds drawn (default 0.95).
    pub nis_bound_probability: Option<f64>,
    /// The NEES through dead-reckoning windows against the truth (drives
    /// with truth only).
    pub consistency: Option<NeesConsistency>,
    /// The wheel-health monitor's lines (one per wheel, then each stretch a
    /// wheel was out of the fusion).
    pub wheel_health: Vec<String>,
}

/// The averaged NEES of one block of the state at one point of the windows.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NeesRow {
    /// `pose` (x, y, yaw) or `motion` (speed, yaw rate).
    pub block: String,
    /// Degrees of freedom.
    pub dof: u32,
    /// Fraction of the window elapsed.
    pub fraction: f64,
    /// Windows averaged.
    pub windows: u32,
    /// Averaged NEES.
    pub nees: f64,
    /// Lower and upper 95 % bounds of the average.
    pub lower: f64,
    /// Upper bound.
    pub upper: f64,
    /// `consistent`, `over-confident by ×k` or `under-confident by ×k`.
    pub verdict: String,
}

/// Filter consistency: NEES through dead-reckoning windows against the truth.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NeesConsistency {
    /// Window length, s.
    pub outage_s: f64,
    /// The verdict, e.g. `pose: consistent; motion: consistent`.
    pub summary: String,
    /// One row per block and point.
    pub rows: Vec<NeesRow>,
}

/// A scalar time series.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TimeSeries {
    /// Timestamps, s.
    pub t_s: Vec<f64>,
    /// Values, in the unit the field that holds the series names.
    pub value: Vec<f64>,
}

/// Cross-correlation between GNSS yaw rate and the wheel/gyro yaw rate by lag (figure 8).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct CrossCorrelation {
    /// Lags, samples.
    pub lag: Vec<i64>,
    /// Correlation coefficient at each lag.
    pub correlation: Vec<f64>,
    /// The lag the model uses, if any (marked; otherwise the peak is marked).
    pub chosen_lag: Option<i64>,
}

/// One coefficient of a regression model.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Coefficient {
    /// Name, e.g. `α0`, `α1`, `MA2`.
    pub name: String,
    /// Estimate.
    pub estimate: f64,
    /// Standard error.
    pub std_error: f64,
    /// t value.
    pub t_value: f64,
    /// Two-sided p value.
    pub p_value: f64,
}

/// A fitted regression model (table 1 of the TedriS paper).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct RegressionModel {
    /// The model option, e.g. `lag −2`, `lag −2 + MA(2)`.
    pub name: String,
    /// The coefficients.
    pub coefficients: Vec<Coefficient>,
    /// Goodness-of-fit figures, e.g. R², residual σ, Box–Pierce p.
    pub statistics: Vec<NamedValue>,
}

/// A label with a number.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct NamedValue {
    /// The label, with its unit.
    pub name: String,
    /// The value.
    pub value: f64,
}

/// The fill of the TedriS repositories.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Repositories {
    /// Repository index n (R_n), may be negative.
    pub index: Vec<i64>,
    /// Tuples stored in each repository.
    pub fill: Vec<u64>,
    /// The minimum fill that ends training, if set.
    pub min_fill: Option<u64>,
    /// The maximum fill of a repository, if set.
    pub max_fill: Option<u64>,
}

/// One method's error through one outage.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MethodSeries {
    /// The method, e.g. `TedriS`, `RTS`.
    pub method: String,
    /// Timestamps, s.
    pub t_s: Vec<f64>,
    /// Horizontal dead-reckoning error, m.
    pub error_m: Vec<f64>,
}

/// The dead-reckoning error through one GNSS outage (figures 6–7 of the TedriS paper).
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OutageRun {
    /// Name of the outage, e.g. `DR update`, `outage 2 (812–893 s)`.
    pub name: String,
    /// One series per method; time axes start at the outage start.
    pub series: Vec<MethodSeries>,
}

/// The TedriS section.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Tedris {
    /// Cross-correlation by lag.
    pub cross_correlation: Option<CrossCorrelation>,
    /// Regression models, shown side by side.
    pub models: Vec<RegressionModel>,
    /// GNSS heading during training, rad (yaw or course: drawn unwrapped, in degrees).
    pub gnss_heading_rad: Option<TimeSeries>,
    /// Heading reconstructed by the training phase, rad, same convention.
    pub training_heading_rad: Option<TimeSeries>,
    /// Repository fill.
    pub repositories: Option<Repositories>,
    /// Error through each outage.
    pub outages: Vec<OutageRun>,
    /// The error threshold line, m (the paper: 1).
    pub threshold_m: f64,
}

impl Default for Tedris {
    fn default() -> Self {
        Tedris {
            cross_correlation: None,
            models: Vec::new(),
            gnss_heading_rad: None,
            training_heading_rad: None,
            repositories: None,
            outages: Vec::new(),
            threshold_m: 1.0,
        }
    }
}

/// Final errors of one method over sliding outage windows.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MethodSample {
    /// The method.
    pub method: String,
    /// One value per window, m.
    pub final_error_m: Vec<f64>,
}

/// The outage evaluation: errors at the end of sliding simulated outages.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OutageEvaluation {
    /// Length of each simulated outage, s, if fixed.
    pub window_s: Option<f64>,
    /// One entry per method.
    pub methods: Vec<MethodSample>,
    /// The 95 % error bound of one method through the same windows
    /// (issue 31; absent in reports made before it).
    pub bound: Option<OutageBound>,
}

/// Error and 95 % bound against time in outage, over sliding windows, with
/// the coverage.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OutageBound {
    /// The method (parameter set) whose windows these are.
    pub method: String,
    /// The bound's factor in words (how it was fitted).
    pub factor: String,
    /// Per window: time since the outage start, s.
    pub time_s: Vec<Vec<f64>>,
    /// Per window: the horizontal error at each time, m.
    pub error_m: Vec<Vec<f64>>,
    /// Per window: the 95 % bound at each time, m.
    pub bound_m: Vec<Vec<f64>>,
    /// Windows whose final error is within the bound.
    pub within: usize,
    /// The median bound at the windows' ends over the median final error.
    pub sharpness: f64,
}

/// A kinematic shape's calibration (a tricycle against its tracker, a
/// differential drive against its GNSS fixes): its own parameters, not a
/// car's circumferences.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Kinematic {
    /// The shape and why it was chosen (`differential drive (the log has
    /// body velocity …)`).
    pub shape: String,
    /// What it was calibrated against (`gnss`, `truth`).
    pub method: String,
    /// One row per parameter, in the shape's order.
    pub params: Vec<KinematicParam>,
    /// The fit in words (windows used, residual at the window ends).
    pub fit: String,
}

/// One parameter of a kinematic calibration.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct KinematicParam {
    /// Name with unit (`speed_scale`, `yaw_bias_rps`).
    pub name: String,
    /// The value: fitted, or nominal when not estimated.
    pub value: f64,
    /// Its standard error, when estimated.
    pub std: Option<f64>,
    /// `estimated`, or why not.
    pub status: String,
}
