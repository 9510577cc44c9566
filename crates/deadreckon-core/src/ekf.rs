//! The extended Kalman filter over a whole drive (eq. 11–19 of Welte et al.).
//!
//! Two timing schemes:
//!
//! - [`Timing::WheelEpochs`] (the paper's): one epoch per wheel row; the state is
//!   predicted to the wheel timestamp and updated with the wheels and the most
//!   recent *unused* reading of each other sensor (older readings between two
//!   wheel epochs are discarded, as in the paper) and with a GNSS fix if one
//!   arrived since the previous epoch.
//! - [`Timing::EachMeasurement`]: every reading is processed at its own
//!   timestamp, one epoch per reading.
//!
//! Any sensor may be absent: the filter uses the streams the drive has. The
//! per-epoch predicted and updated states, covariances and Jacobians are kept
//! when asked (`record`), for the RTS smoother.

use nalgebra::{Matrix2, SMatrix, SVector, Vector2};

use crate::drive::{Drive, Wheels};
use crate::kalman::{self, CovarianceForm};
use crate::model::{self, Mat, State, V};
use crate::observation::Sensors;
use crate::vehicle::{Noise, Params};
use crate::Error;

/// When the filter runs its epochs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Timing {
    /// One epoch per wheel row, with the latest reading of the other sensors (the paper).
    #[default]
    WheelEpochs,
    /// One epoch per reading, each at its own timestamp.
    EachMeasurement,
}

/// How the filter's initial state is chosen.
#[allow(clippy::large_enum_variant)] // a plain value passed once per run
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Init {
    /// From GNSS: the first fix for the position (minus the lever arm) and the
    /// direction of the first 10 m of displacement for the yaw. The filter starts at
    /// the first wheel epoch at or after the first fix.
    #[default]
    Gnss,
    /// From `truth.csv` at the first wheel epoch, with a small covariance.
    Truth,
    /// A given state and covariance at the first wheel epoch at or after `t_s`.
    Given {
        /// Start time, s.
        t_s: f64,
        /// Initial state.
        x: State,
        /// Initial covariance.
        p: Mat,
    },
}

/// Which sensors the filter uses (all by default, when present in the drive).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SensorSet {
    /// Wheel encoders or wheel speeds.
    pub wheels: bool,
    /// Gyro.
    pub gyro: bool,
    /// CAN speed.
    pub speed: bool,
    /// Steering wheel angle.
    pub steering: bool,
    /// GNSS positions.
    pub gnss: bool,
    /// GNSS course as a yaw observation (not in the paper; off by default).
    pub gnss_course: bool,
}

impl Default for SensorSet {
    fn default() -> Self {
        SensorSet {
            wheels: true,
            gyro: true,
            speed: true,
            steering: true,
            gnss: true,
            gnss_course: false,
        }
    }
}

impl SensorSet {
    /// Dead reckoning: every proprioceptive sensor, no GNSS.
    pub fn dead_reckoning() -> Self {
        SensorSet {
            gnss: false,
            gnss_course: false,
            ..Default::default()
        }
    }
}

/// Options of a filter run.
#[derive(Debug, Clone, PartialEq)]
pub struct FilterOptions {
    /// Timing scheme.
    pub timing: Timing,
    /// Initial state.
    pub init: Init,
    /// Sensors to use.
    pub sensors: SensorSet,
    /// GNSS outages: fixes with `start <= t < end` are hidden from the filter.
    pub gnss_outages: Vec<(f64, f64)>,
    /// Covariance update form.
    pub covariance_form: CovarianceForm,
    /// Keep every epoch (needed by the smoother).
    pub record_epochs: bool,
    /// Keep every innovation (for filter-health plots).
    pub record_innovations: bool,
    /// Stop after the last epoch at or before this time, s.
    pub end_s: Option<f64>,
}

