//! An estimated trajectory: what `deadreckon run` writes and every exporter
//! reads; and the tracks of a drive ([`drive_tracks`]): dead-reckoned, with GNSS
//! the filtered and smoothed ones, and the truth as a track of its own.

use crate::aided::{Aided, BiasSwitch};
use crate::ekf::{self, FilterOptions, Init, SensorSet};
use crate::model::{Mat, State};
use crate::vehicle::Origin;
use crate::{Drive, Error, Need, Params};

/// The names of the tracks [`drive_tracks`] builds, in its order.
pub mod names {
    /// Proprioceptive sensors only, from the initial pose.
    pub const DEAD_RECKONED: &str = "dead-reckoned";
    /// The filter with GNSS (causal).
    pub const FILTERED: &str = "filtered";
    /// The RTS-smoothed filter with GNSS.
    pub const SMOOTHED: &str = "smoothed";
    /// The drive's reference trajectory (`truth.csv`), at its own timestamps.
    pub const TRUTH: &str = "truth";
}

/// One estimated pose with its uncertainty.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TrackPoint {
    /// Timestamp, s.
    pub t_s: f64,
    /// East of the origin, m (rear-axle centre).
    pub east_m: f64,
    /// North of the origin, m.
    pub north_m: f64,
    /// Yaw, rad, counter-clockwise from east, wrapped to (-π, π].
    pub yaw_rad: f64,
    /// Longitudinal speed, m/s.
    pub speed_mps: f64,
    /// Yaw rate, rad/s.
    pub yaw_rate_rps: f64,
    /// Covariance of (east, north, yaw): [[ee, en, ey], [ne, nn, ny], [ye, yn, yy]], row-major
    /// (NaN where unknown: the kinematic dead reckoning of a tricycle carries none).
    pub cov_pose: [f64; 9],
}

/// The square root of a variance, clamped at zero; unknown (NaN) stays unknown.
fn std_of(var: f64) -> f64 {
    if var.is_nan() {
        var
    } else {
        var.max(0.0).sqrt()
    }
}

impl TrackPoint {
    /// Standard deviation of the east coordinate, m.
    pub fn std_east_m(&self) -> f64 {
        std_of(self.cov_pose[0])
    }
    /// Standard deviation of the north coordinate, m.
    pub fn std_north_m(&self) -> f64 {
        std_of(self.cov_pose[4])
    }
    /// Standard deviation of the yaw, rad.
    pub fn std_yaw_rad(&self) -> f64 {
        std_of(self.cov_pose[8])
    }
}

/// A named trajectory (e.g. "filtered", "smoothed", "dead-reckoned").
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    /// What produced it.
    pub name: String,
    /// The poses, by increasing time.
    pub points: Vec<TrackPoint>,
    /// The geodetic origin of the local frame, where known (for map exports).
    pub origin: Option<Origin>,
}

impl TrackPoint {
    /// A track point from a state and its covariance (yaw wrapped for output).
    pub fn from_state(t_s: f64, x: &crate::model::State, p: &crate::model::Mat) -> Self {
        use crate::model::{V, X, Y, YAW, YAW_RATE};
        let idx = [X, Y, YAW];
        let mut cov_pose = [0.0; 9];
        for (a, &i) in idx.iter().enumerate() {
            for (b, &j) in idx.iter().enumerate() {
                cov_pose[3 * a + b] = p[(i, j)];
            }
        }
        TrackPoint {
            t_s,
            east_m: x[X],
            north_m: x[Y],
            yaw_rad: crate::angle::wrap(x[YAW]),
            speed_mps: x[V],
            yaw_rate_rps: x[YAW_RATE],
            cov_pose,
        }
    }
}

impl Track {
    /// The filtered states of a filter run.
    /// (the car block of a state with more, [`crate::filter::Layout`]).
    pub fn from_epochs<const N: usize>(
        name: &str,
        epochs: &[crate::ekf::Epoch<N>],
        origin: Option<Origin>,
    ) -> Track {
        Track {
            name: name.into(),
            points: epochs
                .iter()
                .map(|e| car_point(e.t_s, &e.x, &e.p))
                .collect(),
            origin,
        }
    }

    /// The smoothed states of an RTS pass.
    pub fn from_smoothed<const N: usize>(
        name: &str,
        smoothed: &[crate::rts::Smoothed<N>],
        origin: Option<Origin>,
    ) -> Track {
        Track {
            name: name.into(),
            points: smoothed
                .iter()
                .map(|s| car_point(s.t_s, &s.x, &s.p))
                .collect(),
            origin,
        }
    }
}

/// The track point of the car block of a state and covariance.
pub(crate) fn car_point<const N: usize>(
    t_s: f64,
    x: &nalgebra::SVector<f64, N>,
    p: &nalgebra::SMatrix<f64, N, N>,
) -> TrackPoint {
    let car: State = x.fixed_rows::<5>(0).into_owned();
    let pc: Mat = p.fixed_view::<5, 5>(0, 0).into_owned();
    TrackPoint::from_state(t_s, &car, &pc)
}

