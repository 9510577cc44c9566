//! The four-wheel filter one measurement at a time: the step API.
//!
//! A [`Filter`] holds the state, its covariance, the sensor models and the gate
//! counters. [`Filter::predict_to`] advances it in time (eq. 11–12) and one
//! `update_*` method per sensor applies a measurement (eq. 13–17) after a
//! χ² (Mahalanobis) gate with a per-sensor threshold from the vehicle's
//! [`Noise`]. Every update returns an [`Update`]: the innovation, its variance,
//! the normalised innovation squared and whether the gate accepted it.
//!
//! The state layout is a type: [`CarLayout`] (the five car states
//! `[x, y, ψ, v, ψ̇]`, parameters fixed) or [`AugmentedLayout`] (the car states
//! then the six parameters `[b_gyro, a_v, 1/ρ_FL, 1/ρ_FR, 1/ρ_RL, 1/ρ_RR]`,
//! estimated with the car state, as the calibration and the online learner use).
//!
//! The filter serialises (serde) with everything it needs to go on, so a run can
//! stop and resume bit-identically. Batch runs over a recorded drive
//! ([`crate::ekf::run`]) are loops feeding it.
//!
//! ```
//! use deadreckon_core::filter::{CarFilter, CarLayout};
//! use deadreckon_core::model::{Mat, State};
//! use deadreckon_core::{Params, Vehicle};
//!
//! let vehicle = Vehicle::paper_car();
//! let params = Params::nominal(&vehicle);
//! let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
//! let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
//! let mut f = CarFilter::new(&vehicle, &params, None, 0.0, x0, p0).unwrap();
//! f.predict_to(0.02);
//! // 10 m/s for 20 ms on a 1.92 m wheel with 48 ticks: 5 ticks.
//! let u = f.update_wheel_ticks(2, 5.0, 0.02).unwrap().unwrap();
//! assert!(u.accepted && u.nis < 3.0);
//! let u = f.update_gyro(0.0).unwrap();
//! assert!(u.accepted);
//! assert!((f.car_state()[3] - 10.0).abs() < 0.5);
//! ```

use std::marker::PhantomData;

use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
use serde::{Deserialize, Serialize};

use crate::drive::GnssFix;
use crate::gnss_error::{add_wander, Wander};
use crate::kalman::{self, CovarianceForm};
use crate::model::{self, Mat, State, V};
use crate::observation::Sensors;
use crate::vehicle::{Noise, Params, Vehicle};
use crate::Error;

/// Index of the gyro bias in the augmented state.
pub const AUG_BIAS: usize = 5;
/// Index of the speed scale in the augmented state.
pub const AUG_SCALE: usize = 6;
/// Index of the first inverse circumference (FL, then FR, RL, RR) in the augmented state.
pub const AUG_INV_CIRC: usize = 7;
/// Dimension of the augmented state.
pub const N_AUG: usize = 11;

/// Where the six parameters live in a state of dimension `N`.
pub trait Layout<const N: usize>: Copy + std::fmt::Debug + Default + PartialEq {
    /// A short name (`car`, `augmented`).
    const NAME: &'static str;
    /// Index in the state of parameter `j` (0 gyro bias, 1 speed scale, 2..6 the
    /// inverse circumferences FL..RR), or `None` when the parameters are fixed.
    fn param_index(j: usize) -> Option<usize>;
    /// Index in the state of the receiver's wander east (north follows), or
    /// `None` when the fixes are taken as white ([`crate::gnss_error`]).
    fn wander_index() -> Option<usize> {
        None
    }
    /// Whether the gyro bias (parameter 0, which must then be a state) walks
    /// by `noise.gyro_bias_walk_rps_per_sqrt_s` ([`crate::gyro_drift`]);
    /// the calibration's parameters are constants.
    fn bias_walks() -> bool {
        false
    }
}

/// The five car states; the parameters are fixed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct CarLayout;

impl Layout<5> for CarLayout {
    const NAME: &'static str = "car";
    fn param_index(_j: usize) -> Option<usize> {
        None
    }
}

/// The car states then the six parameters, estimated as constant states.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct AugmentedLayout;

impl Layout<N_AUG> for AugmentedLayout {
    const NAME: &'static str = "augmented";
    fn param_index(j: usize) -> Option<usize> {
        (j < 6).then_some(5 + j)
    }
}

/// The filter with fixed parameters.
pub type CarFilter = Filter<CarLayout, 5>;
/// The filter with the parameters as states.
pub type AugmentedFilter = Filter<AugmentedLayout, N_AUG>;