impl Default for FilterOptions {
    fn default() -> Self {
        FilterOptions {
            timing: Timing::WheelEpochs,
            init: Init::Gnss,
            sensors: SensorSet::default(),
            gnss_outages: Vec::new(),
            covariance_form: CovarianceForm::Joseph,
            record_epochs: true,
            record_innovations: false,
            end_s: None,
        }
    }
}

/// One filter epoch, as the smoother needs it. `N` is 5 for the car state and
/// 11 for the state augmented with the six parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Epoch<const N: usize = 5> {
    /// Timestamp, s.
    pub t_s: f64,
    /// x̂_{k|k-1}.
    pub x_pred: SVector<f64, N>,
    /// P_{k|k-1}.
    pub p_pred: SMatrix<f64, N, N>,
    /// F_k, the Jacobian of the prediction from the previous epoch to this one,
    /// car block only: the full Jacobian is `diag(f, I)` (the parameters of the
    /// augmented state are constants), which keeps a recorded hour of the
    /// 11-state filter a quarter smaller.
    pub f: Mat,
    /// x̂_{k|k}.
    pub x: SVector<f64, N>,
    /// P_{k|k}.
    pub p: SMatrix<f64, N, N>,
}

/// Which sensor an innovation belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum SensorKind {
    /// Wheel `0..4` (FL, FR, RL, RR).
    Wheel(u8),
    /// Gyro.
    Gyro,
    /// CAN speed.
    Speed,
    /// Steering.
    Steering,
    /// GNSS position (2-D; the NIS has 2 degrees of freedom).
    Gnss,
    /// GNSS course.
    Course,
}

impl SensorKind {
    /// A short stable name.
    pub fn name(&self) -> &'static str {
        match self {
            SensorKind::Wheel(0) => "wheel_fl",
            SensorKind::Wheel(1) => "wheel_fr",
            SensorKind::Wheel(2) => "wheel_rl",
            SensorKind::Wheel(_) => "wheel_rr",
            SensorKind::Gyro => "gyro",
            SensorKind::Speed => "speed",
            SensorKind::Steering => "steering",
            SensorKind::Gnss => "gnss",
            SensorKind::Course => "course",
        }
    }
    /// Degrees of freedom of the measurement.
    pub fn dof(&self) -> usize {
        if *self == SensorKind::Gnss {
            2
        } else {
            1
        }
    }
}

/// One recorded innovation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InnovationRecord {
    /// Timestamp, s.
    pub t_s: f64,
    /// Sensor.
    pub sensor: SensorKind,
    /// Innovation (first component for GNSS).
    pub y: f64,
    /// Innovation variance (first diagonal element for GNSS).
    pub s: f64,
    /// Normalised innovation squared.
    pub nis: f64,
    /// False when the measurement was rejected by the gate.
    pub accepted: bool,
}

/// Counts of what the filter used, gated and skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct FilterStats {
    /// Epochs run.
    pub epochs: usize,
    /// Wheel rows used.
    pub wheel_updates: usize,
    /// Wheel rows skipped because the interval since the previous row was a gap
    /// (more than 5 times the median interval).
    pub wheel_gaps: usize,
    /// Gyro readings used.
    pub gyro_updates: usize,
    /// CAN speed readings used.
    pub speed_updates: usize,
    /// Steering readings used.
    pub steering_updates: usize,
    /// Readings of the other sensors not used because a newer one arrived before the
    /// next wheel epoch (the paper's scheme).
    pub readings_superseded: usize,
    /// GNSS fixes used.
    pub gnss_updates: usize,
    /// GNSS fixes rejected by the Mahalanobis gate.
    pub gnss_rejected: usize,
    /// Fixes accepted after `gnss_max_rejections` consecutive rejections, with the
    /// position covariance inflated (the filter had lost the GNSS track).
    pub gnss_recoveries: usize,
    /// GNSS fixes hidden by an outage window.
    pub gnss_hidden: usize,
    /// GNSS course readings used.
    pub course_updates: usize,
}

