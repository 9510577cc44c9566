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

mod gates;
mod layout;
#[cfg(test)]
mod tests;

pub use gates::{gate_chi2, GateCounts, SensorKind, Update, N_SENSORS};
pub use layout::{AugmentedLayout, CarLayout, Layout, AUG_BIAS, AUG_INV_CIRC, AUG_SCALE, N_AUG};

/// The yaw standard deviation added at a GNSS recovery, rad (about 6°): a
/// filter that lost the fixes for long has lost its heading too, and the
/// fix that ends it must be free to turn it. Not tuned.
pub const RECOVERY_YAW_STD_RAD: f64 = 0.1;
/// Below this speed a GNSS course says nothing about the yaw, m/s.
pub const COURSE_MIN_SPEED_MPS: f64 = 3.0;
/// The receiver's velocity noise a course is taken to carry, m/s: the
/// course's standard deviation is this over the speed (u-blox-class
/// receivers quote 0.05–0.5 m/s; the upper end, as the course is an
/// option off by default and not tuned).
pub const COURSE_VELOCITY_STD_MPS: f64 = 0.5;
/// The largest standard deviation of a course used, rad (about 17°).
pub const COURSE_MAX_STD_RAD: f64 = 0.3;

/// The filter with fixed parameters.
pub type CarFilter = Filter<CarLayout, { model::N }>;
/// The filter with the parameters as states.
pub type AugmentedFilter = Filter<AugmentedLayout, N_AUG>;

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
    consecutive: [u32; N_SENSORS],
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
        x.fixed_rows_mut::<{ model::N }>(0).copy_from(&x0);
        p.fixed_view_mut::<{ model::N }, { model::N }>(0, 0)
            .copy_from(&p0);
        if L::param_index(0).is_some() {
            let sd = prior_std.ok_or_else(|| {
                Error::param(
                    "prior_std",
                    crate::Value::Unstated,
                    crate::Rule::Said(
                        "the augmented filter needs prior standard deviations".into(),
                    ),
                )
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
                return Err(Error::param(
                    "prior_std",
                    crate::Value::Unstated,
                    crate::Rule::Positive,
                ));
            }
        }
        if let Some(w) = L::wander_index() {
            let sd = vehicle.noise.gnss_wander_std_m;
            if !(sd.is_finite() && sd > 0.0) {
                return Err(Error::param(
                    "noise.gnss_wander_std_m",
                    sd,
                    crate::Rule::Said(
                        "must be positive in a filter with the receiver's wander".into(),
                    ),
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
            consecutive: [0; N_SENSORS],
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
        self.x.fixed_rows::<{ model::N }>(0).into_owned()
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

    /// [`Filter::predict_to`] with the yaw rate's process noise per step
    /// `process_yaw_rate_rps` instead of the vehicle's (a wheel epoch
    /// without a gyro reading: `Noise::gyro_gap_process_yaw_rate_rps`).
    pub fn predict_to_with_yaw_rate_noise(
        &mut self,
        t_s: f64,
        process_yaw_rate_rps: f64,
        copy_out: bool,
    ) -> Option<Prediction<N>> {
        let own = self.noise.process_yaw_rate_rps;
        self.noise.process_yaw_rate_rps = process_yaw_rate_rps;
        let out = if copy_out {
            Some(self.predict_to(t_s))
        } else {
            self.advance_to(t_s);
            None
        };
        self.noise.process_yaw_rate_rps = own;
        out
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
            .fixed_rows_mut::<{ model::N }>(0)
            .copy_from(&model::evolve_slipping(&car, dt, g));
        // P11 ← F P11 Fᵀ + Q (symmetrised), P12 ← F P12.
        let p11 = self
            .p
            .fixed_view::<{ model::N }, { model::N }>(0, 0)
            .into_owned();
        let n11 = model::propagate_covariance(&p11, &f5, &q5);
        self.p
            .fixed_view_mut::<{ model::N }, { model::N }>(0, 0)
            .copy_from(&n11);
        // Column j ≥ 5 (its car rows) and its mirror, row j of the car
        // columns (F's shape checked by `propagate_covariance` above).
        let (car_cols, param_cols) = self.p.data.0.split_at_mut(model::N);
        for (j, col) in param_cols.iter_mut().enumerate() {
            let head: [f64; model::N] = std::array::from_fn(|i| col[i]);
            let nc = model::shaped_times(&f5, &head);
            for (i, (&v, car_col)) in nc.iter().zip(car_cols.iter_mut()).enumerate() {
                col[i] = v;
                car_col[model::N + j] = v;
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
        let mut row = [(0usize, 0.0f64); model::N + 1];
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

    /// A standing car does not turn: the pseudo-measurement `ψ̇ = 0` with
    /// standard deviation [`crate::standstill::STANDSTILL_YAW_RATE_STD_RPS`]
    /// ([`crate::standstill`]). Not gated and not counted: it is the
    /// model's, not a sensor's.
    pub fn update_standstill(&mut self) -> Result<(), Error> {
        let r = crate::standstill::STANDSTILL_YAW_RATE_STD_RPS.powi(2);
        let y = -self.x[model::YAW_RATE];
        let pre =
            kalman::ScalarInnovation::sparse(&self.p, &[(model::YAW_RATE, 1.0)], r, y, self.t_s)?;
        match self.held() {
            None => pre.apply(&mut self.x, &mut self.p, kalman::CovarianceForm::Joseph),
            Some(hold) => pre.apply_holding(&mut self.x, &mut self.p, &hold),
        }
        self.refresh_params();
        Ok(())
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
        jac.fixed_view_mut::<2, { model::N }>(0, 0).copy_from(&jac5);
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
            self.p[(model::YAW, model::YAW)] += RECOVERY_YAW_STD_RAD.powi(2);
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
        let Some(speed) = speed_mps.filter(|s| *s > COURSE_MIN_SPEED_MPS) else {
            return Ok(None);
        };
        let sigma = (COURSE_VELOCITY_STD_MPS / speed).min(COURSE_MAX_STD_RAD);
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