/// Which sensor a measurement comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
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
    /// Every kind, in a fixed order (for tables).
    pub const ALL: [SensorKind; 9] = [
        SensorKind::Wheel(0),
        SensorKind::Wheel(1),
        SensorKind::Wheel(2),
        SensorKind::Wheel(3),
        SensorKind::Gyro,
        SensorKind::Speed,
        SensorKind::Steering,
        SensorKind::Gnss,
        SensorKind::Course,
    ];

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

    fn slot(&self) -> usize {
        match self {
            SensorKind::Wheel(i) => (*i as usize).min(3),
            SensorKind::Gyro => 4,
            SensorKind::Speed => 5,
            SensorKind::Steering => 6,
            SensorKind::Gnss => 7,
            SensorKind::Course => 8,
        }
    }
}

/// The χ² gate of a sensor, from the vehicle's noise settings.
pub fn gate_chi2(noise: &Noise, sensor: SensorKind) -> f64 {
    match sensor {
        SensorKind::Wheel(_) => noise.wheel_gate_chi2,
        SensorKind::Gyro => noise.gyro_gate_chi2,
        SensorKind::Speed => noise.speed_gate_chi2,
        SensorKind::Steering => noise.steering_gate_chi2,
        SensorKind::Course => noise.course_gate_chi2,
        SensorKind::Gnss => noise.gnss_gate_chi2,
    }
}

/// The outcome of one measurement update.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Update {
    /// The sensor.
    pub sensor: SensorKind,
    /// Innovation `z − h(x̂⁻)` (first component for GNSS).
    pub y: f64,
    /// Innovation variance (first diagonal element for GNSS).
    pub s: f64,
    /// Normalised innovation squared `ỹᵀ S⁻¹ ỹ`.
    pub nis: f64,
    /// `ln det S` of the innovation covariance the gate decided with (`ln s`
    /// for a scalar): with `nis`, the measurement's Gaussian log-likelihood
    /// (what [`crate::wander_fit`] compares receiver models by).
    pub ln_det_s: f64,
    /// False when the χ² gate rejected the measurement (the state is unchanged).
    pub accepted: bool,
}

/// Per-sensor gate counters: measurements used and rejected, and recoveries
/// (a measurement accepted after too many consecutive rejections).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct GateCounts {
    /// Accepted measurements, per sensor in [`SensorKind::ALL`] order.
    pub accepted: [u64; 9],
    /// Rejected measurements, same order.
    pub rejected: [u64; 9],
    /// Recoveries, same order.
    pub recovered: [u64; 9],
}

impl GateCounts {
    /// Accepted measurements of one sensor.
    pub fn accepted(&self, k: SensorKind) -> u64 {
        self.accepted[k.slot()]
    }
    /// Rejected measurements of one sensor.
    pub fn rejected(&self, k: SensorKind) -> u64 {
        self.rejected[k.slot()]
    }
    /// Recoveries of one sensor.
    pub fn recovered(&self, k: SensorKind) -> u64 {
        self.recovered[k.slot()]
    }
    /// Adds the counts of another run (e.g. of every outage window).
    pub fn add(&mut self, other: &GateCounts) {
        for i in 0..self.accepted.len() {
            self.accepted[i] += other.accepted[i];
            self.rejected[i] += other.rejected[i];
            self.recovered[i] += other.recovered[i];
        }
    }
    /// The counts added since `earlier` (the same counters at an earlier
    /// time: a filter cloned from it counts on from there).
    pub fn since(&self, earlier: &GateCounts) -> GateCounts {
        let d = |a: &[u64; 9], b: &[u64; 9]| std::array::from_fn(|k| a[k].saturating_sub(b[k]));
        GateCounts {
            accepted: d(&self.accepted, &earlier.accepted),
            rejected: d(&self.rejected, &earlier.rejected),
            recovered: d(&self.recovered, &earlier.recovered),
        }
    }
    /// Rejected measurements of every sensor.
    pub fn total_rejected(&self) -> u64 {
        self.rejected.iter().sum()
    }
    /// `(name, accepted, rejected, recovered)` for every sensor with any measurement.
    pub fn rows(&self) -> Vec<(&'static str, u64, u64, u64)> {
        SensorKind::ALL
            .iter()
            .filter(|k| self.accepted(**k) + self.rejected(**k) > 0)
            .map(|k| {
                (
                    k.name(),
                    self.accepted(*k),
                    self.rejected(*k),
                    self.recovered(*k),
                )
            })
            .collect()
    }
}