/// The result of a filter run.
#[derive(Debug, Clone)]
pub struct FilterOutput<const N: usize = 5> {
    /// Every epoch (empty unless `record_epochs`).
    pub epochs: Vec<Epoch<N>>,
    /// Every innovation (empty unless `record_innovations`).
    pub innovations: Vec<InnovationRecord>,
    /// Counters.
    pub stats: FilterStats,
}

impl<const N: usize> Default for FilterOutput<N> {
    fn default() -> Self {
        FilterOutput {
            epochs: Vec::new(),
            innovations: Vec::new(),
            stats: FilterStats::default(),
        }
    }
}

/// A hook called after every epoch with the time and the updated state and
/// covariance, which it may change (e.g. to reset the state to the truth).
pub trait EpochHook<const N: usize = 5> {
    /// Called after the updates of the epoch at `t_s`.
    fn after_epoch(&mut self, t_s: f64, x: &mut SVector<f64, N>, p: &mut SMatrix<f64, N, N>);
}

impl<const N: usize> EpochHook<N> for () {
    fn after_epoch(&mut self, _t_s: f64, _x: &mut SVector<f64, N>, _p: &mut SMatrix<f64, N, N>) {}
}

/// Dimension of the augmented state: the car state then the six parameters
/// `[b_gyro, a_v, 1/ρ_FL, 1/ρ_FR, 1/ρ_RL, 1/ρ_RR]`.
pub const N_AUG: usize = 11;
/// Index of the gyro bias in the augmented state.
pub const AUG_BIAS: usize = 5;
/// Index of the speed scale in the augmented state.
pub const AUG_SCALE: usize = 6;
/// Index of the first inverse circumference (FL, then FR, RL, RR) in the augmented state.
pub const AUG_INV_CIRC: usize = 7;

/// The filter's running state. With `N == 5` the parameters are fixed; with
/// `N == N_AUG` they are states, and the sensor models read them from the state.
struct Filter<'a, const N: usize> {
    sensors: Sensors,
    noise: Noise,
    form: CovarianceForm,
    x: SVector<f64, N>,
    p: SMatrix<f64, N, N>,
    t: f64,
    opts: &'a FilterOptions,
    out: FilterOutput<N>,
    consecutive_rejections: u32,
    wheels_present: [bool; 4],
}