impl Track {
    /// The drive's reference trajectory as a track named `truth`, at its own
    /// timestamps, with a zero covariance. Speed and yaw rate are derived from
    /// the poses (as the truth calibration does), or NaN where they cannot be.
    /// `None` without truth.
    pub fn from_truth(drive: &Drive) -> Option<Track> {
        if drive.truth.is_empty() {
            return None;
        }
        let reference = crate::reference::Reference::from_truth(&drive.truth);
        let points = drive
            .truth
            .iter()
            .map(|p| {
                let derived = reference.as_ref().and_then(|r| r.state_at(p.t_s));
                TrackPoint {
                    t_s: p.t_s,
                    east_m: p.east_m,
                    north_m: p.north_m,
                    yaw_rad: crate::angle::wrap(p.yaw_rad),
                    speed_mps: p
                        .speed_mps
                        .or(derived.map(|x| x[crate::model::V]))
                        .unwrap_or(f64::NAN),
                    yaw_rate_rps: derived.map_or(f64::NAN, |x| x[crate::model::YAW_RATE]),
                    cov_pose: [0.0; 9],
                }
            })
            .collect();
        Some(Track {
            name: names::TRUTH.into(),
            points,
            origin: drive.vehicle.origin,
        })
    }
}

/// The estimated tracks of a drive with `params`: dead-reckoned first, then,
/// with at least two GNSS fixes, the filtered and the smoothed track.
///
/// Dead reckoning starts from `init_pose` (east m, north m, yaw rad) when
/// given, else from the truth, else from the start of the smoothed track.
pub fn drive_tracks(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<Vec<Track>, Error> {
    Ok(drive_tracks_and_switch(drive, params, opts, init_pose)?.0)
}

/// [`drive_tracks`], and what the aided run's gyro-bias switch saw
/// (`None` without one or without GNSS: [`crate::aided::switch`]).
pub fn drive_tracks_and_switch(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<(Vec<Track>, Option<BiasSwitch>), Error> {
    let mut out = Vec::new();
    let mut smoothed_start = None;
    let mut switch = None;
    if drive.gnss.len() >= 2 {
        let a = aided_tracks(drive, params, opts)?;
        smoothed_start = a.smoothed_start;
        switch = a.switch;
        out.push(a.filtered);
        out.push(a.smoothed);
    }
    let init = dead_reckoning_init(drive, init_pose, smoothed_start)?;
    out.insert(0, dead_reckoned(drive, params, opts, init)?);
    Ok((out, switch))
}

/// The GNSS-aided run of [`aided_tracks`]: its two tracks and what it saw.
#[derive(Debug, Clone)]
pub struct AidedTracks {
    /// The filtered track ([`names::FILTERED`]).
    pub filtered: Track,
    /// The smoothed track ([`names::SMOOTHED`]).
    pub smoothed: Track,
    /// The smoothed first epoch's time, car state and covariance (where
    /// dead reckoning starts without a pose or the truth).
    pub smoothed_start: Option<(f64, State, Mat)>,
    /// What the gyro-bias switch saw (`None` without one).
    pub switch: Option<BiasSwitch>,
    /// The run's innovations (as `opts.record_innovations` asks; of the
    /// hypothesis handed out with the switch), its counters and the
    /// indices of the fixes the gate rejected; no epochs, and no wheel
    /// monitor's report ([`ekf::check_wheels`] gives `run`'s).
    pub output: ekf::FilterOutput,
}

/// The filtered and smoothed tracks of the GNSS-aided filter the vehicle
/// calls for ([`crate::aided`]: a gyro bias state, [`crate::gyro_drift`];
/// the receiver's wander, [`crate::gnss_error`], smoothed with its `φ`;
/// the gyro-bias switch), and what its run saw: the one source of these
/// tracks, for `run` ([`drive_tracks`]) and for the report's trajectories
/// and filter health ([`aided_run`], which hands them out as they are made).
pub fn aided_tracks(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
) -> Result<AidedTracks, Error> {
    let mut kept = Kept {
        filtered: Vec::new(),
        smoothed: Vec::new(),
        innovations: opts.record_innovations.then(Vec::new),
    };
    let run = aided_run(drive, params, opts, &mut kept)?;
    let mut output = run.output;
    output.innovations = kept.innovations.unwrap_or_default();
    kept.smoothed.reverse();
    let origin = drive.vehicle.origin;
    Ok(AidedTracks {
        filtered: Track {
            name: names::FILTERED.into(),
            points: kept.filtered,
            origin,
        },
        smoothed: Track {
            name: names::SMOOTHED.into(),
            points: kept.smoothed,
            origin,
        },
        smoothed_start: run.smoothed_start,
        switch: run.switch,
        output,
    })
}

/// What [`aided_run`] hands out as the filter and the smoother make it
/// (`Send`, as [`Aided::smoothed_each`]'s visitor is).
pub trait AidedObserver {
    /// Each innovation of the run, in its order (of the hypothesis handed
    /// out with the switch).
    fn innovation(&mut self, r: ekf::InnovationRecord);
    /// Each filtered epoch's point, first to last.
    fn filtered(&mut self, p: TrackPoint);
    /// Each smoothed epoch's point, last to first (after every filtered one).
    fn smoothed(&mut self, p: TrackPoint);
}

/// [`aided_tracks`]'s collector: the points kept, the innovations when
/// recorded.
struct Kept {
    filtered: Vec<TrackPoint>,
    smoothed: Vec<TrackPoint>,
    innovations: Option<Vec<ekf::InnovationRecord>>,
}

impl AidedObserver for Kept {
    fn innovation(&mut self, r: ekf::InnovationRecord) {
        if let Some(v) = &mut self.innovations {
            v.push(r);
        }
    }
    fn filtered(&mut self, p: TrackPoint) {
        self.filtered.push(p);
    }
    fn smoothed(&mut self, p: TrackPoint) {
        if self.smoothed.is_empty() {
            self.smoothed.reserve_exact(self.filtered.len());
        }
        self.smoothed.push(p);
    }
}

/// What [`aided_run`] returns besides what it handed out.
#[derive(Debug, Clone)]
pub struct AidedRun {
    /// The smoothed first epoch's time, car state and covariance.
    pub smoothed_start: Option<(f64, State, Mat)>,
    /// What the gyro-bias switch saw (`None` without one).
    pub switch: Option<BiasSwitch>,
    /// The run's counters and the indices of the fixes the gate rejected
    /// (no innovations: they went to the observer; no epochs).
    pub output: ekf::FilterOutput,
}

/// The run of [`aided_tracks`], each filtered and smoothed point and each
/// innovation handed to `obs` as it is made instead of kept: the report
/// takes only what it draws from them (a [`TrackPoint`] is 120 bytes, an
/// [`ekf::InnovationRecord`] 48, about seven a wheel epoch; issue 30).
/// `opts.record_innovations` is not read.
pub fn aided_run(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    obs: &mut (dyn AidedObserver + Send),
) -> Result<AidedRun, Error> {
    // The run keeps no epochs: the smoother runs the filter again
    // ([`Aided::smoothed_each`]).
    let opts = FilterOptions {
        record_epochs: false,
        record_innovations: false,
        ..opts.clone()
    };
    let mut output = ekf::FilterOutput::default();
    let f = Aided::run_observed(drive, params, &opts, &mut |e, u| {
        obs.filtered(TrackPoint::from_state(e.t_s, &e.x, &e.p));
        output
            .gnss_gated
            .extend(u.gated_fix_t_s.and_then(|t| ekf::fix_index(drive, t)));
        for u in u.updates {
            obs.innovation(ekf::InnovationRecord::of(e.t_s, u));
        }
    })?;
    output.stats = f.stats();
    // Smoothed from the last epoch to the first.
    let mut start = None;
    f.smoothed_each(drive, params, &opts, &mut |t, x, p| {
        obs.smoothed(TrackPoint::from_state(t, x, p));
        start = Some((t, *x, *p));
    })?;
    Ok(AidedRun {
        smoothed_start: start,
        switch: f.bias_switch(),
        output,
    })
}

/// Where dead reckoning starts: the given pose, else the truth, else the
/// start of the smoothed GNSS-aided track.
pub fn dead_reckoning_init(
    drive: &Drive,
    init_pose: Option<(f64, f64, f64)>,
    smoothed_start: Option<(f64, State, Mat)>,
) -> Result<Init, Error> {
    Ok(if let Some((e, n, y)) = init_pose {
        Init::Given {
            t_s: drive.wheels.t_s(0),
            x: State::from([e, n, y, 0.0, 0.0]),
            p: Mat::from_diagonal(&State::from([1e-4, 1e-4, 1e-6, 4.0, 0.25])),
        }
    } else if !drive.truth.is_empty() {
        Init::Truth
    } else if let Some((t_s, x, p)) = smoothed_start {
        Init::Given { t_s, x, p }
    } else {
        return Err(Need::InitialPose.into());
    })
}

/// The dead-reckoned track (proprioceptive sensors only) from `init`.
pub fn dead_reckoned(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init: Init,
) -> Result<Track, Error> {
    // Each epoch's point, not the epoch (a sixth of the memory).
    let mut points = Points(Vec::new());
    ekf::run(
        drive,
        params,
        &FilterOptions {
            init,
            sensors: SensorSet::dead_reckoning(),
            record_epochs: false,
            ..opts.clone()
        },
        &mut points,
    )?;
    Ok(Track {
        name: names::DEAD_RECKONED.into(),
        points: points.0,
        origin: drive.vehicle.origin,
    })
}

/// The track point of every epoch of a run, in order.
struct Points(Vec<TrackPoint>);

impl ekf::EpochHook for Points {
    fn after_epoch(&mut self, t_s: f64, x: &mut State, p: &mut Mat) {
        self.0.push(TrackPoint::from_state(t_s, x, p));
    }
}

/// The track named `name` among `tracks`, or an error listing the names there are.
pub fn find<'a>(tracks: &'a [Track], name: &str) -> Result<&'a Track, Error> {
    tracks.iter().find(|t| t.name == name).ok_or_else(|| {
        Error::from(Need::Track {
            name: name.to_string(),
            have: tracks.iter().map(|t| t.name.clone()).collect(),
        })
    })
}