/// The prediction of one step, as the smoother needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Prediction<const N: usize> {
    /// x̂_{k|k-1}.
    pub x: SVector<f64, N>,
    /// P_{k|k-1}.
    pub p: SMatrix<f64, N, N>,
    /// Jacobian of the car block (the parameters are constants: F = diag(f, I)).
    pub f: Mat,
}

/// The four-wheel EKF as a step object; see the module documentation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(bound = "")]
pub struct Filter<L: Layout<N>, const N: usize> {
    sensors: Sensors,
    noise: Noise,
    form: CovarianceForm,
    x: SVector<f64, N>,
    p: SMatrix<f64, N, N>,
    t_s: f64,
    wheels_present: [bool; 4],
    /// Wheels taken out of the fusion by the wheel-health monitor
    /// ([`crate::wheel_health`]).
    #[serde(default)]
    wheels_excluded: [bool; 4],
    /// Consecutive rejections per sensor (same order as [`GateCounts`]).
    consecutive: [u32; 9],
    /// When the current run of rejected GNSS fixes began, s.
    #[serde(default)]
    gnss_rejecting_since_s: Option<f64>,
    gates: GateCounts,
    #[serde(skip)]
    layout: PhantomData<L>,
}

impl<L: Layout<N>, const N: usize> Filter<L, N> {
    /// A filter at time `t0_s` with car state `x0` and covariance `p0`. With a
    /// layout that estimates the parameters, they start at `params` with standard
    /// deviations `prior_std` (circumferences in metres), which is then required.
    pub fn new(
        vehicle: &Vehicle,
        params: &Params,
        prior_std: Option<&Params>,
        t0_s: f64,
        x0: State,
        p0: Mat,
    ) -> Result<Self, Error> {
        vehicle.validate()?;
        params.validate()?;
        let mut x = SVector::<f64, N>::zeros();
        let mut p = SMatrix::<f64, N, N>::zeros();
        x.fixed_rows_mut::<5>(0).copy_from(&x0);
        p.fixed_view_mut::<5, 5>(0, 0).copy_from(&p0);
        if L::param_index(0).is_some() {
            let sd = prior_std.ok_or_else(|| {
                Error::InvalidParams("the augmented filter needs prior standard deviations".into())
            })?;
            let c = params.circumferences();
            let cs = sd.circumferences();
            let mut set = |j: usize, v: f64, var: f64| {
                if let Some(i) = L::param_index(j) {
                    x[i] = v;
                    p[(i, i)] = var;
                }
            };
            set(0, params.gyro_bias_rps, sd.gyro_bias_rps.powi(2));
            set(1, params.speed_scale, sd.speed_scale.powi(2));
            for i in 0..4 {
                // σ(1/ρ) = σ(ρ)/ρ².
                set(2 + i, 1.0 / c[i], (cs[i] / (c[i] * c[i])).powi(2));
            }
            if (0..6)
                .filter_map(L::param_index)
                .any(|j| p[(j, j)].is_nan() || p[(j, j)] <= 0.0)
            {
                return Err(Error::InvalidParams(
                    "prior standard deviations of the parameters must be positive".into(),
                ));
            }
        }
        if let Some(w) = L::wander_index() {
            let sd = vehicle.noise.gnss_wander_std_m;
            if !(sd.is_finite() && sd > 0.0) {
                return Err(Error::InvalidParams(
                    "a filter with the receiver's wander needs noise.gnss_wander_std_m > 0".into(),
                ));
            }
            p[(w, w)] = sd * sd;
            p[(w + 1, w + 1)] = sd * sd;
        }
        Ok(Filter {
            sensors: Sensors::new(vehicle, params),
            noise: vehicle.noise,
            form: CovarianceForm::default(),
            x,
            p,
            t_s: t0_s,
            wheels_present: vehicle.wheels_present,
            wheels_excluded: [false; 4],
            consecutive: [0; 9],
            gnss_rejecting_since_s: None,
            gates: GateCounts::default(),
            layout: PhantomData,
        })
    }

    /// Chooses the covariance update form (Joseph by default).
    pub fn with_covariance_form(mut self, form: CovarianceForm) -> Self {
        self.form = form;
        self
    }