impl<const N: usize> Filter<'_, N> {
    fn car(&self) -> State {
        self.x.fixed_rows::<5>(0).into_owned()
    }

    /// Points the sensor models at the parameters held in the augmented state.
    fn refresh_params(&mut self) {
        if N == N_AUG {
            self.sensors.params.gyro_bias_rps = self.x[AUG_BIAS];
            self.sensors.params.speed_scale = self.x[AUG_SCALE];
            for i in 0..4 {
                self.sensors.inv_circumference[i] = self.x[AUG_INV_CIRC + i];
            }
        }
    }

    fn predict(&mut self, t: f64) -> (SVector<f64, N>, SMatrix<f64, N, N>, Mat) {
        let dt = (t - self.t).max(0.0);
        let car = self.car();
        let f5 = model::jacobian(&car, dt);
        let q5 = model::process_noise(&self.noise, dt);
        self.x
            .fixed_rows_mut::<5>(0)
            .copy_from(&model::evolve(&car, dt));
        if N == 5 {
            self.p = kalman::predict_covariance(
                &self.p,
                &SMatrix::<f64, N, N>::from_fn(|i, j| f5[(i % 5, j % 5)]),
                &SMatrix::<f64, N, N>::from_fn(|i, j| q5[(i % 5, j % 5)]),
            );
        } else {
            // F = diag(F_car, I) and Q = diag(Q_car, 0): only the car rows and
            // columns change. P11 ← F P11 Fᵀ + Q, P12 ← F P12, P22 unchanged.
            let p11 = self.p.fixed_view::<5, 5>(0, 0).into_owned();
            let n11 = f5 * p11 * f5.transpose() + q5;
            let n11 = (n11 + n11.transpose()) * 0.5;
            self.p.fixed_view_mut::<5, 5>(0, 0).copy_from(&n11);
            for j in 5..N {
                let col: State = self.p.fixed_view::<5, 1>(0, j).into_owned();
                let nc = f5 * col;
                for i in 0..5 {
                    self.p[(i, j)] = nc[i];
                    self.p[(j, i)] = nc[i];
                }
            }
        }
        self.t = t;
        (self.x, self.p, f5)
    }

    /// A scalar update from a car-state model `pred = (h, H)`; `param` adds the
    /// derivative with respect to one parameter (index in the parameter block)
    /// when the parameters are states.
    fn scalar(
        &mut self,
        sensor: SensorKind,
        z: f64,
        pred: (f64, model::Row),
        r: f64,
        param: Option<(usize, f64)>,
    ) -> Result<(), Error> {
        let (h, row5) = pred;
        let mut row = SVector::<f64, N>::zeros();
        row.fixed_rows_mut::<5>(0).copy_from(&row5);
        if let (true, Some((j, d))) = (N == N_AUG, param) {
            row[5 + j] = d;
        }
        let y = if sensor == SensorKind::Course {
            crate::angle::diff(z, h)
        } else {
            z - h
        };
        let inn = kalman::update_scalar(&mut self.x, &mut self.p, y, &row, r, self.form, self.t)?;
        self.refresh_params();
        if self.opts.record_innovations {
            self.out.innovations.push(InnovationRecord {
                t_s: self.t,
                sensor,
                y: inn.y,
                s: inn.s,
                nis: inn.nis,
                accepted: true,
            });
        }
        Ok(())
    }

    fn wheels(&mut self, wheels: &Wheels, k: usize, max_interval: f64) -> Result<(), Error> {
        let interval = wheels.t_s(k) - wheels.t_s(k - 1);
        if interval > max_interval {
            self.out.stats.wheel_gaps += 1;
            return Ok(());
        }
        self.out.stats.wheel_updates += 1;
        match wheels {
            Wheels::Ticks(rows) => {
                let r = rows[k];
                let r2 = self.noise.wheel_ticks.powi(2);
                for (i, z) in [r.fl, r.fr, r.rl, r.rr].into_iter().enumerate() {
                    if !self.wheels_present[i] {
                        continue;
                    }
                    let pred = self.sensors.wheel_ticks(&self.car(), i, interval);
                    // ∂h/∂(1/ρ_i) = h·ρ_i: the model is linear in the inverse circumference.
                    let d = pred.0 / self.sensors.inv_circumference[i];
                    self.scalar(
                        SensorKind::Wheel(i as u8),
                        z as f64,
                        pred,
                        r2,
                        Some((2 + i, d)),
                    )?;
                }
            }
            Wheels::Speeds(rows) => {
                let r = rows[k];
                let r2 = self.noise.wheel_speed_mps.powi(2);
                for (i, z) in [r.fl_mps, r.fr_mps, r.rl_mps, r.rr_mps]
                    .into_iter()
                    .enumerate()
                {
                    let pred = self.sensors.wheel_speed(&self.car(), i);
                    let d = pred.0 / self.sensors.inv_circumference[i];
                    self.scalar(SensorKind::Wheel(i as u8), z, pred, r2, Some((2 + i, d)))?;
                }
            }
        }
        Ok(())
    }

    fn gnss(&mut self, fix: &crate::drive::GnssFix) -> Result<(), Error> {
        let (h, jac5) = self.sensors.gnss(&self.car());
        let mut jac = SMatrix::<f64, 2, N>::zeros();
        jac.fixed_view_mut::<2, 5>(0, 0).copy_from(&jac5);
        let y = Vector2::new(fix.east_m, fix.north_m) - h;
        let r = Matrix2::identity() * fix.std_m.powi(2);
        let (mut s, _, mut nis) = kalman::innovation_stats(&self.p, &y, &jac, &r, self.t)?;
        let mut accepted = nis <= self.noise.gnss_gate_chi2;
        if !accepted && self.consecutive_rejections >= self.noise.gnss_max_rejections {
            // Lost: widen the position (and yaw) uncertainty to cover the
            // innovation, then take the fix.
            let d2 = y.norm_squared();
            for i in [model::X, model::Y] {
                self.p[(i, i)] += d2;
            }
            self.p[(model::YAW, model::YAW)] += 0.1f64.powi(2);
            (s, _, nis) = kalman::innovation_stats(&self.p, &y, &jac, &r, self.t)?;
            accepted = true;
            self.out.stats.gnss_recoveries += 1;
        }
        self.consecutive_rejections = if accepted {
            0
        } else {
            self.consecutive_rejections + 1
        };
        if accepted {
            kalman::update_vector(&mut self.x, &mut self.p, &y, &jac, &r, self.form, self.t)?;
            self.refresh_params();
            self.out.stats.gnss_updates += 1;
        } else {
            self.out.stats.gnss_rejected += 1;
        }
        if self.opts.record_innovations {
            self.out.innovations.push(InnovationRecord {
                t_s: self.t,
                sensor: SensorKind::Gnss,
                y: y[0],
                s: s[(0, 0)],
                nis,
                accepted,
            });
        }
        if accepted && self.opts.sensors.gnss_course {
            if let (Some(course), Some(speed)) = (fix.course_yaw_rad(), fix.speed_mps) {
                if speed > 3.0 {
                    // Course noise shrinks with speed: about 0.5 m/s of velocity noise.
                    let sigma = (0.5 / speed).min(0.3);
                    let pred = self.sensors.yaw(&self.car());
                    self.scalar(SensorKind::Course, course, pred, sigma * sigma, None)?;
                    self.out.stats.course_updates += 1;
                }
            }
        }
        Ok(())
    }

    /// Eq. (4): one gyro reading.
    fn gyro(&mut self, value: f64) -> Result<(), Error> {
        let pred = self.sensors.gyro(&self.car());
        let r = self.noise.gyro_rps.powi(2);
        self.scalar(SensorKind::Gyro, value, pred, r, Some((0, 1.0)))?;
        self.out.stats.gyro_updates += 1;
        Ok(())
    }

    /// Eq. (5): one CAN speed reading.
    fn can_speed(&mut self, value: f64) -> Result<(), Error> {
        let pred = self.sensors.can_speed(&self.car());
        let r = self.noise.speed_mps.powi(2);
        let d_scale = self.x[V];
        self.scalar(SensorKind::Speed, value, pred, r, Some((1, d_scale)))?;
        self.out.stats.speed_updates += 1;
        Ok(())
    }

    /// Eq. (7): one steering-wheel reading, with the prior speed.
    fn steering(&mut self, steering_wheel_rad: f64) -> Result<(), Error> {
        let (z, r) =
            self.sensors
                .steering_measurement(steering_wheel_rad, self.x[V], self.noise.steering);
        let pred = self.sensors.steering(&self.car());
        self.scalar(SensorKind::Steering, z, pred, r, None)?;
        self.out.stats.steering_updates += 1;
        Ok(())
    }

    fn record(&mut self, pred: (SVector<f64, N>, SMatrix<f64, N, N>, Mat)) {
        self.out.stats.epochs += 1;
        if self.opts.record_epochs {
            self.out.epochs.push(Epoch {
                t_s: self.t,
                x_pred: pred.0,
                p_pred: pred.1,
                f: pred.2,
                x: self.x,
                p: self.p,
            });
        }
    }
}

