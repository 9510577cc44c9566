//! Where the filter starts: [`initial_state`] from the options' [`Init`]
//! (a given state, the truth, or GNSS), and [`GnssInit`], the GNSS start one
//! fix at a time, as the online filter needs it.

use serde::{Deserialize, Serialize};

use crate::drive::{Drive, GnssFix};
use crate::ekf::{FilterOptions, Init};
use crate::model::{Mat, State};
use crate::{Error, Input, Task};

/// Interpolated reference pose from the truth at `t`, as a full state (speed and
/// yaw rate derived by finite differences where not given).
///
/// [`Reference::from_truth`]'s `state_at(t)`, bit for bit, from the poses
/// up to two past `t`: a pose's state reads its neighbours and the yaw
/// unwrapped from the first pose, never a later one, and whether every
/// pose has its speed (checked on the whole truth). It built the whole
/// reference for one state (17 MB on the bench's hour, at every start from
/// the truth; issue 30).
///
/// [`Reference::from_truth`]: crate::reference::Reference::from_truth
pub fn truth_state(drive: &Drive, t: f64) -> Option<State> {
    state_of_truth(&drive.truth, t)
}

/// [`truth_state`] of the poses `truth`.
fn state_of_truth(truth: &[crate::drive::TruthPose], t: f64) -> Option<State> {
    // The first pose after `t`: the state reads it and the one before.
    let after = truth.partition_point(|p| p.t_s <= t);
    let upto = if after < truth.len() {
        (after + 3).min(truth.len())
    } else {
        truth.len()
    };
    let all_speeds = |p: &[crate::drive::TruthPose]| p.iter().all(|p| p.speed_mps.is_some());
    let poses = if all_speeds(&truth[..upto]) == all_speeds(truth) {
        &truth[..upto]
    } else {
        truth
    };
    crate::reference::Reference::from_truth(poses).and_then(|r| r.state_at(t))
}

/// The filter's start: time, car state and covariance, as `opts.init` says.
pub fn initial_state(drive: &Drive, opts: &FilterOptions) -> Result<(f64, State, Mat), Error> {
    let hidden = |t: f64| crate::drive::in_windows(t, &opts.gnss_outages);
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
            let x = truth_state(drive, t0)
                .ok_or_else(|| Error::needs(Task::InitFromTruth, Input::TruthCovering))?;
            let p = Mat::from_diagonal(&State::from([1e-4, 1e-4, 1e-6, 1e-2, 1e-4]));
            Ok((t0, x, p))
        }
        Init::Gnss => {
            let visible: Vec<GnssFix> = drive
                .gnss
                .iter()
                .filter(|g| !hidden(g.t_s))
                .copied()
                .collect();
            let mut init = GnssInit::new(drive.vehicle.gnss_lever_arm_m);
            visible
                .iter()
                .find_map(|g| init.push(g))
                .ok_or_else(|| init.why_not())
        }
    }
}

/// Initialisation from GNSS, one fix at a time (usable online): the first fix
/// gives the position (minus the lever arm) and the direction of the first
/// [`GnssInit::MIN_DISPLACEMENT_M`] of displacement the yaw; the filter starts
/// at the first fix's time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct GnssInit {
    lever_arm_m: f64,
    first: Option<GnssFix>,
}

impl GnssInit {
    /// Displacement from the first fix that fixes the initial yaw, m.
    pub const MIN_DISPLACEMENT_M: f64 = 10.0;

    /// Waiting for fixes, with the vehicle's GNSS lever arm.
    pub fn new(lever_arm_m: f64) -> Self {
        GnssInit {
            lever_arm_m,
            first: None,
        }
    }

    /// True once the first fix has been taken.
    pub fn has_first(&self) -> bool {
        self.first.is_some()
    }

    /// Takes one fix; returns the start (time, state, covariance) once the
    /// vehicle has moved far enough from the first fix.
    pub fn push(&mut self, g: &GnssFix) -> Option<(f64, State, Mat)> {
        let Some(first) = self.first else {
            self.first = Some(*g);
            return None;
        };
        if g.t_s <= first.t_s
            || (g.east_m - first.east_m).hypot(g.north_m - first.north_m) < Self::MIN_DISPLACEMENT_M
        {
            return None;
        }
        let yaw = (g.north_m - first.north_m).atan2(g.east_m - first.east_m);
        let l = self.lever_arm_m;
        let x = State::from([
            first.east_m - l * yaw.cos(),
            first.north_m - l * yaw.sin(),
            yaw,
            0.0,
            0.0,
        ]);
        let sp = first.std_m.max(0.1);
        let p = Mat::from_diagonal(&State::from([sp * sp, sp * sp, 0.3f64.powi(2), 4.0, 0.25]));
        Some((first.t_s, x, p))
    }

    /// Why no start was found.
    pub fn why_not(&self) -> Error {
        Error::needs(
            Task::InitFromGnss,
            if self.first.is_none() {
                Input::GnssFix
            } else {
                Input::Travel { distance_m: 10.0 }
            },
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::TruthPose;
    use crate::reference::Reference;

    /// Bug (issue 30): `truth_state` built the reference of the whole truth
    /// to read one state; from the poses up to `t` it must give the same
    /// bits, with the yaw wrapping, and with a speed missing after `t` (the
    /// whole truth then derives every speed).
    #[test]
    fn truth_state_built_the_whole_reference_for_one_state() {
        for missing_speed_at in [None, Some(150)] {
            let truth: Vec<TruthPose> = (0..200)
                .map(|i| {
                    let t = 10.0 + i as f64 * 0.01 + 1e-4 * ((i * 7) % 5) as f64;
                    TruthPose {
                        t_s: t,
                        east_m: 3.0 * t + (0.3 * t).sin(),
                        north_m: t * t * 0.1,
                        yaw_rad: crate::angle::wrap(3.0 + 2.5 * t),
                        speed_mps: (Some(i) != missing_speed_at).then_some(1.0 + 0.01 * i as f64),
                    }
                })
                .collect();
            let whole = Reference::from_truth(&truth).expect("a reference");
            for k in 0..=2100 {
                let t = 9.99 + k as f64 * 0.001;
                let a = state_of_truth(&truth, t);
                let b = whole.state_at(t);
                assert_eq!(a.is_some(), b.is_some(), "t {t}");
                if let (Some(a), Some(b)) = (a, b) {
                    for j in 0..5 {
                        assert_eq!(a[j].to_bits(), b[j].to_bits(), "t {t}, state {j}");
                    }
                }
            }
        }
    }
}