    /// Time of the state, s.
    pub fn time_s(&self) -> f64 {
        self.t_s
    }
    /// The whole state.
    pub fn state(&self) -> &SVector<f64, N> {
        &self.x
    }
    /// The whole covariance.
    pub fn covariance(&self) -> &SMatrix<f64, N, N> {
        &self.p
    }
    /// The car block `[x, y, ψ, v, ψ̇]` of the state.
    pub fn car_state(&self) -> State {
        self.x.fixed_rows::<5>(0).into_owned()
    }
    /// Replaces state and covariance (e.g. a reset to a reference pose).
    pub fn set_state(&mut self, x: SVector<f64, N>, p: SMatrix<f64, N, N>) {
        self.x = x;
        self.p = p;
        self.refresh_params();
    }
    /// The parameters the sensor models use now (estimated ones with the augmented layout).
    pub fn params(&self) -> Params {
        let mut p = self.sensors.params;
        let c = self.sensors.inv_circumference;
        p.circumference_fl_m = 1.0 / c[0];
        p.circumference_fr_m = 1.0 / c[1];
        p.circumference_rl_m = 1.0 / c[2];
        p.circumference_rr_m = 1.0 / c[3];
        p
    }
    /// Standard deviations of the parameters held in the state (circumferences
    /// in metres), `None` when they are fixed.
    pub fn params_std(&self) -> Option<Params> {
        let sd = |j: usize| L::param_index(j).map(|i| self.p[(i, i)].max(0.0).sqrt());
        let c = self.params().circumferences();
        // σ(ρ) = ρ² σ(1/ρ).
        Some(Params {
            gyro_bias_rps: sd(0)?,
            speed_scale: sd(1)?,
            circumference_fl_m: c[0] * c[0] * sd(2)?,
            circumference_fr_m: c[1] * c[1] * sd(3)?,
            circumference_rl_m: c[2] * c[2] * sd(4)?,
            circumference_rr_m: c[3] * c[3] * sd(5)?,
        })
    }
    /// Gate counters since the start.
    pub fn gates(&self) -> &GateCounts {
        &self.gates
    }
    /// Whether wheel `i` has a sensor (`wheels_present`).
    pub fn wheel_present(&self, i: usize) -> bool {
        self.wheels_present.get(i).copied().unwrap_or(false)
    }

    /// Takes wheel `i` out of the fusion (`true`) or back in: while out, its
    /// `update_wheel_*` return `None` as for an absent wheel. Used by the
    /// wheel-health monitor ([`crate::wheel_health`]).
    pub fn set_wheel_excluded(&mut self, i: usize, excluded: bool) {
        if let Some(e) = self.wheels_excluded.get_mut(i) {
            *e = excluded;
        }
    }
    /// Whether wheel `i` is out of the fusion (see [`Filter::set_wheel_excluded`]).
    pub fn wheel_excluded(&self, i: usize) -> bool {
        self.wheels_excluded.get(i).copied().unwrap_or(false)
    }
    /// The noise and gate settings.
    pub fn noise(&self) -> &Noise {
        &self.noise
    }
    /// The filter with its yaw process noise per `process_step_s` set to
    /// `process_yaw_rad` instead of the vehicle's (the RTS calibration's
    /// passes with `CalibrationOptions::smoothing_process_yaw_rad`, e.g.
    /// [`crate::calibrate::SMOOTHING_PROCESS_YAW_RAD`]).
    pub fn with_process_yaw_rad(mut self, process_yaw_rad: f64) -> Self {
        self.noise.process_yaw_rad = process_yaw_rad;
        self
    }
    /// Eq. (6)/(8) at the current state: the ticks wheel `i` should count over
    /// `interval_s`.
    pub fn predicted_wheel_ticks(&self, i: usize, interval_s: f64) -> f64 {
        self.sensors.wheel_ticks(&self.car_state(), i, interval_s).0
    }
    /// The speed wheel `i` should report at the current state, m/s.
    pub fn predicted_wheel_speed(&self, i: usize) -> f64 {
        self.sensors.wheel_speed(&self.car_state(), i).0
    }

    /// The parameter states held (not corrected) by the next update, when
    /// any: the speed scale and the circumferences while the yaw standard
    /// deviation is above `noise.scale_hold_yaw_std_rad` (2°). A position
    /// mismatch then comes mostly from the unknown heading, and the
    /// linearised position model is off by `1 − cos δψ` of the distance
    /// (4 % at 17°), more than any tyre: learnt from it, family car 30's
    /// circumferences went +107 mm at pull-away with the heading 13–20° off
    /// (standard deviation 17°), +450 mm by 50 s, and the fixes were gated
    /// from then on. The update is a Schmidt ("consider") update: the held
    /// states keep their value, and their covariance with the others
    /// follows ([`kalman::ScalarInnovation::apply_holding`]).
    fn held(&self) -> Option<[bool; N]> {
        L::param_index(1)?;
        if self.p[(model::YAW, model::YAW)].sqrt() <= self.noise.scale_hold_yaw_std_rad {
            return None;
        }
        let mut hold = [false; N];
        for j in 1..6 {
            if let Some(i) = L::param_index(j) {
                hold[i] = true;
            }
        }
        Some(hold)
    }