/// Median wheel interval, s.
fn median_interval(wheels: &Wheels) -> f64 {
    let mut d: Vec<f64> = (1..wheels.len())
        .map(|k| wheels.t_s(k) - wheels.t_s(k - 1))
        .collect();
    if d.is_empty() {
        return 0.02;
    }
    let mid = d.len() / 2;
    *d.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
}

/// Interpolated reference pose from the truth at `t`, as a full state (speed and
/// yaw rate derived by finite differences where not given).
pub fn truth_state(drive: &Drive, t: f64) -> Option<State> {
    crate::reference::Reference::from_truth(&drive.truth).and_then(|r| r.state_at(t))
}

fn initial_state(drive: &Drive, opts: &FilterOptions) -> Result<(f64, State, Mat), Error> {
    match opts.init {
        Init::Given { t_s, x, p } => Ok((t_s, x, p)),
        Init::Truth => {
            let t0 = drive.wheels.t_s(0).max(
                drive
                    .truth
                    .first()
                    .map(|t| t.t_s)
                    .unwrap_or(f64::NEG_INFINITY),
            );
            let x = truth_state(drive, t0).ok_or_else(|| {
                Error::Insufficient(
                    "initialisation from the truth needs truth.csv covering the drive".into(),
                )
            })?;
            let p = Mat::from_diagonal(&State::from([1e-4, 1e-4, 1e-6, 1e-2, 1e-4]));
            Ok((t0, x, p))
        }
        Init::Gnss => {
            let first = drive
                .gnss
                .iter()
                .find(|g| !in_outage(&opts.gnss_outages, g.t_s))
                .ok_or_else(|| {
                    Error::Insufficient("initialisation from GNSS needs at least one fix".into())
                })?;
            let far = drive
                .gnss
                .iter()
                .filter(|g| g.t_s > first.t_s && !in_outage(&opts.gnss_outages, g.t_s))
                .find(|g| (g.east_m - first.east_m).hypot(g.north_m - first.north_m) >= 10.0)
                .ok_or_else(|| {
                    Error::Insufficient(
                        "initialisation from GNSS needs the vehicle to move 10 m".into(),
                    )
                })?;
            let yaw = (far.north_m - first.north_m).atan2(far.east_m - first.east_m);
            let l = drive.vehicle.gnss_lever_arm_m;
            let x = State::from([
                first.east_m - l * yaw.cos(),
                first.north_m - l * yaw.sin(),
                yaw,
                0.0,
                0.0,
            ]);
            let sp = first.std_m.max(0.1);
            let p = Mat::from_diagonal(&State::from([sp * sp, sp * sp, 0.3f64.powi(2), 4.0, 0.25]));
            Ok((first.t_s, x, p))
        }
    }
}

