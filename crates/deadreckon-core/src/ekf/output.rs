//! What a filter run gives: its epochs ([`Epoch`], for the smoother), its
//! innovations, its counters ([`FilterStats`]) and the hook called after
//! every epoch ([`EpochHook`]).

use nalgebra::{SMatrix, SVector};
use serde::{Deserialize, Serialize};

use crate::filter::{Filter, GateCounts, Layout, Prediction, SensorKind};
use crate::model::Mat;
use crate::wheel_health::WheelHealth;

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

impl<const N: usize> Epoch<N> {
    /// The epoch a filter has just run: its prediction and its updated state.
    pub fn after<L: Layout<N>>(f: &Filter<L, N>, prediction: &Prediction<N>) -> Self {
        Epoch {
            t_s: f.time_s(),
            x_pred: prediction.x,
            p_pred: prediction.p,
            f: prediction.f,
            x: *f.state(),
            p: *f.covariance(),
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

impl InnovationRecord {
    /// The record of update `u` of the epoch at `t_s`.
    pub fn of(t_s: f64, u: &crate::filter::Update) -> Self {
        InnovationRecord {
            t_s,
            sensor: u.sensor,
            y: u.y,
            s: u.s,
            nis: u.nis,
            accepted: u.accepted,
        }
    }
}

/// Counts of what the filter used, gated and skipped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct FilterStats {
    /// Epochs run.
    pub epochs: usize,
    /// Wheel rows used.
    pub wheel_updates: usize,
    /// Wheel rows skipped because the interval since the previous row was a gap
    /// (more than 5 times the median interval).
    pub wheel_gaps: usize,
    /// Gyro readings used (accepted by the gate).
    pub gyro_updates: usize,
    /// CAN speed readings used (accepted by the gate).
    pub speed_updates: usize,
    /// Steering readings used (accepted by the gate).
    pub steering_updates: usize,
    /// Readings of the other sensors not used because a newer one arrived before the
    /// next wheel epoch (the paper's scheme).
    pub readings_superseded: usize,
    /// Steering readings held back for a later epoch with a gyro reading,
    /// because the gyro was live but had no reading at the steering's epoch
    /// ([`crate::gyro_hold`]).
    #[serde(default)]
    pub steering_deferred: usize,
    /// Wheel epochs without a gyro reading of their own while the gyro was
    /// live, predicted with `Noise::gyro_gap_process_yaw_rate_rps` (0 when
    /// that is off).
    #[serde(default, skip_serializing_if = "is_zero")]
    pub gyro_gap_epochs: usize,
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
    /// Per-sensor χ² gate counters (accepted, rejected, recovered).
    pub gates: GateCounts,
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
    /// What the wheel-health monitor saw (`None` without one).
    pub wheel_health: Option<WheelHealth>,
    /// Indices in `drive.gnss` of the fixes the χ² gate rejected, in order.
    pub gnss_gated: Vec<usize>,
}

impl<const N: usize> Default for FilterOutput<N> {
    fn default() -> Self {
        FilterOutput {
            epochs: Vec::new(),
            innovations: Vec::new(),
            stats: FilterStats::default(),
            wheel_health: None,
            gnss_gated: Vec::new(),
        }
    }
}

/// A hook called after every epoch with the time and the updated state and
/// covariance, which it may change (e.g. to reset the state to the truth).
pub trait EpochHook<const N: usize = 5> {
    /// Called after the updates of the epoch at `t_s`.
    fn after_epoch(&mut self, t_s: f64, x: &mut SVector<f64, N>, p: &mut SMatrix<f64, N, N>);
    /// True for a hook that never changes anything (the loop then skips it).
    fn is_noop(&self) -> bool {
        false
    }
}

impl<const N: usize> EpochHook<N> for () {
    fn after_epoch(&mut self, _t_s: f64, _x: &mut SVector<f64, N>, _p: &mut SMatrix<f64, N, N>) {}
    fn is_noop(&self) -> bool {
        true
    }
}

/// Whether a count is zero (not written to JSON).
fn is_zero(n: &usize) -> bool {
    *n == 0
}