    /// Points the sensor models at the parameters held in the state.
    fn refresh_params(&mut self) {
        if let Some(i) = L::param_index(0) {
            self.sensors.params.gyro_bias_rps = self.x[i];
        }
        if let Some(i) = L::param_index(1) {
            self.sensors.params.speed_scale = self.x[i];
        }
        for w in 0..4 {
            if let Some(i) = L::param_index(2 + w) {
                self.sensors.inv_circumference[w] = self.x[i];
            }
        }
    }

    /// Eq. (11)–(12): predicts the state to `t_s` (no change for `t_s` before the
    /// state's time). The parameters are constants: with F = diag(F_car, I) and
    /// Q = diag(Q_car, 0) only the car rows and columns of P change.
    pub fn predict_to(&mut self, t_s: f64) -> Prediction<N> {
        let f = self.advance_to(t_s);
        Prediction {
            x: self.x,
            p: self.p,
            f,
        }
    }

    /// [`Filter::predict_to`] without copying the predicted state and
    /// covariance out: returns the car block of F only.
    pub fn advance_to(&mut self, t_s: f64) -> Mat {
        let dt = (t_s - self.t_s).max(0.0);
        let car = self.car_state();
        let g = self.sensors.rear_slip_gradient_rad_per_mps2;
        let f5 = model::jacobian_slipping(&car, dt, g);
        let q5 = model::process_noise(&self.noise, dt);
        self.x
            .fixed_rows_mut::<5>(0)
            .copy_from(&model::evolve_slipping(&car, dt, g));
        // P11 ← F P11 Fᵀ + Q (symmetrised), P12 ← F P12.
        let p11 = self.p.fixed_view::<5, 5>(0, 0).into_owned();
        let n11 = model::propagate_covariance(&p11, &f5, &q5);
        self.p.fixed_view_mut::<5, 5>(0, 0).copy_from(&n11);
        // Column j ≥ 5 (its car rows) and its mirror, row j of the car columns.
        let (car_cols, param_cols) = self.p.data.0.split_at_mut(5);
        for (j, col) in param_cols.iter_mut().enumerate() {
            let head: [f64; 5] = std::array::from_fn(|i| col[i]);
            let nc = model::jacobian_times(&f5, &head);
            for (i, (&v, car_col)) in nc.iter().zip(car_cols.iter_mut()).enumerate() {
                col[i] = v;
                car_col[5 + j] = v;
            }
        }
        // The receiver's wander: F = diag(F_car, I, φ·I₂) (crate::gnss_error).
        if let Some(w) = L::wander_index() {
            self.wander().propagate(w, dt, &mut self.x, &mut self.p);
        }
        // The gyro bias's random walk: F = I, Q = walk²·dt.
        if L::bias_walks() {
            if let Some(i) = L::param_index(0) {
                let walk = self.noise.gyro_bias_walk_rps_per_sqrt_s;
                self.p[(i, i)] += walk * walk * dt;
            }
        }
        self.t_s = t_s.max(self.t_s);
        f5
    }

    /// The receiver's wander model of the noise settings.
    fn wander(&self) -> Wander {
        Wander {
            std_m: self.noise.gnss_wander_std_m,
            tau_s: self.noise.gnss_wander_tau_s,
        }
    }

    /// The receiver's wander estimate `[east, north]`, m (zeros when the
    /// layout has none).
    pub fn wander_m(&self) -> [f64; 2] {
        L::wander_index().map_or([0.0; 2], |w| [self.x[w], self.x[w + 1]])
    }

    fn gate_chi2(&self, sensor: SensorKind) -> f64 {
        gate_chi2(&self.noise, sensor)
    }