fn in_outage(outages: &[(f64, f64)], t: f64) -> bool {
    outages.iter().any(|&(a, b)| t >= a && t < b)
}

/// A cursor over a timestamped stream: yields the readings up to a time.
struct Cursor {
    next: usize,
}

impl Cursor {
    /// Advances past all readings with `t <= t_end`; returns the index of the last
    /// one passed and how many were passed.
    fn advance(
        &mut self,
        times: impl Fn(usize) -> f64,
        len: usize,
        t_end: f64,
    ) -> (Option<usize>, usize) {
        let start = self.next;
        while self.next < len && times(self.next) <= t_end {
            self.next += 1;
        }
        let n = self.next - start;
        (if n > 0 { Some(self.next - 1) } else { None }, n)
    }
}

/// Runs the EKF over `drive` with the calibration `params`.
pub fn run(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    hook: &mut dyn EpochHook,
) -> Result<FilterOutput, Error> {
    run_generic::<5>(drive, params, None, opts, hook)
}

/// Runs the EKF with the state augmented by the six parameters, which start at
/// `params` with standard deviations `prior_std` (circumferences in metres) and
/// are then estimated with the car state. Used by the calibration.
pub fn run_augmented(
    drive: &Drive,
    params: &Params,
    prior_std: &Params,
    opts: &FilterOptions,
) -> Result<FilterOutput<N_AUG>, Error> {
    run_generic::<N_AUG>(drive, params, Some(prior_std), opts, &mut ())
}

