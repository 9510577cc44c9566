//! `deadreckon run`: tracks written for other tools. The tracks of a drive
//! (dead-reckoned, filtered, smoothed, and the truth), those chosen
//! (optionally time-synced with another, as evo pairs them), written in the
//! format of the file's extension (CSV, GeoJSON, TUM, KITTI, MCAP), with the
//! wheel-health verdict of the aided run. The CSV carries the 95 % bound
//! of the dead-reckoned and filtered poses ([`bounds_95_m`]).

use std::path::{Path, PathBuf};

use deadreckon_core::aided::BiasSwitch;
use deadreckon_core::bound::BoundFit;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::wheel_health::WheelHealth;
use deadreckon_core::{evo, track, Drive, Params, Track};
use deadreckon_io::TrackFormat;

use crate::error::{invalid, While};
use crate::Error;

/// Which tracks go into the file.
#[derive(Debug, Clone, Default)]
pub struct Selection {
    /// Those named, in this order (empty: every estimated track).
    pub names: Vec<String>,
    /// TUM/KITTI: the track's poses paired in time with this one's.
    pub sync_with: Option<String>,
    /// Largest time difference of paired poses, s.
    pub max_diff_s: f64,
}

/// Every track of a drive: the estimated ones
/// ([`deadreckon_core::track::drive_tracks`]) and, with truth, `truth`.
pub fn drive_tracks(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<Vec<Track>, Error> {
    Ok(drive_tracks_and_switch(drive, params, opts, init_pose)?.0)
}

/// [`drive_tracks`], and what the aided run's gyro-bias switch saw
/// (`None` without one: `[noise] gyro_bias_switch_llr`,
/// [`deadreckon_core::aided::switch`]).
pub fn drive_tracks_and_switch(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<(Vec<Track>, Option<BiasSwitch>), Error> {
    let (mut t, switch) = track::drive_tracks_and_switch(drive, params, opts, init_pose)?;
    t.extend(Track::from_truth(drive));
    Ok((t, switch))
}

/// The 95 % bound of each pose of each of `tracks` (those of
/// [`drive_tracks`] with the same `opts` and `init_pose`), m, empty for a
/// track without one ([`deadreckon_core::bound_pose`]'s rule): the
/// filtered track's from its covariance and the last fix given at or
/// before each pose (what `stream` gives its poses); the dead-reckoned
/// track's from its covariance and, when it started from the smoothed
/// GNSS track, the declared accuracy of the last fix at or before its
/// start (none from the truth or a given pose). The smoothed track, the
/// truth and tracks without a covariance have none: the factor was fitted
/// on the causal filter's outages.
pub fn bounds_95_m(
    drive: &Drive,
    tracks: &[Track],
    fit: &BoundFit,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Vec<Vec<f64>> {
    use deadreckon_core::bound_pose;
    let wander_carried = bound_pose::carries_wander(&drive.vehicle.noise);
    tracks
        .iter()
        .map(|t| {
            if deadreckon_io::carries_no_covariance(t) {
                return Vec::new();
            }
            match t.name.as_str() {
                track::names::FILTERED => bound_pose::filtered_bounds_m(
                    t,
                    &drive.gnss,
                    &opts.gnss_outages,
                    fit,
                    wander_carried,
                ),
                track::names::DEAD_RECKONED => {
                    // A smoothed start separated from the receiver's wander
                    // carries the offset in its covariance: no floor.
                    let from_gnss =
                        init_pose.is_none() && drive.truth.is_empty() && !wander_carried;
                    let start = t.points.first().map_or(f64::NEG_INFINITY, |p| p.t_s);
                    let handed = drive.gnss.partition_point(|g| g.t_s <= start);
                    let std_m = match handed.checked_sub(1) {
                        Some(i) if from_gnss => {
                            deadreckon_core::bound::receiver_std_m(&drive.gnss[i])
                        }
                        _ => 0.0,
                    };
                    bound_pose::dead_reckoned_bounds_m(t, std_m, fit)
                }
                _ => Vec::new(),
            }
        })
        .collect()
}

impl Selection {
    /// Whether [`select`] may take the truth's track into `format`: when
    /// tracks are named or synced, or the format holds one track (its
    /// error lists the names to choose from). Otherwise it writes every
    /// estimated track and never the truth.
    pub fn may_choose_truth(&self, format: TrackFormat) -> bool {
        !self.names.is_empty() || self.sync_with.is_some() || format.holds_one_track()
    }
}

/// The tracks to write into `out`: those named, or every estimated track
/// (moved out of `all`, not copied); for TUM and KITTI exactly one,
/// optionally synced with another.
pub fn select(
    all: Vec<Track>,
    s: &Selection,
    out: &Path,
    format: TrackFormat,
) -> Result<Vec<Track>, Error> {
    let have: Vec<String> = all.iter().map(|t| t.name.clone()).collect();
    // The track to sync with, taken before `all` is moved from.
    let other = s.sync_with.as_ref().map(|w| track::find(&all, w).cloned());
    let mut chosen: Vec<Track> = if s.names.is_empty() {
        all.into_iter()
            .filter(|t| t.name != track::names::TRUTH)
            .collect()
    } else {
        s.names
            .iter()
            .map(|n| track::find(&all, n).cloned())
            .collect::<Result<_, _>>()?
    };
    if format.holds_one_track() && chosen.len() != 1 {
        invalid!(
            "{} holds one track: choose it with --track NAME ({})",
            out.display(),
            have.join(", ")
        );
    }
    if let Some(other) = other {
        if !format.holds_one_track() {
            invalid!("--sync-with is for TUM and KITTI files (one track)");
        }
        chosen[0] = evo::synced(&chosen[0], &other?, s.max_diff_s)?;
    }
    Ok(chosen)
}

/// Writes tracks in `format` (MCAP with `mcap`'s schemas); a CSV carries
/// `bounds` (per track, [`bounds_95_m`]; missing or empty: none).
pub fn write(
    path: &Path,
    format: TrackFormat,
    tracks: &[Track],
    bounds: &[Vec<f64>],
    mcap: deadreckon_ros::McapOptions,
) -> Result<(), Error> {
    let context = || format!("writing {}", path.display());
    match format {
        TrackFormat::Csv => {
            deadreckon_io::write_track_csv_with_bounds(path, tracks, bounds).doing(context)
        }
        TrackFormat::GeoJson => deadreckon_io::write_track_geojson(path, tracks).doing(context),
        TrackFormat::Tum => deadreckon_io::write_track_tum(path, &tracks[0]).doing(context),
        TrackFormat::Kitti => deadreckon_io::write_track_kitti(path, &tracks[0]).doing(context),
        TrackFormat::Mcap => {
            deadreckon_ros::write_mcap_with(path, tracks, None, mcap).doing(context)
        }
        f => Err(Error::While {
            what: context(),
            source: format!("{}: format {f:?} is not written by run", path.display()).into(),
        }),
    }
}

/// What `run` wrote.
#[derive(Debug)]
pub struct Written {
    /// The file.
    pub path: PathBuf,
    /// Its format.
    pub format: TrackFormat,
    /// Each track's name and number of poses.
    pub tracks: Vec<(String, usize)>,
    /// The wheel monitor over the GNSS-aided run, or why it was not run
    /// (`None`: not asked, as for a tricycle).
    pub health: Option<Result<WheelHealth, String>>,
    /// What the aided run's gyro-bias switch saw (`None` without one).
    pub bias_switch: Option<BiasSwitch>,
}

impl Written {
    /// The `--json` object.
    pub fn json(&self) -> serde_json::Value {
        serde_json::json!({
            "wrote": self.path.display().to_string(),
            "tracks": self.tracks.iter().map(|(name, n)| serde_json::json!({"name": name, "poses": n})).collect::<Vec<_>>(),
            "wheel_health": self.health.as_ref().and_then(|h| h.as_ref().ok()).map(crate::json::wheel_health_json),
            "gyro_bias_switch": self.bias_switch.as_ref().map(crate::json::bias_switch_json),
        })
    }

    /// The text: the tracks, the wheel health, the files written.
    pub fn lines(&self) -> Vec<String> {
        let mut out: Vec<String> = self
            .tracks
            .iter()
            .map(|(name, n)| format!("{name:<14} {n:>7} poses"))
            .collect();
        match &self.health {
            Some(Ok(h)) => out.extend(crate::text::wheel_health_lines(h)),
            Some(Err(why)) => out.push(format!("wheel health: not checked ({why})")),
            None => {}
        }
        out.extend(self.bias_switch.as_ref().map(ToString::to_string));
        out.push(format!("wrote {}", self.path.display()));
        if self.format == TrackFormat::Kitti {
            out.push(format!(
                "wrote {} (the poses' timestamps)",
                deadreckon_io::kitti_times_path(&self.path).display()
            ));
        }
        out
    }
}

/// Writes the chosen tracks of a car's drive to `out` (a CSV with the
/// 95 % bound of `bound`'s factor, [`bounds_95_m`]) and checks the wheels
/// over the aided run (unless the monitor is off).
#[allow(clippy::too_many_arguments)]
pub fn write_car(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
    out: &Path,
    s: &Selection,
    mcap: deadreckon_ros::McapOptions,
    bound: &BoundFit,
) -> Result<Written, Error> {
    let format = TrackFormat::from_path(out)?;
    // The truth's track only where `select` can choose it (its track is
    // twice the size of an estimated one at 100 Hz).
    let (all, bias_switch) = if s.may_choose_truth(format) {
        drive_tracks_and_switch(drive, params, opts, init_pose)?
    } else {
        track::drive_tracks_and_switch(drive, params, opts, init_pose)?
    };
    let t = select(all, s, out, format)?;
    let bounds = if format == TrackFormat::Csv {
        bounds_95_m(drive, &t, bound, opts, init_pose)
    } else {
        Vec::new()
    };
    write(out, format, &t, &bounds, mcap)?;
    // (A drive without GNSS has no aided run: the health is then not checked.)
    let health = match opts.wheel_monitor {
        Some(_) => {
            deadreckon_core::ekf::check_wheels(drive, params, opts).map_err(|e| e.to_string())
        }
        None => Err("--no-wheel-monitor".into()),
    };
    Ok(Written {
        path: out.to_path_buf(),
        format,
        tracks: t.iter().map(|t| (t.name.clone(), t.points.len())).collect(),
        health: Some(health),
        bias_switch,
    })
}

/// Writes a tricycle's chosen tracks (dead-reckoned through its own
/// kinematics from the first tracker pose, and the tracker's): the log at
/// `log`, or `drive` read from it (an imported tricycle directory).
pub fn write_tricycle(
    log: &Path,
    drive: Option<&Drive>,
    params: Option<&str>,
    out: &Path,
    s: &Selection,
    mcap: deadreckon_ros::McapOptions,
) -> Result<Written, Error> {
    let (all, _) = crate::kinematic::tricycle_tracks(log, drive, params)?;
    write_tracks(all, out, s, mcap)
}

/// Writes the chosen tracks of `all` (no wheel health: a kinematic
/// shape's tracks).
pub fn write_tracks(
    all: Vec<Track>,
    out: &Path,
    s: &Selection,
    mcap: deadreckon_ros::McapOptions,
) -> Result<Written, Error> {
    let format = TrackFormat::from_path(out)?;
    let t = select(all, s, out, format)?;
    write(out, format, &t, &[], mcap)?;
    Ok(Written {
        path: out.to_path_buf(),
        format,
        tracks: t.iter().map(|t| (t.name.clone(), t.points.len())).collect(),
        health: None,
        bias_switch: None,
    })
}