    /// Decides on a measurement with NIS `nis`: accepted when within the gate,
    /// or after `max_rejections` consecutive rejections (a recovery).
    fn decide(&mut self, sensor: SensorKind, nis: f64) -> (bool, bool) {
        let k = sensor.slot();
        let max = if sensor == SensorKind::Gnss {
            self.noise.gnss_max_rejections
        } else {
            self.noise.max_rejections
        };
        let within = nis <= self.gate_chi2(sensor);
        // A GNSS recovery also waits for the rejections to have lasted
        // `gnss_recovery_after_s`: a multipath burst is a few seconds.
        let patient = sensor != SensorKind::Gnss || {
            let since = if within {
                self.t_s
            } else {
                *self.gnss_rejecting_since_s.get_or_insert(self.t_s)
            };
            self.t_s - since >= self.noise.gnss_recovery_after_s
        };
        let recovery = !within && self.consecutive[k] >= max && patient;
        let accepted = within || recovery;
        self.consecutive[k] = if accepted { 0 } else { self.consecutive[k] + 1 };
        if accepted && sensor == SensorKind::Gnss {
            self.gnss_rejecting_since_s = None;
        }
        if accepted {
            self.gates.accepted[k] += 1;
        } else {
            self.gates.rejected[k] += 1;
        }
        if recovery {
            self.gates.recovered[k] += 1;
        }
        (accepted, recovery)
    }

    /// A gated scalar update from a car-state model `pred = (h, H)`; `param`
    /// adds the derivative with respect to parameter `j` when it is a state.
    fn scalar(
        &mut self,
        sensor: SensorKind,
        z: f64,
        pred: (f64, model::Row),
        r: f64,
        param: Option<(usize, f64)>,
    ) -> Result<Update, Error> {
        let (h, row5) = pred;
        // H by its non-zero entries: the car states, then the parameter.
        let mut row = [(0usize, 0.0f64); 6];
        let mut n = 0;
        for (j, &d) in row5.iter().enumerate() {
            if d != 0.0 {
                row[n] = (j, d);
                n += 1;
            }
        }
        if let Some((j, d)) = param {
            if let Some(i) = L::param_index(j) {
                if d != 0.0 {
                    row[n] = (i, d);
                    n += 1;
                }
            }
        }
        let y = if sensor == SensorKind::Course {
            crate::angle::diff(z, h)
        } else {
            z - h
        };
        let pre = kalman::ScalarInnovation::sparse(&self.p, &row[..n], r, y, self.t_s)?;
        let (s, nis) = (pre.s, pre.nis());
        let (accepted, _) = self.decide(sensor, nis);
        if accepted {
            match self.held() {
                // Both covariance forms are the same for a scalar (see `apply`).
                None => pre.apply(&mut self.x, &mut self.p, kalman::CovarianceForm::Joseph),
                Some(hold) => pre.apply_holding(&mut self.x, &mut self.p, &hold),
            }
            self.refresh_params();
        }
        Ok(Update {
            sensor,
            y,
            s,
            nis,
            ln_det_s: s.ln(),
            accepted,
        })
    }

    /// Eq. (6)/(8): the ticks of wheel `i` over `interval_s`. `None` when the
    /// wheel has no sensor (`wheels_present`) or is out of the fusion
    /// ([`Filter::set_wheel_excluded`]).
    pub fn update_wheel_ticks(
        &mut self,
        i: usize,
        ticks: f64,
        interval_s: f64,
    ) -> Result<Option<Update>, Error> {
        if !self.wheel_present(i) || self.wheel_excluded(i) {
            return Ok(None);
        }
        let pred = self.sensors.wheel_ticks(&self.car_state(), i, interval_s);
        // ∂h/∂(1/ρ_i) = h·ρ_i: the model is linear in the inverse circumference.
        let d = pred.0 / self.sensors.inv_circumference[i];
        let r = self.noise.wheel_ticks.powi(2);
        self.scalar(SensorKind::Wheel(i as u8), ticks, pred, r, Some((2 + i, d)))
            .map(Some)
    }

    /// The speed of wheel `i`, m/s. `None` when the wheel has no sensor or is
    /// out of the fusion.
    pub fn update_wheel_speed(
        &mut self,
        i: usize,
        speed_mps: f64,
    ) -> Result<Option<Update>, Error> {
        if !self.wheel_present(i) || self.wheel_excluded(i) {
            return Ok(None);
        }
        let pred = self.sensors.wheel_speed(&self.car_state(), i);
        let d = pred.0 / self.sensors.inv_circumference[i];
        let r = self.noise.wheel_speed_mps.powi(2);
        self.scalar(
            SensorKind::Wheel(i as u8),
            speed_mps,
            pred,
            r,
            Some((2 + i, d)),
        )
        .map(Some)
    }

    /// Eq. (4): one gyro reading, rad/s.
    pub fn update_gyro(&mut self, yaw_rate_rps: f64) -> Result<Update, Error> {
        let pred = self.sensors.gyro(&self.car_state());
        let r = self.noise.gyro_rps.powi(2);
        self.scalar(SensorKind::Gyro, yaw_rate_rps, pred, r, Some((0, 1.0)))
    }

