//! One track as the text files trajectory tools read: TUM (`evo`, the TUM RGB-D
//! tools, rpg_trajectory_evaluation) and KITTI odometry poses; and the choice
//! of a track format by file extension.
//!
//! Both are in the drive's local frame: x east, y north, z up (0), metres; the
//! pose is the rear-axle centre with its yaw about z (counter-clockwise from
//! east). Fixed precision ([`deadreckon_core::evo`]'s constants): times to the
//! nanosecond (9 decimals), positions to the micrometre (6 decimals),
//! quaternion and rotation entries to 9 decimals.

use std::path::{Path, PathBuf};

use deadreckon_core::evo::{POSITION_DECIMALS as P, ROTATION_DECIMALS as R, TIME_DECIMALS as T};
use deadreckon_core::{Track, TrackPoint};

use crate::{atomic_write, IoError};

/// The track formats `deadreckon run --out` writes, chosen by extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum TrackFormat {
    /// `.csv`: every track, with covariances ([`crate::write_track_csv`]).
    Csv,
    /// `.geojson` or `.json`: every track on a map ([`crate::write_track_geojson`]).
    GeoJson,
    /// `.tum`: one track, `timestamp tx ty tz qx qy qz qw` ([`write_track_tum`]).
    Tum,
    /// `.kitti`: one track, 3×4 pose matrices, no timestamps ([`write_track_kitti`]).
    Kitti,
    /// `.mcap`: every track, Foxglove and ROS 2 messages (written by `deadreckon-ros`).
    Mcap,
}

impl TrackFormat {
    /// The format of `path` by its extension; an unknown extension is an error
    /// naming the ones known.
    pub fn from_path(path: &Path) -> Result<TrackFormat, IoError> {
        // Extensions in any case (`track.CSV`).
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("csv") => Ok(TrackFormat::Csv),
            Some("geojson") | Some("json") => Ok(TrackFormat::GeoJson),
            Some("tum") => Ok(TrackFormat::Tum),
            Some("kitti") => Ok(TrackFormat::Kitti),
            Some("mcap") => Ok(TrackFormat::Mcap),
            other => Err(IoError::Unwritable {
                path: path.to_path_buf(),
                message: format!(
                    "unknown track format {} (use .csv, .geojson, .tum, .kitti or .mcap)",
                    other.map_or("(no extension)".to_string(), |e| format!(".{e}"))
                ),
            }),
        }
    }

    /// True for the formats that hold exactly one track (TUM, KITTI).
    pub fn holds_one_track(self) -> bool {
        matches!(self, TrackFormat::Tum | TrackFormat::Kitti)
    }
}

/// The comment line that heads a TUM file (`evo` and the TUM tools skip lines
/// starting with `#`).
pub const TUM_HEADER: &str = "# timestamp tx ty tz qx qy qz qw";

fn check(path: &Path, track: &Track) -> Result<(), IoError> {
    if track.points.is_empty() {
        return Err(IoError::Unwritable {
            path: path.to_path_buf(),
            message: format!("track `{}` has no poses", track.name),
        });
    }
    if let Some(p) = track.points.iter().find(|p| {
        !(p.t_s.is_finite()
            && p.east_m.is_finite()
            && p.north_m.is_finite()
            && p.yaw_rad.is_finite())
    }) {
        return Err(IoError::Unwritable {
            path: path.to_path_buf(),
            message: format!(
                "track `{}`: non-finite pose at t = {} s (east {}, north {}, yaw {})",
                track.name, p.t_s, p.east_m, p.north_m, p.yaw_rad
            ),
        });
    }
    Ok(())
}

/// The TUM line of one pose (no newline).
pub fn tum_line(p: &TrackPoint) -> String {
    let half = 0.5 * p.yaw_rad;
    format!(
        "{:.T$} {:.P$} {:.P$} {:.P$} {:.R$} {:.R$} {:.R$} {:.R$}",
        p.t_s,
        p.east_m,
        p.north_m,
        0.0,
        0.0,
        0.0,
        half.sin(),
        half.cos()
    )
}

/// The KITTI line of one pose: the first three rows of the 4×4 pose matrix,
/// row-major (no newline).
pub fn kitti_line(p: &TrackPoint) -> String {
    let (s, c) = p.yaw_rad.sin_cos();
    format!(
        "{c:.R$} {:.R$} {:.R$} {:.P$} {s:.R$} {c:.R$} {:.R$} {:.P$} {:.R$} {:.R$} {:.R$} {:.P$}",
        -s, 0.0, p.east_m, 0.0, p.north_m, 0.0, 0.0, 1.0, 0.0
    )
}

/// Writes one track as a TUM trajectory file (atomically): a [`TUM_HEADER`]
/// comment, a comment naming the track and frame, then one line per pose,
/// `timestamp tx ty tz qx qy qz qw` separated by single spaces. An empty track
/// or a non-finite pose is an error naming the track and time.
pub fn write_track_tum(path: &Path, track: &Track) -> Result<(), IoError> {
    check(path, track)?;
    atomic_write(path, |w| {
        writeln!(w, "{TUM_HEADER}")?;
        writeln!(
            w,
            "# deadreckon track `{}`: local frame x east, y north, z up (m), s",
            track.name
        )?;
        for p in &track.points {
            writeln!(w, "{}", tum_line(p))?;
        }
        Ok(())
    })
}

/// Where [`write_track_kitti`] writes the timestamps of `path`: beside it,
/// `<stem>.times.txt` (the KITTI odometry `times.txt` layout).
pub fn kitti_times_path(path: &Path) -> PathBuf {
    let stem = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    path.with_file_name(format!("{stem}.times.txt"))
}

/// Writes one track as KITTI odometry poses (atomically): one line per pose
/// with the 12 entries of its 3×4 matrix [R | t], nothing else (no header, no
/// timestamps: KITTI readers take every line as a pose). The timestamps go
/// to [`kitti_times_path`], one per line in seconds, in the same order, as
/// KITTI's `times.txt`.
pub fn write_track_kitti(path: &Path, track: &Track) -> Result<(), IoError> {
    check(path, track)?;
    let times = kitti_times_path(path);
    atomic_write(&times, |w| {
        for p in &track.points {
            writeln!(w, "{:.T$}", p.t_s)?;
        }
        Ok(())
    })?;
    atomic_write(path, |w| {
        for p in &track.points {
            writeln!(w, "{}", kitti_line(p))?;
        }
        Ok(())
    })
}
