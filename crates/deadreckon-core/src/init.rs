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
pub fn truth_state(drive: &Drive, t: f64) -> Option<State> {
    crate::reference::Reference::from_truth(&drive.truth).and_then(|r| r.state_at(t))
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