    /// Eq. (5): one CAN speed reading, m/s.
    pub fn update_speed(&mut self, speed_mps: f64) -> Result<Update, Error> {
        let pred = self.sensors.can_speed(&self.car_state());
        let r = self.noise.speed_mps.powi(2);
        let d_scale = self.x[V];
        self.scalar(SensorKind::Speed, speed_mps, pred, r, Some((1, d_scale)))
    }

    /// Eq. (7): one steering-wheel reading, rad, with the prior speed (the
    /// wheel angle with the vehicle's steering offset and understeer at the
    /// prior state: [`Sensors::wheel_angle`]).
    pub fn update_steering(&mut self, steering_wheel_rad: f64) -> Result<Update, Error> {
        let car = self.car_state();
        let wheel_angle = self.sensors.wheel_angle(steering_wheel_rad, &car);
        if wheel_angle.abs() > crate::observation::STEERING_CONSTRAINT_ABOVE_RAD {
            // Large wheel angles: the constraint form, stable up to ±90°.
            let (h, row, r) =
                self.sensors
                    .steering_constraint(&car, wheel_angle, self.noise.steering);
            return self.scalar(SensorKind::Steering, 0.0, (h, row), r, None);
        }
        let (z, r) = self
            .sensors
            .steering_measurement(wheel_angle, self.x[V], self.noise.steering);
        let pred = self.sensors.steering(&self.car_state());
        self.scalar(SensorKind::Steering, z, pred, r, None)
    }

    /// Eq. (10): one GNSS position (through the lever arm), gated by its
    /// Mahalanobis distance. After `gnss_max_rejections` consecutive rejections
    /// the filter takes itself to be lost: it widens its position (and yaw)
    /// covariance to cover the innovation and takes the fix (a recovery).
    pub fn update_gnss(&mut self, fix: &GnssFix) -> Result<Update, Error> {
        let (mut h, jac5) = self.sensors.gnss(&self.car_state());
        let mut jac = SMatrix::<f64, 2, N>::zeros();
        jac.fixed_view_mut::<2, 5>(0, 0).copy_from(&jac5);
        if let Some(w) = L::wander_index() {
            add_wander(w, &self.x, &mut h, &mut jac);
        }
        let y = Vector2::new(fix.east_m, fix.north_m) - h;
        let r = Matrix2::identity() * fix.std_m.powi(2);
        let (mut s, _, mut nis) = kalman::innovation_stats(&self.p, &y, &jac, &r, self.t_s)?;
        let ln_det_s = s.determinant().ln();
        let (accepted, recovery) = self.decide(SensorKind::Gnss, nis);
        if recovery {
            let d2 = y.norm_squared();
            for i in [model::X, model::Y] {
                self.p[(i, i)] += d2;
            }
            self.p[(model::YAW, model::YAW)] += 0.1f64.powi(2);
            (s, _, nis) = kalman::innovation_stats(&self.p, &y, &jac, &r, self.t_s)?;
        }
        if accepted {
            match self.held() {
                None => {
                    kalman::update_vector(
                        &mut self.x,
                        &mut self.p,
                        &y,
                        &jac,
                        &r,
                        self.form,
                        self.t_s,
                    )?;
                }
                Some(hold) => {
                    kalman::update_vector_holding(
                        &mut self.x,
                        &mut self.p,
                        &y,
                        &jac,
                        &r,
                        &hold,
                        self.t_s,
                    )?;
                }
            }
            self.refresh_params();
        }
        Ok(Update {
            sensor: SensorKind::Gnss,
            y: y[0],
            s: s[(0, 0)],
            nis,
            ln_det_s,
            accepted,
        })
    }