fn run_generic<const N: usize>(
    drive: &Drive,
    params: &Params,
    prior_std: Option<&Params>,
    opts: &FilterOptions,
    hook: &mut dyn EpochHook<N>,
) -> Result<FilterOutput<N>, Error> {
    drive.validate()?;
    params.validate()?;
    let (t0, x0, p0) = initial_state(drive, opts)?;
    let sensors = Sensors::new(&drive.vehicle, params);
    let mut x = SVector::<f64, N>::zeros();
    let mut p = SMatrix::<f64, N, N>::zeros();
    x.fixed_rows_mut::<5>(0).copy_from(&x0);
    p.fixed_view_mut::<5, 5>(0, 0).copy_from(&p0);
    if N == N_AUG {
        let sd = prior_std.ok_or_else(|| {
            Error::InvalidParams("the augmented filter needs prior standard deviations".into())
        })?;
        let c = params.circumferences();
        let cs = sd.circumferences();
        x[AUG_BIAS] = params.gyro_bias_rps;
        x[AUG_SCALE] = params.speed_scale;
        p[(AUG_BIAS, AUG_BIAS)] = sd.gyro_bias_rps.powi(2);
        p[(AUG_SCALE, AUG_SCALE)] = sd.speed_scale.powi(2);
        for i in 0..4 {
            x[AUG_INV_CIRC + i] = 1.0 / c[i];
            // σ(1/ρ) = σ(ρ)/ρ².
            p[(AUG_INV_CIRC + i, AUG_INV_CIRC + i)] = (cs[i] / (c[i] * c[i])).powi(2);
        }
        if (0..6).any(|j| p[(5 + j, 5 + j)].is_nan() || p[(5 + j, 5 + j)] <= 0.0) {
            return Err(Error::InvalidParams(
                "prior standard deviations of the parameters must be positive".into(),
            ));
        }
    }
    let mut f = Filter {
        sensors,
        noise: drive.vehicle.noise,
        form: opts.covariance_form,
        x,
        p,
        t: t0,
        opts,
        out: FilterOutput::default(),
        consecutive_rejections: 0,
        wheels_present: drive.vehicle.wheels_present,
    };
    let wheels = &drive.wheels;
    let max_interval = 5.0 * median_interval(wheels);
    let k0 = (0..wheels.len())
        .find(|&k| wheels.t_s(k) >= t0)
        .unwrap_or(wheels.len());
    if k0 + 1 >= wheels.len() {
        return Err(Error::Insufficient(
            "no wheel epochs after the initial time".into(),
        ));
    }
    let use_ = opts.sensors;
    // Readings before the start are skipped.
    let mut gyro = Cursor {
        next: drive.yaw_rate.partition_point(|s| s.t_s <= t0),
    };
    let mut speed = Cursor {
        next: drive.speed.partition_point(|s| s.t_s <= t0),
    };
    let mut steer = Cursor {
        next: drive.steering.partition_point(|s| s.t_s <= t0),
    };
    let mut gnss = Cursor {
        next: drive.gnss.partition_point(|s| s.t_s <= t0),
    };

    match opts.timing {
        Timing::WheelEpochs => {
            for k in (k0 + 1)..wheels.len() {
                let t = wheels.t_s(k);
                if opts.end_s.is_some_and(|e| t > e) {
                    break;
                }
                let pred = f.predict(t);
                if use_.wheels {
                    f.wheels(wheels, k, max_interval)?;
                }
                let (gi, n) = gyro.advance(|i| drive.yaw_rate[i].t_s, drive.yaw_rate.len(), t);
                if let (Some(i), true) = (gi, use_.gyro) {
                    f.out.stats.readings_superseded += n - 1;
                    f.gyro(drive.yaw_rate[i].value)?;
                }
                let (si, n) = speed.advance(|i| drive.speed[i].t_s, drive.speed.len(), t);
                if let (Some(i), true) = (si, use_.speed) {
                    f.out.stats.readings_superseded += n - 1;
                    f.can_speed(drive.speed[i].value)?;
                }
                let (di, n) = steer.advance(|i| drive.steering[i].t_s, drive.steering.len(), t);
                if let (Some(i), true) = (di, use_.steering) {
                    f.out.stats.readings_superseded += n - 1;
                    f.steering(drive.steering[i].value)?;
                }
                let start = gnss.next;
                let (last, _) = gnss.advance(|i| drive.gnss[i].t_s, drive.gnss.len(), t);
                if let (Some(last), true) = (last, use_.gnss) {
                    // Use the newest visible fix of the interval.
                    let visible = (start..=last)
                        .rev()
                        .find(|&i| !in_outage(&opts.gnss_outages, drive.gnss[i].t_s));
                    f.out.stats.gnss_hidden += (start..=last)
                        .filter(|&i| in_outage(&opts.gnss_outages, drive.gnss[i].t_s))
                        .count();
                    if let Some(i) = visible {
                        f.gnss(&drive.gnss[i])?;
                    }
                }
                hook.after_epoch(t, &mut f.x, &mut f.p);
                f.record(pred);
            }
        }
        Timing::EachMeasurement => {
            // Merge the streams by time. Ties: wheels, gyro, speed, steering, GNSS.
            #[derive(Clone, Copy)]
            enum Ev {
                Wheel(usize),
                Gyro(usize),
                Speed(usize),
                Steer(usize),
                Gnss(usize),
            }
            let mut evs: Vec<(f64, u8, Ev)> = Vec::new();
            let t_end = wheels
                .t_s(wheels.len() - 1)
                .min(opts.end_s.unwrap_or(f64::INFINITY));
            if use_.wheels {
                evs.extend(
                    ((k0 + 1)..wheels.len())
                        .filter(|&k| wheels.t_s(k) <= t_end)
                        .map(|k| (wheels.t_s(k), 0, Ev::Wheel(k))),
                );
            }
            let within = |t: f64| t > t0 && t <= t_end;
            if use_.gyro {
                evs.extend(
                    drive
                        .yaw_rate
                        .iter()
                        .enumerate()
                        .filter(|(_, s)| within(s.t_s))
                        .map(|(i, s)| (s.t_s, 1, Ev::Gyro(i))),
                );
            }
            if use_.speed {
                evs.extend(
                    drive
                        .speed
                        .iter()
                        .enumerate()
                        .filter(|(_, s)| within(s.t_s))
                        .map(|(i, s)| (s.t_s, 2, Ev::Speed(i))),
                );
            }
            if use_.steering {
                evs.extend(
                    drive
                        .steering
                        .iter()
                        .enumerate()
                        .filter(|(_, s)| within(s.t_s))
                        .map(|(i, s)| (s.t_s, 3, Ev::Steer(i))),
                );
            }
            if use_.gnss {
                for (i, g) in drive.gnss.iter().enumerate().filter(|(_, g)| within(g.t_s)) {
                    if in_outage(&opts.gnss_outages, g.t_s) {
                        f.out.stats.gnss_hidden += 1;
                    } else {
                        evs.push((g.t_s, 4, Ev::Gnss(i)));
                    }
                }
            }
            evs.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            for (t, _, ev) in evs {
                let pred = f.predict(t);
                match ev {
                    Ev::Wheel(k) => f.wheels(wheels, k, max_interval)?,
                    Ev::Gyro(i) => f.gyro(drive.yaw_rate[i].value)?,
                    Ev::Speed(i) => f.can_speed(drive.speed[i].value)?,
                    Ev::Steer(i) => f.steering(drive.steering[i].value)?,
                    Ev::Gnss(i) => f.gnss(&drive.gnss[i])?,
                }
                hook.after_epoch(t, &mut f.x, &mut f.p);
                f.record(pred);
            }
        }
    }
    Ok(f.out)
}
