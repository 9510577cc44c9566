//! `deadreckon run`: write the dead-reckoned track (and, with GNSS, the filtered
//! and smoothed ones, and the truth) with covariances, or one of them as TUM or
//! KITTI for `evo`.

use std::path::Path;

use anyhow::{Context, Result};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::{evo, track, Track};
use deadreckon_io::TrackFormat;

use super::common;
use deadreckon_api::kinematic;

use crate::args::run::*;

/// The tracks to write: those named (in the order given), or every estimated
/// track; for TUM and KITTI exactly one, optionally synced with another.
fn select(all: &[Track], a: &RunArgs, format: TrackFormat) -> Result<Vec<Track>> {
    let mut chosen: Vec<Track> = if a.track.is_empty() {
        all.iter()
            .filter(|t| t.name != track::names::TRUTH)
            .cloned()
            .collect()
    } else {
        a.track
            .iter()
            .map(|n| track::find(all, n).cloned())
            .collect::<Result<_, _>>()?
    };
    if format.holds_one_track() && chosen.len() != 1 {
        let have: Vec<&str> = all.iter().map(|t| t.name.as_str()).collect();
        anyhow::bail!(
            "{} holds one track: choose it with --track NAME ({})",
            a.out.display(),
            have.join(", ")
        );
    }
    if let Some(with) = &a.sync_with {
        anyhow::ensure!(
            format.holds_one_track(),
            "--sync-with is for TUM and KITTI files (one track)"
        );
        let other = track::find(all, with)?;
        chosen[0] = evo::synced(&chosen[0], other, a.max_diff_s)?;
    }
    Ok(chosen)
}

/// Writes tracks in the format of the file's extension.
pub fn write_tracks(
    path: &Path,
    format: TrackFormat,
    tracks: &[Track],
    mcap: McapContent,
) -> Result<()> {
    match format {
        TrackFormat::Csv => deadreckon_io::write_track_csv(path, tracks)?,
        TrackFormat::GeoJson => deadreckon_io::write_track_geojson(path, tracks)?,
        TrackFormat::Tum => deadreckon_io::write_track_tum(path, &tracks[0])?,
        TrackFormat::Kitti => deadreckon_io::write_track_kitti(path, &tracks[0])?,
        TrackFormat::Mcap => {
            let options = match mcap {
                McapContent::Foxglove => deadreckon_ros::McapOptions::FOXGLOVE,
                McapContent::Ros2 => deadreckon_ros::McapOptions::ROS2,
                McapContent::Both => deadreckon_ros::McapOptions::BOTH,
            };
            deadreckon_ros::write_mcap_with(path, tracks, None, options)?
        }
        f => anyhow::bail!("{}: format {f:?} is not written by run", path.display()),
    }
    Ok(())
}

/// Runs `run`.
pub fn run(a: RunArgs, load: &common::Loader) -> Result<()> {
    common::check_output(&a.out, &[&a.dir, Path::new(&a.params)])?;
    if kinematic::is_tricycle_log(&a.dir) {
        // The tricycle is dead-reckoned through its own kinematics (the car
        // filter's wheel and steering observations oscillate at its steering
        // angles near 1.1 rad), from the first tracker pose.
        anyhow::ensure!(
            a.init_pose.is_none(),
            "a tricycle log starts from its first tracker pose: --init-pose is not used"
        );
        let all = kinematic::tricycle_tracks(&a.dir, &a.params)?;
        let format = TrackFormat::from_path(&a.out)?;
        let t = select(&all, &a, format)?;
        write_tracks(&a.out, format, &t, a.mcap)
            .with_context(|| format!("writing {}", a.out.display()))?;
        for tr in &t {
            outln!("{:<14} {:>7} poses", tr.name, tr.points.len());
        }
        outln!("wrote {}", a.out.display());
        return Ok(());
    }
    let drive = load.drive(&a.dir)?;
    let (params, drive) = deadreckon_api::load::params_corrected(&a.params, drive)?;
    let init_pose = match &a.init_pose {
        Some(s) => {
            let v: Vec<f64> = s
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .context("--init-pose EAST_M,NORTH_M,YAW_RAD")?;
            anyhow::ensure!(
                v.len() == 3 && v.iter().all(|x| x.is_finite()),
                "--init-pose needs three finite numbers EAST_M,NORTH_M,YAW_RAD"
            );
            Some((v[0], v[1], v[2]))
        }
        None => None,
    };
    let opts = FilterOptions {
        timing: a.timing.into(),
        wheel_monitor: common::wheel_monitor(a.no_wheel_monitor),
        ..Default::default()
    };
    let format = TrackFormat::from_path(&a.out)?;
    let all = common::all_tracks(&drive, &params, &opts, init_pose)?;
    let t = select(&all, &a, format)?;
    write_tracks(&a.out, format, &t, a.mcap)
        .with_context(|| format!("writing {}", a.out.display()))?;
    // The monitor over the GNSS-aided run (the filtered track's).
    // (A drive without GNSS has no aided run: the health is then not checked.)
    let health = match opts.wheel_monitor {
        Some(_) => deadreckon_core::wheel_health::check_drive(&drive, &params, &opts)
            .map_err(|e| e.to_string()),
        None => Err("--no-wheel-monitor".into()),
    };
    if a.json {
        let v = serde_json::json!({
            "wrote": a.out.display().to_string(),
            "tracks": t.iter().map(|tr| serde_json::json!({"name": tr.name, "poses": tr.points.len()})).collect::<Vec<_>>(),
            "wheel_health": health.as_ref().ok().map(deadreckon_api::json::wheel_health_json),
        });
        common::print_json(load, v)?;
        return Ok(());
    }
    for tr in &t {
        outln!("{:<14} {:>7} poses", tr.name, tr.points.len());
    }
    match &health {
        Ok(h) => common::print_wheel_health(h)?,
        Err(why) => outln!("wheel health: not checked ({why})"),
    }
    outln!("wrote {}", a.out.display());
    if format == TrackFormat::Kitti {
        outln!(
            "wrote {} (the poses' timestamps)",
            deadreckon_io::kitti_times_path(&a.out).display()
        );
    }
    Ok(())
}