    /// A GNSS course (yaw, rad) as a yaw observation, used above 3 m/s only
    /// (`None` below, or without a speed); its noise shrinks with speed (about
    /// 0.5 m/s of velocity noise).
    pub fn update_course(
        &mut self,
        course_yaw_rad: f64,
        speed_mps: Option<f64>,
    ) -> Result<Option<Update>, Error> {
        let Some(speed) = speed_mps.filter(|s| *s > 3.0) else {
            return Ok(None);
        };
        let sigma = (0.5 / speed).min(0.3);
        let pred = self.sensors.yaw(&self.car_state());
        self.scalar(
            SensorKind::Course,
            course_yaw_rad,
            pred,
            sigma * sigma,
            None,
        )
        .map(Some)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn filter() -> CarFilter {
        let v = Vehicle::paper_car();
        let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
        CarFilter::new(&v, &Params::nominal(&v), None, 0.0, x0, p0).unwrap()
    }

    #[test]
    fn a_wheel_reading_far_outside_the_gate_is_rejected_and_counted() {
        let mut f = filter();
        f.predict_to(0.02);
        let before = *f.state();
        let u = f.update_wheel_ticks(0, 500.0, 0.02).unwrap().unwrap();
        assert!(!u.accepted && u.nis > 1e3);
        assert_eq!(*f.state(), before);
        assert_eq!(f.gates().rejected(SensorKind::Wheel(0)), 1);
        assert_eq!(f.gates().accepted(SensorKind::Wheel(0)), 0);
    }

    #[test]
    fn consecutive_rejections_end_in_a_recovery() {
        let mut f = filter();
        let max = Vehicle::paper_car().noise.max_rejections as u64;
        let mut t = 0.0;
        for _ in 0..=max {
            t += 0.02;
            f.predict_to(t);
            f.update_wheel_ticks(2, 5000.0, 0.02).unwrap();
        }
        let rl = SensorKind::Wheel(2);
        assert_eq!(f.gates().rejected(rl), max);
        assert_eq!(f.gates().recovered(rl), 1);
        assert_eq!(f.gates().accepted(rl), 1);
    }

    #[test]
    fn absent_wheels_are_never_used() {
        let mut v = Vehicle::paper_car();
        v.wheels_present = [true, false, true, false];
        let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let mut f =
            CarFilter::new(&v, &Params::nominal(&v), None, 0.0, x0, Mat::identity()).unwrap();
        f.predict_to(0.02);
        assert!(f.update_wheel_speed(1, 10.0).unwrap().is_none());
        assert!(f.update_wheel_ticks(3, 5.0, 0.02).unwrap().is_none());
        assert!(f.update_wheel_speed(0, 10.0).unwrap().is_some());
    }

    fn augmented() -> AugmentedFilter {
        let v = Vehicle::paper_car();
        let sd = Params {
            gyro_bias_rps: 0.01,
            speed_scale: 0.05,
            circumference_fl_m: 0.01,
            circumference_fr_m: 0.01,
            circumference_rl_m: 0.01,
            circumference_rr_m: 0.01,
        };
        let x0 = State::from([0.0, 0.0, 0.3, 10.0, 0.05]);
        let p0 = Mat::from_diagonal(&State::from([1.0, 1.0, 0.01, 1.0, 0.01]));
        AugmentedFilter::new(&v, &Params::nominal(&v), Some(&sd), 0.0, x0, p0).unwrap()
    }

    fn epoch(f: &mut AugmentedFilter, k: usize) {
        for (i, z) in [5.0, 6.0, 5.0, 4.0].into_iter().enumerate() {
            f.update_wheel_ticks(i, z + (k % 3) as f64, 0.02).unwrap();
        }
        f.update_gyro(0.05 + 1e-3 * k as f64).unwrap();
        f.update_speed(10.1).unwrap();
        f.update_steering(0.2).unwrap();
        if k.is_multiple_of(10) {
            let fix = GnssFix {
                t_s: f.time_s(),
                east_m: 0.2 * k as f64,
                north_m: 0.05,
                std_m: 0.5,
                course_deg: None,
                speed_mps: None,
            };
            f.update_gnss(&fix).unwrap();
        }
    }

    #[test]
    fn scalar_updates_keep_the_covariance_exactly_symmetric() {
        let mut a = augmented();
        for k in 1..200 {
            a.predict_to(0.02 * k as f64);
            epoch(&mut a, k);
            let p = a.covariance();
            assert_eq!(*p, p.transpose(), "epoch {k}");
        }
    }

    #[test]
    fn the_augmented_layout_holds_the_parameters() {
        let v = Vehicle::paper_car();
        let p = Params::nominal(&v);
        let sd = Params {
            gyro_bias_rps: 0.01,
            speed_scale: 0.05,
            circumference_fl_m: 0.01,
            circumference_fr_m: 0.01,
            circumference_rl_m: 0.01,
            circumference_rr_m: 0.01,
        };
        let x0 = State::from([0.0, 0.0, 0.0, 10.0, 0.0]);
        let f = AugmentedFilter::new(&v, &p, Some(&sd), 0.0, x0, Mat::identity()).unwrap();
        let got = f.params_std().unwrap();
        assert!((got.circumference_fl_m - 0.01).abs() < 1e-12);
        assert!((f.params().circumference_rr_m - p.circumference_rr_m).abs() < 1e-12);
        assert!(AugmentedFilter::new(&v, &p, None, 0.0, x0, Mat::identity()).is_err());
        assert!(filter().params_std().is_none());
    }
}
